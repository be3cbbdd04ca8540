"""Calibration of any array from a lab's own data: pads and point sets.

A finger's calibration (:class:`~tactsense.estimate.finger.calibrate.Calibration`) follows the
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

import json
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from tactsense._validation import TactsenseInputError
from tactsense.estimate._kind import kind_or_none
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
        :class:`~tactsense.estimate.contacts.baseline.DriftBaseline` started from it follows
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


def load_calibration(path: str | Path, sensor=None):
    """A calibration file of either kind: a finger's
    (:class:`~tactsense.estimate.finger.calibrate.Calibration`) or an array's
    (:class:`ArrayCalibration`), checked against ``sensor`` when given."""
    from tactsense.estimate.finger.calibrate import Calibration

    path = Path(path)
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, json.JSONDecodeError):
        data = None  # the finger's loader says what is wrong with the file
    # ---- three-axis calibration (r8-triest) ----
    from tactsense.estimate.triaxial.calibration import TriaxialCalibration, is_triaxial_calibration

    if is_triaxial_calibration(data):
        calibration = TriaxialCalibration.from_dict(data, source=str(path))
        if sensor is not None:
            calibration.check_sensor(sensor)
        return calibration
    if sensor is not None and int(getattr(sensor, "components", 1)) > 1:
        raise ArrayCalibrationError(
            f"{path} is not a three-axis calibration; {sensor.name!r} reads "
            f"{sensor.components} components a taxel: calibrate it with 'tactsense "
            "calibrate' on its own sweeps"
        )
    # ---- /r8-triest ----
    if isinstance(data, dict) and data.get("format") == FORMAT:
        calibration = ArrayCalibration.from_dict(data, source=str(path))
        if sensor is not None:
            calibration.check_sensor(sensor)
        return calibration
    kind = kind_or_none(sensor)
    if kind is not None and kind.array_calibration:
        calibration = Calibration.load(path)  # a finger's: named as such below
        raise ArrayCalibrationError(
            f"{path} is a finger's calibration; {sensor.name!r} is a {kind.label}: "
            "calibrate it with 'tactsense calibrate' on its own recording"
        )
    return Calibration.load(path, sensor)
