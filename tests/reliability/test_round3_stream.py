"""Round three of "nothing lost" (issue 31), the stream's part: every frame its own time
stamp at its last byte, strictly increasing; the counters of what was no frame stored
and printed; one rule for JustFloat's values and for a short run at either end of the
line; a clear word for an unknown format and for a recording named like another file.

Every case failed before its fix (checked against the unfixed code)."""

import socket
import threading
import time

import numpy as np
import pytest

from tactsense.sensor import load_sensor
from tactsense.stream import Emulator, LossCounters, StreamReader
from tactsense.stream.reader import STAMP_STEP_S, ByteClock
from tactsense.stream.sources import open_source, parse_format

SPEC = load_sensor("pad16")
FRAMES = np.random.default_rng(3).integers(0, 100, (400, *SPEC.shape))  # no AA/55 byte


# ---- item 2: stamps ----------------------------------------------------------------------


def test_byte_clock_spreads_a_read_by_byte_position():
    """The documented rule: bytes of one read spread evenly over (t_lo, t_read]."""
    clock = ByteClock()
    clock.add(10, t_read=1.0, woke=1.0)  # waited for: the window is one instant
    clock.add(100, t_read=2.0)  # the bytes were waiting: window (1.0, 2.0]
    assert clock.byte_time(10) == 1.0
    assert clock.byte_time(10 + 50) == pytest.approx(1.5)
    assert clock.byte_time(110) == 2.0
    a, _ = clock.stamp(60)
    b, _ = clock.stamp(60)  # two frames ending at one byte: still strictly later
    assert b == pytest.approx(a + STAMP_STEP_S)


def _burst_stamps(source_of, frames=FRAMES):
    """Frames sent as fast as the line takes them (64 to a write)."""
    fmt = source_of[0]
    emulator = Emulator(SPEC, frames, speed=0, rng=1, wire_format=fmt)
    _, port = emulator.start_tcp()
    try:
        url = f"socket://127.0.0.1:{port}"
        if fmt is None:
            stream = StreamReader(url, sensor=SPEC)
        else:
            stream = open_source(f"{fmt.spec()}:{url}", sensor=fmt.sensor_as_sent(SPEC))
        with stream:
            got = list(stream.frames(max_frames=len(frames)))
    finally:
        emulator.stop()
    return got


@pytest.mark.parametrize("spec", [None, "text", "marker", "justfloat"])
def test_every_frame_of_one_read_has_its_own_increasing_stamp(spec):
    got = _burst_stamps((None if spec is None else parse_format(spec),))
    assert len(got) > 300
    host = np.array([f.host_time_s for f in got])
    arrival = np.array([f.arrival for f in got])
    assert (np.diff(host) > 0).all(), f"{(np.diff(host) <= 0).sum()} repeated host stamps"
    assert (np.diff(arrival) > 0).all()


def test_mcap_header_stamps_increase_strictly():
    """The MCAP writer stamps each message with the frame's host time (ns)."""
    mcap_reader = pytest.importorskip("mcap.reader")
    ros2 = pytest.importorskip("mcap_ros2.decoder")
    from tactsense.interop.mcap import record_mcap

    emulator = Emulator(SPEC, FRAMES[:200], speed=0, rng=1)
    _, port = emulator.start_tcp()
    import tempfile
    from pathlib import Path

    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "r.mcap"
        try:
            with StreamReader(f"socket://127.0.0.1:{port}", sensor=SPEC) as stream:
                record_mcap(stream, out, max_frames=200)
        finally:
            emulator.stop()
        with open(out, "rb") as handle:
            reader = mcap_reader.make_reader(handle, decoder_factories=[ros2.DecoderFactory()])
            decoded = list(reader.iter_decoded_messages(topics=["/tactile_states"]))
    log = np.array([message.log_time for _, _, message, _ in decoded])
    stamp = np.array([m.header.stamp.sec * 10**9 + m.header.stamp.nanosec for *_, m in decoded])
    assert len(stamp) >= 150
    assert (np.diff(stamp) > 0).all(), f"{(np.diff(stamp) <= 0).sum()} repeated header stamps"
    assert (np.diff(log) > 0).all()


