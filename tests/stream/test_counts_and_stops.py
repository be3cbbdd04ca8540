"""Counts printed are counts kept, on a device faster than the host; SIGTERM stops a
command as cleanly as Ctrl-C (a recording closed with its frames, an output never
half-written)."""

import dataclasses
import json
import os
import re
import signal
import subprocess
import sys
import time

import numpy as np
import pytest

import tactsense as ts
from tactsense.io.recording import read_recording

CLI = [sys.executable, "-m", "tactsense_launcher"]
RUN = {"capture_output": True, "text": True, "timeout": 180}


@pytest.fixture(scope="module")
def fast_device():
    """`tactsense emulate` sending as fast as the line takes frames, over and over."""
    process = subprocess.Popen(
        [*CLI, "emulate", "--port", "0", "--speed", "1e6", "--loop"],
        stdout=subprocess.PIPE,
        stderr=subprocess.DEVNULL,
        text=True,
    )
    url = process.stdout.readline().strip()
    assert url.startswith("socket://127.0.0.1:"), url
    yield url
    process.send_signal(signal.SIGINT)
    process.wait(10)


def _said(result) -> str:
    return " ".join((result.stdout + result.stderr).split())


@pytest.mark.parametrize("n", [300, 1000, 20000])
def test_record_writes_exactly_n_frames_and_prints_what_it_wrote(tmp_path, fast_device, n):
    out = tmp_path / "fast.h5"
    result = subprocess.run([*CLI, "record", fast_device, "--frames", str(n), "--out", str(out),
                             "--quiet"], **RUN)  # fmt: skip
    assert result.returncode == 0, result.stderr
    rec = read_recording(out)
    assert len(rec) == n and rec.closed_cleanly
    printed = re.search(r"wrote \S+: (\d+) frames", _said(result))
    assert printed and int(printed.group(1)) == len(rec), _said(result)
    # the sequence is unbroken unless losses say otherwise
    steps = np.diff(rec.sequence.astype(np.int64)) % 65536
    assert int(np.sum(steps - 1)) == rec.losses["lost"]


def test_live_counts_agree_with_its_output(tmp_path, fast_device):
    out = tmp_path / "est.jsonl"
    result = subprocess.run([*CLI, "live", fast_device, "--frames", "3000", "--out", str(out)],
                            **RUN)  # fmt: skip
    assert result.returncode == 0, result.stderr
    lines = out.read_text().splitlines()
    said = re.search(r"(\d+) estimates from (\d+) frames \((\d+) for the baseline\)", _said(result))
    assert said, _said(result)
    estimates, frames, baseline = map(int, said.groups())
    assert estimates == len(lines) and frames == 3000 and estimates + baseline == frames
    assert all("axial_mm" in json.loads(line) for line in lines[:3])


def _wait_for_frames(path, at_least: int, timeout_s: float = 60.0) -> None:
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        if path.exists():
            try:
                if len(read_recording(path)) >= at_least:
                    return
            except Exception:
                pass
        time.sleep(0.2)
    raise AssertionError(f"{path} never held {at_least} frames")


def test_sigterm_closes_a_recording_as_cleanly_as_ctrl_c(tmp_path):
    device = subprocess.Popen(
        [*CLI, "emulate", "--port", "0", "--speed", "40", "--loop"],
        stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True,
    )  # fmt: skip
    try:
        url = device.stdout.readline().strip()
        out = tmp_path / "term.h5"
        line = [*CLI, "record", url, "--out", str(out), "--quiet"]
        recorder = subprocess.Popen(line, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        _wait_for_frames(out, 20)
        recorder.send_signal(signal.SIGTERM)
        stdout, stderr = recorder.communicate(timeout=30)
    finally:
        device.send_signal(signal.SIGINT)
        device.wait(10)
    said = " ".join((stdout + stderr).split())
    assert recorder.returncode == 143, said
    assert "Traceback" not in said
    rec = read_recording(out)
    assert rec.closed_cleanly, "closed by its writer, not killed"
    printed = re.search(r"wrote \S+ \(stopped by SIGTERM\): (\d+) frames", said)
    assert printed and int(printed.group(1)) == len(rec) >= 20, said
    steps = np.diff(rec.sequence.astype(np.int64)) % 65536
    assert int(np.sum(steps - 1)) == rec.losses["lost"] == 0  # frames intact, in order


def test_sigterm_on_a_long_locate_leaves_nothing_half_written(tmp_path):
    spec = ts.fearing1990_initial()
    short = ts.simulate(spec, ts.repeated_load(spec, repeats=40), rng=0)
    tiles = -(-300_000 // len(short.frames))  # several seconds of locate
    frames = np.tile(short.frames, (tiles, 1, 1))
    long = dataclasses.replace(
        short, frames=frames, time_s=np.arange(len(frames)) * spec.scan_period_s, truth={}
    )
    rec = tmp_path / "long.h5"
    ts.write_recording(rec, long)
    out = tmp_path / "est.csv"
    line = [*CLI, "locate", str(rec), "--out", str(out)]
    process = subprocess.Popen(line, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 60
    while not [p for p in os.listdir(tmp_path) if ".partial" in p]:  # the work has begun
        assert time.monotonic() < deadline and process.poll() is None, process.communicate()
        time.sleep(0.05)
    process.send_signal(signal.SIGTERM)
    _, err = process.communicate(timeout=60)
    assert process.returncode == 143, err
    assert "stopped by SIGTERM" in err and "Traceback" not in err, err
    assert not out.exists()
    assert not [p for p in os.listdir(tmp_path) if ".partial" in p]
    assert read_recording(rec).frames.shape == frames.shape  # the input untouched


def test_device_time_is_stored_exactly_in_microseconds(tmp_path):
    """Issue 22: the device clock is kept exactly, as the integers the frames carried
    (float seconds were one float step off for about 29 % of frames at 7 Hz)."""
    from tactsense.io.recording import write_recording
    from tactsense.stream import Emulator, StreamReader, record

    spec = ts.fearing1990_initial()
    source = ts.simulate(spec, ts.probe_sweep(spec), rng=0)
    emulator = Emulator.from_recording(source, speed=1e6)
    thread, port = emulator.start_tcp()
    out = tmp_path / "exact.h5"
    try:
        with StreamReader(f"socket://127.0.0.1:{port}") as stream:
            record(stream, out, max_frames=120)
    finally:
        emulator.stop()
        thread.join(timeout=10)
    recording = ts.read_recording(out)
    assert recording.device_time_us.dtype == np.int64
    # the twin's clock: round(k * period) microseconds from its first scan (docs/protocol.md)
    k = np.arange(len(recording.frames)) + int(recording.sequence[0])
    period_us = 1e6 / spec.electronics.scan_rate_hz
    np.testing.assert_array_equal(
        recording.device_time_us, np.round(k * period_us).astype(np.int64)
    )
    # and it survives a copy through write_recording
    copy = tmp_path / "copy.h5"
    write_recording(copy, recording)
    np.testing.assert_array_equal(ts.read_recording(copy).device_time_us, recording.device_time_us)
