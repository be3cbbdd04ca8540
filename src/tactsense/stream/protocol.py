"""The tactsense wire protocol, versions 1 and 2: packets, their encoding and decoding.

Specified for firmware authors in ``docs/protocol.md``; this module is its reference
implementation. In short: every packet is ``version | kind | body | CRC-32``, COBS-encoded
(so it contains no zero byte) and followed by one zero byte, the delimiter. A reader that
joins the line at any moment, or loses bytes, resynchronises at the next zero byte.

Frame packet body (all little-endian)::

    sequence     u16   frame counter, wraps from 65535 to 0
    device_time  u64   start of the frame's scan on the device clock [us]
    rows, cols   u8    shape of the array
    counts       u16 x rows*cols, row-major (row 0 = tip row, axis -1 around the finger)

Version 2 adds one FRAME layout, for taxels of several components (a three-axis taxel's
x, y, z): ``components u8`` (1..4) after ``cols``, then ``rows*cols*components`` counts,
row-major by taxel with the component fastest (the frame ``(rows, cols, components)``
flattened in C order). Every other packet is the same in both versions; a version-1
frame still reads as it always did, and a device of one component may keep sending it.

The CRC is CRC-32/ISO-HDLC (the CRC of zlib, Ethernet and PNG: polynomial 0x04C11DB7,
reflected, initial value and final XOR 0xFFFFFFFF) of every byte before it, stored
little-endian. It is computed with :func:`zlib.crc32` and the framing with the ``cobs``
package: no hand-written CRC or framing.
"""

from __future__ import annotations

import json
import struct
import zlib
from dataclasses import dataclass
from enum import IntEnum

import numpy as np
from cobs import cobs

VERSION = 1
"""The version of the host's commands (every device understands them) and of a FRAME of
one component per taxel."""
FRAME_V2 = 2
"""The version of a FRAME with a ``components`` byte: several components per taxel."""
VERSIONS = (VERSION, FRAME_V2)
"""Versions a packet may carry; IDENT and END are laid out alike in both."""
MAX_COMPONENTS = 4
"""Most components a taxel may report in a version-2 FRAME."""
DELIMITER = b"\x00"

_HEAD = struct.Struct("<BB")  # version, kind
_FRAME = struct.Struct("<BBHQBB")  # version, kind, sequence, device time [us], rows, cols
_FRAME_V2 = struct.Struct("<BBHQBBB")  # ... rows, cols, components
_CRC = struct.Struct("<I")
_END = struct.Struct("<BBHI")  # version, kind, last sequence sent, frames sent (mod 2**32)

SEQUENCE_MODULUS = 1 << 16


class Kind(IntEnum):
    """Packet kinds: device to host below 0x80, host to device from 0x80."""

    FRAME = 0x01
    """One scan of the array."""
    IDENT = 0x02
    """The device's identity: a UTF-8 JSON object (``docs/protocol.md``)."""
    END = 0x03
    """The device stopped streaming: the last sequence number sent and the frames sent."""
    IDENTIFY = 0x81
    """Host asks for an IDENT packet."""
    START = 0x82
    """Host asks the device to start streaming frames."""
    STOP = 0x83
    """Host asks the device to stop; the device answers with END."""


class ProtocolError(ValueError):
    """Raised when a packet cannot be decoded; ``reason`` names the kind of loss."""

    def __init__(self, reason: str, message: str):
        super().__init__(message)
        self.reason = reason


@dataclass(frozen=True)
class FramePacket:
    """A decoded frame: its counter, device time and counts."""

    sequence: int
    device_time_us: int
    counts: np.ndarray
    """(rows, cols) uint16 [counts]; (rows, cols, components) from a version-2 frame of
    more than one component (the component axis last)."""
    version: int = VERSION
    """The FRAME layout it came in (1, or 2 with a components byte)."""


@dataclass(frozen=True)
class EndPacket:
    last_sequence: int
    frames_sent: int


@dataclass(frozen=True)
class ControlPacket:
    """IDENT (with its JSON body), IDENTIFY, START or STOP."""

    kind: Kind
    body: dict


def frame_size(rows: int, cols: int, components: int = 1) -> int:
    """Bytes of a frame packet before COBS encoding (header, counts and CRC): version 1
    for one component per taxel, version 2 (one byte more of header) for several."""
    head = _FRAME.size if components == 1 else _FRAME_V2.size
    return head + 2 * rows * cols * components + _CRC.size


