"""Checks of a finger's calibration: the plane-stress fit of section 4.1 (depth and nu
from a knife-edge sweep), the limits a fit must keep, and the array's health (sensitivity,
jitter; Figs. 8-11)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import least_squares

from tactsense._validation import CalibrationError
from tactsense.estimate.creep import Viscoelastic, creep_bounds
from tactsense.physics.halfplane import impulse_response

# ---- the plane-stress fit of section 4.1 --------------------------------------------


@dataclass(frozen=True)
class ModelFit:
    """Depth and Poisson's ratio fitted to a knife-edge sweep (section 4.1)."""

    depth_mm: float
    poisson_ratio: float
    centre_mm: float
    amplitude: float
    rms_percent: float
    """RMS residual as a percentage of full scale (the largest reading)."""


def fit_plane_stress(positions_mm, response, *, youngs_modulus: float = 2.5e5) -> ModelFit:
    """Least-squares fit of eq. 7's depth and nu to one tactel's knife-edge sweep.

    After amplitude normalization (a free amplitude) and a free centre, the
    shape of the plane-stress line-load response fixes the depth and nu.

    Parameters
    ----------
    positions_mm : ndarray, shape (n,)
        Knife-edge positions along the finger [mm].
    response : ndarray, shape (n,)
        Fractional deflection of the tactel [-].
    """
    x = np.asarray(positions_mm, dtype=float)
    r = np.asarray(response, dtype=float)
    if x.shape != r.shape or x.size < 6:
        raise CalibrationError("a model fit needs at least 6 positions with one response each")
    if r.max() <= 0:
        raise CalibrationError("the tactel never responded: no contact in the sweep")

    def shape(p):
        depth, nu, centre, amplitude = p
        h = -impulse_response(
            (x - centre) * 1e-3, depth * 1e-3, youngs_modulus=youngs_modulus, poisson_ratio=nu
        )
        return amplitude * h / h.max() if h.max() > 0 else amplitude * h

    start = [3.0, 0.3, float(x[np.argmax(r)]), float(r.max())]
    fit = least_squares(
        lambda p: shape(p) - r,
        start,
        bounds=(
            [DEPTH_BOUNDS[0], NU_BOUNDS[0], x.min(), 0],
            [DEPTH_BOUNDS[1], NU_BOUNDS[1], x.max(), np.inf],
        ),
    )
    depth, nu, centre, amplitude = fit.x
    rms = 100 * float(np.sqrt(np.mean(fit.fun**2)) / r.max())
    return ModelFit(float(depth), float(nu), float(centre), float(amplitude), rms)


DEPTH_BOUNDS = (0.2, 30.0)
"""Depths a knife-edge fit may return [mm]."""
NU_BOUNDS = (0.0, 0.5)
"""Poisson's ratios a knife-edge fit may return [-]: rubber is 0 to 0.5."""
MAX_FIT_RMS_PERCENT = 10.0
"""A fit whose RMS residual exceeds this share of full scale describes another tactel,
another load, or no contact at all [%]."""


def _at(value: float, bound: float) -> bool:
    return abs(value - bound) <= 1e-3 * max(1.0, abs(bound))


def check_model_fit(fit: ModelFit) -> list[str]:
    """Why a knife-edge fit cannot be trusted (empty if it can)."""
    problems = []
    for name, value, bounds, unit in (
        ("depth", fit.depth_mm, DEPTH_BOUNDS, " mm"),
        ("Poisson's ratio", fit.poisson_ratio, NU_BOUNDS, ""),
    ):
        for bound in bounds:
            if _at(value, bound):
                problems.append(f"{name} stopped at its bound {bound:g}{unit}")
    if fit.rms_percent > MAX_FIT_RMS_PERCENT:
        problems.append(
            f"the residual is {fit.rms_percent:.1f} % of full scale (at most "
            f"{MAX_FIT_RMS_PERCENT:g} % expected)"
        )
    return problems


