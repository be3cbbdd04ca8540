"""Readers of the wire formats that existing arrays speak (docs/devices.md): every
emulator format arrives bit-identical, and the faults each format can see are counted
exactly (the emulator logs what it injected, independently of the reader)."""

import json
import re
import signal
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from tactsense.cli import app
from tactsense.io.recording import read_recording
from tactsense.sensor import load_sensor
from tactsense.stream import Emulator, FaultRates, LossCounters, StreamError
from tactsense.stream.sources import FORMATS, open_source, parse_format, split_source

SPEC = load_sensor("pad16")
FRAMES = np.random.default_rng(0).integers(0, 100, (300, *SPEC.shape))  # no AA/55 byte
FORMAT_SPECS = [
    "text",
    "text,sep=tab,prefix=F:,header=2",
    "text,sep=space",
    "marker",
    "marker,start=A5A5A5,width=16,order=big",
    "marker,width=16,order=little",
    "justfloat",
]


def _run(spec: str, faults: FaultRates | None = None, frames=FRAMES):
    fmt = parse_format(spec)
    emulator = Emulator(SPEC, frames, speed=0, faults=faults, rng=1, wire_format=fmt)
    _, port = emulator.start_tcp()
    try:
        # 8-bit samples: pad16 described as it sends them (an 8-bit converter)
        as_sent = fmt.sensor_as_sent(SPEC)
        with open_source(f"{fmt.spec()}:socket://127.0.0.1:{port}", sensor=as_sent) as stream:
            got = list(stream.frames())
    finally:
        emulator.stop()
    return emulator, stream, got


def _is_subsequence(got, sent) -> bool:
    j = 0
    for frame in got:
        while j < len(sent) and not np.array_equal(sent[j], frame.counts):
            j += 1
        if j == len(sent):
            return False
        j += 1
    return True


@pytest.mark.parametrize("spec", FORMAT_SPECS)
def test_round_trip_is_bit_identical(spec):
    emulator, stream, got = _run(spec)
    assert stream.ended  # the line closed when the frames ran out
    assert len(got) == len(FRAMES)
    np.testing.assert_array_equal(np.stack([f.counts for f in got]), emulator.frames)
    assert emulator.frames.dtype == np.uint16 and got[0].counts.dtype == np.uint16
    assert stream.stats.as_dict() == LossCounters(frames=len(FRAMES)).as_dict()
    assert [f.index for f in got] == list(range(len(FRAMES)))
    times = np.array([f.device_time_s for f in got])
    assert times[0] == 0 and np.all(np.diff(times) >= 0)  # host arrival since the first


@pytest.mark.parametrize("spec", ["text,prefix=F:", "marker,width=16", "justfloat"])
@pytest.mark.parametrize("fault", ["truncate", "garbage"])
def test_faults_are_counted_exactly(spec, fault):
    emulator, stream, got = _run(spec, FaultRates(**{fault: 0.1}))
    injected = getattr(emulator.log, fault)
    assert injected > 10
    counted = stream.stats.truncated if fault == "truncate" else stream.stats.garbage
    assert counted == injected
    assert len(got) == len(FRAMES) - injected
    assert _is_subsequence(got, emulator.frames)  # the frames that arrive are intact
    assert stream.stats.lost == 0  # no sequence number: what is missing is not known


def test_a_dropped_frame_is_invisible():
    """docs/devices.md: none of these formats can count a frame that never arrived."""
    emulator, stream, got = _run("marker", FaultRates(drop=0.1))
    assert emulator.log.drop > 10
    assert len(got) == len(FRAMES) - emulator.log.drop
    assert stream.stats.summary() == f"{len(got)} frames"
    assert (emulator.log.drop, len(got)) == (31, 269)  # as docs/devices.md quotes


def test_eight_bits_keep_the_top_bits_of_the_twin():
    frames = np.random.default_rng(2).integers(0, 4096, (20, *SPEC.shape))
    emulator, _, got = _run("marker", frames=frames)
    np.testing.assert_array_equal(emulator.frames, frames >> 4)  # 12 bits -> 8
    np.testing.assert_array_equal(np.stack([f.counts for f in got]), frames >> 4)


def _decode(spec: str, data: bytes, finish: bool = True):
    stats = LossCounters()
    decoder = parse_format(spec).decoder((4, 4), stats, "test")
    frames = decoder.feed(data) + (decoder.finish() if finish else [])
    return frames, stats


