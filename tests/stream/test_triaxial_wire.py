"""Three-axis taxels on the wire (issue 35, item 3): the version-2 FRAME against its
layout assembled independently (struct, zlib, cobs), version-1 frames read unchanged,
the emulator and the reader of a three-axis device end to end with every loss counted,
and the text, marker and JustFloat formats with several values per taxel."""

import re
import struct
import zlib
from pathlib import Path

import numpy as np
import pytest
from cobs import cobs
from hypothesis import given, settings
from hypothesis import strategies as st

from tactsense.sensor import load_sensor
from tactsense.stream import Emulator, FaultRates, LossCounters, StreamError, StreamReader
from tactsense.stream.framed import FormatError
from tactsense.stream.protocol import (
    ControlPacket,
    FramePacket,
    Kind,
    ProtocolError,
    decode_packet,
    encode_control,
    encode_frame,
    encoded_frame_size,
    frame_size,
)
from tactsense.stream.sources import open_source, parse_format

MAG = load_sensor("mag4x4")
PAD = load_sensor("pad16")


def _three_axis_frames(n: int, seed: int = 0) -> np.ndarray:
    """Counts around the converter's zero field (offset binary), each component its own."""
    rng = np.random.default_rng(seed)
    return (32768 + rng.integers(-3000, 3000, (n, *MAG.frame_shape))).astype(np.uint16)


# ---- the packet ---------------------------------------------------------------------


def test_a_v2_frame_is_its_documented_layout():
    # assembled by hand: header <BBHQBBB, then the counts with the component fastest,
    # i.e. the (rows, cols, components) array flattened in C order
    counts = np.arange(2 * 3 * 3, dtype=np.uint16).reshape(2, 3, 3) + 32760
    flat = [counts[r, c, k] for r in range(2) for c in range(3) for k in range(3)]
    body = struct.pack("<BBHQBBB", 2, 1, 9, 10_000, 2, 3, 3) + struct.pack("<18H", *flat)
    expected = cobs.encode(body + struct.pack("<I", zlib.crc32(body))) + b"\x00"
    assert encode_frame(9, 10_000, counts) == expected
    assert frame_size(2, 3, 3) == len(body) + 4
    assert encoded_frame_size(2, 3, 3) == len(expected)  # one COBS byte, one delimiter


@settings(max_examples=60, deadline=None)
@given(
    rows=st.integers(1, 9),
    cols=st.integers(1, 9),
    components=st.integers(1, 4),
    sequence=st.integers(0, 10**6),
    time_us=st.integers(0, 2**64 - 1),
    seed=st.integers(0, 2**32 - 1),
)
def test_any_v2_frame_round_trips(rows, cols, components, sequence, time_us, seed):
    counts = np.random.default_rng(seed).integers(0, 65536, (rows, cols, components))
    counts = counts.astype(np.uint16)
    wire = encode_frame(sequence, time_us, counts)
    assert wire.endswith(b"\x00") and b"\x00" not in wire[:-1]
    packet = decode_packet(wire[:-1])
    assert isinstance(packet, FramePacket) and packet.version == 2
    assert (packet.sequence, packet.device_time_us) == (sequence % 65536, time_us)
    # one component comes back as the (rows, cols) frame of a scalar sensor
    expected = counts[..., 0] if components == 1 else counts
    np.testing.assert_array_equal(packet.counts, expected)


def test_a_v1_frame_reads_unchanged():
    # the bytes of docs/protocol.md's worked example (version 1), as tests/stream/
    # test_protocol.py checks them against the encoder of round 1
    wire = bytes.fromhex(
        "04 01 01 01 04 09 2e 02 01 01 01 01 0f 02 02 d0 07 d1 07 d2 07 ff ff c1 4c 57 e0"
    )
    packet = decode_packet(wire)
    assert packet.version == 1 and packet.counts.shape == (2, 2)
    np.testing.assert_array_equal(packet.counts, [[2000, 2001], [2002, 65535]])
    assert (packet.sequence, packet.device_time_us) == (1, 142857)
    # and a scalar frame is still sent as version 1, byte for byte
    assert encode_frame(1, 142857, packet.counts) == wire + b"\x00"


