"""The command line of capture from several devices: emulate --skin, live --skin (the
status lines, a device dropping out) and record --skin's summary."""

import json
import os
import signal
import subprocess
import sys
import threading
import time

import pytest
from typer.testing import CliRunner

from tactsense.cli import app
from tactsense.io.robot_recording import read_manifest
from tactsense.robot import skin_to_toml_string
from tactsense.stream.robot import RobotSources
from tactsense.stream.robot_emulator import device_emulators, start_device_emulators

from .test_robot_capture import _streams, small_skin

runner = CliRunner()


@pytest.fixture
def skin_file(tmp_path):
    path = tmp_path / "small.toml"
    path.write_text(skin_to_toml_string(small_skin()))
    return path


def test_live_reports_every_device_and_the_one_that_dropped(skin_file):
    skin = small_skin()
    running = start_device_emulators(device_emulators(skin, _streams(skin), seed=2))

    def kill_board_c() -> None:  # once it has streamed for half a second
        while running["board_c"].emulator.started_at is None:
            time.sleep(0.01)
        time.sleep(0.5)
        running["board_c"].stop()

    killer = threading.Thread(target=kill_board_c, daemon=True)
    urls = [f"{d}={r.url}" for d, r in running.items()]
    try:
        killer.start()
        result = runner.invoke(
            app,
            ["live", "--skin", str(skin_file), *urls, "--duration", "2.5", "--dropout-s", "0.5"],
        )
    finally:
        for device in running.values():
            device.stop()
    assert result.exit_code == 0, result.output
    lines = [json.loads(line) for line in result.stdout.splitlines() if line.startswith("{")]
    last = {line["device"]: line for line in lines}
    assert set(last) == {"board_a", "board_b", "board_c"}
    assert last["board_c"]["state"] == "dropped" and last["board_c"]["dropped_at_s"]
    for device in ("board_a", "board_b"):
        assert last[device]["state"] == "stopped"
        assert last[device]["lost"] == 0
        assert abs(last[device]["drift_ppm"]) < 1000
        # skew: the drift over the time streamed
        assert abs(last[device]["skew_ms"]) < 1000e-6 * 3 * 1e3
    # the rates are each board's: board_a 200 Hz, board_b 250 Hz (within 5 %)
    assert last["board_a"]["rate_hz"] == pytest.approx(200.0, rel=0.05)
    assert last["board_b"]["rate_hz"] == pytest.approx(250.0, rel=0.05)
    # a status line per device at least every second, while it streams
    assert sum(line["device"] == "board_a" for line in lines) >= 2


def test_emulate_skin_serves_a_pty_per_board_until_ctrl_c(skin_file):
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)}
    command = [sys.executable, "-m", "tactsense", "emulate", "--skin", str(skin_file),
               "--drift-ppm", "40", "--clock-offset-s", "12"]  # fmt: skip
    process = subprocess.Popen(
        command, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True
    )
    try:
        urls = [process.stdout.readline().strip() for _ in range(3)]
        assert [u.split("=")[0] for u in urls] == ["board_a", "board_b", "board_c"], urls
        assert all(u.split("=")[1].startswith("/dev/") for u in urls), urls  # a pty each
        with RobotSources(small_skin(), urls) as sources:
            frames = list(sources.frames(duration_s=1.0))
        for status in sources.status.values():
            assert status.frames > 0 and status.losses.lost == 0, status.line()
        # the clocks start 12 s ahead (to a scan) and run 40 ppm fast
        first = {}
        for frame in frames:
            first.setdefault(frame.device, frame.device_time_us)
        assert all(12e6 <= t < 12e6 + 0.5e6 for t in first.values()), first
    finally:
        process.send_signal(signal.SIGINT)
        _, err = process.communicate(timeout=20)
    assert process.returncode == 0, err
    assert "clock +40.0 ppm" in err and "board_c: sent" in err


def test_record_skin_prints_each_device_and_what_was_written(skin_file, tmp_path):
    skin = small_skin()
    running = start_device_emulators(device_emulators(skin, _streams(skin), seed=4))
    out = tmp_path / "run"
    try:
        result = runner.invoke(
            app,
            ["record", "--skin", str(skin_file), *(r.url for r in running.values()),
             "--duration", "1", "--out", str(out)],
        )  # fmt: skip
    finally:
        for device in running.values():
            device.stop()
    assert result.exit_code == 0, result.output
    text = " ".join(result.output.split())
    assert f"wrote {out}" in text and "from 3 devices" in text
    manifest = read_manifest(out)
    assert manifest["closed_cleanly"] and set(manifest["streams"]) == {"a1", "a2", "b1", "c1"}
    assert all(e["source"].startswith("socket://127.0.0.1:") for e in manifest["devices"].values())
    # --force replaces a robot recording, and only one
    again = runner.invoke(
        app,
        ["record", "--skin", str(skin_file), *(r.url for r in running.values()),
         "--duration", "1", "--out", str(out)],
    )  # fmt: skip
    assert again.exit_code == 2 and "exists; pass --force" in " ".join(again.output.split())


def test_a_board_that_cannot_be_opened_stops_nothing_half_made(skin_file, tmp_path):
    out = tmp_path / "run"
    result = runner.invoke(
        app, ["record", "--skin", str(skin_file), "socket://127.0.0.1:1", "--out", str(out)]
    )
    assert result.exit_code == 2
    assert "cannot open socket://127.0.0.1:1" in " ".join(result.output.split())
    assert not out.exists()


def test_emulate_skin_replays_a_robot_recording(skin_file, tmp_path):
    from tactsense.stream.robot_recorder import record_robot

    skin = small_skin()
    running = start_device_emulators(device_emulators(skin, _streams(skin), seed=5))
    try:
        run = record_robot(RobotSources(skin, {d: r.url for d, r in running.items()}),
                           tmp_path / "run", duration_s=0.5)  # fmt: skip
    finally:
        for device in running.values():
            device.stop()
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)}
    command = [sys.executable, "-m", "tactsense", "emulate", "--skin", str(skin_file),
               "--recording", str(run), "--loop", "--port", "0"]  # fmt: skip
    process = subprocess.Popen(
        command, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True
    )
    try:
        urls = [process.stdout.readline().strip() for _ in range(3)]
        with RobotSources(skin, urls) as sources:
            frames = list(sources.frames(duration_s=0.5))
    finally:
        process.send_signal(signal.SIGINT)
        process.communicate(timeout=20)
    assert frames
    names = [p.name for p in skin.patches]
    for frame in frames:
        for name, counts in frame.patches.items():
            # the recorded frames of that patch (1000 (p + 1) + t), none of another
            value = int(counts.flat[0]) - 1000 * (names.index(name) + 1)
            assert 0 <= value < 40 and (counts == counts.flat[0]).all(), (name, value)
