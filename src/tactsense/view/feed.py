"""What the browser view shows, frame by frame: the layout once, then one message a frame.

A *feed* runs in a thread of its own. It reads frames (from a live stream or from a
recording), estimates the contact of each, and hands every frame's message (JSON
text) to a ``publish`` callable. The server (:mod:`tactsense.view.server`) passes the
messages on to the pages. Nothing here knows about HTTP. The layout message is
:mod:`tactsense.view.layout`'s; what runs on each frame, :mod:`tactsense.view.locators`'.
"""

from __future__ import annotations

import json
import math
import threading
import time
from collections import deque
from collections.abc import Callable
from pathlib import Path

import numpy as np

from tactsense.io.recording import RecordingReader
from tactsense.sensor import SensorSpec
from tactsense.stream.live import LiveLocator
from tactsense.stream.reader import LOSS_KINDS, StreamError, StreamFrame, StreamReader
from tactsense.view.layout import (  # noqa: F401 - re-exported: their home was here
    COLORMAP,
    MAX_FINE,
    SURFACE_STEPS,
    flat_steps,
    layout_message,
    not_estimated_note,
    project_points,
)
from tactsense.view.locators import (  # noqa: F401 - re-exported: their home was here
    DEFLECTION,
    DeflectionOnly,
    estimates,
    multi_contact,
    view_locator,
)
from tactsense.view.vectors import decorate_frame, is_vector

HISTORY_S = 20.0
"""Seconds of recent frames a page receives when it connects (for its time traces)."""

MAX_HISTORY = 2000
"""At most this many recent frames are kept for new pages, whatever the frame rate."""

Publish = Callable[[str], None]


def _finite(value):
    """JSON has no NaN: None stands for a value that does not exist (in lists and dicts
    too, e.g. the contacts of a pad's frame)."""
    if isinstance(value, float) and not math.isfinite(value):
        return None
    if isinstance(value, list):
        return [_finite(v) for v in value]
    if isinstance(value, dict):
        return {k: _finite(v) for k, v in value.items()}
    return value


class _Rate:
    """Frames per second over the last second of arrivals."""

    def __init__(self) -> None:
        self._times: deque[float] = deque(maxlen=4096)

    def __call__(self, now: float) -> float:
        self._times.append(now)
        while self._times and now - self._times[0] > 1.0:
            self._times.popleft()
        if len(self._times) < 2:
            return 0.0
        span = self._times[-1] - self._times[0]
        return (len(self._times) - 1) / span if span > 0 else 0.0


class Feed:
    """Base of the two feeds: frame messages, a thread, a bounded history for new pages."""

    kind = "feed"

    def __init__(self, sensor: SensorSpec, locator: LiveLocator, name: str):
        self.sensor = sensor
        self.locator = locator
        self.name = name
        self.frames_in = 0
        self.status = "starting"
        self.error: str | None = None
        self._publish: Publish = lambda text: None
        self._history: deque[tuple[float, str]] = deque(maxlen=MAX_HISTORY)
        self._history_s = HISTORY_S
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None
        self._rate = _Rate()
        self._lock = threading.Lock()
        self._plane = None
        if multi_contact(sensor):  # contacts drawn on the plane
            plane = project_points(sensor.taxel_positions_mm(), sensor.taxel_normals())
            self._plane = (plane["e_u"], plane["e_v"])

    # ---- what pages receive --------------------------------------------------------

    def source_info(self) -> dict:
        return {
            "kind": self.kind,
            "name": self.name,
            "calibrated": self.locator.calibration is not None,
        }

    def layout(self) -> dict:
        message = layout_message(self.sensor, self.source_info())
        with self._lock:
            message["history"] = [json.loads(text) for _, text in self._history]
        message["status"] = self.status_message()
        return message

    def status_message(self) -> dict:
        return {"type": "status", "status": self.status, "error": self.error}

    def frame_message(self, frame: StreamFrame, estimate: dict | None, health: dict) -> dict:
        deflection = self.locator.last_deflection
        message = {
            "type": "frame",
            "serial": self.frames_in,
            "index": int(frame.index),
            "sequence": int(frame.sequence),
            "time_s": float(frame.device_time_s),
            "host_time_s": float(frame.host_time_s),
            "counts": np.asarray(frame.counts).astype(int).tolist(),
            "deflection": None if deflection is None else np.round(deflection, 6).tolist(),
            "estimate": None
            if estimate is None
            else {k: _finite(v) for k, v in estimate.items() if k != "sequence"},
            "health": health,
        }
        if self._plane is not None and message["estimate"] is not None:
            e_u, e_v = self._plane
            for contact in message["estimate"].get("contacts", []):
                xyz = [contact.get(k) for k in ("x_mm", "y_mm", "z_mm")]
                if xyz[0] is None or xyz[1] is None:
                    contact["u_mm"] = contact["v_mm"] = None
                    continue
                p = np.array([v if v is not None else 0.0 for v in xyz], dtype=float)
                contact["u_mm"] = round(float(p @ e_u), 4)
                contact["v_mm"] = round(float(p @ e_v), 4)
        if is_vector(self.sensor):  # r8-triview: the taxels' arrows, contacts' shear, slip
            decorate_frame(message, self.locator, self.sensor)
        return message

    def _emit(self, message: dict, *, keep: bool = True) -> None:
        text = json.dumps(message, allow_nan=False)
        if keep:
            t = message["time_s"]
            with self._lock:
                if self._history and t < self._history[-1][0]:
                    self._history.clear()  # a seek back: the traces start over
                self._history.append((t, text))
                while self._history and self._history[0][0] < t - self._history_s:
                    self._history.popleft()
        self._publish(text)

    def _set_status(self, status: str, error: str | None = None) -> None:
        self.status, self.error = status, error
        self._publish(json.dumps(self.status_message()))

    # ---- the thread ----------------------------------------------------------------

    def start(self, publish: Publish) -> None:
        """Run the feed in a thread; every message goes to ``publish`` (thread-safe)."""
        self._publish = publish
        self._thread = threading.Thread(target=self._guarded, name=f"tactsense-{self.kind}")
        self._thread.daemon = True
        self._thread.start()

    def stop(self, wait_s: float = 2.0) -> None:
        self._stop.set()
        if self._thread is not None:
            self._thread.join(wait_s)

    def _guarded(self) -> None:
        try:
            self._run()
        except StreamError as error:
            self._set_status("error", str(error))
        except Exception as error:  # shown on the page and by /api/health, not lost
            self._set_status("error", f"{type(error).__name__}: {error}")

    def _run(self) -> None:
        raise NotImplementedError

    def command(self, message: dict) -> None:
        """A control message from a page: ``{"command": "rezero"}`` takes the baseline
        anew from the next frames (the sensor must be untouched); a recording also
        takes playback commands."""
        if message.get("command") == "rezero":
            self.rezero()

    def rezero(self) -> None:
        """Take the baseline anew from the next frames, where the locator can."""
        rezero = getattr(self.locator, "rezero", None)
        if rezero is not None:
            with self._lock:
                rezero()

    def health(self) -> dict:
        return {"frames_in": self.frames_in, "status": self.status, "error": self.error}


