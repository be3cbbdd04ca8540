"""Emulator to reader over real transports: every frame accounted for, whatever the line
does to it. The emulator logs what it injected; the reader must explain every frame it
did not deliver: ``received + lost == sent`` exactly, and lost == frames the line spoiled."""

import numpy as np
import pytest

import tactsense as ts
from tactsense.stream import Emulator, FaultRates, StreamError, StreamReader
from tactsense.stream.protocol import encode_frame


@pytest.fixture(scope="module")
def sweep(initial):
    return ts.simulate(initial, ts.probe_sweep(initial, along="axial"), rng=3)


def _read_all(emulator, **reader_options):
    _, port = emulator.start_tcp()
    try:
        with StreamReader(f"socket://127.0.0.1:{port}", **reader_options) as stream:
            frames = list(stream.frames())
            assert stream.ended, "the stream must end with END"
            return frames, stream.stats, stream.frames_sent
    finally:
        emulator.stop()


def test_clean_line_delivers_every_frame_bit_identical(sweep):
    frames, stats, sent = _read_all(Emulator.from_recording(sweep, speed=0))
    assert sent == len(sweep) == stats.frames == len(frames)
    assert stats.lost == stats.bad_check == stats.garbage == stats.truncated == 0
    np.testing.assert_array_equal(np.stack([f.counts for f in frames]), sweep.frames)
    assert [f.index for f in frames] == list(range(len(sweep)))
    np.testing.assert_allclose([f.device_time_s for f in frames], sweep.time_s, atol=1e-6)


@pytest.mark.parametrize(
    "faults, counter",
    [
        (FaultRates(drop=0.1), None),
        (FaultRates(bitflip=0.1), "bad_check"),
        (FaultRates(truncate=0.1), "truncated"),
        (FaultRates(garbage=0.1), "garbage"),
        (FaultRates(drop=0.05, bitflip=0.05, truncate=0.05, garbage=0.05), None),
    ],
    ids=["drop", "bitflip", "truncate", "garbage", "all"],
)
def test_every_frame_is_received_or_counted_lost(sweep, faults, counter):
    emulator = Emulator.from_recording(sweep, speed=0, faults=faults, repeat=False, rng=5)
    frames, stats, sent = _read_all(emulator)
    log = emulator.log
    assert sent == log.frames == len(sweep)
    assert stats.frames + stats.lost == log.frames
    assert stats.lost == log.frames - log.delivered_intact
    assert stats.lost > 0, "a 10 % fault rate over 154 frames must spoil some"
    if counter is not None:
        assert getattr(stats, counter) > 0
    if faults.drop and not (faults.bitflip or faults.truncate or faults.garbage):
        assert stats.bad_check == stats.truncated == stats.garbage == 0
        assert stats.lost == log.drop
    # what arrives is what was sent, never a damaged frame
    for frame in frames:
        np.testing.assert_array_equal(frame.counts, sweep.frames[frame.index])


def test_stalls_count_as_timeouts_not_losses(sweep):
    emulator = Emulator.from_recording(
        sweep, speed=0, faults=FaultRates(stall=0.03, stall_s=0.3), rng=2
    )
    frames, stats, _ = _read_all(emulator, timeout_s=0.1)
    assert len(frames) == len(sweep)
    assert emulator.log.stall > 0
    assert stats.timeouts >= emulator.log.stall
    assert stats.lost == 0 and stats.frames == len(sweep)


def test_pseudo_terminal_carries_the_frames(sweep):
    emulator = Emulator.from_recording(sweep, speed=0)
    _, path = emulator.start_pty()
    try:
        with StreamReader(path) as stream:
            frames = list(stream.frames())
    finally:
        emulator.stop()
    assert stream.stats.frames == len(sweep) and stream.stats.lost == 0
    np.testing.assert_array_equal(np.stack([f.counts for f in frames]), sweep.frames)


def _loop_reader(sensor):
    stream = StreamReader("loop://", sensor=sensor, start=False, timeout_s=0.05)
    return stream


def test_sequence_wrap_and_gaps_over_loopback(initial):
    counts = np.full(initial.shape, 2000, dtype=np.uint16)
    period_us = initial.scan_period_s * 1e6
    sent = [65533, 65534, 65535, 0, 2, 3]  # 1 is missing across the wrap
    stream = _loop_reader(initial)
    for k in sent:
        index = k if k > 100 else k + 65536
        stream.port.write(encode_frame(k, round(index * period_us), counts))
    frames = list(stream.frames(max_frames=len(sent)))
    assert [f.sequence for f in frames] == sent
    assert [f.index for f in frames] == [0, 1, 2, 3, 5, 6]
    assert stream.stats.lost == 1 and stream.stats.gaps == 1


def test_a_gap_longer_than_the_counter_is_measured_by_the_device_clock(initial):
    counts = np.full(initial.shape, 2000, dtype=np.uint16)
    period_us = initial.scan_period_s * 1e6
    stream = _loop_reader(initial)
    for index in (10, 11, 11 + 70_000):  # 69,999 frames lost: the counter wrapped once
        stream.port.write(encode_frame(index, round(index * period_us), counts))
    frames = list(stream.frames(max_frames=3))
    assert [f.index for f in frames] == [0, 1, 70_001]
    assert stream.stats.lost == 69_999


def test_duplicates_are_dropped_and_counted(initial):
    counts = np.full(initial.shape, 2000, dtype=np.uint16)
    stream = _loop_reader(initial)
    for k in (0, 1, 1, 2):
        stream.port.write(encode_frame(k, k * 1000, counts))
    frames = list(stream.frames(max_frames=3))
    assert [f.sequence for f in frames] == [0, 1, 2]
    assert stream.stats.duplicates == 1 and stream.stats.lost == 0


def test_a_silent_line_is_a_clear_error():
    with pytest.raises(StreamError, match="no answer to IDENTIFY"):
        StreamReader("loop://", identify_timeout_s=0.2)


def test_a_port_that_does_not_exist_is_a_clear_error():
    with pytest.raises(StreamError, match="cannot open /dev/tactsense-no-such-port"):
        StreamReader("/dev/tactsense-no-such-port")
