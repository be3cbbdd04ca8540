"""Contacts from a live stream, frame by frame, as they arrive."""

from __future__ import annotations

import time

import numpy as np

from tactsense.estimate import Flag, locate
from tactsense.estimate.creep import CreepCompensator
from tactsense.estimate.deflection import deflection_from_counts
from tactsense.estimate.locate import CONTACT_THRESHOLD
from tactsense.estimate.realtime import RealTimeLocator
from tactsense.physics.contact import newtons_to_grams
from tactsense.sensor import SensorSpec
from tactsense.stream.reader import StreamFrame

FIELDS = (
    "sequence",
    "device_time_s",
    "host_time_s",
    "row",
    "col",
    "axial_mm",
    "angle_deg",
    "force_n",
    "force_g",
    "skew",
    "peak_deflection",
    "flags",
    "flag_names",
    "latency_ms",
)
"""Fields of every estimate :class:`LiveLocator` returns, in output order."""


def flag_names(flags: int) -> str:
    """The set flags of an estimate as ``A|B`` (empty when none)."""
    return "|".join(flag.name for flag in Flag if flag and flags & flag)


class LiveLocator:
    """The contact of every frame of a stream, with its latency.

    Without a calibration the first ``baseline_frames`` frames (untouched) give the
    baseline and then :class:`~tactsense.estimate.realtime.RealTimeLocator` runs on
    each frame. With a calibration its baseline, nonlinearity table, gains and excluded
    tactels apply from the first frame, and its creep model is inverted causally
    (:class:`~tactsense.estimate.creep.CreepCompensator`).

    Parameters
    ----------
    sensor : SensorSpec
    calibration : Calibration, optional
    baseline_frames : int
        Untouched frames that make the baseline when there is no calibration.
    threshold : float
        Smallest tactel deflection that counts as a contact [-].
    frame_period_s : float, optional
        Time between frames [s], for the creep compensation; default the sensor's.
    baseline : array_like, shape (rows, cols), optional
        Without a calibration: the undeflected readings [counts], known in advance
        (e.g. from the start of a recording); no frames are spent collecting one.
    keep_deflection : bool
        Keep the fractional deflection of the last frame in :attr:`last_deflection`
        (for a display; costs a few microseconds a frame).
    """

    def __init__(
        self,
        sensor: SensorSpec,
        *,
        calibration=None,
        baseline_frames: int = 5,
        threshold: float = CONTACT_THRESHOLD,
        frame_period_s: float | None = None,
        baseline=None,
        keep_deflection: bool = False,
    ):
        self.sensor = sensor
        self.calibration = calibration
        self.threshold = threshold
        self._baseline_frames = int(baseline_frames)
        self._collected: list[np.ndarray] = []
        self._locator: RealTimeLocator | None = None
        self._creep = None
        self._keep = bool(keep_deflection)
        self._baseline = None
        self.last_deflection: np.ndarray | None = None
        """Fractional deflection of the last frame [-] (with ``keep_deflection``)."""
        # compile (or load from Numba's cache) now, not while frames queue up
        RealTimeLocator(sensor, np.full(sensor.shape, 1000.0), threshold=threshold)
        if calibration is not None:
            locate(np.full((1, *sensor.shape), 0.05), sensor, counts=False)
        if calibration is not None:
            calibration.check_sensor(sensor)
            if calibration.viscoelastic is not None:
                self._period = frame_period_s or sensor.scan_period_s
                self._creep = CreepCompensator(calibration.viscoelastic, self._period, sensor.shape)
        elif baseline is not None:
            self._set_baseline(np.asarray(baseline, dtype=float))

    def _set_baseline(self, baseline: np.ndarray) -> None:
        self._baseline = baseline
        self._locator = RealTimeLocator(self.sensor, baseline, threshold=self.threshold)

    def reset(self) -> None:
        """Forget the creep history (after a jump in time, e.g. a seek in a recording)."""
        if self._creep is not None:
            self._creep = CreepCompensator(
                self.calibration.viscoelastic, self._period, self.sensor.shape
            )

    @property
    def ready(self) -> bool:
        """True once estimates come out (the baseline is known)."""
        return self.calibration is not None or self._locator is not None

    def __call__(self, frame: StreamFrame) -> dict | None:
        """The estimate of one frame (a dict of :data:`FIELDS`), or None while the
        baseline is being collected."""
        if self.calibration is not None:
            contact = self._calibrated(frame.counts)
        else:
            if self._locator is None:
                self._collected.append(frame.counts)
                if len(self._collected) < self._baseline_frames:
                    return None
                self._set_baseline(np.median(np.stack(self._collected), axis=0))
                self._collected = []
                return None
            c = self._locator(frame.counts)
            if self._keep:
                self.last_deflection = deflection_from_counts(
                    frame.counts, self._baseline, self.sensor
                )[0]
            contact = (
                c.row, c.col, c.axial_mm, c.angle_deg, c.force_n, c.skew,
                c.peak_deflection, c.flags,
            )  # fmt: skip
        row, col, axial, angle, force, skew, peak, flags = contact
        return {
            "sequence": frame.sequence,
            "device_time_s": frame.device_time_s,
            "host_time_s": frame.host_time_s,
            "row": row,
            "col": col,
            "axial_mm": axial,
            "angle_deg": angle,
            "force_n": force,
            "force_g": float(newtons_to_grams(force)),
            "skew": skew,
            "peak_deflection": peak,
            "flags": int(flags),
            "flag_names": flag_names(int(flags)),
            "latency_ms": 1e3 * (time.perf_counter() - frame.arrival),
        }

    def _calibrated(self, counts: np.ndarray):
        deflection, apply_flags = self.calibration.apply(counts[None], self.sensor)
        if self._creep is not None:
            deflection = self._creep(deflection[0])[None]
        if self._keep:
            self.last_deflection = deflection[0]
        est = locate(deflection, self.sensor, counts=False, threshold=self.threshold)
        flags = int(est.flags[0]) | int(np.bitwise_or.reduce(np.ravel(apply_flags)))
        return (
            float(est.row[0]), float(est.col[0]), float(est.axial_mm[0]),
            float(est.angle_deg[0]), float(est.force_n[0]), float(est.skew[0]),
            float(est.peak_deflection[0]), flags,
        )  # fmt: skip
