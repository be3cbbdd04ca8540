import numpy as np
import pytest

import tactsense as ts
from tactsense.estimate import Flag


@pytest.fixture(scope="module")
def frames(initial):
    probe = ts.Probe(initial.row_axial_mm[4], 10.0, ts.grams_force(50))
    rec = ts.simulate(initial, ts.static(probe, 1.0), flaws=["quantization"], rng=0)
    return rec.frames.astype(float), ts.baseline_from(rec.frames, 5)


def test_clean_frames_have_no_flags(initial, frames):
    counts, baseline = frames
    est = ts.locate(counts[-3:], initial, baseline=baseline)
    assert np.all(est.flags == 0) and np.all(est.converged)


def test_nan_is_flagged_and_the_rest_processed(initial, frames):
    counts, baseline = frames
    bad = counts[-3:].copy()
    bad[1, 0, 5] = np.nan
    est = ts.locate(bad, initial, baseline=baseline)
    assert est.flags[1] & Flag.NAN_INPUT and not est.flags[0] & Flag.NAN_INPUT
    assert np.isfinite(est.row).all()
    assert est.row[1] == pytest.approx(est.row[0], abs=0.01)


def test_saturated_and_dead_tactels_are_flagged(initial, frames):
    counts, baseline = frames
    bad = counts[-2:].copy()
    bad[0, 7, 3] = 4095
    bad[1, 6, 6] = 0
    est = ts.locate(bad, initial, baseline=baseline)
    assert est.flags[0] & Flag.SATURATED and est.flags[1] & Flag.DEAD_TACTEL
    # a saturated frame gives no force (a lower bound only), but still a position
    assert np.isnan(est.force_n[0]) and np.isfinite(est.force_n[1])
    assert np.isfinite(est.row[0]) and np.isfinite(est.axial_mm[0])
    from tactsense.estimate.finger.realtime import RealTimeLocator

    locator = RealTimeLocator(initial, baseline)
    contact = locator(bad[0])
    assert contact.flags & Flag.SATURATED and np.isnan(contact.force_n)
    dead = np.zeros((8, 8), bool)
    dead[2, 2] = True
    est = ts.locate(counts[-1:], initial, baseline=baseline, dead=dead)
    assert est.flags[0] & Flag.DEAD_TACTEL


def test_no_contact_gives_nan_and_a_flag(initial, frames):
    counts, baseline = frames
    est = ts.locate(counts[:2], initial, baseline=baseline)
    assert np.all(est.flags & Flag.NO_CONTACT)
    assert np.all(np.isnan(est.row)) and np.all(np.isnan(est.force_n))
    assert Flag.describe(int(est.flags[0])) == "NO_CONTACT"


def test_wrong_shape_and_missing_baseline_are_errors(initial, frames):
    counts, baseline = frames
    with pytest.raises(ValueError, match=r"expected \(\.\.\., 8, 8\)"):
        ts.locate(counts[:, :7, :], initial, baseline=baseline)
    with pytest.raises(ValueError, match="need a baseline"):
        ts.locate(counts, initial)
    with pytest.raises(ValueError, match="baseline has shape"):
        ts.locate(counts, initial, baseline=counts[:3])
    with pytest.raises(ValueError, match="untouched frames"):
        ts.baseline_from(counts[:2], 5)


def test_estimation_never_imports_the_simulator():
    import ast
    from pathlib import Path

    package = Path(ts.__file__).parent / "estimate"
    for source in package.rglob("*.py"):  # the finger and contacts subpackages too
        tree = ast.parse(source.read_text())
        for node in ast.walk(tree):
            if isinstance(node, ast.ImportFrom):
                assert node.module != "tactsense.simulate", source.name
                assert not (node.module or "").startswith("tactsense.io"), source.name
            if isinstance(node, ast.Import):
                assert all(alias.name != "tactsense.simulate" for alias in node.names)
