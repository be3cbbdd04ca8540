"""Model-based estimation: fit the forward model to a frame (maximum likelihood).

With independent Gaussian reading noise of equal variance (docs/accuracy.md), the
maximum-likelihood contact is the least-squares fit of the expected frame (eqs. 1-2
through the converter, scaled by each tactel's baseline) to the readings. The
parameters are the probe's position along and around the finger and its force; the
fit starts from the interpolation estimate of :func:`~tactsense.estimate.finger.locate`.
Only physics functions are used (the array response), never the simulator.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import least_squares

from tactsense._validation import TactsenseInputError, check_frames
from tactsense.estimate.finger.locate import locate
from tactsense.physics.array_response import probe_response
from tactsense.physics.transduction import deflection_to_counts
from tactsense.sensor import SensorSpec

START_FORCE_N = 0.5
"""The fit's starting force where the interpolation gives none (a saturated frame, or
one whose deflections sum to zero or less) [N]: about a 50-g probe."""


@dataclass
class ModelEstimates:
    """Per-frame maximum-likelihood estimates (NaN where the frame had no contact)."""

    axial_mm: np.ndarray
    angle_deg: np.ndarray
    force_n: np.ndarray
    converged: np.ndarray
    residual_counts: np.ndarray
    """RMS residual of the fit [counts]."""


def fit_frames(
    frames, sensor: SensorSpec, *, baseline, contact_diameter_mm: float = 3.0, start=None
) -> ModelEstimates:
    """Maximum-likelihood probe position and force for each frame.

    Parameters
    ----------
    frames : array_like, shape (T, rows, cols)
        Readings [counts].
    baseline : array_like, shape (rows, cols)
        Undeflected readings [counts].
    contact_diameter_mm : float
        Probe contact size assumed by the model [mm].
    start : Estimates, optional
        Starting points; default :func:`locate` on the same frames.
    """
    frames = check_frames(frames, sensor.shape).astype(float)
    if frames.ndim != 3:
        raise TactsenseInputError(f"frames has shape {frames.shape}; expected (T, rows, cols)")
    baseline = np.asarray(baseline, dtype=float)
    if start is None:
        start = locate(frames, sensor, baseline=baseline)
    n = frames.shape[0]
    out = ModelEstimates(
        *(np.full(n, np.nan) for _ in range(3)), np.zeros(n, bool), np.full(n, np.nan)
    )
    nominal = float(deflection_to_counts(sensor, 0.0, quantize=False))
    scale = baseline / nominal
    steps = np.array([1e-4, 1e-3, 1e-6])  # mm, deg, N: central differences

    def model(thetas):
        thetas = np.atleast_2d(thetas)
        deflection = probe_response(
            sensor,
            thetas[:, 0],
            thetas[:, 1],
            thetas[:, 2],
            contact_diameter_mm=contact_diameter_mm,
        )
        return scale * deflection_to_counts(sensor, deflection, quantize=False)

    def jacobian(theta, usable):
        probes = np.repeat(theta[None, :], 6, axis=0)
        for k in range(3):
            probes[2 * k, k] += steps[k]
            probes[2 * k + 1, k] -= steps[k]
        values = model(probes)
        return np.stack(
            [(values[2 * k] - values[2 * k + 1])[usable] / (2 * steps[k]) for k in range(3)], axis=1
        )

    for k in range(n):
        if not np.isfinite(start.axial_mm[k]):
            continue
        force0 = start.force_n[k]  # NaN when saturated or when the sum is not positive
        force0 = force0 if np.isfinite(force0) and force0 > 1e-3 else START_FORCE_N
        theta0 = np.array([start.axial_mm[k], start.angle_deg[k], force0])
        frame = frames[k]
        usable = np.isfinite(frame) & (frame > 0)
        fit = least_squares(
            lambda t, f=frame, u=usable: (model(t)[0] - f)[u],
            theta0,
            jac=lambda t, f=frame, u=usable: jacobian(t, u),
            x_scale=[0.1, 1.0, 0.01],
        )
        out.axial_mm[k], out.angle_deg[k], out.force_n[k] = fit.x
        out.angle_deg[k] = (out.angle_deg[k] + 180.0) % 360.0 - 180.0
        out.converged[k] = fit.success
        out.residual_counts[k] = np.sqrt(np.mean(fit.fun**2))
    return out
