"""Known weights to a force curve: the presses of a weights recording, the curve of the
contacts' total signal against the weight, its hysteresis and temperature coefficient,
and a load cell's force curve."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from tactsense.estimate.contacts.calibration import ArrayCalibrationError
from tactsense.estimate.contacts.lab_logs import WeightsLog


@dataclass
class Presses:
    """The presses of a weights recording (:func:`weight_presses`), in time order."""

    start: np.ndarray
    """First frame of each press [-]."""
    end: np.ndarray
    """One past its last frame [-]."""
    total: np.ndarray
    """Total signal of the press's settled part [-]."""
    force_n: np.ndarray
    """The known load [N]."""
    saturated: np.ndarray
    """A taxel read the converter's rail during the plateau [bool]."""
    temperature_c: np.ndarray | None = None
    """[degC]"""


PRESS_LEVEL = 0.03
"""A press starts where the frames' total signal rises above the level before it by more
than this share of the recording's range (or 8 times the untouched frames' noise of the
total, if larger) [-], and ends where it falls back below half its rise."""


SMOOTH_FRAMES = 9
"""Frames of the running median the total is followed through (a weight is held for
seconds; noise spikes, and a contact's noise amplified by creep compensation, last a
frame or two) [-]."""

MIN_PRESS_FRAMES = 10
"""A run shorter than this is no weight placed (a bump, or noise) [-]."""


SHORT_PRESS = 0.3
"""A run held less than this share of the series' median hold is no weight placed (a
bump of the residual an FSR keeps after a lift, or noise) [-]."""


def segment_presses(total, *, rest_frames: int = 5, level: float = PRESS_LEVEL):
    """The presses of a recording of weights placed, held and removed in turn, found in
    its frames' total signal alone.

    The total, median-filtered over :data:`SMOOTH_FRAMES` frames, is followed frame by
    frame: while unloaded, a
    press starts when the total rises above the lowest of the last 5 unloaded frames by
    more than ``level`` of the recording's range (or 8 times the noise of the first
    ``rest_frames``, if larger); its level before is the median of the last 3 unloaded
    frames; it ends when the total falls below that level plus half the press's largest
    rise (the weight lifted: creep left after it is less than half the press). Runs
    shorter than :data:`MIN_PRESS_FRAMES`, or than :data:`SHORT_PRESS` of the median
    run, are dropped.

    Returns
    -------
    list of (start, end, floor)
        Frames ``[start, end)`` of each press and the level before it [-].
    """
    from scipy.ndimage import median_filter

    t = median_filter(np.asarray(total, dtype=float), size=SMOOTH_FRAMES, mode="nearest")
    rest = t[:rest_frames]
    noise = 1.4826 * np.median(np.abs(rest - np.median(rest)))
    span = np.percentile(t, 99.5) - np.median(rest)
    on = max(8.0 * noise, level * span, 1e-12)
    presses = []
    unloaded = list(rest)
    start = None
    floor = peak = 0.0
    for i, value in enumerate(t):
        if start is None:
            # the lowest of the last unloaded frames: the tail of a lifted press, still
            # falling, never starts the next one
            if value > min(unloaded[-5:]) + on and i >= 1:
                start, floor, peak = i, float(np.median(unloaded[-3:])), value
            else:
                unloaded.append(value)
        else:
            peak = max(peak, value)
            if value < floor + 0.5 * (peak - floor):
                if i - start >= MIN_PRESS_FRAMES:
                    presses.append((start, i, floor))
                start = None
                unloaded = [value]  # the level after it, not before
    if start is not None and len(t) - start >= MIN_PRESS_FRAMES:
        presses.append((start, len(t), floor))
    if presses:  # the weights of a series are held alike: a short run is a bump
        held = np.median([b - a for a, b, _ in presses])
        presses = [p for p in presses if p[1] - p[0] >= SHORT_PRESS * held]
    return presses