def _serve_once(chunks):
    """A TCP device on 127.0.0.1 that sends ``chunks`` [(bytes, pause before [s])]."""
    server = socket.create_server(("127.0.0.1", 0))
    sent: list[float] = []

    def run():
        conn, _ = server.accept()
        with conn:
            for data, pause in chunks:
                time.sleep(pause)
                conn.sendall(data)
                sent.append(time.perf_counter())
            time.sleep(0.3)
        server.close()

    threading.Thread(target=run, daemon=True).start()
    return server.getsockname()[1], sent


def test_a_marker_frame_before_a_stall_is_stamped_when_it_arrived():
    """A marker frame is confirmed by the next marker, but stamped at its own last byte:
    the frame sent before a stall of 0.8 s is not stored 0.8 s late."""
    samples = [bytes([k] * SPEC.shape[0] * SPEC.shape[1]) for k in range(4)]
    chunks = [
        (b"\xaa\x55" + samples[0], 0.3),
        (b"".join(b"\xaa\x55" + s for s in samples[1:]), 0.8),
    ]
    port, sent = _serve_once(chunks)
    as_sent = parse_format("marker").sensor_as_sent(SPEC)  # 8-bit samples: an 8-bit converter
    with open_source(f"marker:socket://127.0.0.1:{port}", sensor=as_sent) as stream:
        got = list(stream.frames())
    assert len(got) == 4
    assert got[0].counts[0, 0] == 0
    # frame 0 arrived with the first write, frame 1 with the second, 0.8 s later
    assert abs(got[0].arrival - sent[0]) < 0.1
    assert got[1].arrival - got[0].arrival > 0.6


# ---- item 10 (stream parts) and 13 ----------------------------------------------------


def _cli(args):
    from typer.testing import CliRunner

    from tactsense.cli import app

    result = CliRunner().invoke(app, args)
    return result.exit_code, " ".join(result.output.split())


def _decode(spec: str, data: bytes, finish: bool = True):
    stats = LossCounters()
    decoder = parse_format(spec).decoder((4, 4), stats, "test")
    frames = decoder.feed(data) + (decoder.finish() if finish else [])
    return frames, stats


@pytest.mark.parametrize("name", ["r.csv", "r.jsonl", "r"])
def test_record_refuses_an_output_named_as_another_kind_of_file(tmp_path, name):
    emulator = Emulator(SPEC, FRAMES[:30], speed=0, rng=1)
    _, port = emulator.start_tcp()
    out = tmp_path / name
    try:
        code, message = _cli(["record", f"socket://127.0.0.1:{port}", "--out", str(out)])
    finally:
        emulator.stop()
    assert code == 2, message
    assert "HDF5 (.h5, .hdf5) or MCAP (.mcap)" in message
    assert not out.exists()


def test_record_refuses_a_format_its_extension_contradicts(tmp_path):
    out = tmp_path / "r.mcap"
    code, message = _cli(["record", "loop://", "--format", "h5", "--out", str(out)])
    assert code == 2 and "another kind of file than --format h5" in message, message
    assert not out.exists()


@pytest.mark.parametrize("token", ["1_000", "1_0_0_0"])
def test_text_numbers_with_underscores_are_garbage(token):
    line = ",".join([token, *map(str, range(15))]) + "\r\n"
    frames, stats = _decode("text", line.encode())
    assert frames == [] and stats.garbage == 1
    assert stats.garbage_bytes == len(line) - 2  # the line ending is no garbage


def test_a_crlf_garbage_line_counts_its_text_not_its_line_ending():
    _, stats = _decode("text", b"calibrating...\r\n")
    assert (stats.garbage, stats.garbage_bytes) == (1, len("calibrating..."))


def _justfloat(values) -> bytes:
    return np.asarray(values, "<f4").tobytes() + bytes.fromhex("0000807f")


@pytest.mark.parametrize("value", [-0.3, -0.5, 65535.4, -1e-6])
def test_justfloat_checks_the_range_before_rounding(value):
    """A value outside [0, 65535] is no count, however it would round."""
    frames, stats = _decode("justfloat", _justfloat([value, *range(15)]))
    assert frames == [] and (stats.garbage, stats.garbage_bytes) == (1, 64)


@pytest.mark.parametrize(
    "value, count", [(0.5, 1), (2.5, 3), (4.5, 5)]
)  # half to even gave 0, 2, 4
def test_justfloat_rounds_halves_up(value, count):
    frames, stats = _decode("justfloat", _justfloat([value, *range(15)]))
    assert stats.garbage == 0 and frames[0].ravel()[0] == count