def check_viscoelastic_fit(model: Viscoelastic, rms: float, dt: float, fine: int = 16) -> list[str]:
    """Why a creep fit cannot be trusted (empty if it can); ``rms`` as a share [-].

    A fraction at its upper bound, or a time constant at a bound while its fraction is
    more than 1 %, means the data did not hold the steps the model describes (a sweep
    given as --steps, a tactel the load never reached). A fraction of 0 is allowed: a
    finger may well show no creep.
    """
    problems = []
    lower, upper = creep_bounds(dt, fine)
    fractions = (
        ("delayed fraction", model.delayed_fraction, upper[1]),
        ("creep fraction", model.creep_fraction, upper[3]),
    )
    for name, value, bound in fractions:
        if _at(value, bound):
            problems.append(f"{name} stopped at its bound {bound:g}")
    taus = (
        ("delayed time constant", model.delayed_time_constant_s, model.delayed_fraction, 2),
        ("creep time constant", model.creep_time_constant_s, model.creep_fraction, 4),
    )
    for name, tau, fraction, k in taus:
        if fraction > 0.01:
            for bound in (np.exp(lower[k]), np.exp(upper[k])):
                if _at(np.log(tau), np.log(bound)):
                    problems.append(f"{name} stopped at its bound {bound:.3g} s")
    if 100 * rms > MAX_FIT_RMS_PERCENT:
        problems.append(
            f"the residual is {100 * rms:.1f} % of full scale "
            f"(at most {MAX_FIT_RMS_PERCENT:g} % expected)"
        )
    return problems


# ---- health of the array ------------------------------------------------------------


def array_health(
    peak_deflection,
    baseline_frames,
    *,
    probe_grams: float = 50.0,
    nominal_counts: float = 2000.0,
    weak: float = 0.5,
    noisy: float = 4.0,
    expected=None,
):
    """Sensitivity of every tactel and detection of dead, weak and noisy ones (Figs. 8-11).

    Parameters
    ----------
    peak_deflection : ndarray, shape (rows, cols)
        Largest deflection of each tactel under the calibration probe [-].
    baseline_frames : ndarray, shape (T, rows, cols)
        Untouched readings [counts].
    probe_grams : float
        Load of the calibration probe [g].
    weak : float
        A tactel below this share of the median sensitivity is weak [-].
    noisy : float
        A tactel whose untouched noise exceeds this many times the median is noisy [-].
    expected : ndarray, shape (rows, cols), optional
        The model's peak deflection of each tactel (:func:`expected_peaks`); with it,
        weakness is judged on measured over expected, not on the raw peak.

    Returns
    -------
    dict
        ``threshold_g`` (grams per A/D unit, Fig. 8), ``noise_counts`` (standard
        deviation untouched), and boolean masks ``dead``, ``weak``, ``noisy``.
    """
    peak = np.asarray(peak_deflection, dtype=float)
    base = np.asarray(baseline_frames, dtype=float)
    counts_change = nominal_counts * peak / np.maximum(1.0 - peak, 1e-9)
    with np.errstate(divide="ignore"):
        threshold = np.where(counts_change > 0, probe_grams / counts_change, np.inf)
    dead = (base.mean(axis=0) <= 0) | (peak <= 0)
    alive = ~dead
    relative = peak if expected is None else peak / np.asarray(expected, dtype=float)
    median_peak = np.median(relative[alive]) if alive.any() else 0.0
    noise = base.std(axis=0)
    # quantization alone gives 1/sqrt(12) counts; do not call a quiet array noisy
    floor = max(np.median(noise[alive]) if alive.any() else 0.0, 1 / np.sqrt(12))
    return {
        "threshold_g": threshold,
        "noise_counts": noise,
        "dead": dead,
        "weak": alive & (relative < weak * median_peak),
        "noisy": alive & (noise > noisy * floor),
    }


def jitter_statistics(readings, counts_per_gram):
    """Jitter of repeated loads (Figs. 10-11): standard deviation in counts and grams."""
    readings = np.asarray(readings, dtype=float)
    if readings.size < 3:
        raise CalibrationError("jitter needs at least 3 repeated applications")
    std = float(readings.std(ddof=1))
    return {
        "mean_counts": float(readings.mean()),
        "std_counts": std,
        "std_grams": std / counts_per_gram,
        "applications": int(readings.size),
    }