def _plateau(start: int, end: int) -> slice:
    """The settled part of a press: its second half, less its last tenth (the weight
    being lifted)."""
    n = end - start
    return slice(start + n // 2, max(start + n // 2 + 1, end - max(1, n // 10)))


def weight_presses(totals, saturated, log: WeightsLog, *, time_s=None, rest_frames: int = 5,
                   timing=None):  # fmt: skip
    """The presses of a weights recording and their known loads.

    Parameters
    ----------
    totals : ndarray, shape (T,)
        Each frame's total signal (:func:`contact_totals`) [-].
    saturated : ndarray of bool, shape (T,)
        Frames with a taxel at the converter's rail.
    log : WeightsLog
        One row per press (the presses are found in ``timing``,
        :func:`segment_presses`), or timed (the presses are the runs where the logged
        load exceeds 5 % of its largest, at the frames' times ``time_s`` [s]).
    timing : ndarray, shape (T,), optional
        The total the presses are found in (default ``totals``): one with less noise,
        e.g. without creep compensation, which amplifies the noise.

    Each press's total is the median of ``totals`` over its settled part (its second
    half, less its last tenth).
    """
    totals = np.asarray(totals, dtype=float)
    temperature = None
    if log.time_s is None:
        found = segment_presses(totals if timing is None else timing, rest_frames=rest_frames)
        if len(found) != len(log.force_n):
            raise ArrayCalibrationError(
                f"found {len(found)} presses in the recording and {log.source} lists "
                f"{len(log.force_n)} weight{'s' if len(log.force_n) != 1 else ''}: one row per "
                "weight, each placed, held and removed, in the order placed (a press: the total "
                f"signal {PRESS_LEVEL:.0%} of its range above the level before, for "
                f"{MIN_PRESS_FRAMES} frames or more), or give time_s"
            )
        force = log.force_n
        temperature = log.temperature_c
    else:
        time_s = np.asarray(time_s, dtype=float)
        t0, t1 = log.time_s[0], log.time_s[-1]
        heavy = log.force_n > 0.05 * np.max(log.force_n)
        if np.max(log.force_n) <= 0:
            raise ArrayCalibrationError(f"{log.source}: no positive load in the log")
        outside = heavy & ((log.time_s < time_s[0]) | (log.time_s > time_s[-1]))
        if outside.any():
            raise ArrayCalibrationError(
                f"{log.source} has a load at {log.time_s[outside][0]:g} s, outside the "
                f"recording ({time_s[0]:g}-{time_s[-1]:g} s): is it this recording's log, "
                "on its clock?"
            )
        inside = (time_s >= t0) & (time_s <= t1)
        logged = np.where(inside, np.interp(time_s, log.time_s, log.force_n), 0.0)
        loaded = logged > 0.05 * np.max(log.force_n)
        edges = np.flatnonzero(np.diff(np.r_[False, loaded, False].astype(int)))
        found = []
        for a, b in zip(edges[::2], edges[1::2], strict=True):
            if b - a >= 3:  # the log says a load was on: kept however short
                found.append((a, b, 0.0))
        force = np.array([np.median(logged[_plateau(a, b)]) for a, b, _ in found])
        if log.temperature_c is not None:
            tc = np.interp(time_s, log.time_s, log.temperature_c)
            temperature = np.array([np.median(tc[_plateau(a, b)]) for a, b, _ in found])
    if not found:
        raise ArrayCalibrationError(f"no press found in the recording of {log.source}")
    start = np.array([a for a, _, _ in found])
    end = np.array([b for _, b, _ in found])
    # no tare: what is left of the last press (creep, an FSR's hysteresis) is in what
    # locate reads under the next load too
    total = np.array([np.median(totals[_plateau(a, b)]) for a, b, _ in found])
    sat = np.array([bool(np.any(saturated[_plateau(a, b)])) for a, b, _ in found])
    return Presses(start, end, total, np.asarray(force, float), sat, temperature)


SATURATION_SLOPE = 0.2
"""The total has saturated from the weight on which it never again exceeds the lighter
weight's total by more than this share of the mean sensitivity below (the total over
the load of the lighter weight) times the step in load [-]."""

MONOTONE_RANK = 0.8
"""Smallest rank (Spearman) correlation between the weights below the rail and their
totals: below it the log does not follow the recording (weights listed out of order,
another session's log) [-]."""

SAME_WEIGHT = 0.01
"""Presses whose loads differ by less than this share are the same weight (pooled, and
held out together) [-]."""

TOP_MARGIN = 0.02
"""The weight curve is read up to this share above the heaviest calibrated weight's total
(its own presses scatter about it), never beyond half-way to a saturated one [-]."""


def _groups(force, total, saturated):
    """Distinct weights, lightest first: their load [N], median total [-], press count
    and saturation (any press of it at the rail)."""
    order = np.argsort(force, kind="stable")
    groups, current = [], [order[0]]
    for k in order[1:]:
        if force[k] - force[current[0]] <= SAME_WEIGHT * force[current[0]]:
            current.append(k)
        else:
            groups.append(current)
            current = [k]
    groups.append(current)
    return (
        np.array([np.median(force[g]) for g in groups]),
        np.array([np.median(total[g]) for g in groups]),
        np.array([len(g) for g in groups]),
        np.array([bool(np.any(saturated[g])) for g in groups]),
        groups,
    )


def _knots(force, total, count):
    """A monotone curve's knots through the origin: the totals made non-decreasing in the
    load (isotonic regression, each weight by its press count), ties merged."""
    from scipy.optimize import isotonic_regression

    smooth = isotonic_regression(total, weights=count.astype(float), increasing=True).x
    x, ys = [0.0], [[0.0]]
    for t, f in zip(smooth, force, strict=True):
        if t > x[-1] + 1e-12 * max(1.0, abs(t)):
            x.append(float(t))
            ys.append([float(f)])
        elif len(x) > 1:  # weights pooled to one total: one knot at their mean load
            ys[-1].append(float(f))
    return x, [float(np.mean(v)) for v in ys]


def weight_curve(presses: Presses) -> dict:
    """The weight curve of a series of presses of known load.

    Each distinct weight (:data:`SAME_WEIGHT`) gives a knot at its presses' median total
    signal; the knots, through the origin, are made monotone (isotonic regression). The
    calibrated range ends before the first weight that saturated: a taxel at the rail,
    or a total that, from that weight on, never grows again by more than
    :data:`SATURATION_SLOPE` of the mean sensitivity below it. Totals that do not rise
    with the load (:data:`MONOTONE_RANK`) are refused. Each calibrated weight is then
    held out and predicted from the curve of the others (leave-one-out); the heaviest
    lies beyond the others' range and is not predicted (the curve is never
    extrapolated).

    Returns
    -------
    dict
        ``signal_total``, ``force_n`` (knots), ``signal_total_max`` (the curve's top,
        :data:`TOP_MARGIN`), ``weights`` (one entry per distinct weight: load [N],
        presses, total, saturated, and its leave-one-out prediction [N] and error [%]),
        ``saturation`` (the lightest saturated weight [N] and why, or None),
        ``loo_max_error_percent`` (the largest error [%] of the weights held out between
        two others), ``loo_lightest_error_percent`` (the lightest's, read between the
        origin and the next weight, where a response bends most), ``out_of_order``
        (pairs of neighbouring loads [N] whose totals fall as the load rises).
    """
    loads = presses.force_n
    if np.max(loads) < 1.5 * np.min(loads):
        raise ArrayCalibrationError(
            f"the log holds one load ({np.median(loads):.3g} N in all {len(loads)} presses, "
            f"{np.min(loads):.3g}-{np.max(loads):.3g} N): a curve needs weights from light to "
            "heavy (the heaviest at least 1.5 times the lightest)"
        )
    force, total, count, sat, _ = _groups(presses.force_n, presses.total, presses.saturated)
    if len(force) < 3:
        raise ArrayCalibrationError(
            f"the log holds {len(force)} distinct weight{'s' if len(force) != 1 else ''} "
            f"({', '.join(f'{f:.3g} N' for f in force)}): a curve needs at least 3 (each is "
            "held out in turn to measure its error); place weights from light to heavy"
        )
    if np.any(total <= 0):
        k = int(np.flatnonzero(total <= 0)[0])
        raise ArrayCalibrationError(
            f"the {force[k]:.3g}-N weight raised the total signal by {total[k]:.3g}: no "
            "response (a weight off the array, or below the contact threshold)"
        )
    rail = int(np.argmax(sat)) if sat.any() else len(force)
    if rail == 0:
        raise ArrayCalibrationError(
            f"every weight saturated the array (taxels at the converter's rail from the "
            f"lightest, {force[0]:.3g} N): use lighter weights, or a wider contact"
        )
    from scipy.stats import spearmanr

    rank = spearmanr(force[:rail], total[:rail]).statistic if rail >= 3 else 1.0
    if not rank >= MONOTONE_RANK:
        raise ArrayCalibrationError(
            "the total signal does not rise with the load (rank correlation "
            f"{rank:.2f} over the {rail} weights "
            f"below the rail, at least {MONOTONE_RANK:g} expected; "
            + ", ".join(f"{t:.3g} at {f:.3g} N" for f, t in zip(force[:4], total[:4], strict=True))
            + "...): are the weights listed in the order they were placed, and is it this "
            "recording's log?"
        )
    end, reason = rail, None if rail == len(force) else "taxels at the converter's rail"
    for k in range(1, rail):  # a knee: from k on, the total never grows again
        mean = total[k - 1] / force[k - 1]
        growth = SATURATION_SLOPE * mean * (force[k] - force[k - 1])
        if np.all(total[k:rail] < total[k - 1] + growth):
            end = k
            reason = (
                f"the total stopped growing (less than {SATURATION_SLOPE:.0%} of the mean "
                "sensitivity below, from there on)"
            )
            break
    if end < 3:
        raise ArrayCalibrationError(
            f"{end} weight{'s' if end != 1 else ''} below saturation (it starts at "
            f"{force[end]:.3g} N: {reason}): a curve needs at least 3; use lighter weights"
        )
    x, y = _knots(force[:end], total[:end], count[:end])
    top = x[-1] * (1 + TOP_MARGIN)
    if end < len(force):
        top = min(top, max(x[-1], x[-1] + 0.5 * (total[end] - x[-1])))
    weights = []
    for k in range(len(force)):
        entry = {"force_n": float(force[k]), "presses": int(count[k]),
                 "signal_total": float(total[k]), "saturated": bool(k >= end)}  # fmt: skip
        if k < end:
            others = np.arange(end) != k
            xo, yo = _knots(force[:end][others], total[:end][others], count[:end][others])
            if total[k] <= xo[-1]:
                predicted = float(np.interp(total[k], xo, yo))
                entry.update(loo_n=predicted, loo_error_percent=100 * (predicted / force[k] - 1),
                             loo_between=bool(total[k] >= xo[1]))  # fmt: skip
                if total[k] < xo[1]:
                    entry["loo_note"] = "below the others: read between the origin and the next"
            else:
                entry.update(loo_n=None, loo_error_percent=None,
                             loo_note="beyond the others' range: not extrapolated")  # fmt: skip
        weights.append(entry)
    # neighbours whose totals fall as the load rises: pooled by the monotone fit, and a
    # sign of a log out of the placing order more than of a bend
    disorder = [[float(force[k]), float(force[k + 1])] for k in range(end - 1)
                if total[k + 1] < total[k]]  # fmt: skip
    errors = [abs(w["loo_error_percent"]) for w in weights if w.get("loo_between")]
    lightest = [w["loo_error_percent"] for w in weights
                if w.get("loo_error_percent") is not None and not w["loo_between"]]  # fmt: skip
    return {
        "signal_total": x,
        "force_n": y,
        "signal_total_max": float(top),
        "weights": weights,
        "saturation": None if end == len(force) else {"from_n": float(force[end]),
                                                       "reason": reason},
        "loo_max_error_percent": float(max(errors)) if errors else None,
        "loo_lightest_error_percent": float(lightest[0]) if lightest else None,
        "out_of_order": disorder,
    }  # fmt: skip


def hysteresis(presses: Presses, curve: dict) -> dict:
    """Loading and unloading branches of a series placed light to heavy, then heavy to
    light: each branch's knots, and the largest difference between the force the loading
    branch gives an unloading press and its load [N], and as a share of the calibrated
    full scale [%]. Only unsaturated presses count."""
    force = presses.force_n
    top = int(np.argmax(force))
    up, down = force[: top + 1], force[top:]
    if top < 2 or len(down) < 3 or np.any(np.diff(up) < 0) or np.any(np.diff(down) > 0):
        return {"measured": False,
                "why": "the weights were not placed light to heavy and then heavy to light "
                       "(at least 3 presses each way)"}  # fmt: skip
    limit = curve["force_n"][-1] * (1 + SAME_WEIGHT)
    branch = {}
    for name, part in (("loading", slice(0, top + 1)), ("unloading", slice(top, None))):
        f, t, s = force[part], presses.total[part], presses.saturated[part]
        keep = ~s & (f <= limit)
        gf, gt, gc, _, _ = _groups(f[keep], t[keep], s[keep]) if keep.sum() else (None,) * 5
        if keep.sum() < 2:
            return {"measured": False, "why": f"fewer than 2 unsaturated {name} presses"}
        branch[name] = _knots(gf, gt, gc)
    x, y = branch["loading"]
    f, t = force[top:], presses.total[top:]
    use = ~presses.saturated[top:] & (f <= limit) & (t <= x[-1])
    if not use.any():
        return {"measured": False, "why": "no unloading press within the loading branch"}
    difference = np.interp(t[use], x, y) - f[use]
    worst = float(np.max(np.abs(difference)))
    full = float(curve["force_n"][-1])
    return {
        "measured": True,
        "loading": {"signal_total": branch["loading"][0], "force_n": branch["loading"][1]},
        "unloading": {"signal_total": branch["unloading"][0], "force_n": branch["unloading"][1]},
        "max_difference_n": worst,
        "percent_of_full_scale": 100 * worst / full,
        "full_scale_n": full,
    }


def temperature_coefficient(presses: Presses, curve: dict) -> dict:
    """A linear temperature coefficient of the total signal [1/degC]: the presses'
    totals over the curve's total at their load, less 1, fitted as a line in the
    temperature about its median. Needs a log with ``temperature_c`` that varied by at
    least 0.5 degC over the unsaturated presses."""
    if presses.temperature_c is None:
        return {"calibrated": False, "why": "the log has no temperature_c column"}
    force, total = presses.force_n, presses.total
    keep = ~presses.saturated & (force <= curve["force_n"][-1] * (1 + SAME_WEIGHT))
    temp = presses.temperature_c[keep]
    if keep.sum() < 3 or np.ptp(temp) < 0.5:
        return {"calibrated": False,
                "why": f"the temperature varied by {np.ptp(temp):.2g} degC over the presses "
                       "(at least 0.5 needed)"}  # fmt: skip
    expected = np.interp(force[keep], curve["force_n"], curve["signal_total"])
    reference = float(np.median(temp))
    slope = np.polyfit(temp - reference, total[keep] / expected - 1, 1)[0]
    return {"calibrated": True, "coefficient_per_c": float(slope), "reference_c": reference,
            "range_c": [float(temp.min()), float(temp.max())]}  # fmt: skip


def force_curve(estimated, measured, *, bins: int = 8, min_force_n: float = 0.0):
    """Piecewise-linear knots from (estimated, measured) force pairs [N]: the medians of
    both in ``bins`` bins of equal count over the estimated force, made increasing.

    Returns
    -------
    (list, list)
        Knots of estimated and measured force [N].
    """
    estimated = np.asarray(estimated, dtype=float)
    measured = np.asarray(measured, dtype=float)
    keep = np.isfinite(estimated) & np.isfinite(measured) & (measured > min_force_n)
    estimated, measured = estimated[keep], measured[keep]
    if len(estimated) < 2 * bins:
        raise ArrayCalibrationError(
            f"{len(estimated)} frames pair a contact with a measured load; need at least "
            f"{2 * bins} for a force curve of {bins} knots"
        )
    order = np.argsort(estimated)
    parts = np.array_split(order, bins)
    x = np.array([np.median(estimated[p]) for p in parts])
    y = np.maximum.accumulate(np.array([np.median(measured[p]) for p in parts]))
    keep = np.r_[True, np.diff(x) > 1e-12]
    x, y = x[keep], y[keep]
    if len(x) < 2:
        raise ArrayCalibrationError("the estimated forces do not vary: no force curve")
    return [float(v) for v in x], [float(v) for v in y]