def test_a_short_run_before_any_tail_is_garbage_when_the_line_closes_too():
    """Before the first delimiter the reader may have joined mid-frame: garbage, whether
    a tail follows (as before) or the line closes (it was "truncated")."""
    run = bytes(range(1, 11))  # 10 bytes, shorter than a frame, no delimiter in them
    _, before = _decode("justfloat", run + bytes.fromhex("0000807f"))
    _, closed = _decode("justfloat", run)
    assert (before.garbage, before.truncated, before.garbage_bytes) == (1, 0, 10)
    assert (closed.garbage, closed.truncated, closed.garbage_bytes) == (1, 0, 10)


def test_garbage_bytes_are_stored_and_printed(tmp_path):
    from tactsense.io.recording import read_losses
    from tactsense.stream import FaultRates

    fmt = parse_format("text")
    emulator = Emulator(
        SPEC, FRAMES[:100], speed=0, rng=2, wire_format=fmt, faults=FaultRates(garbage=0.2)
    )
    _, port = emulator.start_tcp()
    out = tmp_path / "r.h5"
    try:
        code, message = _cli(
            ["record", f"text:socket://127.0.0.1:{port}", "--sensor", "pad16", "-o", str(out)]
        )
    finally:
        emulator.stop()
    assert code == 0, message
    losses = read_losses(out)
    assert losses["garbage"] == emulator.log.garbage > 0
    assert losses["garbage_bytes"] > 0
    assert f"garbage bytes {losses['garbage_bytes']}" in message


@pytest.mark.parametrize("source", ["csvline:/dev/ttyACM0", "csv,sep=tab:socket://127.0.0.1:9"])
def test_an_unknown_format_is_named_with_the_known_ones(source):
    code, message = _cli(["record", source, "--sensor", "pad16", "--out", "never.h5"])
    assert code == 2, message
    name = source.partition(",")[0].partition(":")[0]
    assert f"unknown wire format '{name}'" in message
    assert "text, marker, justfloat" in message
    assert "could not open" not in message and "cannot open" not in message


# ---- item 8: emulators in another format -------------------------------------------------


@pytest.mark.parametrize("spec", ["text", "marker"])
def test_a_format_emulator_on_a_pty_waits_for_the_host_to_open_it(spec):
    """`record text:/dev/pts/N` started a second after the emulator gets every frame
    from the first (it streamed at once, into a line nobody had open, and pyserial
    discards what arrived before it opened the line)."""
    fmt = parse_format(spec)
    emulator = Emulator(SPEC, FRAMES[:50], speed=0, wire_format=fmt)
    _, path = emulator.start_pty()
    try:
        time.sleep(1.0)  # the host comes later than the emulator's boot time (0.25 s)
        # a pty never closes: the last marker frame waits for a marker that never comes
        n = 50 if spec == "text" else 49
        as_sent = fmt.sensor_as_sent(SPEC)
        with open_source(f"{fmt.spec()}:{path}", sensor=as_sent, timeout_s=0.5) as stream:
            got = list(stream.frames(max_frames=n, duration_s=10))
    finally:
        emulator.stop()
    assert len(got) == n
    np.testing.assert_array_equal(np.stack([f.counts for f in got]), emulator.frames[:n])


def test_8_bit_marker_frames_are_the_top_8_bits_of_the_converter():
    """One shift for every recording: adc_bits - 8 (4 for pad16's 12 bits), not one that
    depends on the largest count of the recording (it was 2 bits for one, 3 for another)."""
    bits = SPEC.electronics.adc_bits
    fmt = parse_format("marker")
    for top in (1000, 2000, 4095):
        frames = np.linspace(0, top, 50 * 256).astype(np.uint16).reshape(50, *SPEC.shape)
        sent = Emulator(SPEC, frames, wire_format=fmt).frames
        np.testing.assert_array_equal(sent, frames >> (bits - 8))


# ---- item 9: live compiles and warms before the first frame ------------------------------


