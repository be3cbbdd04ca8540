"""What a recording's readings say about its taxels and its baseline: the taxels that give
no signal (dead, stuck, without a reading) and a recording whose readings moved the wrong
way or never crossed the contact threshold."""

from __future__ import annotations

import numpy as np

from tactsense.estimate._kind import kind_or_none
from tactsense.estimate.reading import (
    default_threshold,
    reading_mode,
    signal_from_counts,
    unusable_baseline,
)


class ReadingRange:
    """The smallest and largest finite reading of every taxel over a recording, gathered
    piece by piece (bounded memory): what :func:`taxel_health` and
    :func:`no_contact_cause` decide from.

    Parameters
    ----------
    shape : tuple of int
        The frame shape (rows, cols).
    """

    def __init__(self, shape):
        self.low = np.full(shape, np.inf)
        """Smallest finite reading of each taxel so far [counts] (inf: none yet)."""
        self.high = np.full(shape, -np.inf)
        """Largest finite reading of each taxel so far [counts] (-inf: none yet)."""
        self.frames = 0

    def update(self, frames) -> None:
        """Take in a piece of frames (N, rows, cols) [counts]."""
        frames = np.asarray(frames)
        if frames.shape[0] == 0:
            return
        if frames.dtype.kind == "f":
            finite = np.isfinite(frames)
            self.low = np.minimum(self.low, np.where(finite, frames, np.inf).min(axis=0))
            self.high = np.maximum(self.high, np.where(finite, frames, -np.inf).max(axis=0))
        else:
            self.low = np.minimum(self.low, frames.min(axis=0))
            self.high = np.maximum(self.high, frames.max(axis=0))
        self.frames += frames.shape[0]


def taxel_names(sensor, mask, most: int = 8) -> str:
    """The taxels of ``mask`` as a reader names them: ``(row, col)`` on a grid, ``taxel
    k`` on a point set; at most ``most``, then how many more."""
    rows, cols = np.nonzero(np.asarray(mask, dtype=bool))
    kind = kind_or_none(sensor)
    if kind is not None and not kind.image_grid:
        names = [f"taxel {int(c)}" for c in cols]
    else:
        names = [f"({int(r)}, {int(c)})" for r, c in zip(rows, cols, strict=True)]
    text = ", ".join(names[:most])
    return text + (f" and {len(names) - most} more" if len(names) > most else "")


CONSTANT_FRAMES = 50
"""A taxel is named for never changing only over a recording of at least this many frames
[-]: read noise of 0.3 counts quantized to whole counts leaves a healthy taxel on one
value for a few frames (an iCub grasp trial of 4 frames named 5 of 12 healthy taxels
dead); over 50 frames that happens about once in 200."""


def taxel_health(extremes: ReadingRange, baseline, sensor) -> dict:
    """Which taxels of a recording give no signal, decided from its readings.

    * ``no_reading``: not one finite reading in the recording;
    * ``stuck``: every reading at the converter's rail the reading moves toward under
      load (full scale rising, 0 falling), or a rest reading that gives no signal (a
      capacitive junction reading 0: open; a falling reading resting at 0);
    * ``constant``: one value throughout (dead), over :data:`CONSTANT_FRAMES` frames or
      more, when most taxels do change (their read noise, or a touch): where most never
      change (a cell reading exactly 0 at rest, as
      FSR arrays do, or a twin without noise) an unchanging taxel is no sign of a fault;
      nor is one value at the rail opposite the load (0 rising, full scale falling),
      where an untouched cell resting there reads its noise clipped.

    A taxel that reads 0 at rest is none of these by itself. Returns the three masks
    (rows, cols), their union ``dead`` (the taxels that give no signal) and ``excluded``
    (``no_reading | stuck``: the ones to leave out, which would otherwise set NAN_INPUT
    or SATURATED in every frame; a constant taxel's signal is 0 throughout anyway, and it
    may be a healthy one never touched).
    """
    baseline = np.asarray(baseline, dtype=float)
    no_reading = ~np.isfinite(extremes.low)
    falling = reading_mode(sensor)[1]
    rail = 0.0 if falling else float(2**sensor.electronics.adc_bits - 1)
    constant = ~no_reading & (extremes.low == extremes.high)
    stuck = constant & (extremes.low == rail)
    stuck |= ~no_reading & np.isfinite(baseline) & unusable_baseline(baseline, sensor)
    changing = ~no_reading & ~constant
    if np.count_nonzero(changing) <= changing.size // 2 or extremes.frames < CONSTANT_FRAMES:
        constant = np.zeros_like(constant)
    # at the other rail (0 rising, full scale falling) an untouched cell resting there
    # reads its noise clipped: one value throughout is what a healthy one may do
    floor = float(2**sensor.electronics.adc_bits - 1) if falling else 0.0
    constant &= ~stuck & (extremes.low != floor)
    return {
        "no_reading": no_reading,
        "stuck": stuck,
        "constant": constant,
        "dead": no_reading | stuck | constant,
        "excluded": no_reading | stuck,
    }


