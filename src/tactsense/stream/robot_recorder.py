"""Record several devices of one skin into a robot recording as the frames arrive."""

from __future__ import annotations

import time
from collections.abc import Callable
from pathlib import Path

from tactsense.io.robot_recording import RobotRecordingWriter
from tactsense.stream.reader import LOSS_KINDS, LossCounters
from tactsense.stream.robot import RobotSources
from tactsense.stream.robot_layout import RobotSourceError


class PatchLosses:
    """A patch's own loss counters, from its device's.

    A patch read at every scan shares its device's counters. One read every ``k``-th scan
    counts as lost the scans it was due at (``scan % k == 0``) from its first frame to the
    device's last frame sent (the last received, plus the tail END reported lost) that did
    not arrive, and as gaps the breaks among them; the line's damage counters (bad check,
    truncated, garbage, timeouts, duplicates) are its device's.
    """

    def __init__(self, device: LossCounters, every: int):
        self.device = device
        self.every = int(every)
        self.kept = 0
        self.first: int | None = None
        self.last: int | None = None
        self.breaks = 0
        self.device_last = -1  # the device's last scan received

    def seen(self, scan: int) -> None:
        """A device frame (scan number ``scan``) arrived."""
        self.device_last = max(self.device_last, scan)

    def keep(self, scan: int) -> None:
        """The patch's frame at ``scan`` was kept."""
        if self.first is None:
            self.first = scan
        elif scan - self.last > self.every:
            self.breaks += 1
        self.last = scan
        self.kept += 1

    def as_dict(self) -> dict:
        counts = self.device.as_dict()
        if self.every == 1:
            return counts
        k = self.every
        if self.first is None:
            counts.update(frames=0, lost=0, gaps=0)
            return counts
        gap_lost = self.device_last - (self.device.frames - 1)  # within the device's run
        tail = max(self.device.lost - max(gap_lost, 0), 0)
        last_sent = self.device_last + tail
        due = last_sent // k - self.first // k + 1
        lost = max(due - self.kept, 0)
        tail_due = last_sent // k - self.last // k
        counts.update(frames=self.kept, lost=lost, gaps=self.breaks + (tail_due > 0))
        return counts


def record_robot(
    sources: RobotSources,
    out: str | Path,
    *,
    duration_s: float | None = None,
    overwrite: bool = False,
    description: str = "",
    flush_interval_s: float = 1.0,
    progress: Callable[[RobotSources, int], None] | None = None,
    progress_interval_s: float = 0.5,
) -> Path:
    """Write every frame of ``sources`` to a new robot recording until ``duration_s``
    [s], every device has ended or dropped out, or Ctrl-C.

    Each patch's stream is crash-safe (flushed every ``flush_interval_s``); the manifest
    is written at the start (``closed_cleanly: false``), again when a device's state
    changes, and at the end with each device's clock fit and status. On Ctrl-C (or any
    error) the devices are stopped, the frames already received are written, and every
    file is closed cleanly before the exception goes on; a run that ends before any frame
    arrived leaves nothing.

    ``progress(sources, frames_written)`` is called about every ``progress_interval_s``.
    """
    out = Path(out)
    sources.open()
    trackers: dict[str, PatchLosses] = {}
    for device, layout in sources.layouts.items():
        losses = sources.status[device].losses
        for name, every in zip(layout.patches, layout.every, strict=True):
            trackers[name] = PatchLosses(losses, every)
    try:
        writer = RobotRecordingWriter(
            out,
            sources.skin,
            sources.devices_manifest(),
            description=description or _describe(sources),
            losses={name: tracker.as_dict for name, tracker in trackers.items()},
            loss_kinds=LOSS_KINDS,
            overwrite=overwrite,
            flush_interval_s=flush_interval_s,
        )
    except BaseException:
        sources.close()
        raise
    states = _states(sources)
    last_report = time.perf_counter()

    def write(frames) -> None:
        nonlocal states, last_report
        for frame in frames:
            by_device = sources.layouts[frame.device].patches
            for name in by_device:
                trackers[name].seen(frame.scan)
            device_s = frame.device_time_us * 1e-6 if frame.device_time_us >= 0 else -1.0
            for name, counts in frame.patches.items():
                trackers[name].keep(frame.scan)
                writer.append(
                    name, counts, device_s, frame.sequence, frame.host_time_s,
                    device_time_us=frame.device_time_us,
                )  # fmt: skip
            now = time.perf_counter()
            if now - last_report >= progress_interval_s:
                last_report = now
                if progress is not None:
                    progress(sources, len(writer))
                if _states(sources) != states:
                    states = _states(sources)
                    writer.devices = sources.devices_manifest()
                    writer.write_manifest(closed_cleanly=False)

    try:
        write(sources.frames(duration_s=duration_s))
    except BaseException:
        sources.stop()
        try:
            write(sources.frames())  # what the devices sent before they stopped
        finally:
            _finish(sources, writer, progress)
        raise
    if not _finish(sources, writer, progress):
        raise RobotSourceError("no device sent a frame; nothing written:\n" + sources.status_line())
    return out


def _finish(sources: RobotSources, writer: RobotRecordingWriter, progress) -> bool:
    """Close the sources and the recording; False (and nothing left) when it is empty."""
    sources.close()
    if len(writer) == 0:
        writer.discard()
        return False
    writer.close(sources.devices_manifest())
    if progress is not None:
        progress(sources, len(writer))
    return True


def _states(sources: RobotSources) -> tuple[str, ...]:
    return tuple(status.state for status in sources.status.values())


def _describe(sources: RobotSources) -> str:
    return "recorded from " + ", ".join(f"{d}={url}" for d, url in sources.sources.items())
