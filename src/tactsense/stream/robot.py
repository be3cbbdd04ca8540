"""Frames of a robot's skin from several devices at once, each device's clock aligned to
the host's (``docs/robot.md``, "Capture from several devices").

>>> from tactsense.robot import load_skin
>>> from tactsense.stream.robot import RobotSources
>>> skin = load_skin("hand4")
>>> urls = {"board_thumb": "socket://127.0.0.1:5001", ...}          # doctest: +SKIP
>>> with RobotSources(skin, urls) as sources:                      # doctest: +SKIP
...     for frame in sources.frames(duration_s=10):
...         frame.device, frame.patches["thumb_tip"], frame.aligned_time_s
...     print(sources.status_line())

A thread per device reads its line (:func:`tactsense.stream.sources.open_source`, so
every source form works) and puts each frame, split into its patches, on one bounded
queue; the caller takes them in arrival order. A device whose line ends with END has
``ended``; one whose line fails or closes, or that stays silent for ``dropout_s``, has
``dropped`` (when: :attr:`DeviceStatus.dropped_at_s`), and the others go on.
"""

from __future__ import annotations

import math
import queue
import re
import threading
import time
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np

from tactsense._validation import TactsenseInputError
from tactsense.robot import RobotSkin
from tactsense.stream.clock import ClockFit
from tactsense.stream.reader import LossCounters, StreamFrame
from tactsense.stream.robot_layout import DeviceLayout, RobotSourceError, device_layouts
from tactsense.stream.sources import open_source

STATES = ("opening", "streaming", "ended", "dropped", "stopped")
"""A device's states: not yet streaming; streaming; its line ended (END); it dropped out
(its line failed or closed, or it was silent for ``dropout_s``); stopped by the caller."""

_DEVICE_NAME = re.compile(r"[A-Za-z0-9][\w.-]*")
"""What a device's name looks like before ``=`` (a source's options hold a comma)."""

QUEUE_FRAMES = 4096
"""Device frames the queue holds before the device threads wait for the caller."""


@dataclass(frozen=True)
class RobotFrame:
    """One device frame, split into its patches.

    Attributes
    ----------
    device : str
    patches : dict of str -> ndarray (rows, cols)
        The patches read at this scan [counts]: every patch of the device whose rate is
        the device's, the slower ones at every ``k``-th scan only.
    host_time_s : float
        Arrival of the frame's last byte, Unix time [s] (one clock for every device).
    device_time_us : int
        Start of the scan on the device clock, as sent [us] (-1: the source has none).
    aligned_time_s : float
        Start of the scan on the host clock, Unix time [s], by the device's clock fit so
        far (the host arrival where the device sends no time).
    sequence : int
        The device's frame counter (wraps at 65536).
    scan : int
        Frames the device sent before this one since the first received (its scan
        counter, lost frames included; a patch read every ``k``-th scan is in the frames
        whose ``scan % k == 0``) [-].
    arrival : float
        Arrival on :func:`time.perf_counter` [s], for latencies.
    """

    device: str
    patches: dict[str, np.ndarray]
    host_time_s: float
    device_time_us: int
    aligned_time_s: float
    sequence: int
    scan: int
    arrival: float


@dataclass
class DeviceStatus:
    """What one device did so far."""

    device: str
    url: str
    layout: DeviceLayout
    state: str = "opening"
    losses: LossCounters = field(default_factory=LossCounters)
    """The reader's counters (frames delivered and lost, by kind)."""
    clock: ClockFit = field(default_factory=ClockFit)
    """Its clock fit to the host (:func:`time.perf_counter` seconds)."""
    first_host_s: float | None = None
    """Unix time of its first frame [s]."""
    last_host_s: float | None = None
    """Unix time of its last frame [s]."""
    dropped_at_s: float | None = None
    """When it dropped out: Unix time of its last frame (else of the drop) [s]."""
    error: str = ""
    """Why it dropped out."""

    @property
    def frames(self) -> int:
        return self.losses.frames

    @property
    def rate_hz(self) -> float:
        """Frames per second received so far [Hz]."""
        if self.first_host_s is None or self.last_host_s is None or self.frames < 2:
            return 0.0
        return (self.frames - 1) / max(self.last_host_s - self.first_host_s, 1e-9)

    @property
    def skew_s(self) -> float:
        """How far the device clock has run ahead of the host's since its first frame,
        by the fit [s] (drift x time: 50 ppm for a minute is 3 ms); 0 without a fit."""
        if self.clock.count < 2:
            return 0.0
        return self.clock.span_s * (1.0 - self.clock.host_per_device)

    def clock_dict(self, wall_offset_s: float) -> dict:
        """The clock fit for a manifest, its offset on Unix time [s] (empty without
        device times)."""
        fit = self.clock.as_dict()
        if fit:
            fit["offset_s"] += wall_offset_s
        return fit

    def line(self) -> str:
        """One status line: state, rate, losses, clock."""
        text = f"{self.device}: {self.state}, {self.rate_hz:6.1f} frames/s, "
        text += self.losses.summary()
        if self.clock.count >= 2:
            fit = self.clock.as_dict()
            text += (
                f"; clock {fit['drift_ppm']:+.1f} ppm, skew {self.skew_s * 1e3:+.3f} ms, "
                "delay median "
                f"{fit['residual_s'] * 1e3:.2f} ms p99 {fit['residual_p99_s'] * 1e3:.2f} ms"
            )
        if self.error:
            text += f"; {self.error}"
        return text


