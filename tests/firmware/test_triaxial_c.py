"""Version-2 FRAMEs (several components per taxel) in the C library for firmware authors
(firmware/tactsense.c), against the Python reference (tactsense.stream.protocol) and the
host (StreamReader): byte for byte on the worked example of docs/protocol.md and on
random frames of 1 to 4 components, IDENT of a three-axis device, commands of either
version, and a three-axis device in C on a pseudo-terminal read with every loss counted.

The C library encodes (a device sends frames; it never decodes one): "vice versa" here
is the C decoder of the host's commands reading what Python encodes, in version 1 and 2.
"""

from __future__ import annotations

import os
import re
import struct
import subprocess
import tty
import zlib
from pathlib import Path

import numpy as np
import pytest
from cobs import cobs

from tactsense.sensor import load_sensor
from tactsense.stream import StreamReader
from tactsense.stream.protocol import (
    ControlPacket,
    FramePacket,
    Kind,
    decode_packet,
    encode_control,
    encode_frame,
)
from tests.firmware.test_c_encoder import DOCS, _build, _compiler, _packets, _run, _string


@pytest.fixture(scope="module")
def driver(tmp_path_factory) -> Path:
    return _build(tmp_path_factory.mktemp("c2"), "ts_driver", ["-O2"])


def _v2_job(sequence: int, time_us: int, counts: np.ndarray) -> bytes:
    rows, cols, components = counts.shape
    head = struct.pack("<HQBBB", sequence, time_us, rows, cols, components)
    return b"G" + head + counts.astype("<u2").tobytes()


def _random_v2_frames(rng, least: int = 1) -> list[tuple[int, int, np.ndarray]]:
    """Frames of many shapes and 1..4 components (``least`` and up), readings at 0 and
    65535 among them, sequences around the wrap and times up to 2**64 - 1."""
    shapes = [(1, 1), (4, 4), (6, 4), (16, 16), (1, 255), (255, 1), (7, 13), (32, 32)]
    shapes += [(int(r), int(c)) for r, c in rng.integers(1, 30, (6, 2))]
    sequences = [0, 65535, *rng.integers(0, 65536, 8).tolist()]
    times = [0, 2**32, 2**64 - 1, *rng.integers(0, 2**63, 8).tolist()]
    frames = []
    for k, (rows, cols) in enumerate(shapes):
        components = least + k % (5 - least)
        counts = rng.integers(0, 65536, (rows, cols, components))
        choice = rng.random(counts.shape)
        counts[choice < 0.2] = 0
        counts[choice > 0.8] = 65535
        frames.append((sequences[k % len(sequences)], times[k % len(times)], counts))
    return frames


def test_the_worked_v2_example_of_the_docs(driver):
    # the bytes printed in docs/protocol.md's version-2 example, independent of both
    block = re.search(r"<!-- example-frame-v2 -->\s*```text\n(.*?)```", DOCS.read_text(), re.S)
    documented = bytes.fromhex("".join(block.group(1).split()))
    counts = np.array([[[32768, 32769, 40000]], [[32767, 0, 65535]]])  # 2 x 1 taxels, x y z
    for mode in ("buffer", "stream"):
        wire = _run(driver, "encode", mode, data=_v2_job(2, 10_000, counts))
        assert wire == documented == encode_frame(2, 10_000, counts), mode


@pytest.mark.parametrize("mode", ["buffer", "stream"])
def test_random_v2_frames_byte_for_byte(driver, mode):
    # the stream API sends version 2 from 2 components on (1 is a version-1 frame there)
    frames = _random_v2_frames(np.random.default_rng(35), least=1 if mode == "buffer" else 2)
    jobs = b"".join(_v2_job(s, t, c) for s, t, c in frames)
    got = _packets(_run(driver, "encode", mode, data=jobs))
    assert len(got) == len(frames)
    for (sequence, time_us, counts), packet in zip(frames, got, strict=True):
        assert packet == encode_frame(sequence, time_us, counts, version=2), counts.shape
        decoded = decode_packet(packet[:-1])  # the Python decoder reads what C encodes
        assert isinstance(decoded, FramePacket) and decoded.version == 2
        expected = counts[..., 0] if counts.shape[2] == 1 else counts
        np.testing.assert_array_equal(decoded.counts, expected)