class LiveFeed(Feed):
    """Frames of a device as they arrive (:class:`~tactsense.stream.StreamReader`)."""

    kind = "live"

    def __init__(self, reader: StreamReader, locator: LiveLocator):
        super().__init__(reader.sensor, locator, str(reader.url))
        self.reader = reader
        self._last_latency = float("nan")

    def source_info(self) -> dict:
        info = super().source_info()
        info["rate_hz"] = 1.0 / self.reader.frame_period_s if self.reader.frame_period_s else 0
        info["identity"] = {k: v for k, v in self.reader.identity.items() if k != "sensor_toml"}
        return info

    def _health(self, rate: float, latency: float) -> dict:
        stats = self.reader.stats
        health = {"rate_hz": round(rate, 3), "received": stats.frames}
        health.update({kind: getattr(stats, kind) for kind in LOSS_KINDS})
        health["latency_ms"] = _finite(round(latency, 4))
        return health

    def _run(self) -> None:
        reader = self.reader
        reader.start()
        self._set_status("streaming")
        last = time.perf_counter()
        while not self._stop.is_set():
            batch = reader.read_batch(256, wait_s=0.1)
            now = time.perf_counter()
            if not batch:
                if reader.ended:
                    self._set_status("ended", reader.stats.summary())
                    return
                if now - last > reader.timeout_s:
                    reader.stats.timeouts += 1  # as StreamReader.frames counts them
                    last = now
                continue
            last = now
            for frame in batch:
                self.frames_in += 1
                rate = self._rate(frame.arrival)
                estimate = self.locator(frame)
                latency = estimate["latency_ms"] if estimate else float("nan")
                self._emit(self.frame_message(frame, estimate, self._health(rate, latency)))

    def stop(self, wait_s: float = 2.0) -> None:
        super().stop(wait_s)
        self.reader.close()

    def health(self) -> dict:
        health = super().health()
        health["stream"] = self.reader.stats.as_dict()
        return health