def _touch_frames(sensor, row, col):
    """Five untouched frames, then a press at (row, col) raising and lowering counts."""
    from tactsense.stream import StreamFrame

    rows, cols = sensor.shape
    base = np.full(sensor.shape, sensor.electronics.nominal_counts)
    r, c = np.mgrid[0:rows, 0:cols]
    bump = np.exp(-((r - row) ** 2 + (c - col) ** 2) / 3.0)
    frames = [base] * 5 + [base * (1 + 0.25 * bump), base * (1 - 0.25 * bump), base]
    return [
        StreamFrame(k, k, 0.01 * k, 0.0, time.perf_counter(), np.rint(f).astype(np.uint16))
        for k, f in enumerate(frames)
    ]


def _loaded() -> tuple[dict, set]:
    """Every Numba function's compiled (or cache-loaded) signatures, and the modules."""
    import gc
    import sys

    from numba.core.registry import CPUDispatcher

    jitted = {
        id(d): (str(d), len(d.signatures)) for d in gc.get_objects() if isinstance(d, CPUDispatcher)
    }
    return jitted, set(sys.modules)


@pytest.mark.parametrize(
    "name, options",
    [("pad16", {"method": "fit"}), ("pad16", {})],
)
def test_the_first_contact_compiles_and_loads_nothing(name, options):
    """Everything a touch needs is compiled (or loaded from Numba's cache) and imported
    when the locator is made, before the first frame: no Numba function gains a
    signature and no module is imported during the first frames and the first contact
    (the first contact stalled 1.74 s with fit, 60-210 ms by default)."""
    from tactsense.stream.live import LiveContacts, LiveLocator

    sensor = load_sensor(name)
    cls = LiveLocator if sensor.kind == "finger" else LiveContacts
    locator = cls(sensor, **options)
    assert not locator.ready  # the warm-up left no baseline behind
    frames = _touch_frames(sensor, 2, sensor.shape[1] - 3)
    jitted, modules = _loaded()
    estimates = [locator(frame) for frame in frames]
    jitted_after, modules_after = _loaded()
    assert all(e is None for e in estimates[:5])  # the warm-up left no baseline frames
    touched = estimates[5]
    assert touched is not None
    assert touched.get("n_contacts", 1) >= 1 and np.isfinite(touched["force_n"])
    grown = [name for key, (name, n) in jitted_after.items() if n > jitted.get(key, ("", 0))[1]]
    assert not grown, f"compiled or loaded at the first contact: {grown[:5]}"
    assert not modules_after - modules, f"imported: {sorted(modules_after - modules)[:5]}"


def test_live_warms_the_locator_before_opening_a_format_device(monkeypatch):
    """A device of another format streams once its line opens: the locator is made
    first (its frames queued 5 s behind the compilation on a cold cache)."""
    from tactsense.cli import _live_sources as cli_live

    calls = []
    real_locator, real_open = cli_live._locator_for, cli_live._open_reader
    monkeypatch.setattr(
        cli_live, "_locator_for", lambda *a, **k: calls.append("locator") or real_locator(*a, **k)
    )
    monkeypatch.setattr(
        cli_live, "_open_reader", lambda *a, **k: calls.append("open") or real_open(*a, **k)
    )
    emulator = Emulator(SPEC, FRAMES[:40], speed=0, wire_format=parse_format("text"))
    _, port = emulator.start_tcp()
    try:
        code, message = _cli(
            ["live", f"text:socket://127.0.0.1:{port}", "--sensor", "pad16", "--frames", "20"]
        )
    finally:
        emulator.stop()
    assert code == 0, message
    assert calls == ["locator", "open"]


def test_the_first_native_frame_compiles_nothing():
    """Over tactsense's own protocol (COBS packets) the first frames and the first
    contact compile and load nothing: the frames the reader decodes are of the type the
    warm-up compiled (they were read-only views of the packet, another Numba type:
    _follow compiled at the first frame after the baseline, 0.9-2 s on a cold cache)."""
    import numba

    from tactsense.stream.live import LiveContacts, warm_frames

    frames = np.stack([f.counts for f in _touch_frames(SPEC, 5, 9)])
    emulator = Emulator(SPEC, frames, speed=0)
    _, port = emulator.start_tcp()
    locator = LiveContacts(SPEC)
    try:
        with open_source(f"socket://127.0.0.1:{port}", sensor=SPEC) as stream:
            jitted, modules = _loaded()
            got = list(stream.frames(max_frames=len(frames), duration_s=10))
            estimates = [locator(frame) for frame in got]
            jitted_after, modules_after = _loaded()
    finally:
        emulator.stop()
    assert len(got) == len(frames) and estimates[5]["n_contacts"] >= 1
    warmed = numba.typeof(warm_frames(SPEC)[0].counts)
    assert {numba.typeof(f.counts) for f in got} == {warmed}
    grown = [name for key, (name, n) in jitted_after.items() if n > jitted.get(key, ("", 0))[1]]
    assert not grown, f"compiled or loaded at the first native frames: {grown[:5]}"
    assert not modules_after - modules, f"imported: {sorted(modules_after - modules)[:5]}"