def parse_device_sources(skin: RobotSkin, sources: Sequence[str]) -> dict[str, str]:
    """``{device: source}`` from ``DEVICE=SOURCE`` items, or from plain sources taken in
    the skin's device order (not both). A device left out is not read."""
    devices = list(skin.devices)
    named: dict[str, str] = {}
    plain: list[str] = []
    for item in sources:
        name, equals, rest = item.partition("=")
        if equals and name in devices:
            if name in named:
                raise RobotSourceError(f"device {name!r} is given two sources")
            named[name] = rest
        elif equals and _DEVICE_NAME.fullmatch(name):
            raise RobotSourceError(
                f"{item}: {name!r} is no device of {skin.name!r}; its devices: "
                + ", ".join(devices)
            )
        else:
            plain.append(item)
    if named and plain:
        raise RobotSourceError(
            f"give every source as DEVICE=SOURCE or none: {plain[0]!r} names no device of "
            f"{skin.name!r} ({', '.join(devices)})"
        )
    if plain:
        if len(plain) > len(devices):
            raise RobotSourceError(
                f"{len(plain)} sources for the {len(devices)} devices of {skin.name!r} "
                f"({', '.join(devices)})"
            )
        named = dict(zip(devices, plain, strict=False))
    if not named:
        raise RobotSourceError(f"no source given for any device of {skin.name!r}")
    return named


