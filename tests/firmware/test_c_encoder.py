"""The C library for firmware authors (firmware/tactsense.c), compiled with the system C
compiler, against the Python reference (tactsense.stream.protocol) and the host
(StreamReader): byte for byte on the documented example and on random packets, and a
whole device on a pseudo-terminal read with every frame and every loss accounted for.

Skipped only where no C compiler exists and CI is unset; with CI set, a missing
compiler fails."""

from __future__ import annotations

import os
import re
import shutil
import struct
import subprocess
import tty
import zlib
from pathlib import Path

import numpy as np
import pytest
from cobs import cobs

import tactsense as ts
from tactsense.stream import StreamReader
from tactsense.stream.protocol import (
    ControlPacket,
    Kind,
    decode_packet,
    encode_control,
    encode_end,
    encode_frame,
)

ROOT = Path(__file__).resolve().parents[2]
FIRMWARE = ROOT / "firmware"
DRIVER = Path(__file__).with_name("ts_driver.c")
DOCS = ROOT / "docs" / "protocol.md"

STRICT = ["-std=c99", "-Wall", "-Wextra", "-Werror", "-pedantic"]
# the library alone is held to more: it must build cleanly for small targets too
LIBRARY_ONLY = [
    "-Wconversion",
    "-Wsign-conversion",
    "-Wshadow",
    "-Wcast-qual",
    "-Wstrict-prototypes",
    "-Wmissing-prototypes",
]


def _compiler() -> str:
    path = shutil.which("cc") or shutil.which("gcc")
    if path is None:
        if os.environ.get("CI"):
            pytest.fail("no C compiler (cc or gcc) on PATH and CI is set")
        pytest.skip("no C compiler (cc or gcc) on PATH and CI is unset")
    return path


def _build(folder: Path, name: str, extra: list[str]) -> Path:
    cc = _compiler()
    library = folder / f"{name}.o"
    exe = folder / name
    source = str(FIRMWARE / "tactsense.c")
    for command in (
        [cc, *STRICT, *LIBRARY_ONLY, *extra, "-c", source, "-o", str(library)],
        [cc, *STRICT, *extra, f"-I{FIRMWARE}", str(DRIVER), str(library), "-o", str(exe)],
    ):
        done = subprocess.run(command, capture_output=True, text=True, check=False)
        assert done.returncode == 0, f"{' '.join(command)}\n{done.stderr}"
    return exe


@pytest.fixture(scope="module")
def driver(tmp_path_factory) -> Path:
    return _build(tmp_path_factory.mktemp("c"), "ts_driver", ["-O2"])


@pytest.fixture(scope="module", params=["crc-nibble-table", "crc-byte-table"])
def any_driver(request, driver, tmp_path_factory) -> Path:
    """The library as built by default (a 16-word CRC table) and with TS_CRC_BYTE_TABLE."""
    if request.param == "crc-nibble-table":
        return driver
    return _build(tmp_path_factory.mktemp("c"), "ts_driver", ["-O2", "-DTS_CRC_BYTE_TABLE"])


def _run(exe: Path, *args: str, data: bytes = b"", env: dict | None = None) -> bytes:
    done = subprocess.run(
        [str(exe), *args], input=data, capture_output=True, check=False, timeout=60, env=env
    )
    assert done.returncode == 0, done.stderr.decode(errors="replace")
    return done.stdout


# ---- jobs for the driver (its input format is described in ts_driver.c) ------------


def _frame_job(sequence: int, time_us: int, counts: np.ndarray) -> bytes:
    rows, cols = counts.shape
    return (
        b"F" + struct.pack("<HQBB", sequence, time_us, rows, cols) + counts.astype("<u2").tobytes()
    )


def _string(text: str) -> bytes:
    data = text.encode()
    return struct.pack("<H", len(data)) + data


def _packets(wire: bytes) -> list[bytes]:
    assert wire.endswith(b"\x00")
    return [part + b"\x00" for part in wire[:-1].split(b"\x00")]


def _random_frames(rng) -> list[tuple[int, int, np.ndarray]]:
    """Frames of many shapes, sequence numbers around the wrap, times up to 2**64 - 1,
    readings at 0 and 65535 (zero bytes are what COBS must remove)."""
    shapes = [(1, 1), (2, 2), (8, 8), (16, 16), (1, 255), (255, 1), (7, 13), (12, 11), (32, 32)]
    shapes += [(int(r), int(c)) for r, c in rng.integers(1, 40, (8, 2))]
    sequences = [0, 1, 65534, 65535, *rng.integers(0, 65536, 8).tolist()]
    times = [0, 142857, 2**32 - 1, 2**32, 2**63, 2**64 - 1, *rng.integers(0, 2**63, 8).tolist()]
    frames = []
    for k, (rows, cols) in enumerate(shapes):
        counts = rng.integers(0, 65536, (rows, cols))
        choice = rng.random((rows, cols))
        counts[choice < 0.2] = 0
        counts[choice > 0.8] = 65535
        if k == 2:
            counts[:] = 0  # a frame of nothing but zero bytes
        if k == 3:
            counts[:] = 65535
        frames.append((sequences[k % len(sequences)], times[k % len(times)], counts))
    # the wrap-around, in order, on one shape
    for sequence in (65533, 65534, 65535, 0, 1):
        frames.append((sequence, 10**15 + sequence, rng.integers(0, 65536, (8, 8))))
    return frames


