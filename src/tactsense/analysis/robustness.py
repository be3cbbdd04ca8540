"""The inverse crime, measured: how wrong are the contacts when the estimator's model of
the finger is a bit wrong, and does calibrating fix it?

Every other accuracy figure of tactsense estimates frames that the same model made. Here
the frames come from a *true* finger whose depth, Poisson's ratio, rubber modulus, ring
stiffness or gain spread differ from the description the estimator is given, by amounts a
real finger differs from its drawing (10-20 %, and an uncalibrated gain spread). Two
estimators are compared, each without and with the calibration step:

* ``interpolation``: :func:`tactsense.locate` (the paper's eqs. 48 and 54);
* ``model``: :func:`tactsense.estimate.finger.model_fit.fit_frames` (maximum likelihood on the
  forward model, the estimator whose accuracy reaches the Cramer-Rao bound);
* ``calibrated``: the section 4.1 knife-edge fit replaces the assumed depth and Poisson's
  ratio, then the section 3.1 sweep with the 50-g probe gives every tactel's gain against
  the model's expected peak, which also absorbs an error of modulus or ring stiffness.

Positions are random in the interior of the cylinder (rows 2-6), one 50-g probe each,
frames with read noise and quantization; errors are against the load applied.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from tactsense.estimate.finger import calibrate as cal
from tactsense.estimate.finger.deflection import baseline_from
from tactsense.estimate.finger.locate import locate
from tactsense.estimate.finger.model_fit import fit_frames
from tactsense.geometry import wrap_angle_deg
from tactsense.physics.contact import Probe, grams_force
from tactsense.physics.transduction import deflection_to_counts
from tactsense.sensor import SensorSpec
from tactsense.simulate import Scenario, Step, calibration_sweep, knife_edge_sweep, simulate

FLAWS = ["noise", "quantization"]
ALL_FLAWS = ["gain_spread", "jitter", "noise", "quantization", "nonlinearity", "viscoelastic"]
FORWARD = "_forward"
"""Key of a true finger made by another forward model (``simulate(forward=...)``)."""
FLAWS_KEY = "_flaws"
"""Key of a true finger's own flaws (default: read noise and quantization)."""


def perturbations(spec: SensorSpec) -> dict[str, dict]:
    """The true fingers of the study: name -> ``SensorSpec.replace`` arguments."""
    e, r = spec.elastic, spec.rings
    return {
        "as assumed": {},
        "as assumed, every flaw": {FLAWS_KEY: ALL_FLAWS},
        "depth +15 %": {"elastic__effective_depth_mm": 1.15 * e.effective_depth_mm},
        "depth -15 %": {"elastic__effective_depth_mm": 0.85 * e.effective_depth_mm},
        "nu -15 %": {"elastic__effective_poisson_ratio": 0.85 * e.effective_poisson_ratio},
        "modulus +20 %": {"elastic__youngs_modulus_pa": 1.2 * e.youngs_modulus_pa},
        "ring stiffness +20 %": {"rings__copper_modulus_pa": 1.2 * r.copper_modulus_pa},
        "gain spread": {},  # the sensor's gain spread switched on (the others: off)
        "depth +15 %, nu -15 %, modulus +20 %": {
            "elastic__effective_depth_mm": 1.15 * e.effective_depth_mm,
            "elastic__effective_poisson_ratio": 0.85 * e.effective_poisson_ratio,
            "elastic__youngs_modulus_pa": 1.2 * e.youngs_modulus_pa,
        },
        "softer rubber (modulus -30 %)": {"elastic__youngs_modulus_pa": 0.7 * e.youngs_modulus_pa},
        # not the 2-D model with other numbers: the 3-D skin's finite-element response
        "3-D skin": {FORWARD: "finger3d"},
        "3-D skin, every flaw": {FORWARD: "finger3d", FLAWS_KEY: ALL_FLAWS},
        # the same skin on section 2.3's foam dielectric (docs/model.md, section 3c)
        "3-D skin on foam": {FORWARD: "finger3d-foam"},
        "3-D skin on foam, every flaw": {FORWARD: "finger3d-foam", FLAWS_KEY: ALL_FLAWS},
    }


@dataclass(frozen=True)
class Row:
    """One line of the study: errors of one estimator on one true finger."""

    finger: str
    estimator: str
    calibrated: bool
    along_mm: float
    """Largest |error| along the finger [mm]."""
    around_deg: float
    """Largest |error| around the finger [deg]."""
    force_pct: float
    """Largest |error| of the total force [%]."""
    fitted_depth_mm: float
    fitted_nu: float


def _positions(spec: SensorSpec, n: int, rng) -> list[tuple[float, float]]:
    axial = rng.uniform(spec.row_axial_mm[2], spec.row_axial_mm[6], n)
    if spec.closes_circumference:
        angle = rng.uniform(-180.0, 180.0, n)
    else:
        angle = rng.uniform(spec.col_angle_deg[1], spec.col_angle_deg[-2], n)
    return list(zip(axial.tolist(), angle.tolist(), strict=True))


