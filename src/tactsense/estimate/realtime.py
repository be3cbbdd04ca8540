"""A low-latency locator for a tactile servo loop: one frame in, one estimate out."""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from tactsense._signals import deferred_interrupts
from tactsense._validation import TactsenseInputError, check_frames
from tactsense.estimate._fast import locate_frames, prepare_frames
from tactsense.estimate.deflection import Flag
from tactsense.estimate.force import force_per_deflection
from tactsense.estimate.localize import MAX_ITERATIONS, MAX_STEP, TOLERANCE
from tactsense.estimate.locate import CONTACT_THRESHOLD
from tactsense.sensor import SensorSpec


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
    """Everything :func:`~tactsense.estimate.locate` does, for one frame at a time, fast.

    The baseline, the excluded tactels and the constants are prepared once; each call
    runs two compiled functions on the frame and a few float operations, about
    15 microseconds on the project's CPU (docs/performance.md).

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
        self._valid = np.ones(1, dtype=bool)
        self._shape = (1, *sensor.shape)
        # compile (or load from Numba's cache) both paths now, not on the first contact
        self(np.asarray(baseline))
        touched = np.array(self._baseline)
        touched[self.sensor.shape[0] // 2, 0] *= 1.0 + 20 * threshold
        self(touched)

    def _axial(self, row: float) -> float:
        knots = self._rows_axial
        i = min(max(int(row), 0), len(knots) - 2)
        return knots[i] + (row - i) * (knots[i + 1] - knots[i])

    def __call__(self, frame) -> Contact:
        """Estimate the contact of one frame of readings [counts], shape (rows, cols)."""
        frame = np.asarray(frame, dtype=np.float64)
        if frame.shape != self.sensor.shape:
            raise TactsenseInputError(
                f"frame has shape {frame.shape}; expected {self.sensor.shape}"
            )
        # one hold of Ctrl-C around both compiled passes (about 9 us per hold)
        with deferred_interrupts():
            deflection, flags, peak = prepare_frames(
                frame.reshape(self._shape),
                self._baseline,
                self._unusable,
                self._full_scale,
                int(Flag.NAN_INPUT),
                int(Flag.SATURATED),
                int(Flag.DEAD_TACTEL),
            )
            touched = peak[0] >= self._threshold
            if touched:
                row, col, value, iterations, converged, summed, skew, second = locate_frames(
                    deflection,
                    self._valid,
                    self._periodic,
                    self._first_row,
                    TOLERANCE,
                    MAX_ITERATIONS,
                    MAX_STEP,
                )
        flag = int(flags[0])
        if not touched:
            nan = float("nan")
            return Contact(nan, nan, nan, nan, nan, nan, nan, 0, False, flag | int(Flag.NO_CONTACT))
        r, c = float(row[0]), float(col[0])
        rows, cols = self.sensor.shape
        if not converged[0]:
            flag |= int(Flag.NOT_CONVERGED)
        if r < 0.5 or r > rows - 1.5 or (not self._periodic and (c < 0.5 or c > cols - 1.5)):
            flag |= int(Flag.EDGE)
        if self._first_row and r < 1.0:
            flag |= int(Flag.TIP)
        if second[0] >= self._second:
            flag |= int(Flag.MULTIPLE)
        angle = (self._angle0 + self._spacing_deg * c + 180.0) % 360.0 - 180.0
        return Contact(
            r,
            c,
            self._axial(r),
            angle,
            float(value[0]),
            float("nan") if flag & int(Flag.SATURATED) else self._force * float(summed[0]),
            float(skew[0]),
            int(iterations[0]),
            bool(converged[0]),
            flag,
        )
