"""The wire protocol against independent references: the CRC's published check value,
COBS's defining property, and the worked example printed in docs/protocol.md."""

import re
import struct
import zlib
from pathlib import Path

import numpy as np
import pytest
from cobs import cobs
from hypothesis import given, settings
from hypothesis import strategies as st

from tactsense.stream.protocol import (
    EndPacket,
    FramePacket,
    ProtocolError,
    decode_packet,
    encode_end,
    encode_frame,
    encoded_frame_size,
    frame_size,
)

DOCS = Path(__file__).resolve().parents[2] / "docs" / "protocol.md"


def test_crc_is_crc32_iso_hdlc():
    # The catalogue's check value of CRC-32/ISO-HDLC (poly 0x04C11DB7, reflected,
    # init and xorout 0xFFFFFFFF) for the ASCII string "123456789" is 0xCBF43926.
    assert zlib.crc32(b"123456789") == 0xCBF43926


@settings(max_examples=60, deadline=None)
@given(
    rows=st.integers(1, 12),
    cols=st.integers(1, 12),
    sequence=st.integers(0, 10**6),
    time_us=st.integers(0, 2**64 - 1),
    seed=st.integers(0, 2**32 - 1),
    zeros=st.floats(0, 1),
)
def test_any_frame_round_trips_and_has_no_zero_byte(rows, cols, sequence, time_us, seed, zeros):
    rng = np.random.default_rng(seed)
    counts = rng.integers(0, 65536, (rows, cols)).astype(np.uint16)
    counts[rng.random((rows, cols)) < zeros] = 0  # zero bytes are what COBS must remove
    wire = encode_frame(sequence, time_us, counts)
    assert wire.endswith(b"\x00") and b"\x00" not in wire[:-1]
    raw = frame_size(rows, cols)
    # COBS: at least one byte of overhead, at most one per started 254 bytes
    assert encoded_frame_size(rows, cols) <= len(wire) <= raw + -(-raw // 254) + 1
    packet = decode_packet(wire[:-1])
    assert isinstance(packet, FramePacket)
    assert packet.sequence == sequence % 65536
    assert packet.device_time_us == time_us
    np.testing.assert_array_equal(packet.counts, counts)


def test_frame_layout_by_hand():
    # The layout of docs/protocol.md assembled independently with struct and zlib.
    counts = np.arange(6, dtype=np.uint16).reshape(2, 3) + 2000
    body = struct.pack("<BBHQBB", 1, 1, 7, 123456, 2, 3) + struct.pack("<6H", *counts.ravel())
    expected = cobs.encode(body + struct.pack("<I", zlib.crc32(body))) + b"\x00"
    assert encode_frame(7, 123456, counts) == expected
    assert frame_size(2, 3) == len(body) + 4


def test_worked_example_in_the_docs_is_what_the_code_sends():
    text = DOCS.read_text()
    block = re.search(r"<!-- example-frame -->\s*```text\n(.*?)```", text, re.S).group(1)
    wire = bytes.fromhex("".join(block.split()))
    counts = np.array([[2000, 2001], [2002, 65535]], dtype=np.uint16)
    assert wire == encode_frame(1, 142857, counts)


def test_damage_is_classified():
    counts = np.full((8, 8), 2000, dtype=np.uint16)
    wire = encode_frame(3, 0, counts)[:-1]
    full = len(wire)
    with pytest.raises(ProtocolError) as cut:
        decode_packet(wire[:50], full)
    assert cut.value.reason == "truncated"
    flipped = bytearray(wire)
    flipped[40] ^= 0x10
    with pytest.raises(ProtocolError) as flip:
        decode_packet(bytes(flipped).replace(b"\x00", b"\x01"), full)
    assert flip.value.reason == "bad_check"
    with pytest.raises(ProtocolError) as noise:
        decode_packet(b"\x07\xff\xfe", full)
    assert noise.value.reason == "garbage"


def test_end_packet_round_trips():
    packet = decode_packet(encode_end(65535 + 5, 70000)[:-1])
    assert packet == EndPacket(4, 70000)