class RecordingFeed(Feed):
    """Frames of a recording played back: play, pause, step, seek and speed from the page.

    The playback state is shared by every page (one recording, one position). Frames
    are read from the file a block at a time, so memory does not grow with its length.
    With a creep calibration the compensation restarts at every seek or backward step
    (its state is the recent past, which a jump skips).
    """

    kind = "recording"
    BLOCK = 1024

    def __init__(self, path: str | Path, locator_factory, *, speed: float = 1.0):
        self.file = RecordingReader(path)
        sensor = self.file.sensor
        super().__init__(sensor, locator_factory(sensor, self.file), str(path))
        self.n_frames = self.file.n_frames
        self.losses = self.file.losses
        self.speed = float(speed)
        self.position = 0
        self.playing = True
        self._block_start = -1
        self._block: np.ndarray | None = None
        self._times: np.ndarray | None = None
        self._wake = threading.Event()
        self._jumped = False
        self._pending_show = True  # show the frame at the position now (start, seek, step)
        self._finished = False  # played to the last frame (status "ended")
        times = self.file.time_s(0, min(self.n_frames, 2))
        self.period_s = float(np.diff(times)[0]) if len(times) > 1 else sensor.scan_period_s
        if not self.period_s > 0:
            self.period_s = sensor.scan_period_s

    def source_info(self) -> dict:
        info = super().source_info()
        info.update(n_frames=self.n_frames, rate_hz=1.0 / self.period_s, losses=self.losses)
        return info

    def _frame(self, index: int) -> tuple[np.ndarray, float]:
        if self._block is None or not self._block_start <= index < self._block_start + self.BLOCK:
            self._block_start = (index // self.BLOCK) * self.BLOCK
            stop = self._block_start + self.BLOCK
            self._block = self.file.frames(self._block_start, stop)
            self._times = self.file.time_s(self._block_start, stop)
        offset = index - self._block_start
        return self._block[offset], float(self._times[offset])

    def layout(self) -> dict:
        message = super().layout()
        with self._lock:  # the state now: the history's frames carry the state then
            message["playback"] = self._playback()
        return message

    def _playback(self) -> dict:
        return {
            "position": self.position,
            "n_frames": self.n_frames,
            "playing": self.playing,
            "speed": self.speed,
        }

    def _show(self, index: int, rate: float) -> None:
        counts, t = self._frame(index)
        frame = StreamFrame(
            index % 65536, index, t, time.time(), time.perf_counter(), np.asarray(counts)
        )
        self.frames_in += 1
        estimate = self.locator(frame)
        health = {"rate_hz": round(rate, 3), "received": self.n_frames}
        health.update({kind: int(self.losses.get(kind, 0)) for kind in LOSS_KINDS})
        health["latency_ms"] = _finite(round(estimate["latency_ms"], 4)) if estimate else None
        message = self.frame_message(frame, estimate, health)
        message["playback"] = self._playback()
        self._emit(message)

    def command(self, message: dict) -> None:
        """``{"command": "play"|"pause"|"step"|"seek"|"speed"|"rezero", "value": ...}``."""
        command = message.get("command")
        value = message.get("value")
        if command == "rezero":
            self.rezero()
            return
        with self._lock:
            if command in ("play", "step", "seek"):
                self._finished = False
            if command == "play":
                if self.position >= self.n_frames - 1:
                    self.position, self._jumped = 0, True
                self.playing = True
            elif command == "pause":
                self.playing = False
            elif command == "step":
                step = int(value) if isinstance(value, int | float) else 1
                self.playing = False
                self._jumped = step < 0
                self.position = min(max(self.position + step, 0), self.n_frames - 1)
                self._pending_show = True
            elif command == "seek":
                if not isinstance(value, int | float) or not math.isfinite(value):
                    return
                self.position = min(max(int(value), 0), self.n_frames - 1)
                self._jumped = True
                self._pending_show = True
            elif command == "speed":
                if isinstance(value, int | float) and 0 < value <= 1000:
                    self.speed = float(value)
            else:
                return
            playback = self._playback()
        # every page shows the new state at once, even while paused
        self._publish(json.dumps({"type": "playback", **playback}))
        self._wake.set()

    def _run(self) -> None:
        self._set_status("playing")
        next_due = time.perf_counter()
        while not self._stop.is_set():
            with self._lock:
                show_now = self._pending_show
                self._pending_show = False
                if self._jumped:
                    self.locator.reset()
                    self._jumped = False
                playing, position = self.playing, self.position
            now = time.perf_counter()
            if show_now:
                self._show(position, 0.0 if not playing else self._rate(now))
                next_due = now + self.period_s / self.speed
                if playing and position < self.n_frames - 1:
                    with self._lock:
                        self.position += 1
                continue
            if not playing:
                # played to the last frame: ended, not paused (play starts it over)
                self._status_if("ended" if self._finished else "paused")
                self._wake.wait(0.25)
                self._wake.clear()
                continue
            if now < next_due:
                self._wake.wait(min(next_due - now, 0.25))
                self._wake.clear()
                continue
            self._status_if("playing")
            self._show(position, self._rate(now))
            next_due = max(next_due + self.period_s / self.speed, now - 0.5)
            finished = None
            with self._lock:
                if self.position == position:  # not moved by a command meanwhile
                    if position >= self.n_frames - 1:
                        self.playing = False
                        self._finished = True
                        finished = self._playback()
                    else:
                        self.position = position + 1
            if finished is not None:  # every page's play button says "play" now
                self._publish(json.dumps({"type": "playback", **finished}))

    def _status_if(self, status: str) -> None:
        if self.status != status:
            self._set_status(status)

    def stop(self, wait_s: float = 2.0) -> None:
        super().stop(wait_s)
        self._wake.set()
        self.file.close()

    def health(self) -> dict:
        health = super().health()
        health["playback"] = self._playback()
        return health


def __getattr__(name: str):
    """``LOCATORS`` and ``PLURAL``: :mod:`tactsense.view.locators` reads them from the
    registered kinds."""
    if name in ("LOCATORS", "PLURAL"):
        from tactsense.view import locators

        return getattr(locators, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