# ---- the tests ---------------------------------------------------------------------


def test_crc_is_zlibs(any_driver):
    assert _run(any_driver, "crc", data=b"123456789").split() == [b"cbf43926"] * 2
    data = np.random.default_rng(1).integers(0, 256, 3001, dtype=np.uint8).tobytes()
    expected = f"{zlib.crc32(data):08x}".encode()
    assert _run(any_driver, "crc", data=data).split() == [expected] * 2


@pytest.mark.parametrize("mode", ["buffer", "stream"])
def test_worked_example_of_the_docs(any_driver, mode):
    # the bytes printed in docs/protocol.md, independent of the Python encoder
    block = re.search(r"<!-- example-frame -->\s*```text\n(.*?)```", DOCS.read_text(), re.S)
    documented = bytes.fromhex("".join(block.group(1).split()))
    counts = np.array([[2000, 2001], [2002, 65535]])
    wire = _run(any_driver, "encode", mode, data=_frame_job(1, 142857, counts))
    assert wire == documented == encode_frame(1, 142857, counts)


@pytest.mark.parametrize("mode", ["buffer", "stream"])
def test_random_frames_byte_for_byte(any_driver, mode):
    frames = _random_frames(np.random.default_rng(22))
    jobs = b"".join(_frame_job(s, t, c) for s, t, c in frames)
    got = _packets(_run(any_driver, "encode", mode, data=jobs))
    assert len(got) == len(frames)
    for (sequence, time_us, counts), packet in zip(frames, got, strict=True):
        assert packet == encode_frame(sequence, time_us, counts), (sequence, counts.shape)


@pytest.mark.parametrize("mode", ["buffer", "stream"])
def test_end_and_any_packet_byte_for_byte(any_driver, mode):
    rng = np.random.default_rng(5)
    ends = [(0, 0), (0, 1), (65535, 65536), (4, 70000), (1234, 2**32 - 1)]
    jobs = b"".join(b"E" + struct.pack("<HI", last, sent) for last, sent in ends)
    expected = [encode_end(last, sent) for last, sent in ends]
    # the host's commands, as docs/protocol.md prints them
    for kind in (Kind.IDENTIFY, Kind.START, Kind.STOP):
        jobs += b"P" + struct.pack("<BH", kind, 0)
        expected.append(encode_control(kind))
    # bodies of every length around COBS's block of 254 bytes, with and without zeros
    for length in [*range(246, 262), *range(500, 516), 0, 1, 1000]:
        for zeros in (0.0, 0.01, 0.3):
            body = rng.integers(1, 256, length, dtype=np.uint8)
            body[rng.random(length) < zeros] = 0
            body = body.tobytes()
            jobs += b"P" + struct.pack("<BH", 0x42, length) + body
            packet = bytes([1, 0x42]) + body
            expected.append(cobs.encode(packet + struct.pack("<I", zlib.crc32(packet))) + b"\0")
    assert _packets(_run(any_driver, "encode", mode, data=jobs)) == expected


@pytest.mark.parametrize("pieces", ["I", "J"])
def test_ident_is_the_json_the_host_reads(driver, pieces):
    toml = ts.fearing1990_initial().to_toml_string()
    awkward = 'quote " backslash \\ tab \t cr \r bell \x07 unit sep \x1f ü µm 触覚\n'
    cases = [
        (8, 8, 142857143, "tactsense twin", "0.1.0", "c-0001", toml),
        (16, 16, 1000, 'my "array"', "1\\2", "\x01", awkward),
        (255, 1, 3, "", "", "", ""),
        (1, 255, 0, "x", "y", "z", awkward * 3),
    ]
    jobs = b"".join(
        pieces.encode()
        + struct.pack("<BBI", rows, cols, period)
        + b"".join(_string(s) for s in (device, firmware, serial, sensor))
        for rows, cols, period, device, firmware, serial, sensor in cases
    )
    got = _packets(_run(driver, "encode", "stream", data=jobs))
    for (rows, cols, period, device, firmware, serial, sensor), wire in zip(
        cases, got, strict=True
    ):
        packet = decode_packet(wire[:-1])
        assert isinstance(packet, ControlPacket) and packet.kind == Kind.IDENT
        rate = round(1e9 / period, 3) if period else 0.0
        assert packet.body == {
            "device": device,
            "firmware": firmware,
            "serial": serial,
            "protocol": 1,
            "rows": rows,
            "cols": cols,
            "frame_rate_hz": rate,
            "sensor_toml": sensor,
        }


