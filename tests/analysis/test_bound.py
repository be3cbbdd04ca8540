"""Cramer-Rao bound and the model-based estimator that reaches it."""

import numpy as np
import pytest

import tactsense as ts
from tactsense.analysis.bound import cramer_rao_bound, expected_counts, fisher_information
from tactsense.estimate.finger.model_fit import fit_frames
from tactsense.physics.array_response import deflection_batch, probe_response


def test_bound_scales_with_signal(initial):
    # at high signal the position bound falls as 1/F and the absolute force bound is flat
    low = cramer_rao_bound(initial, 12.0, 10.0, 0.2)
    high = cramer_rao_bound(initial, 12.0, 10.0, 0.8)
    assert high["axial_mm"] == pytest.approx(low["axial_mm"] / 4, rel=0.1)
    assert high["angle_deg"] == pytest.approx(low["angle_deg"] / 4, rel=0.1)
    assert high["force_n"] == pytest.approx(low["force_n"], rel=0.15)


def test_fisher_information_is_symmetric_positive_definite(any_preset):
    spec = any_preset
    information = fisher_information(
        spec, float(spec.row_axial_mm[4]), float(spec.col_angle_deg[3]), 0.5
    )
    np.testing.assert_allclose(information, information.T, rtol=1e-12)
    assert np.all(np.linalg.eigvalsh(information) > 0)


def test_expected_counts_is_the_forward_model(initial):
    counts = expected_counts(initial, 12.0, 10.0, 0.5)
    assert (
        counts.shape == (8, 8)
        and counts.max() > 2050
        and np.median(counts) == pytest.approx(2000, abs=1)
    )


def test_model_based_estimator_reaches_the_bound(initial):
    # at the paper's reading noise the fit's RMSE is within 1.2x the bound (60 frames:
    # the ratio itself is uncertain by about 9 %, so 1.35 is the test's limit)
    axial, angle, force = 12.9, 20.0, ts.grams_force(50)
    steps = [ts.Step((), 1.0)] + [ts.Step((ts.Probe(axial, angle, force),), 2 / 7)] * 60
    rec = ts.simulate(initial, ts.Scenario(tuple(steps)), flaws=["noise", "quantization"], rng=3)
    frames = rec.frames[rec.truth["frame_step"] > 0]
    fit = fit_frames(frames, initial, baseline=np.full((8, 8), 2000.0))
    bound = cramer_rao_bound(initial, axial, angle, force)
    assert np.all(fit.converged)
    for values, truth, key in (
        (fit.axial_mm, axial, "axial_mm"),
        (fit.angle_deg, angle, "angle_deg"),
        (fit.force_n, force, "force_n"),
    ):
        rmse = np.sqrt(np.mean((values - truth) ** 2))
        assert rmse < 1.35 * bound[key]
    # the interpolation estimator is far from the bound: aliasing, not noise, limits it
    interp = ts.locate(frames, initial, baseline=np.full((8, 8), 2000.0))
    assert np.sqrt(np.mean((interp.axial_mm - axial) ** 2)) > 5 * bound["axial_mm"]


def test_compiled_probe_response_is_the_general_model(any_preset):
    spec = any_preset
    rng = np.random.default_rng(2)
    n = 200
    axial, angle = rng.uniform(-19, 25, n), rng.uniform(-180, 180, n)
    force, alpha = rng.uniform(0.05, 2, n), rng.uniform(-40, 40, n)
    fast = probe_response(spec, axial, angle, force, alpha_deg=alpha)
    general = deflection_batch(
        spec,
        [
            (ts.Probe(a, b, f, alpha_deg=al), ts.Probe(0, 0, 0))
            for a, b, f, al in zip(axial, angle, force, alpha, strict=True)
        ],
    )
    np.testing.assert_allclose(fast, general, atol=1e-15)


def test_unidentifiable_contact_is_reported(initial):
    # a probe far beyond the wired tactels moves no reading: the bound does not exist
    far = initial.replace(array__wired_cols=1, array__cols=1)
    with pytest.raises(ValueError, match="not identifiable"):
        cramer_rao_bound(far, 12.0, 180.0, 0.5)