def test_a_v1_byte_stream_of_round_7_reads_unchanged():
    """Bytes the encoder of round 7 wrote (stored in triwire_v1_stream.hex, made before
    version 2 existed), read by today's StreamReader over loop://: every frame, its
    sequence across the wrap, its device time and its counts; END settles no loss."""
    text = Path(__file__).with_name("triwire_v1_stream.hex").read_text()
    wire = bytes.fromhex(" ".join(line for line in text.splitlines() if not line.startswith("#")))
    counts = np.random.default_rng(2026).integers(0, 65536, (12, 3, 5))
    counts[0], counts[1] = 0, 65535
    sensor = PAD.replace(grid__rows=3, grid__cols=5)
    stream = StreamReader("loop://", sensor=sensor, start=False, timeout_s=0.05)
    stream.port.write(wire)
    frames = list(stream.frames(max_frames=12))
    assert [f.sequence for f in frames] == [(65530 + k) % 65536 for k in range(12)]
    assert [f.device_time_us for f in frames] == [1_000_000 + 10_000 * k for k in range(12)]
    np.testing.assert_array_equal(np.stack([f.counts for f in frames]), counts)
    assert stream.stats.as_dict() == LossCounters(frames=12).as_dict()
    packets = [decode_packet(raw) for raw in wire.split(b"\x00")[:-1]]
    assert all(p.version == 1 for p in packets[:12])


def test_one_component_may_be_sent_as_v2():
    counts = np.full((2, 2), 7, np.uint16)
    wire = encode_frame(0, 0, counts, version=2)
    assert wire[1:3] == b"\x02\x01"  # after the COBS code byte: version 2, FRAME
    np.testing.assert_array_equal(decode_packet(wire[:-1]).counts, counts)


@pytest.mark.parametrize(
    "counts, version, message",
    [
        (np.zeros((2, 2, 5)), None, "1..4 components"),
        (np.zeros((2, 2, 3)), 1, "version 1 cannot carry 3"),
        (np.zeros((2, 2, 2, 2)), None, "rows, cols, components"),
        (np.zeros((2, 2)), 3, "version 3"),
    ],
)
def test_frames_the_protocol_cannot_carry_are_refused(counts, version, message):
    with pytest.raises(ValueError, match=message):
        encode_frame(0, 0, counts, version=version)


def _sealed(body: bytes) -> bytes:
    return cobs.encode(body + struct.pack("<I", zlib.crc32(body)))


@pytest.mark.parametrize("components", [0, 5, 255])
def test_a_v2_frame_of_impossible_components_is_a_bad_check(components):
    body = struct.pack("<BBHQBBB", 2, 1, 0, 0, 1, 1, components) + b"\x01\x00" * components
    with pytest.raises(ProtocolError) as caught:
        decode_packet(_sealed(body))
    assert caught.value.reason == "bad_check"


def test_a_v2_frame_whose_length_disagrees_is_a_bad_check():
    body = struct.pack("<BBHQBBB", 2, 1, 0, 0, 2, 2, 3) + b"\x01\x00" * 11  # 12 expected
    with pytest.raises(ProtocolError, match="2x2 tactels x 3 components") as caught:
        decode_packet(_sealed(body))
    assert caught.value.reason == "bad_check"


def test_a_cut_v2_frame_is_truncated_not_garbage():
    wire = encode_frame(3, 0, _three_axis_frames(1)[0])[:-1]
    expected = encoded_frame_size(*MAG.shape, MAG.components) - 1
    assert len(wire) == expected  # 115 bytes under one COBS block: exact
    for cut in (3, 20, len(wire) - 1):
        with pytest.raises(ProtocolError) as caught:
            decode_packet(wire[:cut], expected)
        assert caught.value.reason == "truncated", cut


def test_version_2_control_packets_read_as_version_1():
    # IDENT, END and the commands are laid out alike in both versions
    for kind in (Kind.IDENTIFY, Kind.START, Kind.STOP):
        v1 = cobs.decode(encode_control(kind)[:-1])[:-4]
        body = bytes([2]) + v1[1:]
        packet = decode_packet(_sealed(body))
        assert isinstance(packet, ControlPacket) and packet.kind == kind


# ---- a three-axis device, end to end -------------------------------------------------


def _read_all(emulator, **options):
    _, port = emulator.start_tcp()
    try:
        with StreamReader(f"socket://127.0.0.1:{port}", **options) as stream:
            frames = list(stream.frames())
            assert stream.ended
            return frames, stream
    finally:
        emulator.stop()


