"""Calibration of any array from a lab's own data: pads and point sets.

A finger's calibration (:class:`~tactsense.estimate.calibrate.Calibration`) follows the
paper's procedure. A pad or a point set is calibrated from what a lab can record on its
bench:

* **Per-taxel gain** from a *uniform press* (a flat punch larger than the array, or an
  air bladder: every taxel under the same pressure should read the same signal), or
  from a *probe sweep* (a probe pressed on every taxel in turn: every taxel's largest
  reading should be the same). Each taxel's gain is its reading over the median of all
  taxels' readings (``gain > 1``: it reads more than its peers); the calibrated signal
  is the signal over the gain. Taxels that never respond (less than ``min_response``
  of the median) are marked dead.
* **A force curve** from pairs of (force the estimation gives, force a reference load
  cell measured): piecewise linear through the pairs' medians in bins of estimated
  force, as the ROS tactile toolbox maps readings to force, and forced to be monotone.
  The pairs come from a recording and the lab's own force log, a CSV with a time column
  (``time_s``, seconds on the recording's clock) and a force column (``force_n``),
  interpolated to the frames' times.

* **A weight curve** from known weights alone (no sweep, no stage): each weight placed,
  held and removed in turn, the contacts' total signal of every press (over its
  settled part) against the weight, piecewise linear and monotone
  through the origin (:func:`weight_curve`). Saturation (taxels at the converter's rail,
  or a total that stops growing with the load) ends the calibrated range; a contact
  whose total lies beyond it gets no force (NaN, flag ``BEYOND_CALIBRATION``), never an
  extrapolated one. :func:`calibrate_array` reports each weight's leave-one-out error,
  the hysteresis between loading and unloading, and a temperature coefficient where the
  log has them. The weights come from :func:`read_weights_log`.

Everything is stored in one JSON file (``format = tactsense-array-calibration``) with
the sensor description it belongs to, and applied by ``find_contacts(calibration=...)``
(``locate``, ``live``, ``view``): the signal against the calibrated baseline, divided
by the gains, dead taxels zeroed; each contact's force through the curve.
"""

from __future__ import annotations

import csv
import json
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from tactsense._validation import TactsenseInputError, check_frames
from tactsense.estimate.finger.calibrate import save_json

FORMAT = "tactsense-array-calibration"


class ArrayCalibrationError(TactsenseInputError):
    """A calibration that cannot be made, read or applied."""


