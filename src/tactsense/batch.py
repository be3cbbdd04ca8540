"""Recordings of any length in bounded memory: locate piece by piece, write as you go.

:func:`iter_locate` reads a recording chunk by chunk (the HDF5 chunks) and yields the
estimates of each piece; :class:`EstimatesWriter` appends them to a CSV, Parquet or HDF5
file chosen by the extension; :func:`locate_file` joins the two with a progress callback.
Peak memory is that of one piece (65,536 frames of 8 x 8: about 35 MB of float64 and
the estimates), whatever the length of the recording.

Examples
--------
>>> from tactsense.batch import locate_file
>>> summary = locate_file("long.h5", "estimates.parquet")  # doctest: +SKIP
>>> summary["frames"], summary["contacts"]  # doctest: +SKIP
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterator
from dataclasses import fields
from pathlib import Path

import numpy as np

from tactsense._validation import TactsenseInputError
from tactsense.estimate.finger.deflection import Flag
from tactsense.estimate.finger.locate import CONTACT_THRESHOLD, Estimates, locate
from tactsense.estimate.output import FORMATS, EstimatesWriter, output_format
from tactsense.io.recording import RecordingReader

__all__ = [
    "FORMATS",
    "EstimatesWriter",
    "iter_locate",
    "locate_file",
    "output_format",
    "shear_contacts_file",
]


def iter_locate(
    reader: RecordingReader,
    *,
    baseline=None,
    baseline_frames: int = 5,
    calibration=None,
    threshold: float = CONTACT_THRESHOLD,
    chunk_frames: int | None = None,
    workers: int = 1,
) -> Iterator[tuple[int, np.ndarray, Estimates]]:
    """Estimates of a recording, one piece at a time: ``(first frame, time_s, estimates)``.

    The same numbers as :func:`~tactsense.estimate.finger.locate` on the whole recording: the
    baseline is the median of the first ``baseline_frames`` frames (or given), and a
    calibration's creep compensation carries its state from piece to piece.
    """
    sensor = reader.sensor
    compensator = None
    if calibration is not None:
        calibration.check_sensor(sensor)
        compensator = calibration.compensator(sensor.scan_period_s, sensor.shape)
    elif baseline is None:
        if reader.n_frames < baseline_frames:
            raise TactsenseInputError(
                f"{reader.path} has {reader.n_frames} frames; need {baseline_frames} "
                "untouched frames at the start for the baseline"
            )
        baseline = np.median(reader.frames(0, baseline_frames).astype(float), axis=0)
    for start, frames, time_s in reader.chunks(chunk_frames):
        if calibration is not None:
            estimates = locate(
                frames,
                sensor,
                calibration=calibration,
                compensator=compensator,
                threshold=threshold,
                workers=workers,
            )
        else:
            estimates = locate(
                frames, sensor, baseline=baseline, threshold=threshold, workers=workers
            )
        yield start, time_s, estimates


class Tally:
    """Running counts of a recording's estimates, piece by piece: contacts, saturated
    frames, and the sum and largest of the force over the contacts."""

    def __init__(self) -> None:
        self.contacts = self.saturated = 0
        self.force_sum, self.force_max = 0.0, float("nan")

    def add(self, estimates: Estimates) -> None:
        self.contacts += int(np.count_nonzero(np.isfinite(estimates.row)))
        self.saturated += int(np.count_nonzero(estimates.flags & int(Flag.SATURATED)))
        finite = estimates.force_n[np.isfinite(estimates.force_n)]
        if finite.size:
            self.force_sum += float(finite.sum())
            self.force_max = float(np.fmax(self.force_max, finite.max()))

    def merge(self, other: Tally) -> None:
        self.contacts += other.contacts
        self.saturated += other.saturated
        self.force_sum += other.force_sum
        self.force_max = float(np.fmax(self.force_max, other.force_max))

    def summary(self) -> dict:
        mean = self.force_sum / self.contacts if self.contacts else float("nan")
        return {
            "contacts": self.contacts,
            "saturated": self.saturated,
            "force_mean_n": mean,
            "force_max_n": self.force_max,
        }


def locate_file(
    recording: str | Path,
    out: str | Path,
    *,
    baseline_frames: int = 5,
    calibration=None,
    threshold: float = CONTACT_THRESHOLD,
    chunk_frames: int | None = None,
    workers: int = 1,
    progress: Callable[[int, int], None] | None = None,
) -> dict:
    """Locate every frame of a recording file and write the estimates to ``out``.

    Reads and writes piece by piece (bounded memory). ``out`` is written as it is named:
    write to a temporary name and move it into place if it must appear only complete
    (the command line does). ``progress(done, total)`` is called after each piece.

    Returns
    -------
    dict
        ``frames``, ``contacts`` (frames with a contact), ``saturated`` (frames flagged
        SATURATED), ``force_mean_n`` and ``force_max_n`` over the contacts [N], and
        ``movement``: when no frame has a contact although the readings moved by more
        than the threshold, why (:func:`~tactsense.estimate.contacts.baseline.movement_warning`);
        else None.
    """
    output_format(out)
    tally = Tally()
    with RecordingReader(recording) as reader, EstimatesWriter(out) as writer:
        total = reader.n_frames
        if progress is not None:
            progress(0, total)
        for start, time_s, estimates in iter_locate(
            reader,
            baseline_frames=baseline_frames,
            calibration=calibration,
            threshold=threshold,
            chunk_frames=chunk_frames,
            workers=workers,
        ):
            writer.write(start, time_s, estimates)
            tally.add(estimates)
            if progress is not None:
                progress(start + len(estimates), total)
        if writer.rows == 0:  # an empty recording still gets its (empty) file
            empty = Estimates(*(np.zeros(0) for _ in fields(Estimates)))
            writer.write(0, np.zeros(0), empty)
            writer.rows = 0
        movement = None
        if tally.contacts == 0 and total >= baseline_frames:  # why none: from the readings
            from tactsense.estimate.contacts.baseline import ReadingRange, movement_warning

            extremes = ReadingRange(reader.sensor.shape)
            for _, frames, _ in reader.chunks(chunk_frames):
                extremes.update(frames)
            if calibration is not None:
                baseline = calibration.baseline
            else:
                baseline = np.nanmedian(reader.frames(0, baseline_frames).astype(float), axis=0)
            movement = movement_warning(
                extremes, baseline, reader.sensor, threshold, found=False,
                baseline_frames=None if calibration is not None else baseline_frames,
            )  # fmt: skip
    return {"frames": total, **tally.summary(), "movement": movement}


class iter_contacts:
    """The tracked contacts of an open recording, a piece at a time: yields
    ``(start, n_frames, time_s, table, events)`` with the table's ``frame`` column
    counting from the recording's first frame.

    The baseline, as :func:`contacts_file` describes it, and the tracker are kept in
    :attr:`baseline` (None with a finger's calibration) and :attr:`tracker` for the
    caller. Unless a finger's calibration says which taxels are dead, the recording is
    read once first for every taxel's range of readings (:attr:`extremes`), from which
    the taxels that give no signal are found (:attr:`health`,
    :func:`~tactsense.estimate.contacts.baseline.taxel_health`: no finite reading, stuck at the
    rail, or never changing while the others do); the first two are left out (flag
    ``DEAD_TACTEL``; with an array calibration, its own dead taxels are left out
    instead).
    """

    def __init__(
        self,
        reader,
        *,
        baseline_frames: int = 5,
        calibration=None,
        threshold: float | None = None,
        max_contacts: int = 8,
        method: str = "interpolate",
        chunk_frames: int | None = None,
        tracker_options: dict | None = None,
        drift_s: float | None = None,
    ):
        from tactsense.estimate.contacts import default_threshold
        from tactsense.estimate.contacts.array_calibration import ArrayCalibration
        from tactsense.estimate.contacts.baseline import DriftBaseline, ReadingRange, taxel_health
        from tactsense.estimate.contacts.track import ContactTracker
        from tactsense.estimate.creep import creep_applied, memory_possible

        sensor = reader.sensor
        self.reader = reader
        self.compensator = None
        self.baseline = None
        self.start = None
        """The baseline the recording starts from [counts] (None with a finger's
        calibration)."""
        self.extremes = None
        """Every taxel's smallest and largest reading over the recording
        (:class:`~tactsense.estimate.contacts.baseline.ReadingRange`; None with a finger's
        calibration)."""
        self.health = None
        """:func:`~tactsense.estimate.contacts.baseline.taxel_health` of the recording."""
        self.dead = None
        self.creep = "none"
        """Where the creep taken out came from (:func:`~tactsense.estimate.creep.creep_applied`)."""
        array_calibration = isinstance(calibration, ArrayCalibration)
        if threshold is None and array_calibration:  # a weight curve's own threshold
            threshold = calibration.contact_threshold
        if calibration is not None and not array_calibration:
            calibration.check_sensor(sensor)
            self.compensator = calibration.compensator(sensor.scan_period_s, sensor.shape)
        else:
            if array_calibration:  # its baseline, then following drift
                calibration.check_sensor(sensor)
                start = calibration.baseline
            elif reader.n_frames < baseline_frames:
                raise TactsenseInputError(
                    f"{reader.path} has {reader.n_frames} frames; need {baseline_frames} "
                    "untouched frames at the start for the baseline"
                )
            else:
                # NaN-tolerant: one unreadable value in the baseline frames does not
                # make its taxel dead for the whole recording
                start = np.nanmedian(reader.frames(0, baseline_frames).astype(float), axis=0)
            self.start = np.array(start, dtype=float)
            self.extremes = ReadingRange(sensor.shape)
            for _, frames, _ in reader.chunks(chunk_frames):
                self.extremes.update(frames)
            self.health = taxel_health(self.extremes, self.start, sensor)
            if self.health["excluded"].any() and not array_calibration:
                self.dead = self.health["excluded"]
            creep, stiffening, self.creep = creep_applied(sensor, reader.attrs)
            if threshold is None:  # the sensor's, over the noise the creep
                # compensation leaves (the same for the baseline and the contacts)
                threshold = default_threshold(sensor, creep=creep)
            self.baseline = DriftBaseline(
                start, sensor, frame_period_s=sensor.scan_period_s,
                threshold=threshold,
                time_constant_s=math.inf if drift_s is None else drift_s,
                creep=creep, stiffening=stiffening,
                # the lift re-zero only where the readings can carry a memory
                release=None if memory_possible(reader.attrs) else False,
            )  # fmt: skip
        self.tracker = ContactTracker(sensor.scan_period_s, **(tracker_options or {}))
        self._options = dict(calibration=calibration, threshold=threshold,
                             max_contacts=max_contacts, method=method)  # fmt: skip
        self._chunk_frames = chunk_frames

    def __iter__(self):
        from tactsense.estimate.contacts import find_contacts

        sensor = self.reader.sensor
        calibrated = self.compensator is not None
        for start, frames, time_s in self.reader.chunks(self._chunk_frames):
            table = find_contacts(
                frames, sensor, baseline=self.baseline, compensator=self.compensator,
                first_frame=start, dead=self.dead,
                frame_period_s=sensor.scan_period_s if calibrated else None, **self._options,
            )  # fmt: skip
            tracked, events = self.tracker.update(table, first_frame=start)
            yield start, len(frames), time_s, tracked, events


def contacts_file(
    recording: str | Path,
    out: str | Path,
    *,
    baseline_frames: int = 5,
    calibration=None,
    threshold: float | None = None,
    max_contacts: int = 8,
    method: str = "interpolate",
    chunk_frames: int | None = None,
    events_path: str | Path | None = None,
    tracker_options: dict | None = None,
    drift_s: float | None = None,
    progress: Callable[[int, int], None] | None = None,
) -> dict:
    """Every contact of every frame of a recording, tracked, written as a long table.

    Without a calibration the baseline is the median of the first ``baseline_frames``
    frames; with ``drift_s`` [s] it then follows slow drift of untouched taxels with that
    time constant (:class:`~tactsense.estimate.contacts.baseline.DriftBaseline`).

    :func:`~tactsense.estimate.contacts.find_contacts` and
    :class:`~tactsense.estimate.contacts.track.ContactTracker` piece by piece (bounded memory;
    the tracker's state carries across pieces), written by
    :class:`~tactsense.estimate.output.ContactsWriter` (``events_path``: where a CSV's
    events go, by default beside it).

    Returns
    -------
    dict
        ``frames``, ``rows`` (contacts over all frames), ``frames_with_contact``,
        ``ids`` (distinct tracked contacts), ``most`` (largest number in one frame),
        ``births``, ``deaths``, ``merges``, ``splits``, ``below_baseline`` (frames with a
        taxel below its baseline by more than the threshold: the first frames were
        probably touched), ``saturated`` (contacts flagged SATURATED),
        ``beyond_calibration`` (contacts beyond a weight curve's range, force NaN),
        ``force_mean_n``
        and ``force_max_n`` over the contacts of known force [N], ``creep`` (the creep
        taken out: ``"none"`` or ``"described (...)"``,
        :func:`~tactsense.estimate.creep.creep_applied`), ``unusable`` (a sentence
        naming the taxels found to give no signal,
        :func:`~tactsense.estimate.contacts.baseline.health_warning`, or None) and
        ``movement`` (what the way the readings moved says is wrong: against the
        polarity, or no contact although they moved by more than the threshold,
        :func:`~tactsense.estimate.contacts.baseline.movement_warning`; else None).
    """
    from tactsense.estimate.contacts import default_threshold, find_contacts
    from tactsense.estimate.contacts.baseline import health_warning, movement_warning
    from tactsense.estimate.output import ContactsWriter

    output_format(out)
    counts = {"births": 0, "deaths": 0, "merges": 0, "splits": 0}
    frames_with = most = saturated = beyond = 0
    force_sum, force_count, force_max = 0.0, 0, float("nan")
    with RecordingReader(recording) as reader:
        sensor = reader.sensor
        total = reader.n_frames
        pieces = iter_contacts(
            reader, baseline_frames=baseline_frames, calibration=calibration,
            threshold=threshold, max_contacts=max_contacts, method=method,
            chunk_frames=chunk_frames, tracker_options=tracker_options, drift_s=drift_s,
        )  # fmt: skip
        with ContactsWriter(out, events_path=events_path) as writer:
            if progress is not None:
                progress(0, total)
            for start, n, time_s, tracked, events in pieces:
                writer.write_contacts(np.asarray(time_s)[tracked.frame - start], tracked, events)
                per_frame = np.bincount(tracked.frame - start, minlength=n)
                frames_with += int(np.count_nonzero(per_frame))
                most = max(most, int(per_frame.max(initial=0)))
                saturated += int(np.count_nonzero(tracked.flags & int(Flag.SATURATED)))
                beyond += int(np.count_nonzero(tracked.flags & int(Flag.BEYOND_CALIBRATION)))
                finite = tracked.force_n[np.isfinite(tracked.force_n)]
                if finite.size:
                    force_sum += float(finite.sum())
                    force_count += finite.size
                    force_max = float(np.fmax(force_max, finite.max()))
                for e in events:
                    counts[e.kind + "s"] += 1
                if progress is not None:
                    progress(start + n, total)
            if writer.rows == 0:  # no contact at all: the file still gets its columns
                empty, _ = pieces.tracker.update(
                    find_contacts(
                        np.zeros((0, *sensor.shape)), sensor, counts=False, method=method
                    ),  # the same method: its columns (--method joint adds some)
                    first_frame=total,
                )
                writer.write_contacts(np.zeros(0), empty)
            ids = pieces.tracker.next_id
            baseline = pieces.baseline
            creep = pieces.creep
            unusable = movement = None
            if pieces.health is not None:
                unusable = health_warning(pieces.health, sensor)
                movement = movement_warning(
                    pieces.extremes, pieces.start, sensor,
                    default_threshold(sensor) if threshold is None else threshold,
                    found=writer.rows > 0, dead=pieces.health["dead"],
                    baseline_frames=baseline_frames,
                )  # fmt: skip
    return {
        "frames": total,
        "rows": writer.rows,
        "frames_with_contact": frames_with,
        "ids": ids,
        "most": most,
        **counts,
        "below_baseline": 0 if baseline is None else baseline.below_frames,
        "below_first_baseline": 0 if baseline is None else baseline.below_first_frames,
        "saturated": saturated,
        "beyond_calibration": beyond,
        "force_mean_n": force_sum / force_count if force_count else float("nan"),
        "force_max_n": force_max,
        "creep": creep,
        "unusable": unusable,
        "movement": movement,
    }


# ---- three-axis recordings (issue 35): the estimator reads no file itself ----
def shear_contacts_file(
    recording: str | Path,
    out: str | Path,
    *,
    baseline_frames: int = 5,
    calibration=None,
    threshold_counts: float | None = None,
    friction: float | None = None,
    max_contacts: int = 8,
    chunk_frames: int | None = None,
    events_path: str | Path | None = None,
    progress: Callable[[int, int], None] | None = None,
    radius_mm: float | None = None,
) -> dict:
    """Every contact of a three-axis recording, tracked, with shear and slip, written
    as the long table (CSV, Parquet or HDF5 by extension; bounded memory).
    ``radius_mm``: the indenter's sphere [mm] (the response fitted; None: the kind's
    default probe; r9-mjslip2).

    Returns a summary: ``frames``, ``rows``, ``frames_with_contact``, ``ids``, ``most``,
    ``saturated``, ``force_max_n`` and ``shear_max_n`` [N], ``gross_slips`` (contacts
    that slipped) and ``births``/``deaths``/``merges``/``splits``.
    """
    from tactsense.estimate.output import ContactsWriter
    from tactsense.estimate.results import Flag
    from tactsense.estimate.triaxial.locate import (
        check_friction,
        empty_table,
        iter_shear_contacts,
    )

    output_format(out)
    check_friction(friction)
    counts = {"births": 0, "deaths": 0, "merges": 0, "splits": 0}
    frames_with = most = saturated = 0
    force_max = shear_max = float("nan")
    slipped: set[int] = set()
    with RecordingReader(recording) as reader:
        sensor = reader.sensor
        total = reader.n_frames
        pieces = iter_shear_contacts(
            reader, baseline_frames=baseline_frames, calibration=calibration,
            threshold_counts=threshold_counts, friction=friction,
            max_contacts=max_contacts, chunk_frames=chunk_frames, radius_mm=radius_mm,
        )  # fmt: skip
        with ContactsWriter(out, events_path=events_path) as writer:
            if progress is not None:
                progress(0, total)
            ids = 0
            for start, n, time_s, tracked, events in pieces:
                writer.write_contacts(np.asarray(time_s)[tracked.frame - start], tracked, events)
                per_frame = np.bincount(tracked.frame - start, minlength=n)
                frames_with += int(np.count_nonzero(per_frame))
                most = max(most, int(per_frame.max(initial=0)))
                saturated += int(np.count_nonzero(tracked.flags & int(Flag.SATURATED)))
                if len(tracked):
                    force_max = float(np.fmax(force_max, np.nanmax(tracked.force_n)))
                    shear_max = float(np.fmax(shear_max, np.nanmax(tracked.extra["shear_n"])))
                    slipped.update(int(i) for i in tracked.id[tracked.slip])
                    ids = max(ids, int(tracked.id.max()) + 1)
                for e in events:
                    counts[e.kind + "s"] += 1
                if progress is not None:
                    progress(start + n, total)
            if writer.rows == 0:
                writer.write_contacts(np.zeros(0), empty_table(sensor))
    return {"frames": total, "rows": writer.rows, "frames_with_contact": frames_with,
            "ids": ids, "most": most, "saturated": saturated, "force_max_n": force_max,
            "shear_max_n": shear_max, "gross_slips": len(slipped), **counts}  # fmt: skip
