"""Every size docs/protocol.md quotes is read from the page and compared with what the
encoder sends, and the loss counters it defines are checked against the reader."""

import re
from pathlib import Path

import numpy as np
import serial
from cobs import cobs

import tactsense as ts
from tactsense.stream import StreamReader
from tactsense.stream.protocol import encode_frame

TEXT = (Path(__file__).resolve().parents[2] / "docs" / "protocol.md").read_text()
EXAMPLE = np.array([[2000, 2001], [2002, 65535]])


def _number(pattern: str) -> tuple[int, ...]:
    match = re.search(pattern, TEXT, re.S)
    assert match, f"docs/protocol.md no longer says {pattern!r}"
    return tuple(int(group.replace(",", "")) for group in match.groups())


def _frame_8x8() -> tuple[bytes, bytes]:
    counts = np.random.default_rng(0).integers(1900, 2300, (8, 8))
    wire = encode_frame(3, 428571, counts)
    return wire, cobs.decode(wire[:-1])


def test_worked_example_sizes():
    wire = encode_frame(1, 142857, EXAMPLE)
    packet = cobs.decode(wire[:-1])
    assert _number(r"Before COBS \((\d+) bytes\)") == (len(packet),)
    assert _number(r"On the wire \(COBS, then the delimiter; (\d+) bytes\)") == (len(wire),)


def test_worked_example_annotated_bytes():
    # the annotated table before COBS: the hex column of every line, in order
    block = re.search(r"Before COBS \(\d+ bytes\):\s*```text\n(.*?)```", TEXT, re.S).group(1)
    hex_column = "".join(
        re.match(r"((?:[0-9a-f]{2} )*)", line + " ").group(1) for line in block.splitlines()
    )
    packet = cobs.decode(encode_frame(1, 142857, EXAMPLE)[:-1])
    assert bytes.fromhex(hex_column) == packet
    crc = re.search(r"CRC-32 0x([0-9a-f]{8})", block).group(1)
    assert int(crc, 16) == int.from_bytes(packet[-4:], "little")


def test_frame_sizes_of_an_8x8_array():
    wire, packet = _frame_8x8()
    bits, under_crc = _number(r"an 8x8 frame is ([\d,]+) bits,\s+([\d,]+) of them under the CRC")
    assert bits == 8 * len(packet)
    assert under_crc == 8 * (len(packet) - 4)
    assert _number(r"An 8x8 frame is (\d+) bytes before COBS and (\d+) on the wire") == (
        len(packet),
        len(wire),
    )
    assert _number(r"fixed and tiny \((\d+) bytes on a (\d+)-byte 8x8 frame\)") == (
        len(wire) - len(packet),
        len(packet),
    )


def test_garbage_counts_runs_and_garbage_bytes_counts_bytes():
    # what the table of counters says: one per run between delimiters, and its bytes
    assert re.search(r"\| `garbage` \| runs of bytes between two delimiters", TEXT)
    assert re.search(r"\| `garbage_bytes` \| the bytes in those runs", TEXT)
    port = serial.serial_for_url("loop://", timeout=0)
    sensor = ts.fearing1990_initial()
    counts = np.full(sensor.shape, 2000)
    with StreamReader(port, sensor=sensor, start=False) as stream:
        port.write(encode_frame(0, 0, counts))
        port.write(b"\x07" * 10 + b"\x00")  # a run of 10 bytes of noise
        port.write(b"\x00\x00")  # empty runs: no packet and no garbage
        port.write(b"\x03\x07\x07\x07\x07" + b"\x00")  # a run of 5
        port.write(encode_frame(1, 142857, counts))
        frames = []
        for _ in range(20):
            frames += stream.read_batch(10, wait_s=0.1)
            if len(frames) == 2:
                break
        assert stream.stats.frames == 2
        assert stream.stats.garbage == 2
        assert stream.stats.garbage_bytes == 15