@dataclass
class ArrayCalibration:
    """Gains, baseline, dead taxels and a force curve of a pad or a point set."""

    sensor_toml: str
    baseline: np.ndarray
    """Untouched readings [counts], shape of the array."""
    gains: np.ndarray
    """Per-taxel gain [-]: the calibrated signal is the signal over it."""
    dead: np.ndarray
    """Taxels left out [bool]."""
    force_curve: tuple[list, list] | None = None
    """Knots of the piecewise-linear force curve: (estimated [N], measured [N]) when
    ``curve_input`` is ``"model_force_n"``; (total signal [-], force [N]) when it is
    ``"signal_total"``."""
    notes: dict = field(default_factory=dict)
    curve_input: str = "model_force_n"
    """What the curve maps to newtons: the contact's force from the layer model
    (``"model_force_n"``, a load cell's log against a sweep's gains) or the contact's
    total signal (``"signal_total"``, a weight curve)."""
    curve_top: float | None = None
    """Largest total signal the weight curve may be read at [-]: beyond it a contact's
    force is NaN and flagged ``BEYOND_CALIBRATION`` (``"signal_total"`` only)."""

    @property
    def contact_threshold(self) -> float | None:
        """The contact threshold a weight curve's totals were taken with [-] (None for
        other calibrations): ``find_contacts`` uses it unless told otherwise."""
        if self.curve_input != "signal_total":
            return None
        value = self.notes.get("threshold")
        return float(value) if isinstance(value, int | float) and value > 0 else None

    @property
    def sensor(self):
        from tactsense.estimate.finger.calibrate import sensor_of

        return sensor_of(self.sensor_toml)

    def check_sensor(self, sensor) -> None:
        """Raise unless this calibration was made for ``sensor``."""
        mine = self.sensor
        if mine != sensor:
            raise ArrayCalibrationError(
                f"this calibration belongs to sensor {mine.name!r}, not {sensor.name!r} "
                "(or a differently configured one): calibrate this array anew"
            )

    def signal(self, frames, sensor, *, baseline=None):
        """Calibrated signal of every frame and the frames' flags: the signal against
        ``baseline`` (default this calibration's; a
        :class:`~tactsense.estimate.baseline.DriftBaseline` started from it follows
        drift), divided by the gains, dead taxels zeroed."""
        from tactsense.estimate.reading import signal_from_counts

        if baseline is not None and hasattr(baseline, "signal"):
            signal, flags = baseline.signal(frames, dead=self.dead)
        else:
            signal, flags = signal_from_counts(
                frames, self.baseline if baseline is None else baseline, sensor, dead=self.dead
            )
        signal /= np.where(self.dead, 1.0, self.gains)
        return signal, flags

    def contact_force(self, table) -> tuple[np.ndarray, np.ndarray]:
        """The force of each contact of a table [N] through the curve, and the contacts
        beyond the calibrated range [bool] (their force NaN; none for a model-force
        curve, which is extended linearly)."""
        if self.curve_input != "signal_total" or self.force_curve is None:
            return self.force(table.force_n), np.zeros(len(table), bool)
        total = np.asarray(table.extra["_total"], dtype=float)
        return self.force_of_total(total)

    def force_of_total(self, total) -> tuple[np.ndarray, np.ndarray]:
        """Forces of contacts' total signals through the weight curve [N], and which lie
        beyond the calibrated range (force NaN) [bool]."""
        total = np.asarray(total, dtype=float)
        x, y = (np.asarray(v, dtype=float) for v in self.force_curve)
        top = x[-1] if self.curve_top is None else self.curve_top
        slope = (y[-1] - y[-2]) / (x[-1] - x[-2])
        out = np.where(total > x[-1], y[-1] + slope * (total - x[-1]), np.interp(total, x, y))
        beyond = total > top
        out = np.where(beyond | ~np.isfinite(total), np.nan, np.maximum(out, 0.0))
        return out, beyond

    def force(self, estimated) -> np.ndarray:
        """Forces through a model-force curve [N] (unchanged without one; linear beyond
        its ends, never below zero: a load pressing on the array has no negative force)."""
        estimated = np.asarray(estimated, dtype=float)
        if self.force_curve is None:
            return estimated
        if self.curve_input == "signal_total":
            raise ArrayCalibrationError(
                "this calibration's curve maps a contact's total signal, not a model force: "
                "use contact_force or force_of_total"
            )
        x, y = (np.asarray(v, dtype=float) for v in self.force_curve)
        out = np.interp(estimated, x, y)
        if len(x) >= 2:  # extend the end segments rather than clamp
            low = estimated < x[0]
            high = estimated > x[-1]
            slope_lo = (y[1] - y[0]) / (x[1] - x[0])
            slope_hi = (y[-1] - y[-2]) / (x[-1] - x[-2])
            out = np.where(low, y[0] + slope_lo * (estimated - x[0]), out)
            out = np.where(high, y[-1] + slope_hi * (estimated - x[-1]), out)
        out = np.maximum(out, 0.0)  # NaN stays NaN
        return np.where(np.isfinite(estimated), out, np.nan)

    # ---- JSON --------------------------------------------------------------------------

    def to_dict(self) -> dict:
        return {
            "format": FORMAT,
            "version": 1,
            "sensor_toml": self.sensor_toml,
            "baseline_counts": self.baseline.tolist(),
            "gains": self.gains.tolist(),
            "dead": self.dead.tolist(),
            "force_curve": self._curve_dict(),
            "notes": self.notes,
        }

    def _curve_dict(self):
        if self.force_curve is None:
            return None
        x, y = (list(map(float, v)) for v in self.force_curve)
        if self.curve_input == "signal_total":
            return {"input": "signal_total", "signal_total": x, "force_n": y,
                    "signal_total_max": self.curve_top}  # fmt: skip
        return {"estimated_n": x, "measured_n": y}

    def save(self, path: str | Path, *, overwrite: bool = False) -> Path:
        return save_json(self.to_dict(), path, overwrite=overwrite)

    @classmethod
    def from_dict(cls, data: dict, source: str = "calibration") -> ArrayCalibration:
        if not isinstance(data, dict) or data.get("format") != FORMAT:
            raise ArrayCalibrationError(f"{source} is not a tactsense array calibration")
        try:
            curve = data.get("force_curve")
            total = curve is not None and curve.get("input") == "signal_total"
            knots = None
            if curve is not None:
                names = ("signal_total", "force_n") if total else ("estimated_n", "measured_n")
                knots = tuple(list(map(float, curve[name])) for name in names)
            calibration = cls(
                sensor_toml=data["sensor_toml"],
                baseline=np.array(data["baseline_counts"], dtype=float),
                gains=np.array(data["gains"], dtype=float),
                dead=np.array(data["dead"], dtype=bool),
                force_curve=knots,
                notes=data.get("notes", {}),
                curve_input="signal_total" if total else "model_force_n",
                curve_top=float(curve["signal_total_max"]) if total else None,
            )
            sensor = calibration.sensor
        except (KeyError, TypeError, ValueError, AttributeError) as error:
            from tactsense.estimate.finger.calibrate import damaged

            keys = ("format", "sensor_toml", "baseline_counts", "gains", "dead", "force_curve")
            raise ArrayCalibrationError(damaged(source, error, "array calibration", keys)) from None
        for name in ("baseline", "gains", "dead"):
            if getattr(calibration, name).shape != tuple(sensor.shape):
                raise ArrayCalibrationError(
                    f"{source}: {name} has the wrong shape, expected {tuple(sensor.shape)}"
                )
        from tactsense.estimate.finger.calibrate import check_in_use

        check_in_use(source, ~calibration.dead, calibration, ArrayCalibrationError, "taxel",
                     sensor=sensor)  # fmt: skip
        if calibration.force_curve is not None:
            x, y = (np.asarray(v) for v in calibration.force_curve)
            if len(x) < 2 or len(x) != len(y) or np.any(np.diff(x) <= 0) or np.any(np.diff(y) < 0):
                raise ArrayCalibrationError(
                    f"{source}: the force curve needs at least 2 knots, increasing in both "
                    "estimated and measured force"
                )
            top = calibration.curve_top
            if calibration.curve_input == "signal_total" and not (
                top is not None and np.isfinite(top) and top >= x[-1]
            ):
                raise ArrayCalibrationError(
                    f"{source}: force_curve.signal_total_max must be a number at least the "
                    "last knot's total signal"
                )
        return calibration


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


