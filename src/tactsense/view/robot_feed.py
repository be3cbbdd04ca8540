"""What the browser view of a whole hand shows: every patch's signal and contacts, a
message at a time, from a robot recording played back (or live devices, see
:mod:`tactsense.view.robot_live`).

The page is redrawn at a display rate (:data:`DISPLAY_HZ`), not at every patch's scan
rate: at each tick every patch shows its newest frame due by then, through its own
single-array estimator (:func:`~tactsense.view.view_locator`, created with the tick's
period as its frame period), so a 20-patch hand costs twenty estimates a tick whatever
its scan rates. Every message carries the whole hand's state (a page that connects late,
or misses messages, is whole at the next one). Memory is bounded: each stream is read a
block at a time.
"""

from __future__ import annotations

import json
import math
import threading
import time
from collections.abc import Mapping
from pathlib import Path

import numpy as np

from tactsense.io.recording import RecordingReader
from tactsense.io.robot_recording import read_manifest, read_robot_skin, stream_path
from tactsense.stream.reader import StreamFrame
from tactsense.view.robot_estimator import hand_state
from tactsense.view.robot_scene import scene_layout
from tactsense.view.robot_state import HandState  # noqa: F401 - its home was here

DISPLAY_HZ = 30.0
"""Hand frames shown per second at most [Hz]."""


