"""Building an array calibration (:func:`calibrate_array`): gains from a uniform press
or a probe sweep, the force curve from a lab's log or from known weights."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from tactsense._validation import check_frames
from tactsense.estimate._kind import kind_or_none
from tactsense.estimate.contacts.calibration import ArrayCalibration, ArrayCalibrationError
from tactsense.estimate.contacts.find import find_contacts
from tactsense.estimate.contacts.lab_logs import WeightsLog
from tactsense.estimate.contacts.weight_curve import (
    MONOTONE_RANK,
    _plateau,
    force_curve,
    hysteresis,
    temperature_coefficient,
    weight_curve,
    weight_presses,
)

# ---- building one --------------------------------------------------------------------


def _signal(frames, sensor, baseline):
    from tactsense.estimate.reading import signal_from_counts

    return signal_from_counts(frames, baseline, sensor)[0]


def gains_from_press(
    frames, sensor, *, baseline_frames: int = 5, min_response: float = 0.1, threshold=None
):
    """Gains, baseline and dead taxels from a uniform press.

    The loaded frames are those where more than half the taxels read above the contact
    threshold; each taxel's gain is the median, over them, of its signal over the
    frame's median signal.

    Returns
    -------
    gains, baseline, dead, notes
    """
    from tactsense.estimate.reading import default_threshold

    frames = _frames(frames, sensor, baseline_frames)
    baseline = np.nanmedian(frames[:baseline_frames].astype(float), axis=0)
    signal = _signal(frames, sensor, baseline).reshape(len(frames), -1)
    threshold = default_threshold(sensor) if threshold is None else threshold
    loaded = np.mean(signal > threshold, axis=1) > 0.5
    if loaded.sum() < 3:
        raise ArrayCalibrationError(
            f"a uniform press needs frames where most taxels read a contact; "
            f"{int(loaded.sum())} of {len(frames)} frames do (threshold {threshold:g}): "
            "press the whole array, or calibrate from a probe sweep"
        )
    s = signal[loaded]
    ratio = s / np.median(s, axis=1, keepdims=True)
    gains = np.median(ratio, axis=0).reshape(sensor.shape)
    dead = ~(gains > min_response)
    notes = {"method": "uniform press", "loaded_frames": int(loaded.sum())}
    return np.where(dead, 1.0, gains), baseline, dead, notes


def gains_from_sweep(frames, sensor, *, baseline_frames: int = 5, min_response: float = 0.1):
    """Gains, baseline and dead taxels from a probe pressed on every taxel in turn: each
    taxel's largest signal over the median of the largest signals of the taxels the
    sweep reached (those above the contact threshold); the others are dead."""
    from tactsense.estimate.reading import default_threshold

    frames = _frames(frames, sensor, baseline_frames)
    baseline = np.nanmedian(frames[:baseline_frames].astype(float), axis=0)
    peaks = _signal(frames, sensor, baseline).max(axis=0)
    reached = peaks > default_threshold(sensor)
    if reached.mean() < 0.5:
        raise ArrayCalibrationError(
            f"the sweep reached {int(reached.sum())} of {reached.size} taxels (above the "
            "contact threshold): this is not a probe pressed on every taxel in turn "
            "(simulate --scenario calibration, or a probe on a stage)"
        )
    median = np.median(peaks[reached])
    gains = peaks / median
    dead = ~(gains > min_response) | ~reached
    notes = {"method": "probe sweep", "frames": len(frames)}
    return np.where(dead, 1.0, gains), baseline, dead, notes


def _frames(frames, sensor, baseline_frames):
    frames = check_frames(frames, sensor.shape)
    frames = frames.reshape(-1, *sensor.shape)
    if len(frames) <= baseline_frames:
        raise ArrayCalibrationError(
            f"{len(frames)} frames; need more than the {baseline_frames} untouched ones at "
            "the start"
        )
    return frames


def uniform_gains(frames, sensor, *, baseline_frames: int = 5, min_response: float = 0.1):
    """No per-taxel gains (all 1, none dead) and the baseline of the first frames: a
    weight curve alone, without a sweep or a uniform press."""
    frames = _frames(frames, sensor, baseline_frames)
    baseline = np.nanmedian(frames[:baseline_frames].astype(float), axis=0)
    shape = tuple(sensor.shape)
    notes = {"method": "none (uniform gains: no sweep or uniform press given)"}
    return np.ones(shape), baseline, np.zeros(shape, bool), notes


METHODS = {"sweep": gains_from_sweep, "press": gains_from_press, "none": uniform_gains}
"""How the gains are found: a probe on every taxel in turn, a uniform press, or not at
all (a weight curve alone)."""


def calibrate_array(
    frames,
    sensor,
    *,
    method: str = "sweep",
    baseline_frames: int = 5,
    min_response: float = 0.1,
    loads=None,
    force_log: tuple | None = None,
    bins: int = 8,
    partial: bool = False,
    weights: WeightsLog | None = None,
    threshold: float | None = None,
    attrs: dict | None = None,
) -> ArrayCalibration:
    """A pad's or a point set's calibration from a recording (and a force log, or the
    log of known weights).

    More than 10 % of the taxels below ``min_response`` is an error unless ``partial``
    (they are then marked dead).

    Parameters
    ----------
    frames : array_like, shape (T, rows, cols)
        Readings [counts], the first ``baseline_frames`` untouched: equal presses on
        every taxel in turn (``method="sweep"``, ``tactsense simulate --scenario
        calibration``) or a uniform press (``"press"``, :data:`METHODS`).
    loads : (frames, time_s), optional
        The recording the force log belongs to (readings [counts], times [s]; the first
        ``baseline_frames`` untouched): presses of varied force. Default: ``frames``
        (then give ``time_s`` as ``loads=(frames, time_s)``).
    force_log : (times [s], forces [N]), optional
        A reference load cell's readings on the clock of ``loads`` (:func:`read_force_log`):
        the force curve is fitted to them against the gain-corrected estimates.
    weights : WeightsLog, optional
        Known loads of the presses of ``loads`` (:func:`read_weights_log`): the weight
        curve (:func:`weight_curve`) from the contacts' total signal, with the gains
        applied; its presses, leave-one-out errors, saturation, hysteresis
        (:func:`hysteresis`) and temperature coefficient
        (:func:`temperature_coefficient`) go to the notes. Not with ``force_log``.
    threshold : float, optional
        The contact threshold of the totals [-] (:func:`~tactsense.estimate.contacts.
        default_threshold`); ``locate`` should use the same.
    attrs : dict, optional
        The weights recording's attributes: its creep is taken out as ``locate`` takes
        it out (:func:`contact_totals`).
    """

    if method not in METHODS:
        raise ArrayCalibrationError(f"method {method!r}: expected one of {', '.join(METHODS)}")
    kind = kind_or_none(sensor)
    if kind is None or not kind.array_calibration:
        raise ArrayCalibrationError(
            f"an array calibration is for pads and point sets; {sensor.name!r} is a "
            f"{getattr(sensor, 'kind', type(sensor).__name__)}"
        )
    frames = _frames(frames, sensor, baseline_frames)
    options = {"baseline_frames": baseline_frames, "min_response": min_response}
    gains, baseline, dead, notes = METHODS[method](frames, sensor, **options)
    if dead.mean() > 0.1 and not partial:
        raise ArrayCalibrationError(
            f"{int(dead.sum())} of {dead.size} taxels responded less than {min_response:g} of "
            f"the median: the {'press' if method == 'press' else 'sweep'} did not reach them "
            "(press every taxel in turn: simulate --scenario calibration), or pass --partial "
            "to mark them dead"
        )
    calibration = ArrayCalibration(
        sensor_toml=sensor.to_toml_string(), baseline=baseline, gains=gains, dead=dead,
        notes={**notes, "dead_taxels": int(dead.sum()),
               "gain_spread": float(np.std(gains[~dead]) / np.mean(gains[~dead]))},
    )  # fmt: skip
    if weights is not None:
        if force_log is not None:
            raise ArrayCalibrationError("give a force log or a weights log, not both")
        return _add_weight_curve(calibration, sensor, loads, weights, baseline_frames, threshold,
                                 attrs=attrs)  # fmt: skip
    if force_log is None:
        return calibration
    if loads is None:
        raise ArrayCalibrationError("a force log needs its recording's frames and times (loads)")
    load_frames, time_s = loads
    load_frames = _frames(load_frames, sensor, baseline_frames)
    time_s = np.asarray(time_s, dtype=float)
    if len(time_s) != len(load_frames):
        raise ArrayCalibrationError(
            f"{len(time_s)} times for {len(load_frames)} frames of the loads recording"
        )
    log_t, log_f = (np.asarray(v, dtype=float) for v in force_log)
    inside = (time_s >= log_t[0]) & (time_s <= log_t[-1])
    if not inside.any():
        raise ArrayCalibrationError(
            f"the force log covers {log_t[0]:g}-{log_t[-1]:g} s and the recording "
            f"{time_s[0]:g}-{time_s[-1]:g} s: no frame falls within the log"
        )
    # the loads recording's own baseline, the calibration's gains
    own = ArrayCalibration(
        sensor_toml=calibration.sensor_toml,
        baseline=np.median(load_frames[:baseline_frames].astype(float), axis=0),
        gains=calibration.gains, dead=calibration.dead,
    )  # fmt: skip
    table = find_contacts(load_frames, sensor, calibration=own)
    estimated = np.zeros(len(load_frames))
    np.add.at(estimated, table.frame, np.nan_to_num(table.force_n))
    measured = np.interp(time_s, log_t, log_f)
    check_force_log(estimated[inside & (estimated > 0)], measured[inside & (estimated > 0)])
    use = inside & (estimated > 0) & (measured > 0.05 * np.max(log_f))
    loads = measured[use]
    if len(loads) and np.percentile(loads, 90) < 1.5 * np.percentile(loads, 10):
        raise ArrayCalibrationError(
            f"the force log holds one load ({np.median(loads):.3g} N in the frames with a "
            "contact): a force curve needs presses of several forces (a recording of "
            "presses from light to heavy, given with --loads)"
        )
    scale, rank = _log_agreement(estimated[use], measured[use])
    calibration.force_curve = force_curve(estimated[use], measured[use], bins=bins)
    calibration.notes["force_pairs"] = int(use.sum())
    calibration.notes["force_log_scale"] = scale
    calibration.notes["force_log_rank_correlation"] = rank
    return calibration


@dataclass
class _TotalsSeen(ArrayCalibration):
    """An array calibration that keeps each contact's total signal as find_contacts
    computes it (before a contact at the rail loses its force), rows in table order."""

    seen: list = field(default_factory=list)

    def contact_force(self, table):
        total = np.asarray(table.extra["_total"], dtype=float)
        self.seen.append(total.copy())
        return total.copy(), np.zeros(len(total), bool)


def contact_totals(frames, sensor, calibration, *, baseline_frames=5, threshold=None,
                   attrs=None, drift_s: float | None = 2.0):  # fmt: skip
    """Each frame's summed total signal of its contacts [-], as ``locate`` with this
    calibration sees them, and the frames with a contact at the converter's rail [bool].

    The baseline is the frames' own first ``baseline_frames``, then follows drift with
    ``drift_s`` [s] (``locate``'s default 2; None: fixed) and is re-zeroed where a
    taxel's reading falls quickly (a weight lifted), and the creep a recording's
    attributes ``attrs`` call for is taken out
    (:func:`~tactsense.estimate.creep.creep_applied`; None: a measured recording), as
    ``locate`` does: the weight curve then reads the totals ``locate`` will give it.

    Returns
    -------
    totals : ndarray, shape (T,)
    saturated : ndarray of bool, shape (T,)
    creep : str
        Where the creep taken out came from.
    """
    import math

    from tactsense.estimate.contacts.baseline import DriftBaseline
    from tactsense.estimate.creep import creep_applied
    from tactsense.estimate.reading import default_threshold
    from tactsense.estimate.results import Flag

    frames = np.asarray(frames)
    start = np.nanmedian(frames[:baseline_frames].astype(float), axis=0)
    creep, stiffening, label = creep_applied(sensor, attrs or {"source": "measured"})
    threshold = default_threshold(sensor, creep=creep) if threshold is None else float(threshold)
    drift = DriftBaseline(
        start, sensor, frame_period_s=sensor.scan_period_s, threshold=threshold,
        time_constant_s=math.inf if not drift_s else drift_s, creep=creep,
        stiffening=stiffening,
    )  # fmt: skip
    probe = _TotalsSeen(
        sensor_toml=calibration.sensor_toml, baseline=start, gains=calibration.gains,
        dead=calibration.dead,
    )  # fmt: skip
    table = find_contacts(frames, sensor, baseline=drift, calibration=probe, threshold=threshold)
    n = len(frames)
    seen = np.concatenate(probe.seen) if probe.seen else np.zeros(0)
    totals = np.bincount(table.frame, weights=seen, minlength=n)
    rail = (table.flags & int(Flag.SATURATED)) != 0
    saturated = np.bincount(table.frame[rail], minlength=n) > 0
    return totals, saturated, label


def _explain_falling(error, presses, timing) -> None:
    """Raise a clearer error when the totals ``locate`` reads fall with the load but the
    readings against the recording's first frames rise: ``locate``'s re-zero after each
    lift has taken up what the array kept of the last load."""
    from scipy.stats import spearmanr

    if "does not rise with the load" not in str(error) or len(presses.force_n) < 3:
        return
    fixed = np.array([np.median(timing[_plateau(a, b)])
                      for a, b in zip(presses.start, presses.end, strict=True)])  # fmt: skip
    seen = spearmanr(presses.force_n, presses.total).statistic
    raw = spearmanr(presses.force_n, fixed).statistic
    if raw >= MONOTONE_RANK:
        raise ArrayCalibrationError(
            f"the totals locate reads fall as the weights grow (rank correlation {seen:.2f}) "
            f"while the readings against the recording's first frames rise ({raw:.2f}): "
            "locate's re-zero after each lift takes up what the array keeps of a load (an "
            "FSR's hysteresis, creep), so a heavier weight reads less; let the array "
            "recover between weights, or describe its creep (creep_known) so it is taken out"
        ) from None


def _add_weight_curve(calibration, sensor, loads, weights, baseline_frames, threshold,
                      attrs=None):  # fmt: skip
    """:func:`calibrate_array`'s weight curve, on the recording ``loads``."""
    from tactsense.estimate.reading import default_threshold

    if loads is None:
        raise ArrayCalibrationError("a weights log needs its recording's frames and times (loads)")
    load_frames, time_s = loads
    load_frames = _frames(load_frames, sensor, baseline_frames)
    if time_s is not None and len(time_s) != len(load_frames):
        raise ArrayCalibrationError(
            f"{len(time_s)} times for {len(load_frames)} frames of the weights recording"
        )
    if weights.time_s is not None and time_s is None:
        raise ArrayCalibrationError("a timed weights log needs the recording's frame times")
    if threshold is None:  # over the noise the creep compensation leaves, as locate's
        from tactsense.estimate.creep import creep_applied

        applied = creep_applied(sensor, attrs or {"source": "measured"})[0]
        threshold = default_threshold(sensor, creep=applied)
    threshold = float(threshold)
    totals, saturated, creep = contact_totals(
        load_frames, sensor, calibration, baseline_frames=baseline_frames,
        threshold=threshold, attrs=attrs,
    )  # fmt: skip
    # the presses are found in the totals without creep compensation (which amplifies
    # the noise), on the recording's own first frames
    own = ArrayCalibration(
        sensor_toml=calibration.sensor_toml,
        baseline=np.nanmedian(load_frames[:baseline_frames].astype(float), axis=0),
        gains=calibration.gains, dead=calibration.dead,
    )  # fmt: skip
    signal = own.signal(load_frames, sensor)[0].reshape(len(load_frames), -1)
    timing = np.where(signal > threshold, signal, 0.0).sum(axis=1)
    against = np.where(signal < -threshold, -signal, 0.0).sum(axis=1)
    del signal
    try:
        presses = weight_presses(totals, saturated, weights, time_s=time_s,
                                 rest_frames=baseline_frames, timing=timing)  # fmt: skip
    except ArrayCalibrationError as error:
        if against.max(initial=0.0) > 2.0 * timing.max(initial=0.0):  # the other way
            polarity = getattr(getattr(sensor, "transduction", None), "polarity", "rising")
            other = "falling" if polarity == "rising" else "rising"
            raise ArrayCalibrationError(
                f"{error}; the readings moved against the description's polarity "
                f"({polarity!r}: up to {against.max():.3g} of summed signal the other way, "
                f"{timing.max():.3g} with it): if they are {other} under load, set "
                f"[transduction] polarity = {other!r} in the sensor's description"
            ) from None
        raise
    try:
        curve = weight_curve(presses)
    except ArrayCalibrationError as error:
        _explain_falling(error, presses, timing)
        raise
    calibration.force_curve = (curve["signal_total"], curve["force_n"])
    calibration.curve_input = "signal_total"
    calibration.curve_top = curve["signal_total_max"]
    calibration.notes.update(
        weights_log=weights.source,
        weights_column=weights.column,
        threshold=threshold,
        creep_taken_out=creep,
        presses=[
            {"start_frame": int(a), "end_frame": int(b), "force_n": float(f),
             "signal_total": float(t), "saturated": bool(s)}
            for a, b, f, t, s in zip(presses.start, presses.end, presses.force_n,
                                     presses.total, presses.saturated, strict=True)
        ],
        weights=curve["weights"],
        saturation=curve["saturation"],
        loo_max_error_percent=curve["loo_max_error_percent"],
        loo_lightest_error_percent=curve["loo_lightest_error_percent"],
        out_of_order=curve["out_of_order"],
        hysteresis=hysteresis(presses, curve),
        temperature=temperature_coefficient(presses, curve),
    )  # fmt: skip
    return calibration


LOG_SCALE_LIMIT = 10.0
"""A force log whose forces are more than this factor above or below the forces the
recording's layer model gives (median over the frames with a contact) is refused: the
model of a correctly described sensor is well within it (``pad4``'s twin under 24
presses of 0.1-1 N: 1.90, its creep taken out,
``tests/reliability/test_round3_estimate.py``); a log in grams reads about 100 times as
much as one in newtons, in millinewtons 1000 times. (A log in kilograms-force, 0.1
times, can pass unseen.)"""

LOG_RANK_LIMIT = 0.5
"""Smallest rank (Spearman) correlation between the estimated and the logged force over
the frames with a contact: below it the log does not follow the recording (another
session, another clock)."""


def check_force_log(estimated, measured) -> None:
    """Refuse a force log whose sign says it is not a compressive load in newtons.

    ``estimated`` [N] and ``measured`` [N] are the frames with a contact within the log.
    More of them negative than positive: the load cell reads compression negative (or
    the column is another quantity)."""
    measured = np.asarray(measured, dtype=float)
    negative = int(np.count_nonzero(measured < 0))
    if len(measured) and negative > np.count_nonzero(measured > 0):
        raise ArrayCalibrationError(
            f"the force log is negative in {negative} of the {len(measured)} frames with a "
            f"contact (median {np.median(measured):.3g} N): force_n must be the load pressing "
            "on the array, positive in compression (negate the column of a load cell that "
            "reads compression negative)"
        )


def _log_agreement(estimated, measured) -> tuple[float, float]:
    """The log's scale against the recording (median of measured over estimated [-]) and
    the rank correlation of the two [-]; refuse a log in the wrong unit or one that does
    not follow the recording (:data:`LOG_SCALE_LIMIT`, :data:`LOG_RANK_LIMIT`)."""
    from scipy.stats import spearmanr

    estimated = np.asarray(estimated, dtype=float)
    measured = np.asarray(measured, dtype=float)
    if len(estimated) < 3:
        return float("nan"), float("nan")  # force_curve says there are too few pairs
    scale = float(np.median(measured / estimated))
    if not (1 / LOG_SCALE_LIMIT <= scale <= LOG_SCALE_LIMIT):
        raise ArrayCalibrationError(
            f"the force log reads {scale:.3g} times the force the recording shows (median "
            f"over {len(measured)} frames with a contact; a sensor described correctly is "
            f"within {LOG_SCALE_LIMIT:g} times): force_n must be in newtons (a log in grams "
            "reads 102 times as much, in millinewtons 1000 times); if it is, check the "
            "sensor's description (layer, transduction)"
        )
    rank = float(spearmanr(estimated, measured).statistic)
    if not rank >= LOG_RANK_LIMIT:
        raise ArrayCalibrationError(
            f"the force log does not rise with the recording's force (rank correlation "
            f"{rank:.2f} over {len(measured)} frames with a contact, at least "
            f"{LOG_RANK_LIMIT:g} expected): is it the log of the --loads recording, on its "
            "clock (time_s in seconds from the recording's start)?"
        )
    return scale, rank