def encoded_frame_size(rows: int, cols: int, components: int = 1) -> int:
    """Fewest bytes a frame takes on the wire: COBS adds at least one byte (at most one
    per 254), plus the delimiter. Exact for frames of up to 254 bytes (10x10 tactels)."""
    return frame_size(rows, cols, components) + 2


def _seal(packet: bytes) -> bytes:
    return cobs.encode(packet + _CRC.pack(zlib.crc32(packet))) + DELIMITER


def encode_frame(
    sequence: int, device_time_us: int, counts: np.ndarray, *, version: int | None = None
) -> bytes:
    """Encode one frame, delimiter included.

    Parameters
    ----------
    sequence : int
        Frame counter; taken modulo 65536.
    device_time_us : int
        Start of the frame's scan on the device clock [us].
    counts : ndarray, shape (rows, cols) or (rows, cols, components)
        A/D readings [counts], 0..65535; the component axis last (1..4 components).
    version : {1, 2}, optional
        The FRAME layout; default the first that carries the frame: 1 for
        ``(rows, cols)``, 2 for ``(rows, cols, components)``. A frame of one component
        may be sent as version 2 (``components`` = 1).
    """
    counts = np.asarray(counts)
    if counts.ndim not in (2, 3) or not (0 < counts.shape[0] < 256 and 0 < counts.shape[1] < 256):
        raise ValueError(
            f"counts must be (rows, cols) or (rows, cols, components) with 1..255 rows and "
            f"columns; got {counts.shape}"
        )
    components = counts.shape[2] if counts.ndim == 3 else 1
    if not 1 <= components <= MAX_COMPONENTS:
        raise ValueError(f"a taxel carries 1..{MAX_COMPONENTS} components; got {components}")
    if version is None:
        version = VERSION if counts.ndim == 2 else FRAME_V2
    if version not in VERSIONS or (version == VERSION and components != 1):
        raise ValueError(
            f"version {version} cannot carry {components} components per taxel; "
            f"version {FRAME_V2} carries 1..{MAX_COMPONENTS}"
        )
    rows, cols = counts.shape[:2]
    sequence, time_us = sequence % SEQUENCE_MODULUS, int(device_time_us)
    if version == VERSION:
        head = _FRAME.pack(VERSION, Kind.FRAME, sequence, time_us, rows, cols)
    else:
        head = _FRAME_V2.pack(FRAME_V2, Kind.FRAME, sequence, time_us, rows, cols, components)
    return _seal(head + counts.astype("<u2", copy=False).tobytes())


def encode_control(kind: Kind, body: dict | None = None) -> bytes:
    """Encode an IDENT, IDENTIFY, START or STOP packet; IDENT carries a JSON body."""
    payload = b"" if body is None else json.dumps(body, separators=(",", ":")).encode()
    return _seal(_HEAD.pack(VERSION, kind) + payload)


def encode_end(last_sequence: int, frames_sent: int) -> bytes:
    """Encode the END packet a device sends when it stops streaming."""
    return _seal(
        _END.pack(VERSION, Kind.END, last_sequence % SEQUENCE_MODULUS, frames_sent % (1 << 32))
    )


def _looks_like_frame(raw: bytes) -> bool:
    # COBS leaves the bytes before the first zero in place after the code byte: a frame
    # starts with (code >= 3, version, FRAME).
    return len(raw) >= 3 and raw[0] >= 3 and raw[1] in VERSIONS and raw[2] == Kind.FRAME