class _PatchStream:
    """One patch's stream read forwards a block at a time, with a cursor at a time."""

    BLOCK = 1024

    def __init__(self, path: Path, clock: Mapping | None):
        self.file = RecordingReader(path)
        self.n_frames = self.file.n_frames
        # a device clock fitted to the host's (the manifest's, ClockFit.as_dict): t_host =
        # offset_s + t_device / (1 + drift_ppm 1e-6); a simulation's streams share one
        # clock (no fit)
        clock = clock or {}
        self.offset_s = float(clock.get("offset_s", 0.0) or 0.0)
        self.scale = 1.0 / (1.0 + float(clock.get("drift_ppm", 0.0) or 0.0) * 1e-6)
        self.cursor = -1  # the last frame shown
        self._start = -1
        self._frames: np.ndarray | None = None
        self._times: np.ndarray | None = None

    def _load(self, index: int) -> None:
        if self._frames is None or not self._start <= index < self._start + self.BLOCK:
            self._start = (index // self.BLOCK) * self.BLOCK
            self._frames = self.file.frames(self._start, self._start + self.BLOCK)
            self._times = self.file.time_s(self._start, self._start + self.BLOCK)

    def time_of(self, index: int) -> float:
        self._load(index)
        return self.offset_s + self.scale * float(self._times[index - self._start])

    def frame(self, index: int) -> tuple[np.ndarray, float]:
        self._load(index)
        return self._frames[index - self._start], float(self._times[index - self._start])

    def advance_to(self, t: float) -> int | None:
        """Move to the newest frame due by ``t`` [s]; its index if it is new, else None."""
        moved = False
        while self.cursor + 1 < self.n_frames and self.time_of(self.cursor + 1) <= t:
            self.cursor += 1
            moved = True
        return self.cursor if moved else None

    def seek(self, t: float) -> None:
        """Put the cursor before the first frame due after ``t`` (binary search)."""
        low, high = 0, self.n_frames
        while low < high:
            mid = (low + high) // 2
            if self.offset_s + self.scale * float(self.file.time_s(mid, mid + 1)[0]) <= t:
                low = mid + 1
            else:
                high = mid
        self.cursor = low - 2 if low >= 1 else -1  # the frame at t is shown again

    def close(self) -> None:
        self.file.close()


class RobotRecordingFeed:
    """A robot recording played back: play, pause, seek [s] and speed from the page.

    The hand stands at ``joint_positions`` [rad or m] (default the manifest's ``joints``
    where it holds them, else those of the streams' scenario (a simulated grasp's), else
    every joint at 0), or moves as ``joint_states`` (a
    :class:`~tactsense.estimate.robot.JointStates`, on the recording's clock) says.

    The interface of :class:`~tactsense.view.feed.Feed` the server uses: ``start``,
    ``stop``, ``layout``, ``command``, ``health``, ``frames_in``.
    """

    kind = "robot recording"

    def __init__(
        self,
        path: str | Path,
        *,
        joint_positions: Mapping[str, float] | None = None,
        joint_states=None,
        speed: float = 1.0,
        baseline_frames: int = 5,
        threshold: float | None = None,
        display_hz: float = DISPLAY_HZ,
    ):
        self.path = Path(path)
        manifest = read_manifest(self.path)
        self.skin = read_robot_skin(self.path)
        self.name = str(self.path)
        devices = manifest.get("devices", {})
        clock_of = {
            patch: info.get("clock") for info in devices.values() for patch in info["patches"]
        }
        self.streams: dict[str, _PatchStream] = {}
        try:
            for name in manifest.get("streams", []):
                self.skin.patch(name)
                if stream_path(self.path, name).exists():
                    self.streams[name] = _PatchStream(
                        stream_path(self.path, name), clock_of.get(name)
                    )
            baselines = {}
            for name, stream in self.streams.items():
                first = stream.file.frames(0, baseline_frames)
                if len(first):
                    baselines[name] = np.median(np.asarray(first, dtype=float), axis=0)
            self.period_s = 1.0 / float(display_hz)
            firsts = [s.time_of(0) for s in self.streams.values() if s.n_frames]
            self.joint_states = joint_states
            if joint_states is not None:
                joint_states.check(self.skin)
                joint_positions = self._joints_at(min(firsts) if firsts else 0.0)
            if joint_positions is None:
                joint_positions = manifest.get("joints") or self._scenario_joints()
            self.state = hand_state(
                self.skin,
                joint_positions,
                baseline_frames=baseline_frames,
                threshold=threshold,
                frame_period_s=self.period_s,
                baselines=baselines,
            )
        except BaseException:
            self.close_streams()
            raise
        firsts = [s.time_of(0) for s in self.streams.values() if s.n_frames]
        lasts = [s.time_of(s.n_frames - 1) for s in self.streams.values() if s.n_frames]
        self.start_s = min(firsts) if firsts else 0.0
        self.end_s = max(lasts) if lasts else 0.0
        self.n_frames = sum(s.n_frames for s in self.streams.values())
        self.time_s = self.start_s
        self.speed = float(speed)
        self.playing = True
        self.frames_in = 0
        self.status = "starting"
        self.error: str | None = None
        self._publish = lambda text: None
        self._lock = threading.Lock()
        self._wake = threading.Event()
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None
        self._jumped = False
        self._latest: dict | None = None

    def _scenario_joints(self) -> dict | None:
        """The joint state a simulation put in its streams' scenario (a simulated grasp's
        ``joints``), if one did."""
        for stream in self.streams.values():
            try:
                scenario = json.loads(str(stream.file.attrs.get("scenario_json", "{}")))
            except ValueError:
                continue
            joints = scenario.get("joints") if isinstance(scenario, dict) else None
            if isinstance(joints, dict) and joints:
                return joints
        return None

    def _joints_at(self, t: float) -> dict[str, float]:
        """The joint state at ``t`` [s] on the recording's clock, interpolated."""
        names = self.skin.movable_joints
        return dict(zip(names, map(float, self.joint_states.at([t], names)[0]), strict=True))

    # ---- what pages receive ---------------------------------------------------------
    def _playback(self) -> dict:
        return {
            "time_s": round(self.time_s - self.start_s, 6),
            "duration_s": round(self.end_s - self.start_s, 6),
            "playing": self.playing,
            "speed": self.speed,
        }

    def layout(self) -> dict:
        message = scene_layout(self.skin, self.state.joints)
        message["signal_floor"] = self.state.signal_floor
        message["estimator"] = self.state.estimator
        message["source"] = {"kind": self.kind, "name": self.name, "streams": sorted(self.streams)}
        with self._lock:
            message["playback"] = self._playback()
            message["latest"] = self._latest
        message["status"] = {"type": "status", "status": self.status, "error": self.error}
        return message

    def health(self) -> dict:
        return {
            "frames_in": self.frames_in,
            "status": self.status,
            "error": self.error,
            "patch_frames": dict(self.state.frames_seen),
            "joints": dict(self.state.joints),
            "playback": self._playback(),
        }

    def _set_status(self, status: str, error: str | None = None) -> None:
        self.status, self.error = status, error
        self._publish(json.dumps({"type": "status", "status": status, "error": error}))

    def command(self, message: dict) -> None:
        """``{"command": "play"|"pause"|"seek"|"speed", "value": ...}`` (seek: seconds from
        the start)."""
        command, value = message.get("command"), message.get("value")
        number = isinstance(value, int | float) and math.isfinite(value)
        with self._lock:
            if command == "play":
                if self.time_s >= self.end_s:
                    self._seek(self.start_s)
                self.playing = True
            elif command == "pause":
                self.playing = False
            elif command == "seek" and number:
                self._seek(min(max(self.start_s + float(value), self.start_s), self.end_s))
            elif command == "speed" and number and 0 < value <= 1000:
                self.speed = float(value)
            else:
                return
            playback = self._playback()
        self._publish(json.dumps({"type": "playback", **playback}))
        self._wake.set()

    def _seek(self, t: float) -> None:
        self.time_s = t
        for stream in self.streams.values():
            stream.seek(t)
        self._jumped = True

    # ---- the thread -----------------------------------------------------------------
    def start(self, publish) -> None:
        self._publish = publish
        self._thread = threading.Thread(target=self._guarded, name="tactsense-hand", daemon=True)
        self._thread.start()

    def stop(self, wait_s: float = 2.0) -> None:
        self._stop.set()
        self._wake.set()
        if self._thread is not None:
            self._thread.join(wait_s)
        self.close_streams()

    def close_streams(self) -> None:
        for stream in getattr(self, "streams", {}).values():
            stream.close()

    def _guarded(self) -> None:
        try:
            self._run()
        except Exception as error:  # shown on the page and by /api/health, not lost
            self._set_status("error", f"{type(error).__name__}: {error}")

    def _tick(self) -> None:
        with self._lock:
            if self._jumped:
                self.state.reset()
                self._jumped = False
            t = self.time_s
            if self.joint_states is not None:
                self.state.set_joints(self._joints_at(t))
            frames = {}
            for name, stream in self.streams.items():
                index = stream.advance_to(t)
                if index is None:
                    continue
                counts, device_t = stream.frame(index)
                frames[name] = StreamFrame(
                    index % 65536, index, device_t, time.time(), time.perf_counter(), counts
                )
            self.state.update_all(frames)
            self.frames_in += 1
            message = self.state.message(self.frames_in, t - self.start_s)
            message["playback"] = self._playback()
            self._latest = message
        self._publish(json.dumps(message, allow_nan=False))

    def _run(self) -> None:
        self._set_status("playing")
        last = time.perf_counter()
        shown_at = None
        while not self._stop.is_set():
            now = time.perf_counter()
            with self._lock:
                if self.playing:
                    self.time_s = min(self.time_s + (now - last) * self.speed, self.end_s)
                playing, t = self.playing, self.time_s
                ended = playing and t >= self.end_s
                if ended:
                    self.playing = False
            last = now
            if t != shown_at or self._jumped:
                self._tick()
                shown_at = t
            if ended:
                self._publish(json.dumps({"type": "playback", **self._playback()}))
                self._set_status("ended")
            elif not playing and self.status != "paused" and self.status != "ended":
                self._set_status("paused")
            elif playing and self.status != "playing":
                self._set_status("playing")
            self._wake.wait(self.period_s)
            self._wake.clear()