def test_the_emulated_three_axis_device_says_so_and_sends_every_frame():
    sent = _three_axis_frames(150)
    frames, stream = _read_all(Emulator(MAG, sent, speed=0))
    assert stream.identity["protocol"] == 2 and stream.identity["components"] == 3
    assert stream.sensor == MAG  # from IDENT's sensor_toml
    assert stream.stats.as_dict() == LossCounters(frames=150).as_dict()
    np.testing.assert_array_equal(np.stack([f.counts for f in frames]), sent)


def test_a_scalar_device_still_says_version_1():
    assert Emulator(PAD, np.zeros((1, *PAD.shape)), speed=0).identity()["protocol"] == 1
    assert "components" not in Emulator(PAD, np.zeros((1, *PAD.shape))).identity()


def test_every_three_axis_frame_is_received_or_counted_lost():
    faults = FaultRates(drop=0.05, bitflip=0.05, truncate=0.05, garbage=0.05)
    sent = _three_axis_frames(300, seed=1)
    emulator = Emulator(MAG, sent, speed=0, faults=faults, rng=4)
    frames, stream = _read_all(emulator)
    log, stats = emulator.log, stream.stats
    assert stats.frames + stats.lost == log.frames == len(sent)
    assert stats.lost == log.frames - log.delivered_intact > 0
    assert stats.truncated > 0 and stats.bad_check > 0 and stats.garbage > 0
    for frame in frames:  # what arrives is what was sent, never a damaged frame
        np.testing.assert_array_equal(frame.counts, sent[frame.index])


def test_a_three_axis_device_read_as_a_scalar_sensor_is_named():
    emulator = Emulator(MAG, _three_axis_frames(5), speed=0)
    scalar = PAD.replace(grid__rows=4, grid__cols=4)
    with pytest.raises(StreamError, match=r"4x4 tactels x 3 components.*has 4x4 tactels"):
        _read_all(emulator, sensor=scalar)


def test_the_emulator_refuses_frames_without_their_components():
    with pytest.raises(Exception, match=r"expected \(T > 0, 4, 4, 3\)"):
        Emulator(MAG, np.zeros((3, 4, 4)))


# ---- text, marker and JustFloat with several values per taxel ------------------------

FORMATS = ["text", "text,sep=tab,components=3", "marker,width=16", "justfloat,components=3"]


@pytest.mark.parametrize("spec", FORMATS)
def test_formats_carry_three_components_bit_identical(spec):
    sent = _three_axis_frames(60, seed=2)
    fmt = parse_format(spec)
    emulator = Emulator(MAG, sent, speed=0, wire_format=fmt, rng=1)
    _, port = emulator.start_tcp()
    try:
        with open_source(f"{fmt.spec()}:socket://127.0.0.1:{port}", sensor=MAG) as stream:
            got = list(stream.frames())
    finally:
        emulator.stop()
    assert stream.stats.as_dict() == LossCounters(frames=len(sent)).as_dict()
    np.testing.assert_array_equal(np.stack([f.counts for f in got]), sent)


SIGNED = [
    "text,offset=32768",
    "justfloat,offset=32768,scale=0.25",
    "marker,width=16,signed=yes",
    "marker,width=16,order=big,signed=yes",
]


@pytest.mark.parametrize("spec", SIGNED)
def test_signed_readings_arrive_as_offset_binary_counts(spec):
    """A magnetometer's signed readings on the line, offset-binary counts in the file:
    the emulator sends count - 32768 (scaled, for JustFloat), the reader adds it back."""
    sent = _three_axis_frames(60, seed=5)
    sent[0, 0, 0] = [0, 32768, 65535]  # the extremes: -32768, 0 and 32767 on the line
    fmt = parse_format(spec)
    emulator = Emulator(MAG, sent, speed=0, wire_format=fmt, rng=1)
    _, port = emulator.start_tcp()
    try:
        with open_source(f"{fmt.spec()}:socket://127.0.0.1:{port}", sensor=MAG) as stream:
            got = list(stream.frames())
    finally:
        emulator.stop()
    assert stream.stats.as_dict() == LossCounters(frames=len(sent)).as_dict()
    np.testing.assert_array_equal(np.stack([f.counts for f in got]), sent)