def decode_packet(raw: bytes, expected_frame_bytes: int | None = None):
    """Decode one packet (the bytes between two delimiters, without them).

    Parameters
    ----------
    raw : bytes
        COBS-encoded packet.
    expected_frame_bytes : int, optional
        Encoded length of a whole frame (without delimiter), to tell a truncated
        frame from line noise.

    Returns
    -------
    FramePacket, EndPacket or ControlPacket

    Raises
    ------
    ProtocolError
        ``reason`` is ``"truncated"`` (the start of a frame, cut short),
        ``"bad_check"`` (a whole packet whose CRC fails) or ``"garbage"`` (bytes that
        are no packet: noise, or the tail of a packet the reader joined mid-way).
    """
    framelike = _looks_like_frame(raw)
    short = expected_frame_bytes is not None and len(raw) < expected_frame_bytes
    try:
        packet = cobs.decode(raw)
    except cobs.DecodeError:
        reason = "truncated" if framelike and short else "garbage"
        raise ProtocolError(reason, f"not a COBS packet ({len(raw)} bytes)") from None
    if len(packet) < _HEAD.size + _CRC.size or packet[0] not in VERSIONS:
        reason = "truncated" if framelike else "garbage"
        raise ProtocolError(reason, f"no version-1 or -2 packet ({len(packet)} bytes)")
    body, (crc,) = packet[: -_CRC.size], _CRC.unpack_from(packet, len(packet) - _CRC.size)
    if zlib.crc32(body) != crc:
        reason = "truncated" if framelike and short else "bad_check"
        raise ProtocolError(reason, "CRC-32 mismatch")
    kind = body[1]
    if kind == Kind.FRAME:
        return _decode_frame(body)
    if kind == Kind.END and len(body) == _END.size:
        _, _, last, sent = _END.unpack(body)
        return EndPacket(last, sent)
    if kind in (Kind.IDENT, Kind.IDENTIFY, Kind.START, Kind.STOP):
        text = body[_HEAD.size :]
        try:
            data = json.loads(text) if text else {}
        except (UnicodeDecodeError, json.JSONDecodeError):
            raise ProtocolError("bad_check", "control packet body is not JSON") from None
        return ControlPacket(Kind(kind), data if isinstance(data, dict) else {})
    raise ProtocolError("garbage", f"unknown packet kind 0x{kind:02x}")


def _decode_frame(body: bytes) -> FramePacket:
    """A FRAME's body (CRC checked): version 1 ``(rows, cols)``, version 2
    ``(rows, cols, components)`` (``(rows, cols)`` when it carries one component)."""
    version = body[0]
    head = _FRAME if version == VERSION else _FRAME_V2
    if len(body) < head.size:
        raise ProtocolError("truncated", "frame header cut short")
    if version == VERSION:
        _, _, sequence, device_time, rows, cols = head.unpack_from(body)
        components = 1
    else:
        _, _, sequence, device_time, rows, cols, components = head.unpack_from(body)
        if not 1 <= components <= MAX_COMPONENTS:
            raise ProtocolError(
                "bad_check", f"frame of {components} components per taxel (1..{MAX_COMPONENTS})"
            )
    if len(body) != head.size + 2 * rows * cols * components:
        raise ProtocolError(
            "bad_check",
            f"frame of {rows}x{cols} tactels x {components} components has {len(body)} bytes",
        )
    # a native, writable copy: a read-only view of the packet is another type to
    # Numba, compiled at the first frame although the estimator was warmed (0.9-2 s)
    counts = np.frombuffer(body, dtype="<u2", offset=head.size).astype(np.uint16)
    shape = (rows, cols) if components == 1 else (rows, cols, components)
    return FramePacket(sequence, device_time, counts.reshape(shape), version)


class PacketSplitter:
    """Cut a byte stream into packets at the delimiters; keeps the unfinished tail."""

    def __init__(self, max_packet: int = 1 << 20):
        self._tail = b""
        self._max = max_packet
        self._received = 0
        self.overflow_bytes = 0
        """Bytes dropped because no delimiter came within ``max_packet`` bytes."""

    def feed(self, data: bytes) -> list[bytes]:
        """Packets completed by ``data`` (empty ones, from repeated delimiters, skipped)."""
        return [packet for packet, _ in self.feed_ends(data)]

    def feed_ends(self, data: bytes) -> list[tuple[bytes, int]]:
        """Packets completed by ``data``, each with the number of bytes fed up to and
        including its delimiter (its last byte on the wire; for time stamps)."""
        if not data:
            return []
        buffer = self._tail + data
        base = self._received - len(self._tail)  # offset of buffer[0] in the stream
        self._received += len(data)
        out = []
        start = 0
        while (at := buffer.find(DELIMITER, start)) >= 0:
            if at > start:
                out.append((buffer[start:at], base + at + 1))
            start = at + 1
        self._tail = buffer[start:]
        if len(self._tail) > self._max:
            self.overflow_bytes += len(self._tail)
            self._tail = b""
        return out

    @property
    def pending(self) -> int:
        """Bytes received since the last delimiter."""
        return len(self._tail)