@pytest.mark.parametrize("components", [0, 5, 255])
def test_the_c_encoder_refuses_components_outside_1_to_4(driver, components):
    job = _v2_job(0, 0, np.zeros((1, 1, 1)))[:-2]  # header only: patch its components byte
    job = job[:-1] + bytes([components]) + b"\x01\x00" * components
    done = subprocess.run(
        [str(driver), "encode", "buffer"], input=job, capture_output=True, timeout=60, check=False
    )
    assert done.returncode != 0 and b"encoding failed" in done.stderr
    done = subprocess.run(
        [str(driver), "encode", "stream"], input=job, capture_output=True, timeout=60, check=False
    )
    assert done.returncode != 0 and b"ts_set_components refused" in done.stderr


def test_ident_of_a_three_axis_device(driver):
    toml = load_sensor("mag4x4").to_toml_string()
    job = b"K" + struct.pack("<BBBI", 3, 4, 4, 10_000_000)
    job += b"".join(_string(s) for s in ("magnetic skin", "2.0", "m-0001", toml))
    (wire,) = _packets(_run(driver, "encode", "stream", data=job))
    packet = decode_packet(wire[:-1])
    assert isinstance(packet, ControlPacket) and packet.kind == Kind.IDENT
    assert packet.body == {
        "device": "magnetic skin",
        "firmware": "2.0",
        "serial": "m-0001",
        "protocol": 2,
        "rows": 4,
        "cols": 4,
        "components": 3,
        "frame_rate_hz": 100.0,
        "sensor_toml": toml,
    }


def test_commands_of_either_version_are_recognised(driver):
    def version_2(kind: Kind) -> bytes:
        body = bytes([2, kind])
        return cobs.encode(body + struct.pack("<I", zlib.crc32(body))) + b"\x00"

    stream = b"".join(
        [
            encode_control(Kind.IDENTIFY),
            version_2(Kind.START),
            version_2(Kind.STOP),
            bytes([0x07, 3, 0x82]) + b"\x01\x02\x03\x04\x00",  # version 3: not a command
            encode_control(Kind.START),
        ]
    )
    assert _run(driver, "receive", data=stream).split() == [b"81", b"82", b"83", b"82"]


def test_stream_reader_reads_a_three_axis_c_device(driver, tmp_path):
    """A three-axis device in C (ts_set_components(3)) on a pseudo-terminal: IDENT with
    the sensor description, 300 frames of (4, 4, 3), drops of 5 and of the last 2 frames.
    Every frame bit-identical, every loss counted."""
    sensor = load_sensor("mag4x4")
    rows, cols = sensor.shape
    period_ns = round(sensor.scan_period_s * 1e9)
    rng = np.random.default_rng(11)
    frames = rng.integers(0, 65536, (300, *sensor.frame_shape))
    frames[rng.random(frames.shape) < 0.1] = 0
    drops = {50: 5, 300: 2}
    (tmp_path / "frames.bin").write_bytes(frames.astype("<u2").tobytes())
    (tmp_path / "sensor.toml").write_text(sensor.to_toml_string())
    master, slave = os.openpty()
    tty.setraw(slave)
    process = subprocess.Popen(
        [str(driver), "device", str(tmp_path / "frames.bin"), str(tmp_path / "sensor.toml")]
        + [str(rows), str(cols), str(period_ns)]
        + [f"{at}:{count}" for at, count in drops.items()]
        + ["c=3"],
        stdin=master,
        stdout=master,
    )
    try:
        with StreamReader(os.ttyname(slave), timeout_s=5.0) as stream:
            assert stream.sensor == sensor
            assert stream.identity["protocol"] == 2 and stream.identity["components"] == 3
            received = list(stream.frames())
            stats, sent, ended = stream.stats, stream.frames_sent, stream.ended
    finally:
        os.close(slave)
        os.close(master)
        try:
            process.wait(10)
        except subprocess.TimeoutExpired:
            process.kill()
            process.wait()
    assert ended
    assert sent == len(frames) + sum(drops.values())
    assert stats.frames == len(received) == len(frames)
    assert stats.lost == sum(drops.values()) and stats.gaps == len(drops)
    assert stats.bad_check == stats.truncated == stats.garbage == stats.duplicates == 0
    np.testing.assert_array_equal(np.stack([f.counts for f in received]), frames)


def test_v2_frames_under_address_and_undefined_behaviour_sanitizers(tmp_path):
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
    for mode, least in (("buffer", 1), ("stream", 2)):
        frames = _random_v2_frames(np.random.default_rng(6), least=least)
        jobs = b"".join(_v2_job(s, t, c) for s, t, c in frames)
        expected = [encode_frame(s, t, c, version=2) for s, t, c in frames]
        assert _packets(_run(exe, "encode", mode, data=jobs, env=env)) == expected