def test_commands_are_recognised_and_damage_ignored(driver):
    identify, start, stop = (encode_control(k) for k in (Kind.IDENTIFY, Kind.START, Kind.STOP))
    flipped = bytearray(start)
    flipped[4] ^= 0x01
    stream = b"".join(
        [
            identify,
            b"\x13\x37\xff",  # line noise, no delimiter of its own: spoils the next packet
            start,
            bytes(flipped),  # a START with a bad CRC
            b"\x00\x00",  # empty runs
            b"\x05" * 100 + b"\x00",  # too long for a command
            start[:4] + b"\x00",  # cut short
            encode_frame(1, 2, np.ones((2, 2))),  # a device's packet, not a command
            encode_control(Kind.IDENT, {"a": 1}),
            stop,
            start,
            encode_end(1, 2),
            identify,
        ]
    )
    assert _run(driver, "receive", data=stream).split() == [b"81", b"83", b"82", b"81"]


def test_stream_reader_reads_a_c_device_on_a_pseudo_terminal(driver, tmp_path):
    """A whole device in C on a pseudo-terminal (what a USB serial port looks like to the
    host): IDENT with the sensor description, 600 frames, drops of 3 frames, of 70,000
    frames (the 16-bit counter wraps: the host must use the device clock) and of the
    last 2 frames (counted from END). Every frame bit-identical, every loss counted."""
    sensor = ts.fearing1990_initial()
    rows, cols = sensor.shape
    period_ns = round(sensor.scan_period_s * 1e9)
    rng = np.random.default_rng(7)
    frames = rng.integers(0, 65536, (600, rows, cols))
    frames[rng.random(frames.shape) < 0.1] = 0
    frames[rng.random(frames.shape) < 0.1] = 65535
    drops = {100: 3, 250: 70_000, 600: 2}
    (tmp_path / "frames.bin").write_bytes(frames.astype("<u2").tobytes())
    (tmp_path / "sensor.toml").write_text(sensor.to_toml_string())
    master, slave = os.openpty()
    tty.setraw(slave)
    process = subprocess.Popen(
        [str(driver), "device", str(tmp_path / "frames.bin"), str(tmp_path / "sensor.toml")]
        + [str(rows), str(cols), str(period_ns)]
        + [f"{at}:{count}" for at, count in drops.items()],
        stdin=master,
        stdout=master,
    )
    try:
        with StreamReader(os.ttyname(slave), timeout_s=5.0) as stream:
            assert stream.sensor.to_toml_string() == sensor.to_toml_string()
            received = list(stream.frames())
            stats, sent = stream.stats, stream.frames_sent
            ended = stream.ended
    finally:
        os.close(slave)
        os.close(master)
        try:
            process.wait(10)
        except subprocess.TimeoutExpired:
            process.kill()
            process.wait()
    assert ended, "the C device ends its stream with END"
    total = len(frames) + sum(drops.values())
    assert sent == total
    assert stats.frames == len(received) == len(frames)
    assert stats.lost == sum(drops.values()) and stats.gaps == len(drops)
    assert stats.frames + stats.lost == sent
    assert stats.bad_check == stats.truncated == stats.garbage == stats.duplicates == 0
    np.testing.assert_array_equal(np.stack([f.counts for f in received]), frames)
    # the index counts the dropped scans; the device time is the nominal scan clock
    skipped = np.cumsum([drops.get(k, 0) for k in range(len(frames))])
    index = np.arange(len(frames)) + skipped
    assert [f.index for f in received] == index.tolist()
    expected_us = [(int(k) * period_ns + 500) // 1000 for k in index]
    assert [round(f.device_time_s * 1e6) for f in received] == expected_us


def test_under_address_and_undefined_behaviour_sanitizers(tmp_path):
    cc = _compiler()
    probe = tmp_path / "probe.c"
    probe.write_text("int main(void) { return 0; }\n")
    flags = ["-fsanitize=address,undefined", "-fno-sanitize-recover=all", "-g", "-O1"]
    done = subprocess.run(
        [cc, *flags, str(probe), "-o", str(tmp_path / "probe")], capture_output=True, check=False
    )
    if done.returncode != 0 or subprocess.run([str(tmp_path / "probe")], check=False).returncode:
        pytest.skip(f"{cc} cannot build or run with -fsanitize=address,undefined here")
    exe = _build(tmp_path, "ts_driver_asan", flags)
    env = {**os.environ, "ASAN_OPTIONS": "detect_leaks=1", "UBSAN_OPTIONS": "halt_on_error=1"}
    frames = _random_frames(np.random.default_rng(3))
    jobs = b"".join(_frame_job(s, t, c) for s, t, c in frames)
    jobs += b"E" + struct.pack("<HI", 65535, 2**32 - 1)
    body = bytes(range(256)) * 2 + b"\x07" * 88  # 600 bytes, zeros among them
    jobs += b"P" + struct.pack("<BH", 0x42, len(body)) + body
    packet = bytes([1, 0x42]) + body
    expected = [encode_frame(s, t, c) for s, t, c in frames] + [encode_end(65535, 2**32 - 1)]
    expected.append(cobs.encode(packet + struct.pack("<I", zlib.crc32(packet))) + b"\0")
    for mode in ("buffer", "stream"):
        assert _packets(_run(exe, "encode", mode, data=jobs, env=env)) == expected
    noise = np.random.default_rng(4).integers(0, 256, 20_000, dtype=np.uint8).tobytes()
    _run(exe, "receive", data=noise + encode_control(Kind.STOP), env=env)
    assert _run(exe, "crc", data=noise, env=env).split()[0] == f"{zlib.crc32(noise):08x}".encode()


def test_the_example_sketch_streams_to_the_host(tmp_path):
    """firmware/examples/scan_array/scan_array.ino, compiled as C++ against a stub of the
    Arduino API (tests/firmware/arduino_stub.*: Serial on a pseudo-terminal, micros() the
    host's clock, analogRead a known pattern of the driven row and the multiplexer
    address): its sensor description is one the host accepts, its scan period matches
    it, and its frames arrive row-major, complete and on the nominal scan clock."""
    cxx = shutil.which("c++") or shutil.which("g++")
    if cxx is None:
        if os.environ.get("CI"):
            pytest.fail("no C++ compiler (c++ or g++) on PATH and CI is set")
        pytest.skip("no C++ compiler (c++ or g++) on PATH and CI is unset")
    cc, here = _compiler(), Path(__file__).parent
    sketch = FIRMWARE / "examples" / "scan_array" / "scan_array.ino"
    exe = tmp_path / "sketch"
    cxx_flags = ["-std=c++11", "-Wall", "-Wextra", "-Werror", "-pedantic", "-O1"]
    stub = ["-x", "c++", "-include", str(here / "arduino_stub.h"), f"-I{FIRMWARE}"]
    for command in (
        [cc, *STRICT, "-O1", "-c", str(FIRMWARE / "tactsense.c"), "-o", str(tmp_path / "ts.o")],
        [cxx, *cxx_flags, *stub, "-c", str(sketch), "-o", str(tmp_path / "sketch.o")],
        [cxx, *cxx_flags, "-c", str(here / "arduino_stub.cpp"), "-o", str(tmp_path / "stub.o")],
        [cxx, *(str(tmp_path / f) for f in ("ts.o", "sketch.o", "stub.o")), "-o", str(exe)],
    ):
        done = subprocess.run(command, capture_output=True, text=True, check=False)
        assert done.returncode == 0, f"{' '.join(command)}\n{done.stderr}"
    master, slave = os.openpty()
    tty.setraw(slave)
    process = subprocess.Popen([str(exe)], stdin=master, stdout=master)
    try:
        with StreamReader(os.ttyname(slave), timeout_s=2.0) as stream:
            received = list(stream.frames(max_frames=25))
            stream.stop()
            stats, sent, identity = stream.stats, stream.frames_sent, stream.identity
            sensor, ended = stream.sensor, stream.ended
    finally:
        os.close(slave)
        os.close(master)
        try:
            process.wait(10)
        except subprocess.TimeoutExpired:
            process.kill()
            process.wait()
    assert sensor.name == "scan_array" and sensor.shape == (8, 8)
    assert identity["frame_rate_hz"] == sensor.electronics.scan_rate_hz == 100.0
    assert len(received) == 25 and ended
    pattern = (np.arange(64).reshape(8, 8) * 13) % 1024  # STUB_READING(row, col)
    for frame in received:
        np.testing.assert_array_equal(frame.counts, pattern)
        assert round(frame.device_time_s * 1e6) == frame.sequence * 10_000
    # every scan after the first one received is either a frame or counted lost (scans
    # lost before it are not counted by the host today: docs/protocol.md, issue 22)
    assert stats.frames + stats.lost == sent - received[0].sequence
    assert stats.bad_check == stats.truncated == stats.garbage == stats.duplicates == 0