def read_force_log(path: str | Path) -> tuple[np.ndarray, np.ndarray]:
    """A lab's force log: a CSV with columns ``time_s`` [s] and ``force_n`` [N] (other
    columns ignored), rows in time order."""
    path = Path(path)
    try:
        with open(path, newline="", encoding="utf-8") as stream:
            reader = csv.DictReader(stream)
            missing = {"time_s", "force_n"} - set(reader.fieldnames or [])
            if missing:
                raise ArrayCalibrationError(
                    f"{path}: needs the columns time_s and force_n; missing "
                    f"{', '.join(sorted(missing))} (has {', '.join(reader.fieldnames or [])})"
                )
            columns = _numbers(path, reader, ("time_s", "force_n"))
    except OSError as error:
        raise ArrayCalibrationError(f"cannot read {path}: {error.strerror}") from None
    except UnicodeDecodeError:
        raise ArrayCalibrationError(f"{path} is not a text CSV file") from None
    t, f = columns
    if len(t) < 2:
        raise ArrayCalibrationError(f"{path}: needs at least 2 rows of time_s, force_n")
    if not (np.all(np.isfinite(t)) and np.all(np.isfinite(f))):
        raise ArrayCalibrationError(f"{path}: time_s and force_n must be finite numbers")
    if np.any(np.diff(t) <= 0):
        raise ArrayCalibrationError(f"{path}: time_s must increase from row to row")
    return t, f


def _numbers(path, reader: csv.DictReader, names) -> np.ndarray:
    """The columns ``names`` of a CSV's rows as numbers, shape (len(names), rows); a
    blank or non-numeric cell is an error naming its line (1 is the header) and column."""
    values = []
    for row in reader:
        numbers = []
        for name in names:
            cell = row.get(name)
            try:
                numbers.append(float(cell))
            except (TypeError, ValueError):
                shown = "blank" if cell is None or not cell.strip() else repr(cell)
                raise ArrayCalibrationError(
                    f"{path}, line {reader.line_num}: {name} is {shown}; expected a number"
                ) from None
        values.append(numbers)
    return np.array(values, dtype=float).reshape(-1, len(names)).T