def health_warning(health: dict, sensor) -> str | None:
    """One line naming the taxels :func:`taxel_health` found to give no signal, or None."""
    parts = []
    if health["constant"].any():
        parts.append(
            "never changed over the recording (dead, or never touched and without noise; "
            "their signal is 0): " + taxel_names(sensor, health["constant"])
        )
    if health["stuck"].any():
        rail = "0" if sensor_falls(sensor) else f"full scale ({2**sensor.electronics.adc_bits - 1})"
        parts.append(
            f"stuck (every reading at {rail}, or a rest reading that gives no signal; "
            "ignored, flag DEAD_TACTEL): " + taxel_names(sensor, health["stuck"])
        )
    if health["no_reading"].any():
        parts.append(
            "no finite reading (ignored, flag DEAD_TACTEL): "
            + taxel_names(sensor, health["no_reading"])
        )
    if not parts:
        return None
    n = int(np.count_nonzero(health["dead"]))
    return f"{n} of {health['dead'].size} taxels give no signal: " + "; ".join(parts)


def sensor_falls(sensor) -> bool:
    """Whether the sensor's reading falls under load (``[transduction] polarity``)."""
    t = getattr(sensor, "transduction", None)
    return t is not None and t.polarity == "falling"


def movement_warning(
    extremes: ReadingRange, baseline, sensor, threshold: float, *, found: bool,
    dead=None, baseline_frames: int | None = None,
) -> str | None:  # fmt: skip
    """What the way a recording's readings moved says is wrong, or None.

    The signal of every usable taxel's smallest and largest reading against ``baseline``
    [counts] (compression positive, as :func:`~tactsense.estimate.contacts.signal_from_counts`
    takes it) says which way the readings went under load:

    * against the sensor's polarity by more than the contact ``threshold`` [-] and by
      more than twice as far as with it: the polarity is wrong (or the baseline frames
      were touched), whether contacts were ``found`` or not (a drift-following baseline
      follows a wrong-way press down and reads its lift as a contact);
    * no contact ``found`` although the readings moved by more than the default
      threshold (:func:`~tactsense.estimate.contacts.default_threshold`, some 25 times
      the noise) or the one given, whichever is lower: never above the one given (it is
      too high), or above it (the baseline followed the press, or a calibration's dead
      taxels).

    None when nothing moved that far (an untouched recording) or contacts were found
    and the readings moved the right way.
    """
    if extremes.frames == 0:
        return None
    baseline = np.asarray(baseline, dtype=float)
    usable = np.isfinite(extremes.low) & ~unusable_baseline(baseline, sensor)
    if dead is not None:
        usable &= ~np.asarray(dead, dtype=bool)
    lead = "" if found else "no contact found, yet "
    if not usable.any():
        return None if found else "no taxel gives a signal (dead, stuck or without a reading)"
    low = np.where(usable, extremes.low, baseline)
    high = np.where(usable, extremes.high, baseline)
    ends = np.stack([low, high])
    signal, _ = signal_from_counts(ends, np.where(usable, baseline, 1.0), sensor, dead=~usable)
    toward = max(float(signal.max()), 0.0)
    against = max(float(-signal.min()), 0.0)
    falls = sensor_falls(sensor)
    first = f"the first {baseline_frames} frames" if baseline_frames else "the first frames"
    if against > threshold and against > 2.0 * toward:
        went, way, other, polarity, fix = (
            ("rose above", "fall", "rise", "falling", "rising")
            if falls
            else ("fell below", "rise", "fall", "rising", "falling")
        )
        return (
            f"{lead}the readings {went} the baseline (by up to {against:.3g} in signal, "
            f"{toward:.3g} the other way; threshold {threshold:.3g}) where this sensor's "
            f"readings {way} under load ([transduction] polarity = {polarity!r}): if its "
            f"readings {other} when pressed, set polarity = {fix!r} in its description; "
            f"or {first}, which make the baseline, were touched"
        )
    # clearly above the noise: beyond the default threshold (some 25 times the noise)
    # or the one given, whichever is lower
    if found or max(toward, against) <= min(threshold, default_threshold(sensor)):
        return None
    if toward <= threshold:
        return (
            f"{lead}the readings moved (by up to {max(toward, against):.3g} in signal) but "
            f"never above the contact threshold {threshold:.3g}: lower --threshold, or "
            f"check the baseline ({first})"
        )
    return (
        f"{lead}the readings rose above the contact threshold {threshold:.3g} (up to "
        f"{toward:.3g}): the baseline followed the press (--drift-s 0 keeps the first "
        "frames' baseline), or a calibration marks those taxels dead"
    )
