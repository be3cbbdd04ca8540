"""The hand's view live: frames from several devices at once
(:class:`~tactsense.stream.robot.RobotSources`), shown at the display rate.

Each device's frames arrive split into patches; the feed keeps the newest frame of every
patch and, at each display tick, runs each patch that has a new one through its
estimator (every one of a patch's first frames while its baseline is being taken, so a
backlog at the start does not put a touch into the baseline), as the recording's
playback does (:mod:`tactsense.view.robot_feed`). The devices' states (streaming,
ended, dropped), rates, losses and clock fits go with every message.
"""

from __future__ import annotations

import json
import threading
import time
from collections.abc import Mapping

import numpy as np

from tactsense._validation import TactsenseInputError
from tactsense.stream.reader import StreamFrame
from tactsense.view.robot_estimator import HandEstimatorState
from tactsense.view.robot_feed import DISPLAY_HZ
from tactsense.view.robot_scene import scene_layout
from tactsense.view.robot_state import HandState


class RobotLiveFeed:
    """A hand's devices as they stream (the feed interface the server uses)."""

    kind = "robot live"

    def __init__(
        self,
        sources,
        *,
        joint_positions: Mapping[str, float] | None = None,
        baseline_frames: int = 5,
        threshold: float | None = None,
        display_hz: float = DISPLAY_HZ,
    ):
        self.sources = sources
        self.skin = sources.skin
        self.name = ", ".join(f"{d}={u}" for d, u in sources.sources.items())
        self.period_s = 1.0 / float(display_hz)
        self._options = {"baseline_frames": baseline_frames, "threshold": threshold,
                         "frame_period_s": self.period_s}  # fmt: skip
        self.state: HandState = HandState(self.skin, joint_positions, **self._options)
        self._may_switch = True  # to the robot estimator, once every patch has a baseline
        self.frames_in = 0
        self.device_frames = 0
        self.status = "starting"
        self.error: str | None = None
        self._publish = lambda text: None
        self._lock = threading.Lock()
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None
        self._latest: dict | None = None
        self._pending: dict[str, tuple[np.ndarray, float, float, int]] = {}

    def devices(self) -> list[dict]:
        """Each device's state, rate [Hz], losses and clock (one line of text)."""
        return [
            {"device": device, "state": status.state, "rate_hz": round(status.rate_hz, 2),
             "line": status.line()}
            for device, status in self.sources.status.items()
        ]  # fmt: skip

    def layout(self) -> dict:
        message = scene_layout(self.skin, self.state.joints)
        message["signal_floor"] = self.state.signal_floor
        message["estimator"] = self.state.estimator
        message["source"] = {"kind": self.kind, "name": self.name}
        with self._lock:
            message["latest"] = self._latest
        message["status"] = {"type": "status", "status": self.status, "error": self.error}
        return message

    def health(self) -> dict:
        return {
            "frames_in": self.frames_in,
            "device_frames": self.device_frames,
            "status": self.status,
            "error": self.error,
            "devices": self.devices(),
        }

    def command(self, message: dict) -> None:
        """``{"command": "rezero"}``: every patch takes its baseline anew (the robot
        estimator's fixed baselines too: each patch's own estimator takes them, then the
        robot estimator takes over again)."""
        if message.get("command") != "rezero":
            return
        with self._lock:
            if isinstance(self.state, HandEstimatorState):
                fresh = HandState(self.skin, self.state.joints, **self._options)
                fresh.frames_seen = dict(self.state.frames_seen)
                self.state, self._may_switch = fresh, True
                return
            for locator in self.state.locators.values():
                rezero = getattr(locator, "rezero", None)
                if rezero is not None:
                    rezero()

    def _switch(self) -> None:
        """Hand the patches to the robot estimator once each has its baseline (where it
        takes the skin): one compiled call a tick instead of one estimate a patch."""
        locators = self.state.locators
        if not all(getattr(locator, "ready", False) for locator in locators.values()):
            return
        self._may_switch = False
        baselines = {name: getattr(locator, "baseline", None) for name, locator in locators.items()}
        if any(baseline is None for baseline in baselines.values()):
            return
        try:
            hand = HandEstimatorState(self.skin, self.state.joints, baselines=baselines,
                                      threshold=self._options["threshold"])  # fmt: skip
        except TactsenseInputError:  # a kind the robot estimator does not place
            return
        # what each patch shows stays until its next frame
        hand.frames_seen = dict(self.state.frames_seen)
        hand.signals = dict(self.state.signals)
        hand.contacts = dict(self.state.contacts)
        hand.frame_times = dict(self.state.frame_times)
        self.state = hand

    def _set_status(self, status: str, error: str | None = None) -> None:
        self.status, self.error = status, error
        self._publish(json.dumps({"type": "status", "status": status, "error": error}))

    def start(self, publish) -> None:
        self._publish = publish
        self._thread = threading.Thread(target=self._guarded, name="tactsense-hand", daemon=True)
        self._thread.start()

    def stop(self, wait_s: float = 2.0) -> None:
        self._stop.set()
        self.sources.stop()
        if self._thread is not None:
            self._thread.join(wait_s)
        self.sources.close()

    def _guarded(self) -> None:
        try:
            self._run()
        except Exception as error:  # shown on the page and by /api/health, not lost
            self._set_status("error", f"{type(error).__name__}: {error}")

    def _take(self, patch: str, item: tuple) -> None:
        counts, aligned_s, device_s, sequence = item
        frame = StreamFrame(sequence, sequence, device_s, aligned_s, time.perf_counter(), counts)
        with self._lock:
            self.state.update(patch, frame)

    def _tick(self) -> None:
        pending, self._pending = self._pending, {}
        now = time.perf_counter()
        frames = {
            patch: StreamFrame(sequence, sequence, device_s, aligned_s, now, counts)
            for patch, (counts, aligned_s, device_s, sequence) in pending.items()
        }
        with self._lock:
            self.state.update_all(frames)
            if self._may_switch and not isinstance(self.state, HandEstimatorState):
                self._switch()
            self.frames_in += 1
            message = self.state.message(self.frames_in, time.time())
            message["devices"] = self.devices()
            self._latest = message
        self._publish(json.dumps(message, allow_nan=False))

    def _run(self) -> None:
        self.sources.open()
        self._set_status("streaming")
        next_tick = time.perf_counter()
        while not self._stop.is_set():
            frame = self.sources.get(timeout_s=max(0.0, min(next_tick - time.perf_counter(), 0.05)))
            if frame is not None:
                self.device_frames += 1
                device_s = (
                    frame.device_time_us * 1e-6 if frame.device_time_us >= 0 else frame.host_time_s
                )
                for patch, counts in frame.patches.items():
                    item = (np.asarray(counts), frame.aligned_time_s, device_s, frame.sequence)
                    locators = getattr(self.state, "locators", {})
                    if getattr(locators.get(patch), "ready", True):
                        self._pending[patch] = item
                    else:  # the baseline: every one of a patch's first frames, not the newest
                        self._take(patch, item)
            now = time.perf_counter()
            if now >= next_tick:
                self._tick()
                next_tick = max(next_tick + self.period_s, now)
            if frame is None and not self.sources.running:
                self._tick()
                self._set_status("ended", self.sources.status_line())
                return
