"""A three-axis recording's contacts, piece by piece: found, tracked, slip followed,
written as the long table (``tactsense locate``)."""

from __future__ import annotations

import math
from collections.abc import Iterator

import numpy as np

from tactsense._validation import TactsenseInputError
from tactsense.estimate.results import ContactTable

SLIP_COLUMNS = ("slip_state", "stick_ratio", "friction", "slip_onset_s", "slip_detected_s")
"""The columns :class:`~tactsense.estimate.triaxial.slip.SlipMonitor` adds."""


def check_friction(friction: float | None) -> float | None:
    """``friction`` checked: None or a coefficient in [0.05, 5] [-]."""
    if friction is None:
        return None
    if not (isinstance(friction, int | float) and math.isfinite(friction)
            and 0.05 <= friction <= 5.0):  # fmt: skip
        raise TactsenseInputError(f"--friction must be a coefficient in 0.05-5; got {friction!r}")
    return float(friction)


def threshold_counts_of(sensor, threshold: float | None) -> float | None:
    """``--threshold`` on a three-axis sensor, in counts: the ONE rule of ``locate``,
    ``export``, ``live`` and ``view`` (r8-fixb8). ``threshold`` is a fraction of the
    converter's full scale (``2**adc_bits - 1`` counts) that the length of a taxel's field
    change (its three components') must exceed; None: the default,
    :func:`~tactsense.estimate.reading.vector_threshold_counts` (8 read noises times
    sqrt(3), at least 10 counts)."""
    if threshold is None:
        return None
    return float(threshold) * (2**sensor.electronics.adc_bits - 1)


class ShearPipeline:
    """Frames in, tracked contacts with their shear and slip out; state (tracks, slip)
    carried from call to call.

    Parameters
    ----------
    sensor : a three-axis sensor description
    baseline : array_like (rows, cols, 3)
        Rest readings [counts] (a calibration's when one is given).
    calibration : TriaxialCalibration, optional
    threshold_counts : float, optional
        :func:`~tactsense.estimate.triaxial.fit.default_threshold_counts`.
    friction : float, optional
        The friction coefficient [-] for the slip states; None: found per contact.
    max_contacts : int
    dead : array_like of bool (rows, cols), optional
    radius_mm : float, optional
        Radius of the indenter's sphere [mm] (the response fitted is the kind's for it);
        None: the kind's default probe.
    """

    def __init__(self, sensor, baseline, *, calibration=None, threshold_counts=None,
                 friction=None, max_contacts: int = 8, dead=None,
                 radius_mm: float | None = None):  # fmt: skip
        from tactsense.estimate.contacts.track import ContactTracker
        from tactsense.estimate.triaxial.response import check_radius_mm
        from tactsense.estimate.triaxial.slip import SlipMonitor

        self.sensor = sensor
        self.baseline = np.asarray(baseline, dtype=float)
        self.calibration = calibration
        self.threshold_counts = threshold_counts
        self.max_contacts = max_contacts
        self.dead = dead
        self.radius_mm = None if radius_mm is None else check_radius_mm(radius_mm)
        self.tracker = ContactTracker(sensor.scan_period_s)
        self.slip = SlipMonitor(sensor.scan_period_s, check_friction(friction))

    def __call__(self, frames, first_frame: int = 0):
        """``(table, events)`` of ``frames`` (N, rows, cols, 3) [counts]: the tracked
        contacts with the shear and slip columns."""
        from tactsense.estimate.triaxial.fit import find_shear_contacts

        table = find_shear_contacts(
            frames, self.sensor, baseline=self.baseline, calibration=self.calibration,
            threshold_counts=self.threshold_counts, max_contacts=self.max_contacts,
            first_frame=first_frame, dead=self.dead, radius_mm=self.radius_mm,
        )  # fmt: skip
        return self.track(table, first_frame)

    def track(self, table, first_frame: int = 0):
        """``(table, events)``: the contacts ``table`` of
        :func:`~tactsense.estimate.triaxial.fit.find_shear_contacts` (frames from
        ``first_frame``) tracked, with the slip columns (what a call does after the fit:
        one fit can be followed with ``mu`` given and found)."""
        tracked, events = self.tracker.update(table, first_frame=first_frame)
        columns = self.slip.update(
            tracked.frame, tracked.id, tracked.extra["shear_ratio"], tracked.x_mm,
            tracked.y_mm, tracked.extra["shear_angle_deg"], tracked.force_n,
        )  # fmt: skip
        tracked.extra.update(columns)
        tracked.slip = np.asarray(columns["slip_state"] == "gross", dtype=bool)
        if len(tracked):
            self.slip.forget(np.unique(tracked.id[tracked.frame == tracked.frame.max()]))
        return tracked, events


def iter_shear_contacts(reader, *, baseline_frames: int = 5, calibration=None,
                        threshold_counts=None, friction=None, max_contacts: int = 8,
                        chunk_frames: int | None = None,
                        radius_mm: float | None = None) -> Iterator:  # fmt: skip
    """``(start, n, time_s, table, events)`` of an open recording, a piece at a time
    (``radius_mm``: the indenter's sphere [mm], as :class:`ShearPipeline`'s)."""
    sensor = reader.sensor
    if calibration is not None:
        calibration.check_sensor(sensor)
        baseline = calibration.baseline
    else:
        if reader.n_frames < baseline_frames:
            raise TactsenseInputError(
                f"{reader.path} has {reader.n_frames} frames; need {baseline_frames} "
                "untouched frames at the start for the baseline"
            )
        baseline = np.nanmedian(reader.frames(0, baseline_frames).astype(float), axis=0)
    pipeline = ShearPipeline(sensor, baseline, calibration=calibration,
                             threshold_counts=threshold_counts, friction=friction,
                             max_contacts=max_contacts, radius_mm=radius_mm)  # fmt: skip
    for start, frames, time_s in reader.chunks(chunk_frames):
        table, events = pipeline(frames, first_frame=start)
        yield start, len(frames), time_s, table, events


def empty_table(sensor) -> ContactTable:
    """A tracked table with no row but every column (the file's columns when nothing
    was touched)."""
    pipeline = ShearPipeline(sensor, np.zeros(sensor.frame_shape))
    table, _ = pipeline(np.zeros((0, *sensor.frame_shape)))
    return table
