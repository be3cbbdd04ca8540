"""The compiled estimation agrees with the readable reference and the straightforward one."""

import numpy as np
import pytest

import tactsense as ts
from tactsense.estimate import Flag, deflection_from_counts
from tactsense.estimate.finger.angle import skew_along_finger
from tactsense.estimate.finger.force import total_force
from tactsense.estimate.finger.localize import newton_peak
from tactsense.estimate.finger.realtime import RealTimeLocator
from tactsense.physics.array_response import deflection_batch
from tactsense.physics.transduction import deflection_to_counts


@pytest.fixture(scope="module", params=["initial", "improved"])
def batch(request):
    spec = ts.preset(request.param)
    rng = np.random.default_rng(4)
    n = 300
    angle = rng.uniform(-180, 180, n) if spec.closes_circumference else rng.uniform(-70, 70, n)
    states = [
        (ts.Probe(float(a), float(b), float(f), alpha_deg=float(al)),)
        for a, b, f, al in zip(
            rng.uniform(-5, 24, n),
            angle,
            rng.uniform(0.05, 2, n),
            rng.uniform(-30, 30, n),
            strict=True,
        )
    ]
    return spec, deflection_batch(spec, states)


def test_locate_matches_the_numpy_reference(batch):
    spec, deflection = batch
    periodic = spec.closes_circumference
    est = ts.locate(deflection, spec, counts=False, threshold=-1.0)  # every frame
    start = np.unravel_index(deflection.reshape(len(deflection), -1).argmax(1), spec.shape)
    reference = newton_peak(deflection, *start, periodic=periodic, tip_row=spec.array.tip_row)
    np.testing.assert_allclose(est.row, reference.row, atol=1e-7)
    np.testing.assert_allclose(est.col, reference.col, atol=1e-7)
    np.testing.assert_array_equal(est.iterations, reference.iterations)
    np.testing.assert_allclose(est.peak_deflection, reference.value, rtol=1e-10)
    # a sum of zero or less is no force: NaN and flagged (NEGATIVE_FORCE), the rest equal
    total = total_force(deflection, spec)
    negative = total <= 0
    np.testing.assert_allclose(est.force_n[~negative], total[~negative], rtol=1e-10)
    assert np.all(np.isnan(est.force_n[negative]))
    assert np.all((est.flags[negative] & Flag.NEGATIVE_FORCE) != 0)
    assert not np.any(est.flags[~negative] & Flag.NEGATIVE_FORCE)
    with np.errstate(invalid="ignore"):
        skew = skew_along_finger(deflection, reference.row, reference.col, periodic=periodic)
    np.testing.assert_allclose(est.skew, skew, atol=1e-8)


def test_compiled_deflection_matches_eq4_reference(batch):
    spec, deflection = batch
    counts = np.rint(deflection_to_counts(spec, deflection, quantize=False))
    counts[3, 2, 2] = np.nan
    counts[4, 1, 1] = 0
    counts[5, 6, 6] = 4095
    baseline = np.full(spec.shape, 2000.0)
    reference, flags = deflection_from_counts(counts, baseline, spec)
    est = ts.locate(counts, spec, baseline=baseline)
    ours = ts.locate(reference, spec, counts=False)
    np.testing.assert_allclose(est.row, ours.row, atol=1e-9, equal_nan=True)
    assert est.flags[3] & Flag.NAN_INPUT and flags[3] & Flag.NAN_INPUT
    assert est.flags[4] & Flag.DEAD_TACTEL and flags[4] & Flag.DEAD_TACTEL
    assert est.flags[5] & Flag.SATURATED and flags[5] & Flag.SATURATED


def test_real_time_locator_gives_the_batch_answer(batch):
    spec, deflection = batch
    counts = np.rint(deflection_to_counts(spec, deflection[:50], quantize=False))
    baseline = np.full(spec.shape, 2000.0)
    est = ts.locate(counts, spec, baseline=baseline)
    locator = RealTimeLocator(spec, baseline)
    for k, frame in enumerate(counts):
        contact = locator(frame)
        assert contact.flags == est.flags[k]
        if np.isfinite(est.row[k]):
            assert contact.axial_mm == pytest.approx(est.axial_mm[k], abs=1e-9)
            assert contact.angle_deg == pytest.approx(est.angle_deg[k], abs=1e-9)
            assert contact.force_n == pytest.approx(est.force_n[k], rel=1e-12, nan_ok=True)
    with pytest.raises(ValueError, match="expected"):
        locator(np.zeros((7, 8)))


def test_agrees_with_the_straightforward_benchmark_reference(initial):
    from benchmarks.bench_locate import straightforward

    rng = np.random.default_rng(1)
    for axial, angle in zip(rng.uniform(6, 18, 4), rng.uniform(-180, 180, 4), strict=True):
        frame = ts.tactel_deflection(initial, ts.Probe(axial, angle, 0.5))
        x, y, _, skew = straightforward(frame, True)
        est = ts.locate(frame, initial, counts=False)
        assert est.row == pytest.approx(x, abs=0.01)
        assert (est.col - y + 4) % 8 - 4 == pytest.approx(0, abs=0.01)
        assert est.skew == pytest.approx(skew, abs=0.01)
