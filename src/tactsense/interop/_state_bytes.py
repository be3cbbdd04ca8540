"""The CDR bytes of a ``TactileState`` of a sensor whose taxels report several components:
one ``ChannelFloat32`` per component (:func:`tactsense.interop.components.
component_channel_names`), each with the rows x cols values of its component.

Like :class:`tactsense.interop.mcap._Template` for one channel: every byte but the stamp
and the values is the same in every message of one sensor, so the bytes between the
channels' values are taken from a message the library encoded, and the result is checked
against the encoder at construction on two probe messages.
"""

from __future__ import annotations

import struct

import numpy as np

from tactsense.interop.components import component_channel_names, split_components

_STAMP = struct.Struct("<iI")


def state_message(sensor, sec: int, nanosec: int, values, frame_id: str) -> dict:
    """One ``TactileState`` (a dictionary for the encoder) of one frame's values in flat
    order (component fastest): a channel per component."""
    per = split_components(np.asarray(values, dtype=np.float32), sensor)[0]
    return {
        "header": {"stamp": {"sec": sec, "nanosec": nanosec}, "frame_id": frame_id},
        "sensors": [
            {"name": name, "values": per[k].tolist()}
            for k, name in enumerate(component_channel_names(sensor))
        ],
    }


class ComponentStateBytes:
    """``encode(sec, nanosec, values)``: what the encoder makes of :func:`state_message`,
    ``values`` a frame's numbers in flat order (component fastest)."""

    def __init__(self, encoder, sensor, frame_id: str):
        self.sensor = sensor
        k, n = sensor.components, sensor.n_taxels
        probe = np.arange(1, k * n + 1, dtype=np.float32)
        data = bytes(encoder(state_message(sensor, 1, 2, probe, frame_id)))
        per = split_components(probe, sensor)[0].astype("<f4")
        self.head = data[:4]
        self.middles: list[bytes] = []
        at = 12
        for c in range(k):
            found = data.find(per[c].tobytes(), at)
            if found < 0:  # pragma: no cover - the encoder writes the values as given
                raise AssertionError("the CDR layout is not the one assumed")
            self.middles.append(data[at:found])
            at = found + 4 * n
        if at != len(data):  # pragma: no cover
            raise AssertionError("the CDR layout is not the one assumed")
        second = -np.arange(k * n, dtype=np.float32) - 0.5
        for sec, nanosec, values in ((1, 2, probe), (123456, 999_999_999, second)):
            made = bytes(encoder(state_message(sensor, sec, nanosec, values, frame_id)))
            if self.encode(sec, nanosec, values) != made:  # pragma: no cover
                raise AssertionError("the CDR layout is not the one assumed")

    def after_stamp(self, values) -> bytes:
        """The message's bytes after its stamp, for one frame's values (flat order)."""
        per = split_components(np.asarray(values, dtype="<f4"), self.sensor)[0]
        parts = []
        for middle, row in zip(self.middles, per, strict=True):
            parts += [middle, row.tobytes()]
        return b"".join(parts)

    def encode(self, sec: int, nanosec: int, values) -> bytes:
        return b"".join((self.head, _STAMP.pack(sec, nanosec), self.after_stamp(values)))


def frames_only(reader, writer, stamps, progress, host: bool, calibration=None,
                threshold=None) -> dict:  # fmt: skip
    """The MCAP export of a kind that estimates no contacts (yet): its frames alone, as
    ``TactileState`` messages (``contacts`` None: none were estimated); the options of
    contacts refused."""
    from tactsense.interop.components import refuse_contact_options

    refuse_contact_options(reader.sensor, calibration, threshold)
    for start, frames, time_s in reader.chunks():
        n = len(time_s)
        writer.frames_of(frames, stamps(start, np.asarray(time_s)), np.arange(start, start + n))
        if progress is not None:
            progress(start + n, reader.n_frames)
    writer.finish()
    return {
        "frames": writer.frames, "contacts": None, "clock": "host" if host else "recording",
        "kind": reader.sensor.kind,
    }  # fmt: skip
