"""Simulate, then estimate: the paper's accuracy on the paper's designs at the paper's noise.

Tolerances are the paper's figures (section 7-8 and the conclusion), widened only where
the model itself says the 45-deg finger cannot do better; docs/accuracy.md has the
measured tables.
"""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import tactsense as ts
from tactsense.geometry import wrap_angle_deg

G50 = ts.grams_force(50)


def sweep_recording(
    spec, positions, force_n=G50, flaws=("noise", "quantization"), rng=0, threshold=0.005
):
    steps = [ts.Step((), 1.0, "baseline")]
    steps += [ts.Step((ts.Probe(a, b, force_n),), 3 / 7, "") for a, b in positions]
    rec = ts.simulate(spec, ts.Scenario(tuple(steps)), flaws=list(flaws), rng=rng)
    est = ts.locate(rec.frames, spec, baseline=ts.baseline_from(rec.frames, 5), threshold=threshold)
    step = rec.truth["frame_step"]
    keep = (step > 0) & (np.r_[step[1:] == step[:-1], False])  # settled frames only
    truth_axial = rec.truth["step_axial_mm"][step][keep]
    truth_angle = rec.truth["step_angle_deg"][step][keep]
    return est, keep, truth_axial, truth_angle


def interior_positions(spec, n, rng):
    rng = np.random.default_rng(rng)
    axial = rng.uniform(spec.row_axial_mm[2], spec.row_axial_mm[6], n)
    if spec.closes_circumference:
        angle = rng.uniform(-180, 180, n)
    else:
        angle = rng.uniform(spec.col_angle_deg[1], spec.col_angle_deg[-2], n)
    return list(zip(axial, angle, strict=True))


@pytest.mark.parametrize("name", ["initial", "improved"])
def test_localization_and_force_meet_the_paper(name):
    spec = ts.preset(name)
    est, keep, axial, angle = sweep_recording(spec, interior_positions(spec, 60, 1))
    d_axial = est.axial_mm[keep] - axial
    d_angle = wrap_angle_deg(est.angle_deg[keep] - angle)
    force_error = est.force_n[keep] / G50 - 1
    assert np.all(est.converged[keep])
    if name == "initial":
        # the paper: +-0.5 mm along (3.8 mm spacing), +-10 deg around (45 deg), force 20 %
        assert np.abs(d_axial).max() < 0.7
        assert np.abs(d_angle).max() < 11.0
        assert np.abs(force_error).max() < 0.20
    else:
        # 3.3 mm x 18 deg: finer sampling, less aliasing
        assert np.abs(d_axial).max() < 0.5
        assert np.abs(d_angle).max() < 2.0
        assert np.abs(force_error).max() < 0.06
    # "localization of applied forces is to within 0.2 tactel" (conclusion), along the finger
    assert np.abs(d_axial).max() / spec.array.spacing_axial_mm < 0.2
    # "convergence ... typically two or three steps"
    assert np.median(est.iterations[keep]) <= 3


@pytest.mark.parametrize("grams", [10, 50, 200])
def test_accuracy_across_loads(initial, grams):
    # 10 g between two 45-deg strips deflects the nearest tactel only 0.4 %: lower threshold
    est, keep, axial, _ = sweep_recording(
        initial, interior_positions(initial, 20, 2), force_n=ts.grams_force(grams), threshold=0.002
    )
    assert np.abs(est.axial_mm[keep] - axial).max() < (1.0 if grams == 10 else 0.7)
    # at 10 g the summed quantization and read noise of 56 tactels (about 3 counts RMS)
    # is 15 % of the signal: the force tolerance widens with it
    tolerance = {10: 0.45, 50: 0.20, 200: 0.20}[grams]
    assert np.abs(est.force_n[keep] / ts.grams_force(grams) - 1).max() < tolerance


@given(shift=st.integers(-1, 1), d_angle=st.floats(-20, 20), frac=st.floats(0.0, 1.0))
@settings(max_examples=25, deadline=None)
def test_shifted_contact_gives_shifted_estimate(initial, shift, d_angle, frac):
    # one ring spacing along the interior shifts the estimate by one spacing, up to the
    # array's ends entering the window (< 0.05 mm); turning by a strip spacing on the
    # closed ring turns it by that angle
    base = initial.row_axial_mm[4] + frac * initial.array.spacing_axial_mm
    a = ts.tactel_deflection(initial, ts.Probe(base, d_angle, G50))
    b = ts.tactel_deflection(initial, ts.Probe(base + shift * 3.8, d_angle + 45.0, G50))
    ea, eb = ts.locate(np.stack([a, b]), initial, counts=False)._asdict_rows()
    assert eb["axial_mm"] - ea["axial_mm"] == pytest.approx(shift * 3.8, abs=0.05)
    # exact up to where Newton stops: a last step under 0.01 tactel leaves ~1e-4 tactel
    assert wrap_angle_deg(eb["angle_deg"] - ea["angle_deg"]) == pytest.approx(45.0, abs=5e-3)


@given(scale=st.floats(0.05, 20.0), axial=st.floats(8.0, 17.0), angle=st.floats(-180, 180))
@settings(max_examples=25, deadline=None)
def test_scaled_load_gives_scaled_force_and_same_position(initial, scale, axial, angle):
    frame = ts.tactel_deflection(initial, ts.Probe(axial, angle, G50))
    est = ts.locate(np.stack([frame, scale * frame]), initial, counts=False, threshold=0.0)
    assert est.force_n[1] == pytest.approx(scale * est.force_n[0], rel=1e-9)
    assert est.row[1] == pytest.approx(est.row[0], abs=1e-9)
    assert est.col[1] == pytest.approx(est.col[0], abs=1e-9)


def test_contact_size_changes_force_little(initial):
    # Fig. 26: three contact lengths at 50 g; the integral stays within 20 %
    for length in (3.0, 6.0, 12.0):
        frame = ts.tactel_deflection(initial, ts.soft_object(12.5, 10.0, G50, length_mm=length))
        est = ts.locate(frame, initial, counts=False)
        assert est.force_n == pytest.approx(G50, rel=0.20)