def read_stage_log(path: str | Path) -> dict[str, np.ndarray]:
    """A lab's stage or force/torque log: a CSV with ``time_s`` [s], ``position_mm``
    [mm] and ``force_n`` [N] (other columns ignored), rows in time order."""
    path = Path(path)
    try:
        with open(path, newline="", encoding="utf-8") as stream:
            reader = csv.DictReader(stream)
            needed = {"time_s", "position_mm", "force_n"}
            missing = needed - set(reader.fieldnames or [])
            if missing:
                raise ArrayCalibrationError(
                    f"{path}: needs the columns time_s, position_mm and force_n; missing "
                    f"{', '.join(sorted(missing))} (has {', '.join(reader.fieldnames or [])})"
                )
            columns = _numbers(path, reader, ("time_s", "position_mm", "force_n"))
    except OSError as error:
        raise ArrayCalibrationError(f"cannot read {path}: {error.strerror}") from None
    except UnicodeDecodeError:
        raise ArrayCalibrationError(f"{path} is not a text CSV file") from None
    t, position, force = columns
    if len(t) < 2 or not np.all(np.isfinite(columns)):
        raise ArrayCalibrationError(f"{path}: needs at least 2 rows of finite numbers")
    if np.any(np.diff(t) <= 0):
        raise ArrayCalibrationError(f"{path}: time_s must increase from row to row")
    return {"time_s": t, "position_mm": position, "force_n": force}


def presses_from_log(time_s, log: dict, *, loaded_fraction: float = 0.1):
    """The presses a stage log describes, seen in a recording's frames: the last frame of
    every run of frames during which the logged force exceeds ``loaded_fraction`` of its
    largest, and the logged position and force at that frame's time.

    Returns
    -------
    last : ndarray of int
        Frame indices, one per press.
    position_mm, force_n : ndarray
    """
    time_s = np.asarray(time_s, dtype=float)
    inside = (time_s >= log["time_s"][0]) & (time_s <= log["time_s"][-1])
    force = np.interp(time_s, log["time_s"], log["force_n"])
    loaded = inside & (force > loaded_fraction * np.max(log["force_n"]))
    ends = np.flatnonzero(loaded & ~np.r_[loaded[1:], False])
    position = np.interp(time_s[ends], log["time_s"], log["position_mm"])
    return ends, position, force[ends]


# ---- known weights: the log, the presses, the curve ----------------------------------

STANDARD_GRAVITY = 9.80665
"""[m/s^2]: a mass of m grams presses with m * 9.80665e-3 N."""

LOAD_COLUMNS = {
    "force_n": 1.0,
    "force_mn": 1e-3,
    "mass_g": STANDARD_GRAVITY * 1e-3,
    "mass_kg": STANDARD_GRAVITY,
    "weight_g": STANDARD_GRAVITY * 1e-3,
    "weight_kg": STANDARD_GRAVITY,
}
"""The known load's column, by the unit in its name, and its factor to newtons."""

UNITLESS = ("force", "mass", "weight", "load", "grams", "newtons")
"""Load columns without a unit: refused (grams and newtons differ by 102 times)."""


@dataclass
class WeightsLog:
    """A lab's record of known loads (:func:`read_weights_log`)."""

    force_n: np.ndarray
    """The load of each row [N] (masses converted at standard gravity)."""
    time_s: np.ndarray | None
    """Each row's time on the recording's clock [s]; None: one row per press, in the
    order the weights were placed."""
    temperature_c: np.ndarray | None
    """Temperature of each row [degC], when the log has a ``temperature_c`` column."""
    column: str
    """The load column read (``mass_g``, ``force_n``...)."""
    source: str