def test_signed_values_by_hand():
    # one taxel of three components, x y z = -5, 0, 7 on the line (sensor 1x1x3)
    tiny = MAG.replace(grid__rows=1, grid__cols=1).frame_shape
    text = parse_format("text,offset=32768").decoder(tiny, LossCounters(), "t")
    np.testing.assert_array_equal(text.feed(b"-5,0,7\n")[0], [[[32763, 32768, 32775]]])
    marker = parse_format("marker,width=16,signed=yes").decoder(tiny, LossCounters(), "m")
    data = b"\xaa\x55" + np.array([-5, 0, 7], "<i2").tobytes()
    np.testing.assert_array_equal(marker.feed(data * 2)[0], [[[32763, 32768, 32775]]])
    floats = parse_format("justfloat,offset=32768,scale=10").decoder(tiny, LossCounters(), "f")
    data = np.array([-0.5, 0.0, 0.7], "<f4").tobytes() + b"\x00\x00\x80\x7f"
    np.testing.assert_array_equal(floats.feed(data)[0], [[[32763, 32768, 32775]]])


def test_a_signed_value_below_the_offset_is_no_count():
    tiny = MAG.replace(grid__rows=1, grid__cols=1).frame_shape
    stats = LossCounters()
    text = parse_format("text,offset=100").decoder(tiny, stats, "t")
    assert text.feed(b"-101,0,1\n-100,0,1\n") and stats.garbage == 1


@pytest.mark.parametrize(
    "spec, said",
    [
        ("text,offset=1.5", "offset='1.5' must be whole counts"),
        ("justfloat,offset=70000", "offset='70000' must be whole counts"),
        ("text,offset=x", "offset='x'"),
        ("marker,signed=maybe", "signed='maybe' must be no or yes"),
    ],
)
def test_bad_offsets_and_signs_are_refused(spec, said):
    with pytest.raises(FormatError, match=re.escape(said)):
        parse_format(spec)


def test_a_text_line_holds_each_taxels_components_in_turn():
    frame = _three_axis_frames(1)[0]
    line = parse_format("text").encode(frame).decode().strip().split(",")
    assert len(line) == 48
    assert [int(v) for v in line[:3]] == frame[0, 0].tolist()  # x, y, z of taxel (0, 0)
    assert [int(v) for v in line[3:6]] == frame[0, 1].tolist()


@pytest.mark.parametrize("value", ["0", "5", "three", "-1", "1.5"])
@pytest.mark.parametrize("name", ["text", "marker", "justfloat"])
def test_components_outside_1_to_4_are_refused(name, value):
    with pytest.raises(FormatError, match=rf"components='?{value}'? must be .* 1 to 4"):
        parse_format(f"{name},components={value}")


def test_components_that_disagree_with_the_sensor_are_named():
    emulator = Emulator(MAG, _three_axis_frames(3), speed=0)
    with pytest.raises(FormatError, match="components=1, but the sensor 'mag4x4' reports 3"):
        Emulator(MAG, emulator.frames, wire_format=parse_format("text,components=1"))
    with pytest.raises(FormatError, match="components=3, but the sensor 'pad16' reports 1"):
        open_source("text,components=3:loop://", sensor=PAD)


@pytest.mark.parametrize(
    "spec, data, said",
    [
        ("text", b"1,2,3,4,5,6,7,8,9,10,11,12,13,14,15,16\n" * 4, "lines of 16 values"),
        ("marker,width=16", (b"\xaa\x55" + b"\x01\x00" * 16) * 5, "16 samples of 16 bits"),
        ("justfloat", (np.ones(16, "<f4").tobytes() + b"\x00\x00\x80\x7f") * 8, "16 floats"),
    ],
)
def test_a_line_of_one_value_per_taxel_is_a_clear_error(spec, data, said):
    fmt = parse_format(spec)
    decoder = fmt.decoder(MAG.frame_shape, LossCounters(), "test")
    with pytest.raises(StreamError, match="4x4 tactels x 3 components = 48 values") as caught:
        decoder.feed(data)
    assert said in str(caught.value)


def test_the_format_names_its_components_in_its_source():
    assert parse_format("text,components=3").spec() == "text,components=3"
    assert parse_format("justfloat").spec() == "justfloat"
    marker = parse_format("marker,components=2").spec()
    assert marker.endswith(",components=2") and parse_format(marker).components == 2