def test_frames_queued_behind_a_busy_reader_keep_their_spread():
    """Ten text frames arrive 0.1 s apart while the reader is busy for 1.3 s: their
    stamps spread over the wait (they all had the time of the one read that took them,
    so a stall behind them showed as 1.5 ms of latency)."""
    line = (",".join(["7"] * 256) + "\r\n").encode()
    port, sent = _serve_once([(line, 0.2)] + [(line, 0.1)] * 10)
    with open_source(f"text:socket://127.0.0.1:{port}", sensor=SPEC) as stream:
        first = next(stream.frames(max_frames=1))
        time.sleep(1.3)  # busy: the other ten frames queue in the socket
        queued = stream.read_batch(20, wait_s=0.5)
    assert len(queued) == 10
    stamps = np.array([f.arrival for f in queued])
    assert (np.diff(stamps) > 0).all() and stamps[0] > first.arrival
    assert stamps[-1] - stamps[0] > 0.5  # spread over the wait, not one instant
    assert abs(stamps[-1] - sent[-1]) < 0.5


# ---- samples narrower than the converter (8-bit marker frames of a 12-bit sensor) -------


def _marker8_device(frames):
    """A marker device of 8-bit samples (the top 8 of pad16's 12 bits) on 127.0.0.1."""
    fmt = parse_format("marker,width=8")
    emulator = Emulator(SPEC, frames, speed=0, wire_format=fmt)
    _, port = emulator.start_tcp()
    return emulator, f"{fmt.spec()}:socket://127.0.0.1:{port}"


@pytest.mark.parametrize("command, suffix", [("record", ".h5"), ("live", ".jsonl")])
def test_8_bit_samples_under_a_12_bit_description_are_refused(tmp_path, command, suffix):
    """8-bit samples read under pad16's 12-bit description were kept silently (its
    nominal counts 16x the device's, 5x fewer contacts found by locate). Refused, with
    the description that fits what the device sends; nothing written."""
    bits = SPEC.electronics.adc_bits
    nominal = SPEC.electronics.nominal_counts / 2 ** (bits - 8)
    emulator, source = _marker8_device(FRAMES[:40])
    out = tmp_path / f"out{suffix}"
    try:
        code, message = _cli([command, source, "--sensor", "pad16", "--frames", "20",
                              "--out", str(out)])  # fmt: skip
    finally:
        emulator.stop()
    assert code == 2, message
    assert f"{bits}-bit converter" in message and "8-bit samples" in message
    assert f"adc_bits = 8 and nominal_counts = {nominal:g}" in message
    assert not out.exists()


def test_8_bit_samples_described_as_sent_are_recorded(tmp_path):
    """The same device described as it sends (adc_bits 8, nominal counts scaled) records
    every frame as sent, under that description."""
    from tactsense.io.recording import read_recording

    nominal = SPEC.electronics.nominal_counts / 2 ** (SPEC.electronics.adc_bits - 8)
    toml = tmp_path / "pad16_8bit.toml"
    toml.write_text(
        f'kind = "pad"\nextends = "pad16"\nname = "pad16_8bit"\n\n'
        f"[electronics]\nadc_bits = 8\nnominal_counts = {nominal}\n"
    )
    emulator, source = _marker8_device(FRAMES[:40])
    out = tmp_path / "out.h5"
    try:
        code, message = _cli(["record", source, "--sensor", str(toml), "--frames", "30",
                              "--out", str(out)])  # fmt: skip
    finally:
        emulator.stop()
    assert code == 0, message
    recording = read_recording(out)
    assert recording.sensor.electronics.adc_bits == 8
    np.testing.assert_array_equal(recording.frames, emulator.frames[:30])
