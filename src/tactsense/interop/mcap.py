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

import struct
from pathlib import Path

import numpy as np

from tactsense._validation import TactsenseInputError
from tactsense.interop.ros import (
    TACTILE_CONTACT,
    TACTILE_CONTACT_MSGDEF,
    TACTILE_CONTACTS,
    TACTILE_CONTACTS_MSGDEF,
    TACTILE_STATE,
    TACTILE_STATE_MSGDEF,
    contact_geometry,
    tactile_contact,
    tactile_state,
)
from tactsense.kinds import kind_of
from tactsense.sensor import SensorSpec

STATES_TOPIC = "/tactile_states"
CONTACTS_TOPIC = "/tactile_contacts"
CONTACT_LISTS_TOPIC = "/contact_states"
"""One ``TactileContacts`` per frame (upstream's merger publishes them on ``contact_states``)."""


def _writer_class():
    try:
        from mcap_ros2.writer import Writer
    except ImportError:
        raise TactsenseInputError(
            'MCAP needs the mcap extra: pip install "tactsense[mcap]"'
        ) from None
    return Writer


class _Template:
    """The CDR bytes of one message type, with the stamp and the trailing numbers left to
    fill: every other byte (encapsulation, frame_id, name, lengths, padding) is the same
    in every message of one writer, so it is taken from one message the library encoded.

    ``encode(sec, nanosec, values)`` returns what the library's encoder returns for the
    message whose stamp is (sec, nanosec) and whose trailing ``n`` numbers (of ``dtype``)
    are ``values``; checked at construction on two probe messages.
    """

    def __init__(self, encoder, make, n: int, dtype):
        self.n, self.dtype = n, np.dtype(dtype)
        first = np.arange(1, n + 1, dtype=self.dtype)
        data = bytes(encoder(make(1, 2, first)))
        tail = n * self.dtype.itemsize
        self.head, self.middle = data[:4], data[12 : len(data) - tail]
        second = -np.arange(n, dtype=self.dtype) - 0.5
        for sec, nanosec, values in ((1, 2, first), (123456, 999_999_999, second)):
            if self.encode(sec, nanosec, values) != bytes(encoder(make(sec, nanosec, values))):
                raise AssertionError("the CDR layout is not the one assumed")  # pragma: no cover

    def encode(self, sec: int, nanosec: int, values) -> bytes:
        values = np.ascontiguousarray(values, dtype=self.dtype.newbyteorder("<"))
        return b"".join((self.head, _STAMP.pack(sec, nanosec), self.middle, values.tobytes()))

    def after_stamp(self, values) -> bytes:
        """The message's bytes after its stamp (``values`` of ``dtype``, little-endian)."""
        return self.middle + values.tobytes()


class _ContactBytes:
    """The CDR bytes of ``TactileContact`` messages and ``TactileContacts`` lists of them,
    from the bytes the library's encoder makes for each contact name.

    A contact's bytes are its stamp, a middle (frame_id, name, padding) and its twelve
    float64 numbers. Alone, its body starts at offset 0; first in a list, at offset 4
    (after the list's length), later in a list at a multiple of 8 (the end of the
    previous contact's last float64): so two middles per name, taken from the encoder's
    bytes of the contact alone and of the list of it alone. Checked at construction
    against the encoder on lists of 0 to 3 contacts with names of every length mod 8.
    """

    _CACHE = 4096  # names kept (a long recording has a new tracked id now and then)

    def __init__(self, encode_contact, encode_list, make):
        self._encode_contact, self._encode_list, self._make = encode_contact, encode_list, make
        self._middles: dict[str, tuple[bytes, bytes]] = {}
        self.head = bytes(encode_list({"contacts": []}))[:4]
        probe = np.arange(12, dtype="<f8") - 0.5
        same = True
        for k in range(9):  # lists of 0 to 3 contacts, names of every length mod 8
            lengths = (k, 8 - k, 3 * k % 8 + 1)[: min(k, 3)]
            items = [("n" * (n + 1), 1 + j, 2 * j, probe + j) for j, n in enumerate(lengths)]
            for names in (items, items[::-1]):
                expected = bytes(encode_list({"contacts": [make(*item) for item in names]}))
                alone = [bytes(encode_contact(make(*item))) for item in names]
                same &= self.contacts(names) == expected
                same &= alone == [self.contact(*item) for item in names]
        if not same:
            raise AssertionError("the CDR layout is not the one assumed")  # pragma: no cover
        self._middles.clear()

    def _middle(self, name: str) -> tuple[bytes, bytes]:
        middles = self._middles.get(name)
        if middles is None:
            numbers = np.zeros(12)
            alone = bytes(self._encode_contact(self._make(name, 0, 0, numbers)))
            listed = bytes(self._encode_list({"contacts": [self._make(name, 0, 0, numbers)]}))
            middles = (alone[12:-96], listed[16:-96])
            if len(self._middles) >= self._CACHE:
                self._middles.clear()
            self._middles[name] = middles
        return middles

    def contact(self, name: str, sec: int, nanosec: int, numbers) -> bytes:
        """One ``TactileContact``: what the encoder makes of it."""
        numbers = np.ascontiguousarray(numbers, dtype="<f8")
        return b"".join(
            (self.head, _STAMP.pack(sec, nanosec), self._middle(name)[0], numbers.tobytes())
        )

    def contacts(self, items) -> bytes:
        """One ``TactileContacts`` of ``(name, sec, nanosec, numbers)`` items."""
        parts = [self.head, _LENGTH.pack(len(items))]
        for k, (name, sec, nanosec, numbers) in enumerate(items):
            middle = self._middle(name)[1 if k == 0 else 0]
            numbers = np.ascontiguousarray(numbers, dtype="<f8")
            parts += [_STAMP.pack(sec, nanosec), middle, numbers.tobytes()]
        return b"".join(parts)


