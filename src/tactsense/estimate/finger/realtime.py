"""A low-latency locator for a tactile servo loop: one frame in, one estimate out."""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from tactsense import _signals
from tactsense._signals import deliver, gate_ready
from tactsense._validation import TactsenseInputError, check_frames
from tactsense.estimate.finger._fast import locate_deflection_one, locate_one
from tactsense.estimate.finger.force import force_per_deflection
from tactsense.estimate.finger.localize import MAX_ITERATIONS, MAX_STEP, TOLERANCE
from tactsense.estimate.finger.locate import CONTACT_THRESHOLD
from tactsense.estimate.results import Flag
from tactsense.sensor import SensorSpec

_NO_CONTACT = int(Flag.NO_CONTACT)
_NOT_CONVERGED = int(Flag.NOT_CONVERGED)
_EDGE = int(Flag.EDGE)
_TIP = int(Flag.TIP)
_MULTIPLE = int(Flag.MULTIPLE)
_SATURATED = int(Flag.SATURATED)
_NEGATIVE_FORCE = int(Flag.NEGATIVE_FORCE)
_NAN = float("nan")


class Contact(NamedTuple):
    """One frame's estimate (NaN fields and the NO_CONTACT flag when nothing touches)."""

    row: float
    """[tactel]"""
    col: float
    """[tactel]"""
    axial_mm: float
    """[mm]"""
    angle_deg: float
    """[deg]"""
    peak_deflection: float
    """[-]"""
    force_n: float
    """[N]"""
    skew: float
    """[-]"""
    iterations: int
    converged: bool
    flags: int