def test_text_takes_any_separator_and_counts_what_is_no_frame():
    row = list(range(16))
    lines = [
        "0,1 2\t3;4, 5,6,7,8,9,10,11,12,13,14,15",  # a mix of separators
        "calibrating...",  # a message: garbage
        ",".join(map(str, row[:10])),  # cut short: truncated
        ",".join(map(str, [*row, 16])),  # two lines run together: garbage
        ",".join(["1.5", *list(map(str, row[1:]))]),  # not a count: garbage
        "",  # blank: skipped
        ",".join(map(str, row)),
    ]
    frames, stats = _decode("text", ("\r\n".join(lines) + "\r\n").encode())
    assert len(frames) == 2
    np.testing.assert_array_equal(frames[0].ravel(), row)
    assert (stats.garbage, stats.truncated) == (3, 1)
    assert stats.garbage_bytes == len(lines[1]) + len(lines[3]) + len(lines[4])  # no \r\n


def test_text_prefix_and_header():
    row = ",".join(map(str, range(16)))
    data = f"t0,t1\r\nF:{row}\r\n{row}\r\nF:{row}".encode()  # last line: no newline
    frames, stats = _decode("text,prefix=F:,header=1", data)
    assert len(frames) == 2 and stats.garbage == 1  # the line without the prefix


def test_marker_inside_a_frame_is_ignored_in_step():
    """In step the reader checks the marker only where it must be."""
    counts = np.zeros(16, np.uint8)
    counts[3:5] = (0xAA, 0x55)
    wire = b"".join(b"\xaa\x55" + counts.tobytes() for _ in range(4))
    frames, stats = _decode("marker", wire)
    assert len(frames) == 4 and stats.as_dict() == LossCounters().as_dict()


def test_marker_frames_wait_for_the_next_marker_and_a_cut_one_is_counted():
    frame = b"\xaa\x55" + bytes(range(16))
    frames, stats = _decode("marker", frame + frame[:10] + frame + frame, finish=False)
    assert len(frames) == 2  # the last waits for its confirmation
    assert stats.truncated == 1


def test_justfloat_values_that_are_no_counts_are_garbage():
    good = np.arange(16, dtype="<f4").tobytes() + bytes.fromhex("0000807f")
    bad = np.full(16, -1, dtype="<f4").tobytes() + bytes.fromhex("0000807f")
    frames, stats = _decode("justfloat", good + bad + good)
    assert len(frames) == 2 and stats.garbage == 1 and stats.garbage_bytes == 64


def test_justfloat_scale():
    wire = (np.arange(16, dtype="<f4") / 4).tobytes() + bytes.fromhex("0000807f")
    frames, _ = _decode("justfloat,scale=4", wire)
    np.testing.assert_array_equal(frames[0].ravel(), np.arange(16))


@pytest.mark.parametrize(
    "spec, data",
    [
        ("text", b"1,2,3,4\n" * 4),
        ("marker", (b"\xaa\x55" + bytes(8)) * 5),
        ("justfloat", (bytes(32) + bytes.fromhex("0000807f")) * 5),
    ],
)
def test_a_device_of_another_shape_is_named(spec, data):
    with pytest.raises(StreamError, match="sensor has 4x4 = 16"):
        _decode(spec, data)


def test_sources_resolve_through_one_table():
    assert set(FORMATS) == {"text", "marker", "justfloat"}
    assert split_source("socket://127.0.0.1:5000") == (None, "socket://127.0.0.1:5000")
    assert split_source("/dev/ttyUSB0") == (None, "/dev/ttyUSB0")
    fmt, url = split_source("text,prefix=F::/dev/ttyACM0")
    assert (fmt.prefix, url) == ("F:", "/dev/ttyACM0")
    fmt, url = split_source("marker,start=0xA5A5,width=16,order=big:socket://h:1")
    assert (fmt.marker, fmt.width, fmt.order, url) == (b"\xa5\xa5", 16, "big", "socket://h:1")
    assert parse_format(fmt.spec()).spec() == fmt.spec()


def test_the_emulator_on_a_pty():
    fmt = parse_format("text")
    emulator = Emulator(SPEC, FRAMES[:50], speed=0, wire_format=fmt)
    _, path = emulator.start_pty()
    try:
        with open_source(f"text:{path}", sensor=SPEC, timeout_s=0.5) as stream:
            got = list(stream.frames(max_frames=50))
    finally:
        emulator.stop()
    assert len(got) == 50
    np.testing.assert_array_equal(np.stack([f.counts for f in got]), emulator.frames)


def test_record_writes_the_frames_of_a_text_device(tmp_path):
    fmt = parse_format("text,sep=space")
    emulator = Emulator(SPEC, FRAMES[:100], speed=0, wire_format=fmt)
    _, port = emulator.start_tcp()
    out = tmp_path / "pad.h5"
    try:
        result = CliRunner().invoke(
            app,
            ["record", f"text:socket://127.0.0.1:{port}", "--sensor", "pad16", "-o", str(out),
             "--frames", "80", "--quiet"],
        )  # fmt: skip
    finally:
        emulator.stop()
    assert result.exit_code == 0, result.output
    rec = read_recording(out)
    np.testing.assert_array_equal(rec.frames, FRAMES[:80])
    assert rec.sensor.name == "pad16"
    assert rec.losses["garbage"] == 0 and rec.losses["truncated"] == 0


