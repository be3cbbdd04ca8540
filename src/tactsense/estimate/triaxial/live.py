"""Three-axis contacts frame by frame, for ``live`` and ``view``: the same numbers as
``locate`` (:class:`~tactsense.estimate.triaxial.locate.ShearPipeline`), one frame at a
time."""

from __future__ import annotations

import time

import numpy as np

from tactsense.estimate.results import Flag

SHEAR_FIELDS = (
    "id", "x_mm", "y_mm", "z_mm", "row", "col", "force_n", "peak", "major_mm", "minor_mm",
    "orientation_deg", "taxels", "area_mm2", "vx_mm_s", "vy_mm_s", "vz_mm_s", "slip",
    "flags", "shear_x_n", "shear_y_n", "shear_n", "shear_angle_deg", "shear_ratio",
    "slip_state", "stick_ratio", "friction", "slip_onset_s", "slip_detected_s",
)  # fmt: skip
"""Fields of each contact in :class:`LiveShearContacts`' estimates: a pad's contact's
(``LiveContacts``) and the tangential force (x, y, magnitude [N], direction [deg], ratio
[-]) and slip (``slip_state`` one of ``stick``, ``partial``, ``gross``; ``slip`` True in
gross slip; stick ratio c/a [-]; ``friction`` [-]; onset and its detection [s])."""


class LiveShearContacts:
    """Every contact of every frame of a three-axis stream, tracked, with shear and slip.

    The same interface as :class:`tactsense.stream.live.LiveContacts`: called with a
    frame (an object with ``counts`` (rows, cols, 3), ``sequence``, ``device_time_s``,
    ``host_time_s`` and ``arrival`` (``time.perf_counter()`` at arrival)) it returns None
    while the baseline is collected (the first ``baseline_frames`` frames, untouched, or
    the calibration's), then a dict per frame.

    Parameters
    ----------
    sensor : a three-axis sensor description
    baseline_frames : int
    threshold_counts : float, optional
        Smallest change of a taxel's field that counts as contact [counts].
    baseline : array_like (rows, cols, 3), optional
    calibration : TriaxialCalibration, optional
    friction : float, optional
        Friction coefficient [-] for the slip states (None: found per contact).
    keep_deflection : bool
        Keep the last frame's change in :attr:`last_change` [counts] (rows, cols, 3) and
        :attr:`last_deflection` (the same over the converter's full scale [-]).
    radius_mm : float, optional
        Radius of the indenter's sphere [mm] (the response fitted is the kind's for it);
        None: the kind's default probe.
    """

    def __init__(self, sensor, *, baseline_frames: int = 5, threshold_counts=None,
                 baseline=None, calibration=None, friction=None, max_contacts: int = 8,
                 keep_deflection: bool = False,
                 radius_mm: float | None = None):  # fmt: skip
        if calibration is not None:
            calibration.check_sensor(sensor)
            baseline = calibration.baseline
        self.sensor = sensor
        self.calibration = calibration
        self._options = {"calibration": calibration, "threshold_counts": threshold_counts,
                         "friction": friction, "max_contacts": max_contacts,
                         "radius_mm": radius_mm}  # fmt: skip
        self._baseline_frames = max(1, int(baseline_frames))
        self._keep = bool(keep_deflection)
        self._collected: list[np.ndarray] = []
        self._pipeline = None
        self._serial = 0
        self.last_change: np.ndarray | None = None
        self.last_deflection: np.ndarray | None = None
        self.below_frames = 0
        if baseline is not None:
            self._start(np.asarray(baseline, dtype=float))

    def _start(self, baseline: np.ndarray) -> None:
        from tactsense.estimate.triaxial.locate import ShearPipeline

        self._pipeline = ShearPipeline(self.sensor, baseline, **self._options)

    @property
    def ready(self) -> bool:
        return self._pipeline is not None

    @property
    def baseline(self) -> np.ndarray | None:
        return None if self._pipeline is None else self._pipeline.baseline

    def reset(self) -> None:
        """Forget the tracks and slip (after a jump in time)."""
        if self._pipeline is not None:
            self._start(self._pipeline.baseline)
        self._serial = 0

    def rezero(self) -> None:
        """Take the baseline anew from the next ``baseline_frames`` frames (untouched)."""
        self._pipeline = None
        self._collected = []

    def __call__(self, frame) -> dict | None:
        counts = np.asarray(frame.counts, dtype=float)
        if self._pipeline is None:
            self._collected.append(counts)
            if len(self._collected) >= self._baseline_frames:
                self._start(np.nanmedian(np.stack(self._collected), axis=0))
                self._collected = []
            return None
        tracked, _ = self._pipeline(counts[None], first_frame=self._serial)
        self._serial += 1
        if self._keep:
            change = counts - self._pipeline.baseline
            if self.calibration is not None:
                change = self.calibration.apply(change)
            self.last_change = change
            self.last_deflection = change / (2**self.sensor.electronics.adc_bits - 1)
        columns = tracked.columns()
        contacts = [
            {name: _plain(columns[name][k]) for name in SHEAR_FIELDS if name in columns}
            for k in range(len(tracked))
        ]
        flags = int(np.bitwise_or.reduce(tracked.flags)) if len(tracked) else int(Flag.NO_CONTACT)
        return {
            "sequence": getattr(frame, "sequence", self._serial - 1),
            "device_time_s": getattr(frame, "device_time_s", None),
            "host_time_s": getattr(frame, "host_time_s", None),
            "n_contacts": len(contacts),
            "force_n": float(np.nansum(tracked.force_n)) if len(tracked) else 0.0,
            "shear_n": float(np.nansum(tracked.extra["shear_n"])) if len(tracked) else 0.0,
            "flags": flags,
            "flag_names": Flag.describe(flags),
            "rezeroing": False,
            "contacts": contacts,
            "latency_ms": 1e3
            * (time.perf_counter() - getattr(frame, "arrival", time.perf_counter())),
        }


def _plain(value):
    """A NumPy scalar as the Python value JSON writers expect."""
    if isinstance(value, np.bool_ | bool):
        return bool(value)
    if isinstance(value, np.integer):
        return int(value)
    if isinstance(value, str):
        return value
    return float(value)
