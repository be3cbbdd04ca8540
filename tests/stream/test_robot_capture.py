"""Capture from several emulated devices at once (issue 36, item 3): RobotSources, the
robot recorder, device dropouts, Ctrl-C; every device on 127.0.0.1.

A small skin: three boards, four pads; board_a reads a 200 Hz pad and a 100 Hz one (so
the slower is in every second frame). Each patch sends frames whose every taxel holds a
value that names the patch and the frame, so any frame in the wrong place shows.
"""

import dataclasses
import json
import os
import signal
import subprocess
import sys
import threading
import time

import numpy as np
import pytest

from tactsense.io.recording import read_recording
from tactsense.io.robot_recording import (
    aligned_times,
    read_manifest,
    read_robot_recording,
    stream_path,
)
from tactsense.robot import Joint, Patch, Pose, RobotSkin, skin_to_toml_string
from tactsense.sensor import Grid, preset
from tactsense.stream import FaultRates
from tactsense.stream.robot import RobotSources
from tactsense.stream.robot_emulator import device_emulators, start_device_emulators
from tactsense.stream.robot_recorder import record_robot

FRAMES = 40
"""Frames of each patch's stream (they repeat)."""


def _pad(name, rows, cols, rate_hz):
    spec = preset("pad16").replace(
        grid=Grid(rows=rows, cols=cols), electronics__scan_rate_hz=rate_hz
    )
    return dataclasses.replace(spec, name=name)


def small_skin() -> RobotSkin:
    patches = [
        Patch("a1", _pad("a1", 3, 4, 200.0), "base", device="board_a"),
        Patch("a2", _pad("a2", 2, 5, 100.0), "finger", Pose((0.01, 0, 0)), device="board_a"),
        Patch("b1", _pad("b1", 4, 4, 250.0), "finger", device="board_b"),
        Patch("c1", _pad("c1", 3, 3, 125.0), "base", Pose((0, 0.02, 0)), device="board_c"),
    ]
    joint = Joint("j1", "revolute", "base", "finger", Pose((0.05, 0, 0)), (0, 1, 0), -1, 1)
    return RobotSkin("small", "base", ("base", "finger"), (joint,), tuple(patches))


def _streams(skin):
    """Frame t of patch number p: every taxel = 1000 (p + 1) + t [counts]."""
    return {
        patch.name: np.broadcast_to(
            (1000 * (p + 1) + np.arange(FRAMES))[:, None, None], (FRAMES, *patch.sensor.shape)
        ).copy()
        for p, patch in enumerate(skin.patches)
    }


@pytest.fixture
def skin():
    return small_skin()


def _emulate(skin, faults=None, seed=3, drift_ppm=50.0):
    emulators = device_emulators(
        skin, _streams(skin), drift_ppm=drift_ppm, seed=seed, faults=faults
    )
    return emulators, start_device_emulators(emulators)


def _stop(running):
    for device in running.values():
        device.stop()


