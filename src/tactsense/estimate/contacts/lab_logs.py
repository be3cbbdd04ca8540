"""A lab's logs for an array calibration: a load cell's force log, a stage's log of
presses, and the log of known weights placed on the array."""

from __future__ import annotations

import csv
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from tactsense.estimate.contacts.calibration import ArrayCalibrationError


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
