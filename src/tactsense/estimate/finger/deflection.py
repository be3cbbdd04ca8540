"""From A/D counts to fractional deflection, with per-frame quality flags (eq. 4)."""

from __future__ import annotations

import numpy as np

from tactsense._validation import TactsenseInputError, check_frames
from tactsense.estimate.results import Flag
from tactsense.physics.transduction import fractional_deflection
from tactsense.sensor import SensorSpec


def baseline_from(frames, n_frames: int = 5) -> np.ndarray:
    """Baseline (undeflected) reading: the median of the first ``n_frames`` frames.

    Parameters
    ----------
    frames : ndarray, shape (T, rows, cols)
        A recording that starts untouched [counts].
    n_frames : int
    """
    frames = np.asarray(frames, dtype=float)
    if frames.ndim != 3:
        raise TactsenseInputError(f"frames has shape {frames.shape}; expected (T, rows, cols)")
    if not 1 <= n_frames <= frames.shape[0]:
        raise TactsenseInputError(
            f"need {n_frames} untouched frames for a baseline; the recording has {frames.shape[0]}"
        )
    return np.nanmedian(frames[:n_frames], axis=0)


def deflection_from_counts(frames, baseline, sensor: SensorSpec, *, dead=None):
    """Fractional deflection of every tactel (eq. 4) and the flags of each frame.

    Parameters
    ----------
    frames : array_like, shape (..., rows, cols)
        Readings V_S [counts].
    baseline : array_like, shape (rows, cols)
        Undeflected readings V_o [counts].
    sensor : SensorSpec
        Gives the frame shape and the converter's full scale.
    dead : array_like of bool, shape (rows, cols), optional
        Tactels known to be dead (from a calibration).

    Returns
    -------
    deflection : ndarray, shape (..., rows, cols)
        dd / d_o [-]; 0 where a tactel is unusable.
    flags : ndarray of int, shape (...)
        :class:`Flag` bits per frame.
    """
    frames = check_frames(frames, sensor.shape).astype(float)
    baseline = check_frames(baseline, sensor.shape, "baseline").astype(float)
    if baseline.ndim != 2:
        raise TactsenseInputError(f"baseline has shape {baseline.shape}; expected {sensor.shape}")
    lead = frames.shape[:-2]
    flags = np.zeros(lead, dtype=np.int64)
    bad_input = ~np.isfinite(frames)
    flags |= np.where(bad_input.any(axis=(-2, -1)), int(Flag.NAN_INPUT), 0)
    full_scale = 2**sensor.electronics.adc_bits - 1
    saturated = frames >= full_scale
    flags |= np.where(saturated.any(axis=(-2, -1)), int(Flag.SATURATED), 0)
    dead_mask = ~np.isfinite(baseline) | (baseline <= 0)
    if dead is not None:
        dead_mask = dead_mask | np.asarray(dead, dtype=bool)
    reads_zero = np.where(bad_input, False, frames <= 0)
    unusable = bad_input | reads_zero | dead_mask
    flags |= np.where((reads_zero | dead_mask).any(axis=(-2, -1)), int(Flag.DEAD_TACTEL), 0)
    safe = np.where(unusable, 1.0, frames)
    deflection = fractional_deflection(safe, np.where(dead_mask, 1.0, baseline))
    return np.where(unusable, 0.0, deflection), flags