def read_weights_log(path: str | Path) -> WeightsLog:
    """A lab's log of known loads: a CSV whose header names the unit.

    Either **one row per press**, the weights in the order they were placed (no
    ``time_s`` column; an optional ``press`` column numbers them), each placed, held and
    removed: the presses are then found in the recording itself
    (:func:`segment_presses`); or a **timed log** (a load cell's, or the times the
    weights were on), with ``time_s`` [s, the recording's clock].

    The load column is one of :data:`LOAD_COLUMNS`: ``force_n`` [N], ``force_mn``
    [mN], ``mass_g`` [g] or ``mass_kg`` [kg] (masses at standard gravity). An optional
    ``temperature_c`` [degC] column gives the temperature coefficient; other columns are
    ignored.
    """
    path = Path(path)
    try:
        with open(path, newline="", encoding="utf-8") as stream:
            reader = csv.DictReader(stream)
            header = [name.strip() for name in reader.fieldnames or []]
            reader.fieldnames = header
            loads = [name for name in header if name.lower() in LOAD_COLUMNS]
            if len(loads) != 1:
                raise ArrayCalibrationError(_load_column_problem(path, header, loads))
            column = loads[0]
            names = [column]
            if "time_s" in header:
                names.append("time_s")
            unitless_t = [n for n in header if n.lower() in ("temperature", "temp", "t_c")]
            if "temperature_c" in header:
                names.append("temperature_c")
            elif unitless_t:
                raise ArrayCalibrationError(
                    f"{path}: column {unitless_t[0]!r}: name the temperature column "
                    "temperature_c (degrees Celsius)"
                )
            values = dict(zip(names, _numbers(path, reader, names), strict=True))
    except OSError as error:
        raise ArrayCalibrationError(f"cannot read {path}: {error.strerror}") from None
    except UnicodeDecodeError:
        raise ArrayCalibrationError(f"{path} is not a text CSV file") from None
    force = values[column] * LOAD_COLUMNS[column.lower()]
    time = values.get("time_s")
    if len(force) == 0:
        raise ArrayCalibrationError(f"{path}: no rows under the header")
    for name, v in values.items():
        if not np.all(np.isfinite(v)):
            line = int(np.flatnonzero(~np.isfinite(v))[0]) + 2
            raise ArrayCalibrationError(f"{path}, line {line}: {name} is not a finite number")
    if time is None:
        negative = np.flatnonzero(force <= 0)
        if negative.size:
            k = int(negative[0])
            raise ArrayCalibrationError(
                f"{path}, line {k + 2}: {column} is {values[column][k]:g}; every weight placed "
                "must be a positive load"
            )
    else:
        if len(time) < 2:
            raise ArrayCalibrationError(f"{path}: a timed log needs at least 2 rows")
        if np.any(np.diff(time) <= 0):
            raise ArrayCalibrationError(f"{path}: time_s must increase from row to row")
    return WeightsLog(force_n=force, time_s=time, temperature_c=values.get("temperature_c"),
                      column=column, source=str(path))  # fmt: skip


def _load_column_problem(path, header, loads) -> str:
    known = ", ".join(LOAD_COLUMNS)
    if len(loads) > 1:
        return f"{path}: {' and '.join(loads)} are both loads; keep one of them"
    bare = [n for n in header if n.lower() in UNITLESS]
    if bare:
        return (
            f"{path}: column {bare[0]!r} has no unit; name it with its unit: {known} "
            "(grams and newtons differ by 102 times)"
        )
    if "time_s" not in header:
        return (
            f"{path}: needs the columns time_s and force_n (a load cell's log), or a load "
            f"column with its unit ({known}), one row per weight placed; has "
            f"{', '.join(header) or 'no header'}"
        )
    return f"{path}: needs a load column with its unit ({known}); has {', '.join(header)}"


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
    from tactsense.estimate.contacts.find import find_contacts

    if method not in METHODS:
        raise ArrayCalibrationError(f"method {method!r}: expected one of {', '.join(METHODS)}")
    if getattr(sensor, "kind", None) not in ("pad", "points"):
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
    from tactsense.estimate.contacts.find import find_contacts
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


def load_calibration(path: str | Path, sensor=None):
    """A calibration file of either kind: a finger's
    (:class:`~tactsense.estimate.calibrate.Calibration`) or an array's
    (:class:`ArrayCalibration`), checked against ``sensor`` when given."""
    from tactsense.estimate.finger.calibrate import Calibration

    path = Path(path)
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, json.JSONDecodeError):
        data = None  # the finger's loader says what is wrong with the file
    if isinstance(data, dict) and data.get("format") == FORMAT:
        calibration = ArrayCalibration.from_dict(data, source=str(path))
        if sensor is not None:
            calibration.check_sensor(sensor)
        return calibration
    if sensor is not None and getattr(sensor, "kind", "finger") != "finger":
        calibration = Calibration.load(path)  # a finger's: named as such below
        raise ArrayCalibrationError(
            f"{path} is a finger's calibration; {sensor.name!r} is a {sensor.kind_label}: "
            "calibrate it with 'tactsense calibrate' on its own recording"
        )
    return Calibration.load(path, sensor)