class McapTactileWriter:
    """Write frames and contacts of one finger to an MCAP file, as they come.

    Messages are CDR-encoded from a template (:class:`_Template`): the bytes the
    ``mcap-ros2-support`` encoder makes, without building a dictionary per message
    (``fast=False`` encodes each message with that encoder instead: the same file,
    about twenty times slower; kept for the tests and the benchmark).

    Parameters
    ----------
    stream : binary file
        Open for writing (the caller owns it; see :func:`export_mcap` for a path).
    sensor : SensorSpec
    frame_id : str
        The ``frame_id`` of every header: the link the finger is mounted on.
    """

    def __init__(
        self,
        stream,
        sensor: SensorSpec,
        *,
        frame_id: str = "finger",
        chunk_size: int = 1 << 20,
        fast: bool = True,
    ):
        Writer = _writer_class()
        from mcap_ros2._dynamic import serialize_dynamic

        self.sensor = sensor
        self.frame_id = frame_id
        self._writer = Writer(stream, chunk_size=chunk_size)
        self._state = self._writer.register_msgdef(TACTILE_STATE, TACTILE_STATE_MSGDEF)
        self._contact = self._writer.register_msgdef(TACTILE_CONTACT, TACTILE_CONTACT_MSGDEF)
        self._lists = self._writer.register_msgdef(TACTILE_CONTACTS, TACTILE_CONTACTS_MSGDEF)
        self._fast = fast
        self._raw = self._writer._writer  # the mcap Writer under the ROS 2 one
        self._channels: dict[str, int] = {}
        if fast:
            encode_state = serialize_dynamic(TACTILE_STATE, TACTILE_STATE_MSGDEF)[TACTILE_STATE]
            encode_contact = serialize_dynamic(TACTILE_CONTACT, TACTILE_CONTACT_MSGDEF)[
                TACTILE_CONTACT
            ]
            cells = int(np.prod(sensor.shape))
            header = {"frame_id": frame_id}

            def state(sec, nanosec, values):
                return {
                    "header": {"stamp": {"sec": sec, "nanosec": nanosec}, **header},
                    "sensors": [{"name": sensor.name, "values": values.tolist()}],
                }

            def contact(name, sec, nanosec, values):
                def xyz(k):
                    return dict(zip("xyz", map(float, values[3 * k : 3 * k + 3]), strict=True))

                return {
                    "header": {"stamp": {"sec": sec, "nanosec": nanosec}, **header},
                    "name": name,
                    "position": xyz(0),
                    "normal": xyz(1),
                    "wrench": {"force": xyz(2), "torque": xyz(3)},
                }

            encode_lists = serialize_dynamic(TACTILE_CONTACTS, TACTILE_CONTACTS_MSGDEF)[
                TACTILE_CONTACTS
            ]
            self._state_bytes = _Template(encode_state, state, cells, np.float32)
            if sensor.components > 1:  # ---- a channel per component (r8-triinterop) ----
                from tactsense.interop._state_bytes import ComponentStateBytes

                self._state_bytes = ComponentStateBytes(encode_state, sensor, frame_id)
            self._contact_bytes = _ContactBytes(encode_contact, encode_lists, contact)
        self.frames = 0
        self.contacts = 0
        self.lists = 0

    def _channel(self, topic: str, schema) -> int:
        """The channel of a topic, registered at its first message as the ROS 2 writer
        registers it (the same records in the same order)."""
        if topic not in self._channels:
            self._channels[topic] = self._raw.register_channel(
                topic=topic, message_encoding="cdr", schema_id=schema.id
            )
            self._writer._channel_ids[topic] = self._channels[topic]
        return self._channels[topic]

    def frame(self, counts, time_s: float, *, sequence: int | None = None) -> None:
        ns = round(float(time_s) * 1e9)
        sequence = self.frames if sequence is None else int(sequence)
        if not self._fast:
            message = tactile_state(self.sensor, counts, time_s, self.frame_id)
            self._writer.write_message(
                STATES_TOPIC, self._state, message, log_time=ns, publish_time=ns,
                sequence=sequence,
            )  # fmt: skip
        else:
            data = self._state_bytes.encode(
                ns // 1_000_000_000, ns % 1_000_000_000, np.ravel(counts)
            )
            self._raw.add_message(
                channel_id=self._channel(STATES_TOPIC, self._state), log_time=ns,
                publish_time=ns, sequence=sequence, data=data,
            )  # fmt: skip
        self.frames += 1

    def frames_of(self, counts, time_s, sequence) -> None:
        """Many frames at once: counts (k, rows, cols), their times [s] and sequences."""
        if not self._fast:
            for k in range(len(time_s)):
                self.frame(counts[k], float(time_s[k]), sequence=int(sequence[k]))
            return
        channel = self._channel(STATES_TOPIC, self._state)
        values = np.asarray(counts, dtype="<f4").reshape(len(time_s), -1)
        head, after_stamp = self._state_bytes.head, self._state_bytes.after_stamp
        for k in range(len(time_s)):
            ns = round(float(time_s[k]) * 1e9)
            stamp = _STAMP.pack(ns // 1_000_000_000, ns % 1_000_000_000)
            self._raw.add_message(
                channel_id=channel, log_time=ns, publish_time=ns, sequence=int(sequence[k]),
                data=b"".join((head, stamp, after_stamp(values[k]))),
            )  # fmt: skip
        self.frames += len(time_s)

    def contacts_of(self, time_s, axial_mm, angle_deg, force_n, has_contact) -> None:
        """A finger's contacts of many frames at once (vectorised geometry): one
        ``TactileContact`` per frame with a contact, and one ``TactileContacts`` per frame
        (of that contact, or empty)."""
        chosen = np.flatnonzero(has_contact)
        points, normals = contact_geometry(
            self.sensor, np.asarray(axial_mm)[chosen], np.asarray(angle_deg)[chosen]
        )
        self.contacts_at(time_s, chosen, points, normals, np.asarray(force_n, dtype=float)[chosen])

    def contacts_at(
        self, time_s, frame, points_m, normals, force_n, names=None, shear_n=None
    ) -> None:
        """The contacts of consecutive frames.

        One ``TactileContact`` per row (``/tactile_contacts``) and one ``TactileContacts``
        per frame (``/contact_states``; empty for a frame without a contact), stamped
        with the frame's time.

        Parameters
        ----------
        time_s : (n,) array
            The frames' times [s].
        frame : (k,) int array
            Each contact's frame, an index into ``time_s``, non-decreasing.
        points_m : (k, 3) array
            Points [m] in the sensor's frame.
        normals : (k, 3) array
            Outward unit normals there.
        force_n : (k,) array
            Normal forces [N] (pressing inward).
        names : sequence of k str, optional
            The contacts' unique names (within a frame); default the sensor's name (a
            finger's one contact).
        shear_n : (k, 3) array, optional
            The tangential force the object applies [N] in the sensor's frame (a sensor
            that senses shear), added to the wrench's force.
        """
        time_s = np.asarray(time_s, dtype=float)
        frame = np.asarray(frame, dtype=np.int64)
        if len(time_s) == 0:
            return
        points = np.asarray(points_m, dtype=float).reshape(-1, 3)
        normals = np.asarray(normals, dtype=float).reshape(-1, 3)
        force_n = np.asarray(force_n, dtype=float)
        if names is None:
            names = [self.sensor.name] * len(frame)
        force = -force_n[:, None] * normals
        if shear_n is not None:
            shear = np.asarray(shear_n, dtype=float).reshape(-1, 3)
            force = force + shear
        numbers = np.zeros((len(frame), 12), dtype="<f8")
        numbers[:, 0:3], numbers[:, 3:6], numbers[:, 6:9] = points, normals, force
        numbers[:, 9:12] = np.cross(points, force)  # about the frame's origin [N m]
        ns = np.array([round(float(t) * 1e9) for t in time_s], dtype=np.int64)
        bounds = np.searchsorted(frame, np.arange(len(time_s) + 1))
        for f in range(len(time_s)):
            t = int(ns[f])
            sec, nanosec = t // 1_000_000_000, t % 1_000_000_000
            rows = range(bounds[f], bounds[f + 1])
            if self._fast:
                items = [(names[i], sec, nanosec, numbers[i]) for i in rows]
                for item in items:
                    self._raw.add_message(
                        channel_id=self._channel(CONTACTS_TOPIC, self._contact), log_time=t,
                        publish_time=t, sequence=self.contacts,
                        data=self._contact_bytes.contact(*item),
                    )  # fmt: skip
                    self.contacts += 1
                self._raw.add_message(
                    channel_id=self._channel(CONTACT_LISTS_TOPIC, self._lists), log_time=t,
                    publish_time=t, sequence=self.lists, data=self._contact_bytes.contacts(items),
                )  # fmt: skip
            else:
                messages = [
                    tactile_contact(self.sensor, float(time_s[f]), points[i], normals[i],
                                    force_n[i], self.frame_id, name=names[i],
                                    shear_n=None if shear_n is None else shear[i])
                    for i in rows
                ]  # fmt: skip
                for message in messages:
                    self._writer.write_message(
                        CONTACTS_TOPIC, self._contact, message, log_time=t, publish_time=t,
                        sequence=self.contacts,
                    )  # fmt: skip
                    self.contacts += 1
                self._writer.write_message(
                    CONTACT_LISTS_TOPIC, self._lists, {"contacts": messages}, log_time=t,
                    publish_time=t, sequence=self.lists,
                )  # fmt: skip
            self.lists += 1

    def metadata(self, name: str, data: dict[str, str]) -> None:
        """An MCAP metadata record (name and string pairs) in the file."""
        self._raw.add_metadata(name, data)

    def losses(self, counts: dict) -> None:
        """The loss counters (``tactsense.stream.LOSS_KINDS``, each its own count) as the
        metadata record ``tactsense.losses``, which ``tactsense import`` reads back."""
        from tactsense.stream.reader import LOSS_KINDS

        self.metadata(LOSSES_METADATA, {k: str(int(counts.get(k, 0))) for k in LOSS_KINDS})

    def finish(self) -> None:
        self._writer.finish()


LOSSES_METADATA = "tactsense.losses"
"""Name of the MCAP metadata record that holds a recording's loss counters."""

_STAMP = struct.Struct("<iI")
"""builtin_interfaces/Time in CDR: int32 sec, uint32 nanosec, little-endian."""
_LENGTH = struct.Struct("<I")
"""The length of a CDR sequence, uint32, little-endian."""


def export_mcap(
    recording: str | Path,
    out: str | Path,
    *,
    calibration=None,
    baseline_frames: int = 5,
    threshold: float | None = None,
    frame_id: str = "finger",
    start_time_s: float | None = None,
    progress=None,
    fast: bool = True,
    drift_s: float | None = 2.0,
) -> dict:
    """Write a recording's frames and contacts to MCAP, a piece at a time.

    Stamps (headers and log times) are on the host's clock when the recording holds it
    (a recorded stream: each frame's arrival, Unix time), so the file aligns with the
    lab's other bags; otherwise the recording's own times plus ``start_time_s`` (Unix
    time of its first frame; default 0, i.e. 1970). The file's metadata record
    ``tactsense`` says which clock (``clock``: ``host`` or ``recording``), the sensor and
    the frame id. On a pad or a point set every contact of every frame is a message (as
    ``locate`` finds and tracks them, the baseline following drift with ``drift_s``);
    its normal is the nearest taxel's.

    Parameters
    ----------
    recording : path
        HDF5 recording.
    out : path
        The MCAP file (written directly; the command line writes to a temporary name
        and moves it into place).
    calibration : Calibration, optional
        Applied to the contacts, as for ``locate``.
    frame_id : str
        The ``frame_id`` of every header: the URDF link the sensor is mounted on.
    start_time_s : float, optional
        Unix time of the first frame [s], for a recording without host times; an error
        for one with them (they are the truth).
    progress : callable(done, total), optional

    Returns
    -------
    dict
        ``frames`` and ``contacts`` written, and the ``clock`` used.
    """
    from tactsense.batch import iter_locate
    from tactsense.estimate import Flag
    from tactsense.estimate.finger.locate import CONTACT_THRESHOLD
    from tactsense.io.recording import RecordingReader

    with RecordingReader(recording) as reader, open(out, "wb") as stream:
        host = reader.has_host_time
        if host and start_time_s is not None:
            raise TactsenseInputError(
                f"{recording} holds host times (a recorded stream): they are the stamps; "
                "--start-time is for recordings without them"
            )
        offset = 0.0 if start_time_s is None else float(start_time_s)

        def stamps(start: int, time_s: np.ndarray) -> np.ndarray:
            if host:
                return reader.host_time_s(start, start + len(time_s))
            return time_s + offset

        writer = McapTactileWriter(stream, reader.sensor, frame_id=frame_id, fast=fast)
        writer.metadata(
            "tactsense",
            {
                "clock": "host" if host else "recording",
                "clock_meaning": (
                    "arrival of each frame on the recording host, Unix time"
                    if host
                    else f"the recording's frame times plus {offset:.6f} s (Unix time)"
                ),
                "sensor": reader.sensor.name,
                "frame_id": frame_id,
                "source": str(Path(recording).name),
            },
        )
        if reader.losses:
            writer.losses(reader.losses)
        if not kind_of(reader.sensor).contact_estimation:  # ---- r8-triinterop ----
            from tactsense.interop._state_bytes import frames_only

            return frames_only(reader, writer, stamps, progress, host, calibration, threshold)
        if kind_of(reader.sensor).multi_contact:  # every contact, tracked: one message each
            from tactsense.batch import iter_contacts
            from tactsense.interop.components import component_contacts, shear_vectors

            sensor = reader.sensor
            positions = sensor.taxel_positions_mm()
            taxel_normals = sensor.taxel_normals()
            if sensor.components > 1:  # r8-triinterop: the three-axis estimator's contacts
                pieces = component_contacts(
                    reader, baseline_frames=baseline_frames, calibration=calibration,
                    threshold=threshold,
                )  # fmt: skip
                if pieces is None:  # not installed: the frames alone
                    from tactsense.interop._state_bytes import frames_only

                    return frames_only(reader, writer, stamps, progress, host, calibration,
                                       threshold)  # fmt: skip
            else:
                pieces = iter_contacts(reader, baseline_frames=baseline_frames,
                                       calibration=calibration, threshold=threshold,
                                       drift_s=drift_s)  # fmt: skip
            for start, n, time_s, table, _ in pieces:
                frames = reader.frames(start, start + n)
                when = stamps(start, time_s)
                writer.frames_of(frames, when, np.arange(start, start + n))
                xyz = np.column_stack([table.x_mm, table.y_mm, table.z_mm])
                keep = np.isfinite(xyz).all(axis=1) & np.isfinite(table.force_n)
                xyz = xyz[keep]
                # the normal of the taxel nearest each contact (+z everywhere on a pad)
                nearest = np.argmin(
                    ((xyz[:, None, :] - positions[None, :, :]) ** 2).sum(axis=-1), axis=1
                ) if len(xyz) else np.zeros(0, int)  # fmt: skip
                # upstream: "unique name of the contact"; RViz keeps one per (frame_id, name)
                names = [f"{sensor.name}/{i}" for i in table.id[keep]]
                writer.contacts_at(
                    when, table.frame[keep] - start, xyz * 1e-3, taxel_normals[nearest],
                    table.force_n[keep], names, shear_n=shear_vectors(table, keep),
                )  # fmt: skip
                if progress is not None:
                    progress(start + n, reader.n_frames)
            writer.finish()
            clock = "host" if host else "recording"
            return {
                "frames": writer.frames, "contacts": writer.contacts, "clock": clock,
                "kind": reader.sensor.kind,
            }  # fmt: skip
        pieces = iter_locate(
            reader,
            baseline_frames=baseline_frames,
            calibration=calibration,
            threshold=CONTACT_THRESHOLD if threshold is None else threshold,
        )
        for start, time_s, est in pieces:
            frames = reader.frames(start, start + len(time_s))
            when = stamps(start, time_s)
            writer.frames_of(frames, when, np.arange(start, start + len(time_s)))
            touching = ((est.flags & int(Flag.NO_CONTACT)) == 0) & np.isfinite(est.force_n)
            writer.contacts_of(when, est.axial_mm, est.angle_deg, est.force_n, touching)
            if progress is not None:
                progress(start + len(time_s), reader.n_frames)
        writer.finish()
        clock = "host" if host else "recording"
        return {"frames": writer.frames, "contacts": writer.contacts, "clock": clock}


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
                writer.losses(reader.stats.as_dict())
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
