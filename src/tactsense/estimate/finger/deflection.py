"""From A/D counts to fractional deflection, with per-frame quality flags (eq. 4)."""

from __future__ import annotations

from enum import IntFlag

import numpy as np

from tactsense._validation import TactsenseInputError, check_frames
from tactsense.physics.transduction import fractional_deflection
from tactsense.sensor import SensorSpec


class Flag(IntFlag):
    """Quality flags of an estimate; several may be set at once."""

    NONE = 0
    NO_CONTACT = 1
    """No tactel deflects more than the contact threshold: nothing is reported."""
    NAN_INPUT = 2
    """The frame held NaN or infinite readings; those tactels were ignored."""
    SATURATED = 4
    """A tactel read the converter's full scale: the load there is unknown."""
    DEAD_TACTEL = 8
    """A tactel read zero counts (open junction) or was marked dead; it was ignored."""
    NOT_CONVERGED = 16
    """Newton's method did not reach 0.01 tactel within its iteration limit."""
    EDGE = 32
    """The peak lies within half a tactel of an open edge of the array: biased inward."""
    TIP = 64
    """The peak lies toward the tip row, where the half-plane model does not hold."""
    MULTIPLE = 128
    """A second, separate contact was seen; the fields describe the largest one."""
    BELOW_BASELINE = 256
    """A taxel read below its baseline by more than the contact threshold where no
    tension beside a contact explains it (a resistive taxel, a frame without contact, or
    deeper than the frame's largest compression:
    :func:`~tactsense.estimate.baseline.below_baseline`): the baseline was taken under
    load, or has drifted (:class:`~tactsense.estimate.baseline.DriftBaseline`)."""
    NEGATIVE_FORCE = 512
    """A tactel is above the contact threshold but the deflections sum to zero or less:
    the skin reads as much tension as compression around the contact (as the solid 3-D
    skin can, whose tensile side lobes cancel its compression, ``docs/model.md``
    sections 3a-3b), so the sum is no measure of the load; the force is NaN."""
    BEYOND_CALIBRATION = 1024
    """The contact's total signal lies beyond the range its array calibration's weights
    covered (above the heaviest unsaturated weight): its force would be an extrapolation,
    so it is NaN (:mod:`~tactsense.estimate.array_calibration`)."""

    @classmethod
    def describe(cls, value: int) -> str:
        """Names of the flags set in ``value``, joined by '|' ('' for none)."""
        return "|".join(flag.name for flag in cls if flag and value & flag)


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