class RobotSources:
    """Frames from several devices of one skin, as they arrive.

    Parameters
    ----------
    skin : RobotSkin
    sources : mapping of device -> source, or sequence of str
        Each device's source (any form :func:`~tactsense.stream.sources.open_source`
        takes); a sequence as :func:`parse_device_sources`. Devices left out are not read.
    timeout_s : float, optional
        A device frame later than this after the one before counts as a timeout [s]
        (default 3 scan periods + 0.05 s).
    dropout_s : float
        A device silent this long has dropped out [s] (> 0).
    first_frame_timeout_s : float
        A device with no frame this long after START has dropped out [s] (> 0).
    stop_wait_s : float
        At the end, how long each device is given to answer STOP with END [s].
    queue_frames : int
        Device frames waiting for the caller at most (then the devices wait) [-].
    """

    def __init__(
        self,
        skin: RobotSkin,
        sources: Mapping[str, str] | Sequence[str],
        *,
        timeout_s: float | None = None,
        dropout_s: float = 2.0,
        first_frame_timeout_s: float = 5.0,
        stop_wait_s: float = 0.5,
        queue_frames: int = QUEUE_FRAMES,
    ):
        for name, value in (
            ("dropout_s", dropout_s),
            ("first_frame_timeout_s", first_frame_timeout_s),
        ):
            if not (math.isfinite(value) and 0 < value <= 1e6):
                raise TactsenseInputError(f"{name} must lie in (0, 1e6] s; got {value!r}")
        if timeout_s is not None and not (math.isfinite(timeout_s) and 0 < timeout_s <= 3600):
            raise TactsenseInputError(f"timeout_s must lie in (0, 3600] s; got {timeout_s!r}")
        self.skin = skin
        self._positional = not isinstance(sources, Mapping) and not any(
            "=" in str(s) and str(s).partition("=")[0] in skin.devices for s in sources
        )  # r7-fixc: plain sources, in the skin's device order: checked by IDENT on open
        if not isinstance(sources, Mapping):
            sources = parse_device_sources(skin, list(sources))
        layouts = device_layouts(skin)
        for device in sources:
            if device not in layouts:
                raise RobotSourceError(
                    f"{skin.name!r} has no device {device!r}; its devices: {', '.join(layouts)}"
                )
        self.sources = dict(sources)
        self.layouts = {d: layouts[d] for d in layouts if d in self.sources}
        self.timeout_s = timeout_s
        self.dropout_s = float(dropout_s)
        self.first_frame_timeout_s = float(first_frame_timeout_s)
        self.stop_wait_s = float(stop_wait_s)
        self.status = {
            d: DeviceStatus(d, str(self.sources[d]), layout) for d, layout in self.layouts.items()
        }
        self.wall_offset_s = time.time() - time.perf_counter()
        """Unix time minus :func:`time.perf_counter` [s], one for every device."""
        self._queue: queue.Queue = queue.Queue(maxsize=max(int(queue_frames), 1))
        self._stop = threading.Event()
        self._closed = False
        self._threads: dict[str, threading.Thread] = {}
        self._readers: dict = {}
        self._running = 0
        self._opened = False

    # ---- opening and closing ---------------------------------------------------
    def open(self) -> RobotSources:
        """Open every device's line (an error if any cannot be opened: nothing stays
        open) and start a reading thread for each."""
        if self._opened:
            return self
        try:
            for device, layout in self.layouts.items():
                self._readers[device] = open_source(
                    self.sources[device], sensor=layout.spec(), timeout_s=self.timeout_s,
                    start=False,
                )  # fmt: skip
                self.status[device].losses = self._readers[device].stats
        except BaseException:
            for reader in self._readers.values():
                reader.close()
            raise
        if self._positional:  # r7-fixc
            self._positional = False
            remapped = self._by_ident()
            if remapped is not None:
                for reader in self._readers.values():
                    reader.close()
                self._readers = {}
                self.sources = remapped
                layouts = device_layouts(self.skin)
                self.layouts = {d: layouts[d] for d in layouts if d in remapped}
                self.status = {
                    d: DeviceStatus(d, str(remapped[d]), layout)
                    for d, layout in self.layouts.items()
                }
                return self.open()
        self._opened = True
        for device in self.layouts:
            thread = threading.Thread(
                target=self._read_device, args=(device,), name=f"robot-{device}", daemon=True
            )
            self._threads[device] = thread
            self._running += 1
            thread.start()
        return self

    def _by_ident(self) -> dict[str, str] | None:
        """Plain sources checked against each device's IDENT (``robot_device``, what
        ``tactsense emulate --skin`` sends): None when they are in order (or a device does
        not say), else ``{device: source}`` mapped by IDENT; an error when IDENT names a
        board the skin lacks or two sources name one board."""
        named = {}
        for device, reader in self._readers.items():
            if not hasattr(reader, "_identify"):
                return None
            try:
                reader._identify(1.0)
            except Exception:  # a device that does not answer: keep the order given
                return None
            finally:
                self.status[device].losses = reader.stats
            board = reader.identity.get("robot_device")
            if not isinstance(board, str):
                return None
            named[device] = board
        if all(board == device for device, board in named.items()):
            return None
        said = ", ".join(f"{self.sources[d]} is {b}" for d, b in named.items())
        if len(set(named.values())) != len(named) or not set(named.values()) <= set(
            self.skin.devices
        ):
            raise RobotSourceError(
                f"by their IDENT, {said}: not one source per board of {self.skin.name!r} "
                f"({', '.join(self.skin.devices)}); give DEVICE=SOURCE"
            )
        return {board: self.sources[device] for device, board in named.items()}

    def stop(self) -> None:
        """Ask every device to stop (STOP, then END settles its last losses); frames
        already received can still be taken from :meth:`frames`."""
        self._stop.set()

    def close(self) -> None:
        """Stop every device, wait for its thread and close its line (idempotent)."""
        self._stop.set()
        self._closed = True
        for thread in self._threads.values():
            thread.join(timeout=self.stop_wait_s + 5.0)

    def __enter__(self) -> RobotSources:
        return self.open()

    def __exit__(self, *exc) -> None:
        self.close()

    # ---- the device threads ----------------------------------------------------
    def _put(self, item) -> None:
        while True:
            try:
                self._queue.put(item, timeout=0.1)
                return
            except queue.Full:
                if self._closed:
                    return

    def _read_device(self, device: str) -> None:
        status = self.status[device]
        reader = self._readers[device]
        layout = status.layout
        timeout = reader.timeout_s
        try:
            reader.start()
            started = last = last_timeout = time.perf_counter()
            while not self._stop.is_set():
                batch = reader.read_batch(64, wait_s=0.05)
                now = time.perf_counter()
                if batch:
                    status.state = "streaming"
                    for frame in batch:
                        self._put(self._robot_frame(status, layout, frame))
                    last = last_timeout = now
                    continue
                if reader.ended:
                    status.state = "ended"
                    break
                if now - last_timeout >= timeout:
                    reader.stats.timeouts += 1
                    last_timeout = now
                if status.last_host_s is None and now - started >= self.first_frame_timeout_s:
                    self._drop(status, f"no frame within {self.first_frame_timeout_s:g} s of START")
                    break
                if status.last_host_s is not None and now - last >= self.dropout_s:
                    self._drop(status, f"silent for {self.dropout_s:g} s")
                    break
        except TactsenseInputError as error:
            self._drop(status, str(error))
        except Exception as error:  # a thread must always report its end
            self._drop(status, f"{type(error).__name__}: {error}")
        finally:
            if status.state in ("opening", "streaming"):
                status.state = "stopped"
            try:
                if status.state != "dropped" and hasattr(reader, "stop"):
                    reader.stop(wait_s=self.stop_wait_s)
            except Exception:  # the line died while stopping: the counts stand as they are
                pass
            finally:
                try:
                    reader.close()
                except Exception:
                    pass
                self._put((device, None))

    def _drop(self, status: DeviceStatus, why: str) -> None:
        status.state = "dropped"
        status.error = why
        status.dropped_at_s = (
            status.last_host_s
            if status.last_host_s is not None
            else time.perf_counter() + self.wall_offset_s
        )

    def _robot_frame(
        self, status: DeviceStatus, layout: DeviceLayout, frame: StreamFrame
    ) -> RobotFrame:
        host = frame.arrival + self.wall_offset_s
        if frame.device_time_us >= 0:
            status.clock.add(frame.device_time_s, frame.arrival)
            aligned = status.clock.to_host(frame.device_time_s) + self.wall_offset_s
        else:
            aligned = host
        scan = frame.index
        if status.first_host_s is None:
            status.first_host_s = host
        status.last_host_s = host
        return RobotFrame(
            device=status.device,
            patches=layout.unpack(frame.counts, scan),
            host_time_s=host,
            device_time_us=int(frame.device_time_us),
            aligned_time_s=float(aligned),
            sequence=int(frame.sequence),
            scan=int(scan),
            arrival=frame.arrival,
        )

    # ---- the caller's side -----------------------------------------------------
    @property
    def running(self) -> int:
        """Devices whose threads have not finished."""
        return self._running

    def frames(self, *, duration_s: float | None = None) -> Iterator[RobotFrame]:
        """Yield frames from every device as they arrive, until every device has ended,
        dropped out or been stopped (:meth:`stop`, or ``duration_s`` [s] after the first
        call). Frames received before a stop are all yielded."""
        if not self._opened:
            self.open()
        deadline = None if duration_s is None else time.perf_counter() + float(duration_s)
        while self._running:
            if deadline is not None and time.perf_counter() >= deadline:
                self.stop()
            try:
                item = self._queue.get(timeout=0.05)
            except queue.Empty:
                continue
            if isinstance(item, tuple):
                self._running -= 1
                continue
            yield item

    __iter__ = frames

    def get(self, timeout_s: float = 0.1) -> RobotFrame | None:
        """The next frame, waiting up to ``timeout_s`` [s]; None if none came (or every
        device has finished)."""
        deadline = time.perf_counter() + timeout_s
        while self._running:
            try:
                item = self._queue.get(timeout=max(deadline - time.perf_counter(), 0.0))
            except queue.Empty:
                return None
            if isinstance(item, tuple):
                self._running -= 1
                continue
            return item
        return None

    def status_line(self) -> str:
        """Every device's status, one line each."""
        return "\n".join(s.line() for s in self.status.values())

    def devices_manifest(self) -> dict[str, dict]:
        """Each device as a robot recording's manifest holds it: patches, source, clock
        fit (Unix time), status, dropped_at_s, error, losses, and ``unused`` (frames that
        arrived after the stop: neither kept nor lost)."""
        out = {}
        for device, status in self.status.items():
            out[device] = {
                "patches": list(status.layout.patches),
                "source": status.url,
                "clock": status.clock_dict(self.wall_offset_s),
                "status": "dropped" if status.state == "dropped" else "ok",
                "state": status.state,
                "dropped_at_s": status.dropped_at_s,
                "error": status.error,
                "rate_hz": status.layout.rate_hz,
                "losses": status.losses.as_dict(),
                "unused": int(getattr(self._readers.get(device), "unused", 0)),
            }
        return out


__all__ = [
    "STATES",
    "DeviceStatus",
    "RobotFrame",
    "RobotSourceError",
    "RobotSources",
    "parse_device_sources",
]