def _expected_frame(skin, name, scan):
    """What patch ``name`` holds at the device's scan ``scan``: board_a's frames cycle
    every 80 scans (a2's 40 frames at every second scan), the others' every 40."""
    every = {"a2": 2}.get(name, 1)
    cycle = 2 * FRAMES if name.startswith("a") else FRAMES
    p = [patch.name for patch in skin.patches].index(name)
    return 1000 * (p + 1) + ((scan % cycle) // every) % FRAMES


def test_layout_packs_and_unpacks_every_patch(skin):
    from tactsense.stream.robot_layout import device_layouts

    layouts = device_layouts(skin)
    assert list(layouts) == ["board_a", "board_b", "board_c"]
    a = layouts["board_a"]
    assert a.every == (1, 2) and a.rate_hz == 200.0 and a.frame_shape == (1, 22)
    frames = {"a1": np.full((3, 4), 7), "a2": np.arange(10).reshape(2, 5)}
    packed = a.pack(frames)
    assert packed.dtype == np.uint16 and packed.shape == (1, 22)
    assert set(a.unpack(packed, scan=1)) == {"a1"}  # a2 is read at even scans only
    back = a.unpack(packed, scan=4)
    for name, frame in frames.items():
        np.testing.assert_array_equal(back[name], frame)


def test_record_three_devices_frames_losses_and_clocks(skin, tmp_path):
    faults = {"board_a": FaultRates(drop=0.05), "board_b": FaultRates(bitflip=0.05)}
    emulators, running = _emulate(skin, faults)
    try:
        sources = RobotSources(skin, {d: r.url for d, r in running.items()})
        out = record_robot(sources, tmp_path / "run", duration_s=2.5)
    finally:
        _stop(running)
    recording = read_robot_recording(out)
    manifest = read_manifest(out)
    assert recording.closed_cleanly and sorted(recording.streams) == ["a1", "a2", "b1", "c1"]
    for device, emulator in emulators.items():
        entry = manifest["devices"][device]
        assert entry["status"] == "ok" and entry["state"] == "stopped"
        losses = entry["losses"]
        log = emulator.log
        # every frame the device made is received, lost or arrived after the stop
        assert losses["frames"] + losses["lost"] + entry["unused"] == log.frames
        # the spoilt ones are the lost ones (those after the stop are neither kept nor
        # lost: exact when none arrived after it)
        spoilt = log.frames - log.delivered_intact
        assert losses["lost"] <= spoilt <= losses["lost"] + entry["unused"]
        assert (losses["lost"] > 0) == (device != "board_c")
        assert (losses["bad_check"] > 0) == (device == "board_b")
    for name, stream in recording.streams.items():
        device = skin.patch(name).device
        started = emulators[device].started_scan
        scans = (stream.sequence.astype(np.int64) - started) % 65536
        assert stream.frames.shape[1:] == skin.patch(name).sensor.shape
        # each frame is the one its scan carried, every taxel of it
        expected = np.array([_expected_frame(skin, name, s) for s in scans])
        flat = stream.frames.reshape(len(stream.frames), -1)
        np.testing.assert_array_equal(flat, np.repeat(expected[:, None], flat.shape[1], axis=1))
        # the stream's own loss count: its scans that were due and never came
        every = {"a2": 2}.get(name, 1)
        assert np.all(scans % every == 0)
        with_tail = manifest["devices"][device]["losses"]
        device_scans = (
            recording.streams["a1" if device == "board_a" else name].sequence.astype(np.int64)
            - started
        ) % 65536
        gap_lost = int(device_scans[-1] - (len(device_scans) - 1))
        last_sent = int(device_scans[-1]) + with_tail["lost"] - gap_lost
        due = np.arange(scans[0], last_sent + 1, every)
        lost = len(np.setdiff1d(due, scans))
        assert stream.losses["lost"] == lost, name
    # the clocks: every frame's aligned time within 1 ms of when its device scanned it
    for name in recording.streams:
        device = skin.patch(name).device
        times = aligned_times(out, name)
        truth = emulators[device].scheduled_host_time(recording.streams[name].device_time_us)
        error = times - (truth + sources.wall_offset_s)
        assert np.max(np.abs(error)) < 1e-3, (name, np.max(np.abs(error)))
        clock = manifest["devices"][device]["clock"]
        assert clock["pairs"] == manifest["devices"][device]["losses"]["frames"]


def test_a_device_that_drops_out_does_not_stop_the_others(skin, tmp_path):
    _, running = _emulate(skin)

    def kill_board_b() -> None:  # once it has streamed for a second
        while running["board_b"].emulator.started_at is None:
            time.sleep(0.01)
        time.sleep(1.0)
        running["board_b"].stop()

    killer = threading.Thread(target=kill_board_b, daemon=True)
    try:
        sources = RobotSources(skin, {d: r.url for d, r in running.items()}, dropout_s=0.5)
        killer.start()
        out = record_robot(sources, tmp_path / "run", duration_s=3.0)
    finally:
        _stop(running)
    manifest = read_manifest(out)
    b = manifest["devices"]["board_b"]
    assert b["status"] == "dropped" and b["error"]
    recording = read_robot_recording(out)
    last_b = recording.streams["b1"].host_time_s[-1]
    assert b["dropped_at_s"] == pytest.approx(last_b, abs=1e-6)
    for name in ("a1", "a2", "c1"):  # went on for more than a second after the drop
        assert recording.streams[name].host_time_s[-1] > last_b + 1.0
        assert manifest["devices"][skin.patch(name).device]["status"] == "ok"
    assert manifest["closed_cleanly"]


def test_silent_device_drops_out_after_the_timeout(skin):
    emulators, running = _emulate(skin)
    try:
        with RobotSources(skin, {d: r.url for d, r in running.items()}, dropout_s=0.3) as sources:
            stalled = False
            for frame in sources.frames(duration_s=1.5):
                if not stalled and frame.device == "board_c":
                    # the device stalls for 5 s: its line stays open, silent
                    emulators["board_c"].faults = FaultRates(stall=1.0, stall_s=5.0)
                    stalled = True
            status = sources.status["board_c"]
            assert status.state == "dropped" and "silent" in status.error
            assert sources.status["board_a"].state == "stopped"
    finally:
        for emulator in emulators.values():
            emulator.faults = FaultRates()
        _stop(running)


def test_sources_by_name_or_in_order(skin):
    from tactsense.stream.robot import parse_device_sources
    from tactsense.stream.robot_layout import RobotSourceError

    assert parse_device_sources(skin, ["board_b=loop://", "board_a=socket://h:1"]) == {
        "board_b": "loop://",
        "board_a": "socket://h:1",
    }
    assert parse_device_sources(skin, ["x", "y"]) == {"board_a": "x", "board_b": "y"}
    with pytest.raises(RobotSourceError, match="DEVICE=SOURCE or none"):
        parse_device_sources(skin, ["board_a=x", "y"])
    with pytest.raises(RobotSourceError, match="4 sources for the 3 devices"):
        parse_device_sources(skin, list("wxyz"))
    with pytest.raises(RobotSourceError, match="two sources"):
        parse_device_sources(skin, ["board_a=x", "board_a=y"])
    with pytest.raises(RobotSourceError, match="no device 'board_z'"):
        RobotSources(skin, {"board_z": "loop://"})


def test_boards_that_cannot_scan_their_patches_together_are_refused():
    from tactsense.stream.robot_layout import DeviceLayout, RobotSourceError

    odd = small_skin()
    patches = list(odd.patches)
    patches[1] = dataclasses.replace(patches[1], sensor=_pad("a2", 2, 5, 60.0))
    odd = dataclasses.replace(odd, patches=tuple(patches))
    with pytest.raises(RobotSourceError, match="does not divide"):
        DeviceLayout.of(odd, "board_a")
    big = dataclasses.replace(
        odd,
        patches=tuple(
            Patch(f"p{i}", _pad(f"p{i}", 200, 200, 100.0), "base", device="one") for i in range(2)
        ),
    )
    with pytest.raises(RobotSourceError, match="at most 65025"):
        DeviceLayout.of(big, "one")


@pytest.mark.parametrize("sent", [signal.SIGINT, signal.SIGKILL], ids=["sigint", "sigkill"])
def test_a_record_stopped_midway_leaves_every_file_readable(skin, tmp_path, sent):
    """Ctrl-C closes everything cleanly; a kill leaves every stream readable up to its
    last flush and a manifest that says capture never finished."""
    skin_file = tmp_path / "small.toml"
    skin_file.write_text(skin_to_toml_string(skin))
    _, running = _emulate(skin)
    out = tmp_path / "run"
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)}
    urls = [f"{d}={r.url}" for d, r in running.items()]
    command = [sys.executable, "-m", "tactsense", "record", "--skin", str(skin_file), *urls,
               "--out", str(out), "--quiet"]  # fmt: skip
    try:
        process = subprocess.Popen(command, env=env, stderr=subprocess.PIPE, text=True)
        deadline = time.monotonic() + 60
        # wait until frames are on disk (the streams flush once a second)
        while time.monotonic() < deadline and process.poll() is None:
            try:
                if read_recording(stream_path(out, "c1")).frames.shape[0] > 100:
                    break
            except Exception:
                pass
            time.sleep(0.2)
        assert process.poll() is None, process.stderr.read()
        process.send_signal(sent)
        _, err = process.communicate(timeout=30)
    finally:
        _stop(running)
    manifest = json.loads((out / "robot.json").read_text())
    recording = read_robot_recording(out)
    if sent == signal.SIGKILL:
        assert process.returncode == -signal.SIGKILL
        assert not manifest["closed_cleanly"] and not recording.closed_cleanly
        for stream in recording.streams.values():
            assert len(stream.frames) > 50 and len(stream.frames) == len(stream.host_time_s)
        return
    assert process.returncode == 0, err
    assert "stopped by" in err
    assert manifest["closed_cleanly"]
    for name, stream in recording.streams.items():
        losses = manifest["devices"][skin.patch(name).device]["losses"]
        if name != "a2":
            assert len(stream.frames) == losses["frames"], name
        assert len(stream.frames) > 50
    assert not list(tmp_path.glob("*.partial"))


def test_a_board_in_another_wire_format_has_host_times_and_no_clock_fit(skin):
    """FORMAT:URL sources work too; without device time the aligned time is the arrival."""
    from tactsense.stream.robot_emulator import DeviceEmulator
    from tactsense.stream.robot_layout import device_layouts
    from tactsense.stream.sources import parse_format

    layout = device_layouts(skin)["board_b"]
    frames = layout.pack_streams({"b1": _streams(skin)["b1"]})
    emulator = DeviceEmulator(layout, frames, wire_format=parse_format("text"), repeat=True)
    _, port = emulator.start_tcp()
    try:
        with RobotSources(skin, {"board_b": f"text:socket://127.0.0.1:{port}"}) as sources:
            received = list(sources.frames(duration_s=1.0))
    finally:
        emulator.stop()
    assert len(received) > 50
    for frame in received:
        assert frame.device_time_us == -1 and frame.aligned_time_s == frame.host_time_s
        value = int(frame.patches["b1"].flat[0]) - 3000
        assert 0 <= value < FRAMES and (frame.patches["b1"] == frame.patches["b1"].flat[0]).all()
    assert sources.devices_manifest()["board_b"]["clock"] == {}