# ---- docs/protocol.md, "Version 2" ---------------------------------------------------

DOCS = Path(__file__).resolve().parents[2] / "docs" / "protocol.md"
EXAMPLE_V2 = np.array([[[32768, 32769, 40000]], [[32767, 0, 65535]]])


def _section() -> str:
    text = DOCS.read_text()
    return text[text.index("## Version 2") : text.index("## Not in version 1")]


def test_the_worked_v2_example_is_what_the_code_sends():
    section = _section()
    block = re.search(r"<!-- example-frame-v2 -->\s*```text\n(.*?)```", section, re.S)
    wire = encode_frame(2, 10_000, EXAMPLE_V2)
    assert bytes.fromhex("".join(block.group(1).split())) == wire
    # the annotated bytes before COBS, line by line, and the sizes quoted
    annotated = re.search(r"Before COBS \((\d+) bytes\):\s*```text\n(.*?)```", section, re.S)
    hex_column = "".join(
        re.match(r"((?:[0-9a-f]{2} )*)", line + " ").group(1)
        for line in annotated.group(2).splitlines()
    )
    packet = cobs.decode(wire[:-1])
    assert bytes.fromhex(hex_column) == packet and int(annotated.group(1)) == len(packet)
    assert re.search(r"On the wire \((\d+) bytes\)", section).group(1) == str(len(wire))
    crc = re.search(r"CRC-32 0x([0-9a-f]{8})", annotated.group(2)).group(1)
    assert int(crc, 16) == int.from_bytes(packet[-4:], "little")


def test_the_size_of_a_mag4x4_frame_in_the_docs():
    before, on_wire = re.search(
        r"A 4x4 three-axis frame \(`mag4x4`\) is (\d+) bytes before COBS and (\d+) on the wire",
        _section(),
    ).groups()
    wire = encode_frame(0, 0, _three_axis_frames(1)[0])
    assert (int(before), int(on_wire)) == (len(cobs.decode(wire[:-1])), len(wire))
    assert MAG.frame_shape == (4, 4, 3)


# ---- the command line: emulate --format ... --components, record, info ---------------


def test_emulate_and_record_a_three_axis_text_device(tmp_path):
    """`emulate --format text --components 3` prints a source that `record --components 3`
    reads; the recording holds the simulated (T, 4, 4, 3) frames and `info` says so."""
    import signal
    import subprocess
    import sys

    from typer.testing import CliRunner

    from tactsense.cli import app
    from tactsense.io.recording import read_recording

    simulated = tmp_path / "sim.h5"
    runner = CliRunner()
    done = runner.invoke(app, ["simulate", "--sensor", "mag4x4", "-o", str(simulated)])
    assert done.exit_code == 0, done.output
    command = [
        *(sys.executable, "-m", "tactsense.cli", "emulate", "--recording", str(simulated)),
        *("--format", "text,sep=space", "--components", "3", "--port", "0", "--speed", "1e6"),
    ]
    device = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        source = device.stdout.readline().strip()
        assert source.startswith("text,sep=space,components=3:socket://127.0.0.1:"), source
        url = source.partition(":")[2]
        out = tmp_path / "live.h5"
        result = runner.invoke(
            app,
            [
                *("record", f"text:{url}", "--components", "3", "--sensor", "mag4x4"),
                *("-o", str(out), "--frames", "40", "--quiet"),
            ],
        )
        assert result.exit_code == 0, result.output
    finally:
        device.send_signal(signal.SIGINT)
        device.wait(10)
    live = read_recording(out)
    assert live.frames.shape == (40, 4, 4, 3)
    np.testing.assert_array_equal(live.frames, read_recording(simulated).frames[:40])
    info = runner.invoke(app, ["info", str(out)], env={"COLUMNS": "300"})
    assert "40 x 4 x 4 x 3 counts" in " ".join(info.output.split())


def test_an_ident_whose_components_disagree_with_its_description_is_named():
    class Liar(Emulator):
        def identity(self) -> dict:
            return {**super().identity(), "components": 2}

    emulator = Liar(MAG, _three_axis_frames(3), speed=0)
    with pytest.raises(StreamError, match=r"says 2 components per taxel, but .* has 3"):
        _read_all(emulator)
