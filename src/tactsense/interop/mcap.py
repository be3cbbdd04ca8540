"""Recordings and live streams as MCAP files for ROS 2 and Foxglove.

Frames go on the topic ``/tactile_states`` as ``tactile_msgs/msg/TactileState`` and
contacts on ``/tactile_contacts`` as ``tactile_msgs/msg/TactileContact``
(:mod:`tactsense.interop.ros`), in the ``ros2msg`` schema encoding with CDR messages
(``mcap-ros2-support``): ROS 2 tools (``ros2 bag play``, with the toolbox's messages
built) and Foxglove open them. ROS 2 over a JSON schema, because ROS 2 tools read
only CDR and Foxglove reads both.

Log times are the frames' times on the device clock (or, for a stream, the host's
arrival time), in nanoseconds.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from tactsense._validation import TactsenseInputError
from tactsense.interop.ros import (
    TACTILE_CONTACT,
    TACTILE_CONTACT_MSGDEF,
    TACTILE_STATE,
    TACTILE_STATE_MSGDEF,
    contact_geometry,
    tactile_contact,
    tactile_state,
)
from tactsense.sensor import SensorSpec

STATES_TOPIC = "/tactile_states"
CONTACTS_TOPIC = "/tactile_contacts"


def _writer_class():
    try:
        from mcap_ros2.writer import Writer
    except ImportError:
        raise TactsenseInputError(
            'MCAP needs the mcap extra: pip install "tactsense[mcap]"'
        ) from None
    return Writer


class McapTactileWriter:
    """Write frames and contacts of one finger to an MCAP file, as they come.

    Parameters
    ----------
    stream : binary file
        Open for writing (the caller owns it; see :func:`export_mcap` for a path).
    sensor : SensorSpec
    frame_id : str
        The ``frame_id`` of every header: the link the finger is mounted on.
    """

    def __init__(
        self, stream, sensor: SensorSpec, *, frame_id: str = "finger", chunk_size: int = 1 << 20
    ):
        Writer = _writer_class()
        self.sensor = sensor
        self.frame_id = frame_id
        self._writer = Writer(stream, chunk_size=chunk_size)
        self._state = self._writer.register_msgdef(TACTILE_STATE, TACTILE_STATE_MSGDEF)
        self._contact = self._writer.register_msgdef(TACTILE_CONTACT, TACTILE_CONTACT_MSGDEF)
        self.frames = 0
        self.contacts = 0

    def frame(self, counts, time_s: float, *, sequence: int | None = None) -> None:
        ns = round(float(time_s) * 1e9)
        message = tactile_state(self.sensor, counts, time_s, self.frame_id)
        self._writer.write_message(
            STATES_TOPIC, self._state, message, log_time=ns, publish_time=ns,
            sequence=self.frames if sequence is None else int(sequence),
        )  # fmt: skip
        self.frames += 1

    def contacts_of(self, time_s, axial_mm, angle_deg, force_n, has_contact) -> None:
        """Contacts of many frames at once (vectorised geometry)."""
        chosen = np.flatnonzero(has_contact)
        if len(chosen) == 0:
            return
        points, normals = contact_geometry(
            self.sensor, np.asarray(axial_mm)[chosen], np.asarray(angle_deg)[chosen]
        )
        for k, i in enumerate(chosen):
            t = float(time_s[i])
            ns = round(t * 1e9)
            message = tactile_contact(
                self.sensor, t, points[k], normals[k], force_n[i], self.frame_id
            )
            self._writer.write_message(
                CONTACTS_TOPIC, self._contact, message, log_time=ns, publish_time=ns,
                sequence=self.contacts,
            )  # fmt: skip
            self.contacts += 1

    def finish(self) -> None:
        self._writer.finish()


def export_mcap(
    recording: str | Path,
    out: str | Path,
    *,
    calibration=None,
    baseline_frames: int = 5,
    threshold: float | None = None,
    frame_id: str = "finger",
    progress=None,
) -> dict:
    """Write a recording's frames and contacts to MCAP, a piece at a time.

    Parameters
    ----------
    recording : path
        HDF5 recording.
    out : path
        The MCAP file (written directly; the command line writes to a temporary name
        and moves it into place).
    calibration : Calibration, optional
        Applied to the contacts, as for ``locate``.
    progress : callable(done, total), optional

    Returns
    -------
    dict
        ``frames`` and ``contacts`` written.
    """
    from tactsense.batch import iter_locate
    from tactsense.estimate import Flag
    from tactsense.estimate.locate import CONTACT_THRESHOLD
    from tactsense.io.recording import RecordingReader

    with RecordingReader(recording) as reader, open(out, "wb") as stream:
        writer = McapTactileWriter(stream, reader.sensor, frame_id=frame_id)
        pieces = iter_locate(
            reader,
            baseline_frames=baseline_frames,
            calibration=calibration,
            threshold=CONTACT_THRESHOLD if threshold is None else threshold,
        )
        for start, time_s, est in pieces:
            frames = reader.frames(start, start + len(time_s))
            for k in range(len(time_s)):
                writer.frame(frames[k], float(time_s[k]), sequence=start + k)
            touching = ((est.flags & int(Flag.NO_CONTACT)) == 0) & np.isfinite(est.force_n)
            writer.contacts_of(time_s, est.axial_mm, est.angle_deg, est.force_n, touching)
            if progress is not None:
                progress(start + len(time_s), reader.n_frames)
        writer.finish()
        return {"frames": writer.frames, "contacts": writer.contacts}


def record_mcap(
    reader,
    out: str | Path,
    *,
    max_frames: int | None = None,
    duration_s: float | None = None,
    overwrite: bool = False,
    frame_id: str = "finger",
    progress=None,
    progress_interval_s: float = 0.5,
) -> Path:
    """Write the frames of a stream to MCAP as they arrive (``tactsense record --out X.mcap``).

    Frames are stamped with their arrival on the host's clock. The file is written in
    small chunks (about 4 KB) flushed as they fill, and finished (index and summary) at
    the end, at Ctrl-C too; a recorder killed outright leaves the chunks written so far
    and no summary (``mcap recover`` rebuilds it). For a recording that survives
    ``kill -9`` whole, record to HDF5 and ``tactsense export`` it.
    """
    import time

    out = Path(out)
    _writer_class()  # a clear error before the file is made, if the extra is missing
    stream = open(out, "wb" if overwrite else "xb")
    writer = None
    try:
        writer = McapTactileWriter(stream, reader.sensor, frame_id=frame_id, chunk_size=4096)
        start = last = time.perf_counter()
        reported = 0
        try:
            for frame in reader.frames(max_frames=max_frames, duration_s=duration_s):
                writer.frame(frame.counts, frame.host_time_s, sequence=frame.sequence)
                now = time.perf_counter()
                if now - last >= progress_interval_s:
                    stream.flush()
                    if progress is not None:
                        rate = (writer.frames - reported) / (now - last)
                        progress(writer.frames, reader.stats, rate)
                    last, reported = now, writer.frames
        finally:
            try:
                if hasattr(reader, "stop"):
                    reader.stop(wait_s=0.5)  # END settles the last frames' losses
            finally:
                writer.finish()
                if progress is not None:
                    elapsed = max(time.perf_counter() - start, 1e-9)
                    progress(writer.frames, reader.stats, writer.frames / elapsed)
    except BaseException:
        stream.close()
        if writer is None or writer.frames == 0:
            out.unlink(missing_ok=True)  # a failed start leaves no empty file
        raise
    stream.close()
    return out