DOC = (Path(__file__).parents[2] / "docs" / "devices.md").read_text()


def _example(name: str) -> list[str]:
    block = re.search(rf"<!-- example-{name} -->\n```text\n(.*?)```", DOC, re.S)
    return block.group(1).splitlines()


def test_the_examples_in_devices_md_are_what_the_formats_send():
    big = np.array([[2000, 2001], [2002, 4095]], np.uint16)
    small = np.array([[1, 2], [3, 255]], np.uint16)
    text = [line.replace("\\r", "\r").replace("\\n", "\n").replace("\\t", "\t") for line in
            _example("text")]  # fmt: skip
    assert text == [
        parse_format("text").encode(big).decode(),
        parse_format("text,sep=tab,prefix=F:").encode(big).decode(),
    ]
    assert [bytes.fromhex(line) for line in _example("marker")] == [
        parse_format("marker").encode(small),
        parse_format("marker,width=16,order=big").encode(big),
        parse_format("marker,width=16").encode(big),
    ]
    (line,) = _example("justfloat")
    assert bytes.fromhex(line) == parse_format("justfloat").encode(big)
    # and each reads back as the frame it shows (an independent check of the bytes)
    assert np.array_equal(np.frombuffer(bytes.fromhex(line)[:-4], "<f4"), big.ravel())


def test_view_feeds_a_format_source():
    """`tactsense view FORMAT:URL`: the live feed takes frames from a format reader and
    ends when the line closes."""
    from tactsense.view import LiveFeed, view_locator

    fmt = parse_format("justfloat")
    emulator = Emulator(SPEC, FRAMES[:60], speed=0, wire_format=fmt)
    _, port = emulator.start_tcp()
    messages = []
    try:
        reader = open_source(f"justfloat:socket://127.0.0.1:{port}", sensor=SPEC, start=False)
        feed = LiveFeed(reader, view_locator(SPEC, baseline_frames=5))
        feed.start(messages.append)
        feed._thread.join(90)  # a cold Numba cache compiles the locator first
    finally:
        emulator.stop()
    assert feed.frames_in == 60 and feed.status == "ended", feed.health()
    frames = [m for m in map(json.loads, messages) if m["type"] == "frame"]
    assert len(frames) == 60 and frames[-1]["health"]["received"] == 60


def test_live_estimates_from_a_text_device(tmp_path):
    finger = load_sensor("initial")
    rec = __import__("tactsense").simulate(
        finger, __import__("tactsense").probe_sweep(finger), rng=0
    )
    emulator = Emulator(finger, rec.frames[:60], speed=0, wire_format=parse_format("text"))
    _, port = emulator.start_tcp()
    out = tmp_path / "live.jsonl"
    try:
        result = CliRunner().invoke(
            app,
            ["live", f"text:socket://127.0.0.1:{port}", "--sensor", "initial", "--frames",
             "40", "-o", str(out)],
        )  # fmt: skip
    finally:
        emulator.stop()
    assert result.exit_code == 0, result.output
    lines = [json.loads(line) for line in out.read_text().splitlines()]
    assert len(lines) == 35  # 5 frames make the baseline
    assert [e["sequence"] for e in lines] == list(range(5, 40))


def test_a_stall_counts_timeouts():
    fmt = parse_format("text")
    faults = FaultRates(stall=0.05, stall_s=0.3)
    emulator = Emulator(SPEC, FRAMES[:100], speed=0, faults=faults, rng=3, wire_format=fmt)
    _, port = emulator.start_tcp()
    try:
        with open_source(f"text:socket://127.0.0.1:{port}", sensor=SPEC, timeout_s=0.1) as s:
            got = list(s.frames())
    finally:
        emulator.stop()
    assert len(got) == 100 and emulator.log.stall >= 2
    # each 0.3 s stall is at least 2 intervals of 0.1 s with no frame, at most 3
    assert 2 * emulator.log.stall <= s.stats.timeouts <= 3 * emulator.log.stall


def test_emulate_format_prints_a_source_that_record_reads(tmp_path):
    """The command line end to end: the address `emulate --format` prints is the source."""
    command = [
        *(sys.executable, "-m", "tactsense.cli", "emulate", "--sensor", "pad16"),
        *("--scenario", "press", "--format", "marker,width=16,order=big", "--port", "0"),
    ]
    device = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        source = device.stdout.readline().strip()
        assert source.startswith("marker,start=AA55,width=16,order=big:socket://127.0.0.1:")
        out = tmp_path / "pad.h5"
        result = CliRunner().invoke(
            app, ["record", source, "--sensor", "pad16", "-o", str(out), "--frames", "30"]
        )
        assert result.exit_code == 0, result.output
        assert len(read_recording(out).frames) == 30
    finally:
        device.send_signal(signal.SIGINT)
        device.wait(10)