def _calibrate(assumed: SensorSpec, truth: SensorSpec, flaws, seed: int, forward: str = "twin"):
    """The two calibration steps run on the true finger (made by ``forward``); the
    estimator's corrected model."""
    knife = simulate(truth, knife_edge_sweep(truth), flaws=flaws, rng=seed, forward=forward)
    base = baseline_from(knife.frames, 5)
    signal = (knife.frames[:, 4, 0] - base[4, 0]) / knife.frames[:, 4, 0]
    last, steps = knife.last_loaded_frames(4, 0)
    fit = cal.fit_plane_stress(knife.truth["step_axial_mm"][steps], signal[last])
    corrected = assumed.replace(
        elastic__effective_depth_mm=fit.depth_mm, elastic__effective_poisson_ratio=fit.poisson_ratio
    )
    sweep = simulate(truth, calibration_sweep(truth), flaws=flaws, rng=seed + 1, forward=forward)
    calibration = cal.calibrate_sweep(sweep.frames, corrected)
    return corrected, calibration, fit


def _errors(estimates_axial, estimates_angle, estimates_force, truth_steps):
    axial, angle, force = truth_steps
    d_along = np.abs(estimates_axial - axial)
    d_around = np.abs(wrap_angle_deg(estimates_angle - angle))
    d_force = 100 * np.abs(estimates_force / force - 1)
    # a located contact whose force the estimator withholds (NEGATIVE_FORCE, SATURATED)
    # counts as a force error of 100 %, not as no error
    withheld = np.isfinite(estimates_axial) & ~np.isfinite(estimates_force)
    d_force = np.where(withheld, 100.0, d_force)
    return float(np.nanmax(d_along)), float(np.nanmax(d_around)), float(np.nanmax(d_force))


def robustness_study(
    assumed: SensorSpec,
    *,
    n_positions: int = 24,
    grams: float = 50.0,
    seed: int = 0,
    fingers: list[str] | None = None,
    progress: Callable[[str], None] | None = None,
) -> list[Row]:
    """Estimate contacts on true fingers that differ from ``assumed``; see the module.

    Parameters
    ----------
    assumed : SensorSpec
        The description the estimators are given (and the true finger's starting point).
    n_positions : int
        Random interior probe positions per true finger.
    fingers : list of str, optional
        Names from :func:`perturbations` (default all).

    Returns
    -------
    list of Row
        For each true finger: interpolation and model, each uncalibrated and calibrated.
    """
    rng = np.random.default_rng(seed)
    positions = _positions(assumed, n_positions, rng)
    force = grams_force(grams)
    steps = [Step((), 1.0, "baseline")]
    steps += [Step((Probe(a, b, force),), 3 / 7, "") for a, b in positions]
    scene = Scenario(tuple(steps), name="robustness")
    table = perturbations(assumed)
    rows: list[Row] = []
    for name in fingers or list(table):
        if progress is not None:
            progress(name)
        change = dict(table[name])
        forward = change.pop(FORWARD, "twin")
        flaws = change.pop(FLAWS_KEY, FLAWS + (["gain_spread"] if name == "gain spread" else []))
        truth = assumed.replace(**change)
        rec = simulate(truth, scene, flaws=flaws, rng=seed + 7, forward=forward)
        step = rec.truth["frame_step"]
        last = np.flatnonzero((step > 0) & np.r_[step[1:] != step[:-1], True])
        s = step[last]
        applied = (
            rec.truth["step_axial_mm"][s],
            rec.truth["step_angle_deg"][s],
            rec.truth["step_force_n"][s],
        )
        frames = rec.frames[last].astype(float)
        baseline = baseline_from(rec.frames, 5)
        corrected, calibration, fit = _calibrate(assumed, truth, flaws, seed + 11, forward)
        for calibrated in (False, True):
            spec = corrected if calibrated else assumed
            if calibrated:
                est = locate(frames, spec, calibration=calibration)
                # the model fit works on counts: the calibrated deflection, re-expressed
                # at the nominal operating point of the corrected model
                deflection, _ = calibration.apply(frames, spec)
                nominal = float(deflection_to_counts(spec, 0.0, quantize=False))
                counts = deflection_to_counts(spec, deflection, quantize=False)
                model_base = np.full(spec.shape, nominal)
            else:
                est = locate(frames, spec, baseline=baseline)
                counts, model_base = frames, baseline
            fitted = fit_frames(counts, spec, baseline=model_base)
            for estimator, values in (
                ("interpolation", (est.axial_mm, est.angle_deg, est.force_n)),
                ("model", (fitted.axial_mm, fitted.angle_deg, fitted.force_n)),
            ):
                along, around, force_pct = _errors(*values, applied)
                rows.append(
                    Row(
                        name,
                        estimator,
                        calibrated,
                        along,
                        around,
                        force_pct,
                        fit.depth_mm,
                        fit.poisson_ratio,
                    )
                )
    return rows


def markdown_table(rows: list[Row], spec: SensorSpec) -> str:
    """The study as a Markdown table: worst errors, uncalibrated -> calibrated."""
    lines = [
        "| true finger | estimator | along [mm] | around [deg] | force [%] "
        "| knife fit: depth [mm], nu |",
        "|---|---|---|---|---|---|",
    ]
    by_key = {(r.finger, r.estimator, r.calibrated): r for r in rows}
    for finger in dict.fromkeys(r.finger for r in rows):
        for estimator in ("interpolation", "model"):
            raw, fixed = by_key[(finger, estimator, False)], by_key[(finger, estimator, True)]
            lines.append(
                f"| {finger} | {estimator} | {raw.along_mm:.2f} -> {fixed.along_mm:.2f} "
                f"| {raw.around_deg:.1f} -> {fixed.around_deg:.1f} "
                f"| {raw.force_pct:.1f} -> {fixed.force_pct:.1f} "
                + f"| {fixed.fitted_depth_mm:.2f}, {fixed.fitted_nu:.2f} |"
            )
    return "\n".join(lines)
