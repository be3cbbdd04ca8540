"""A finger's calibration tables (section 3 of the paper): per-tactel gains, the baseline
with its drift and re-zero, and the nonlinearity's lookup table."""

from __future__ import annotations

import numpy as np

from tactsense._validation import CalibrationError, check_frames
from tactsense.sensor import SensorSpec

# ---- gains -------------------------------------------------------------------------


def gain_table(deflection, *, min_response: float = 0.01, reference: float | None = None):
    """Per-tactel gain from a recording of a probe swept over every tactel (section 3.1).

    The gain parameter of the paper is each tactel's largest fractional
    deflection during the sweep; divided by a reference it becomes the gain
    that normalizes frames (Fig. 7 after calibration). The reference is the
    deflection the model predicts for the calibration probe centred on a
    tactel (absolute gains), or, without it, the median over the array
    (relative gains, as in the paper).

    Parameters
    ----------
    deflection : ndarray, shape (T, rows, cols)
        Fractional deflection of the sweep [-].
    min_response : float
        A tactel whose largest deflection stays below this is left uncalibrated
        (gain 1, reported in ``uncalibrated``) [-].

    Returns
    -------
    gains : ndarray, shape (rows, cols)
        Relative gain [-].
    peak : ndarray, shape (rows, cols)
        Largest deflection of each tactel [-].
    uncalibrated : ndarray of bool, shape (rows, cols)
    """
    deflection = np.asarray(deflection, dtype=float)
    if deflection.ndim != 3 or deflection.shape[0] < 2:
        raise CalibrationError(
            f"a gain calibration needs a sweep of frames (T, rows, cols); got {deflection.shape}"
        )
    return gains_from_peak(deflection.max(axis=0), min_response=min_response, reference=reference)


def gains_from_peak(peak, *, min_response: float = 0.01, reference=None):
    """:func:`gain_table` from each tactel's largest deflection (for sweeps read in pieces)."""
    peak = np.asarray(peak, dtype=float)
    calibrated = peak >= min_response
    if not calibrated.any():
        raise CalibrationError(
            f"no tactel deflected more than {min_response:.3g}: the recording has no contact"
        )
    if reference is None:
        reference = np.median(peak[calibrated])
    gains = np.where(calibrated, peak / reference, 1.0)
    return gains, peak, ~calibrated


# ---- baseline, drift and re-zero ---------------------------------------------------


def track_baseline(
    frames,
    initial_baseline,
    sensor: SensorSpec,
    *,
    touch: float = 0.005,
    release: float = 0.003,
    rate: float = 0.2,
    settle_frames: int = 2,
):
    """Follow the zero of every tactel while nothing touches, and re-zero after contact.

    A frame is *touched* when its largest deflection against the current
    baseline exceeds ``touch``; contact is *broken* when it falls below
    ``release``. While untouched, the baseline follows the readings with an
    exponential average (``rate`` per frame), which absorbs slow drift; once
    contact has been broken for ``settle_frames`` frames, the baseline is reset
    to the current reading (the paper's "new zero deflection point after
    contact is broken"), so that residual strain is not read as force.

    Parameters
    ----------
    frames : ndarray, shape (T, rows, cols)
        Readings [counts].
    initial_baseline : ndarray, shape (rows, cols)
        Zero before the first frame [counts].

    Returns
    -------
    baselines : ndarray, shape (T, rows, cols)
        Baseline to use for each frame [counts].
    touched : ndarray of bool, shape (T,)
    """
    frames = check_frames(frames, sensor.shape).astype(float)
    if frames.ndim != 3:
        raise CalibrationError(f"frames has shape {frames.shape}; expected (T, rows, cols)")
    baseline = np.array(initial_baseline, dtype=float)
    baselines = np.empty_like(frames)
    touched = np.zeros(frames.shape[0], dtype=bool)
    in_contact, quiet = False, 0
    for k, frame in enumerate(frames):
        level = np.nanmax((frame - baseline) / np.where(frame > 0, frame, np.inf))
        if in_contact:
            if level < release:
                quiet += 1
                if quiet >= settle_frames:
                    in_contact, quiet = False, 0
                    baseline = frame.copy()
        elif level > touch:
            in_contact, quiet = True, 0
        touched[k] = in_contact
        if not in_contact:
            baseline = np.where(np.isfinite(frame), (1 - rate) * baseline + rate * frame, baseline)
        baselines[k] = baseline
    return baselines, touched


# ---- nonlinearity -----------------------------------------------------------------


def nonlinearity_table(loads, deflections, *, linear_below: float | None = None):
    """Lookup table from measured deflection to the deflection of a linear sensor (Fig. 6).

    The linear reference is the straight line through the origin and the
    response to the loads up to ``linear_below`` (default: the smallest half
    of the series), as the paper compares the 1-N response with "the straight
    line from the origin through the strain for a 0.5-N load".

    Parameters
    ----------
    loads : array_like, shape (n,)
        Applied forces [N], increasing.
    deflections : array_like, shape (n,)
        Measured fractional deflection of one cell at each load [-].

    Returns
    -------
    measured, linear : ndarray, shape (n + 1,)
        Table knots, starting at (0, 0); apply with :func:`apply_nonlinearity`.
    """
    loads = np.asarray(loads, dtype=float)
    deflections = np.asarray(deflections, dtype=float)
    if loads.shape != deflections.shape or loads.ndim != 1 or loads.size < 2:
        raise CalibrationError("loads and deflections must be 1-D arrays of the same length >= 2")
    order = np.argsort(loads)
    loads, deflections = loads[order], deflections[order]
    if np.any(np.diff(deflections) <= 0):
        raise CalibrationError("the deflection must grow with the load to build a lookup table")
    limit = np.median(loads) if linear_below is None else linear_below
    low = loads <= limit
    slope = np.sum(deflections[low] * loads[low]) / np.sum(loads[low] ** 2)
    return np.r_[0.0, deflections], np.r_[0.0, slope * loads]


def apply_nonlinearity(deflection, measured, linear):
    """Map measured deflection to linear deflection; the end slopes extrapolate."""
    deflection = np.asarray(deflection, dtype=float)
    result = np.interp(deflection, measured, linear)
    high = (linear[-1] - linear[-2]) / (measured[-1] - measured[-2])
    low = (linear[1] - linear[0]) / (measured[1] - measured[0])
    result = np.where(
        deflection > measured[-1], linear[-1] + high * (deflection - measured[-1]), result
    )
    return np.where(deflection < measured[0], linear[0] + low * (deflection - measured[0]), result)
