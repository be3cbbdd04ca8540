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
from tactsense.estimate.calibrate import save_json

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
    """(estimated [N], measured [N]) knots of the piecewise-linear force curve."""
    notes: dict = field(default_factory=dict)

    @property
    def sensor(self):
        from tactsense.estimate.calibrate import sensor_of

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
        from tactsense.estimate.contacts import signal_from_counts

        if baseline is not None and hasattr(baseline, "signal"):
            signal, flags = baseline.signal(frames, dead=self.dead)
        else:
            signal, flags = signal_from_counts(
                frames, self.baseline if baseline is None else baseline, sensor, dead=self.dead
            )
        signal /= np.where(self.dead, 1.0, self.gains)
        return signal, flags

    def force(self, estimated) -> np.ndarray:
        """Forces through the curve [N] (unchanged without one; linear beyond its ends,
        never below zero: a load pressing on the array has no negative force)."""
        estimated = np.asarray(estimated, dtype=float)
        if self.force_curve is None:
            return estimated
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
            "force_curve": None
            if self.force_curve is None
            else {
                "estimated_n": list(self.force_curve[0]),
                "measured_n": list(self.force_curve[1]),
            },
            "notes": self.notes,
        }

    def save(self, path: str | Path, *, overwrite: bool = False) -> Path:
        return save_json(self.to_dict(), path, overwrite=overwrite)

    @classmethod
    def from_dict(cls, data: dict, source: str = "calibration") -> ArrayCalibration:
        if not isinstance(data, dict) or data.get("format") != FORMAT:
            raise ArrayCalibrationError(f"{source} is not a tactsense array calibration")
        try:
            curve = data.get("force_curve")
            calibration = cls(
                sensor_toml=data["sensor_toml"],
                baseline=np.array(data["baseline_counts"], dtype=float),
                gains=np.array(data["gains"], dtype=float),
                dead=np.array(data["dead"], dtype=bool),
                force_curve=None
                if curve is None
                else (
                    list(map(float, curve["estimated_n"])),
                    list(map(float, curve["measured_n"])),
                ),
                notes=data.get("notes", {}),
            )
            sensor = calibration.sensor
        except (KeyError, TypeError, ValueError) as error:
            from tactsense.estimate.calibrate import damaged

            keys = ("format", "sensor_toml", "baseline_counts", "gains", "dead", "force_curve")
            raise ArrayCalibrationError(damaged(source, error, "array calibration", keys)) from None
        for name in ("baseline", "gains", "dead"):
            if getattr(calibration, name).shape != tuple(sensor.shape):
                raise ArrayCalibrationError(
                    f"{source}: {name} has the wrong shape, expected {tuple(sensor.shape)}"
                )
        from tactsense.estimate.calibrate import check_in_use

        check_in_use(source, ~calibration.dead, calibration, ArrayCalibrationError, "taxel")
        if calibration.force_curve is not None:
            x, y = (np.asarray(v) for v in calibration.force_curve)
            if len(x) < 2 or len(x) != len(y) or np.any(np.diff(x) <= 0) or np.any(np.diff(y) < 0):
                raise ArrayCalibrationError(
                    f"{source}: the force curve needs at least 2 knots, increasing in both "
                    "estimated and measured force"
                )
        return calibration


# ---- building one --------------------------------------------------------------------


def _signal(frames, sensor, baseline):
    from tactsense.estimate.contacts import signal_from_counts

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
    from tactsense.estimate.contacts import default_threshold

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
    from tactsense.estimate.contacts import default_threshold

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


METHODS = {"sweep": gains_from_sweep, "press": gains_from_press}
"""How the gains are found: a probe on every taxel in turn, or a uniform press."""


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
) -> ArrayCalibration:
    """A pad's or a point set's calibration from a recording (and a force log).

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
    """
    from tactsense.estimate.contacts import find_contacts

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
    from tactsense.estimate.calibrate import Calibration

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