class RealTimeLocator:
    """Everything :func:`~tactsense.estimate.finger.locate` does, for one frame at a time, fast.

    The baseline, the excluded tactels and the constants are prepared once; each call
    runs one compiled function on the frame and a few float operations, about
    7 microseconds on the project's CPU (docs/performance.md).

    Ctrl-C: making a locator in the main thread installs the process-wide SIGINT gate
    of :mod:`tactsense._signals`, which hands the signal on to the handler in force
    before it; a press during a frame's compiled call is delivered right after it (a
    KeyboardInterrupt under Python's default handler).
    :func:`tactsense._signals.remove_gate` puts the previous handler back.

    Parameters
    ----------
    sensor : SensorSpec
    baseline : array_like, shape (rows, cols)
        Undeflected readings [counts].
    dead : array_like of bool, shape (rows, cols), optional
    threshold : float
        Smallest tactel deflection that counts as contact [-].

    Examples
    --------
    >>> locator = RealTimeLocator(sensor, baseline)       # doctest: +SKIP
    >>> contact = locator(frame_counts)                  # doctest: +SKIP
    >>> contact.axial_mm, contact.force_n                # doctest: +SKIP
    """

    def __init__(
        self,
        sensor: SensorSpec,
        baseline,
        *,
        dead=None,
        threshold: float = CONTACT_THRESHOLD,
        second_contact: float = 0.3,
    ):
        baseline = check_frames(baseline, sensor.shape, "baseline").astype(float)
        if baseline.ndim != 2:
            raise TactsenseInputError(
                f"baseline has shape {baseline.shape}; expected {sensor.shape}"
            )
        unusable = ~np.isfinite(baseline) | (baseline <= 0)
        if dead is not None:
            unusable |= np.asarray(dead, dtype=bool)
        self.sensor = sensor
        self._baseline = np.where(unusable, 1.0, baseline)
        self._unusable = unusable
        self._full_scale = float(2**sensor.electronics.adc_bits - 1)
        self._periodic = sensor.closes_circumference
        self._first_row = 1 if sensor.array.tip_row else 0
        self._force = force_per_deflection(sensor)
        self._threshold = threshold
        self._second = second_contact
        self._rows_axial = [float(v) for v in sensor.row_axial_mm]
        self._angle0 = float(sensor.col_angle_deg[0])
        self._spacing_deg = float(sensor.array.spacing_angle_deg)
        self._shape = tuple(sensor.shape)
        self._settings = np.array(
            [
                self._full_scale,
                threshold,
                TOLERANCE,
                MAX_STEP,
                1.0 if self._periodic else 0.0,
                self._first_row,
                MAX_ITERATIONS,
                int(Flag.NAN_INPUT),
                int(Flag.SATURATED),
                int(Flag.DEAD_TACTEL),
            ],
            dtype=np.float64,
        )
        self._out = np.empty(10)
        # compile (or load from Numba's cache) both paths now, not on the first contact,
        # for float64 and uint16 readings (the types taken as they come)
        touched = np.array(self._baseline)
        touched[self.sensor.shape[0] // 2, 0] *= 1.0 + 20 * threshold
        for frame in (np.asarray(baseline), touched):
            self(frame)
            if self._full_scale < 2**16:
                self(np.clip(np.round(frame), 0, self._full_scale).astype(np.uint16))

    def _axial(self, row: float) -> float:
        knots = self._rows_axial
        i = min(max(int(row), 0), len(knots) - 2)
        return knots[i] + (row - i) * (knots[i + 1] - knots[i])

    def __call__(self, frame) -> Contact:
        """Estimate the contact of one frame of readings [counts], shape (rows, cols)."""
        frame = np.asarray(frame)
        if frame.shape != self._shape:
            raise TactsenseInputError(
                f"frame has shape {frame.shape}; expected {self.sensor.shape}"
            )
        if frame.dtype != np.float64 and frame.dtype != np.uint16:
            frame = frame.astype(np.float64)
        out = self._out
        # Ctrl-C held back by the process-wide gate's flag (tactsense._signals: a flag
        # set and cleared, where swapping the handler cost about 7 us a frame)
        if gate_ready():
            outer = _signals._inside_compiled
            _signals._inside_compiled = True
            try:
                locate_one(frame, self._baseline, self._unusable, self._settings, out)
            finally:
                _signals._inside_compiled = outer
            if _signals._pressed and not outer:
                deliver()
        else:
            locate_one(frame, self._baseline, self._unusable, self._settings, out)
        return self._contact(out)

    def from_deflection(self, deflection) -> Contact:
        """Estimate the contact of one frame of fractional deflection [-], shape (rows,
        cols), that a calibration made (:meth:`Calibration.apply
        <tactsense.estimate.finger.calibrate.Calibration.apply>`: gains, nonlinearity and creep
        applied, excluded tactels 0): the compiled path of ``live --calibration``."""
        deflection = np.ascontiguousarray(deflection, dtype=np.float64)
        if deflection.shape != self._shape:
            raise TactsenseInputError(
                f"deflection has shape {deflection.shape}; expected {self.sensor.shape}"
            )
        out = self._out
        if gate_ready():
            outer = _signals._inside_compiled
            _signals._inside_compiled = True
            try:
                locate_deflection_one(deflection, self._settings, out)
            finally:
                _signals._inside_compiled = outer
            if _signals._pressed and not outer:
                deliver()
        else:
            locate_deflection_one(deflection, self._settings, out)
        return self._contact(out)

    def _contact(self, out) -> Contact:
        r, c, value, iterations, converged, summed, skew, second, flag, touched = out.tolist()
        flag = int(flag)
        if not touched:
            nan = _NAN
            return Contact(nan, nan, nan, nan, nan, nan, nan, 0, False, flag | _NO_CONTACT)
        rows, cols = self._shape
        if not converged:
            flag |= _NOT_CONVERGED
        if r < 0.5 or r > rows - 1.5 or (not self._periodic and (c < 0.5 or c > cols - 1.5)):
            flag |= _EDGE
        if self._first_row and r < 1.0:
            flag |= _TIP
        if second >= self._second:
            flag |= _MULTIPLE
        if summed <= 0.0:  # more tension than compression: no force (as locate)
            flag |= _NEGATIVE_FORCE
        angle = (self._angle0 + self._spacing_deg * c + 180.0) % 360.0 - 180.0
        return Contact(
            r,
            c,
            self._axial(r),
            angle,
            value,
            _NAN if flag & (_SATURATED | _NEGATIVE_FORCE) else self._force * summed,
            skew,
            int(iterations),
            bool(converged),
            flag,
        )
