"""Record a stream to a crash-safe HDF5 recording as the frames arrive."""

from __future__ import annotations

import time
from collections.abc import Callable
from pathlib import Path

from tactsense.io.recording import RecordingWriter
from tactsense.physics.transduction import sample_offsets
from tactsense.stream.reader import LOSS_KINDS, LossCounters, StreamReader


def record(
    reader: StreamReader,
    out: str | Path,
    *,
    max_frames: int | None = None,
    duration_s: float | None = None,
    overwrite: bool = False,
    flush_interval_s: float = 1.0,
    progress: Callable[[int, LossCounters, float], None] | None = None,
    progress_interval_s: float = 0.5,
) -> Path:
    """Append the frames of ``reader`` to a new recording until a limit, END or Ctrl-C.

    The file is flushed at least every ``flush_interval_s``: a recorder killed at any
    moment leaves every frame up to the last flush readable. At the end (a limit, END,
    Ctrl-C, SIGTERM or an error) the recorder sends STOP, waits up to
    :data:`STOP_WAIT_S` for END, and closes the file cleanly with the loss counters;
    an exception is then re-raised. A run that ends in an exception before any frame
    was kept leaves no file.

    Parameters
    ----------
    reader : StreamReader
    out : path
        New recording (format version 2).
    max_frames : int, optional
    duration_s : float, optional
        Stop after this long [s]; without a limit, record until END or Ctrl-C.
    progress : callable(frames, counters, rate_hz), optional
        Called about every ``progress_interval_s``.

    Returns
    -------
    Path
        ``out``.
    """
    sensor = reader.sensor
    out = Path(out)
    writer = RecordingWriter(
        out,
        sensor,
        sample_offsets(sensor),
        source=str(reader.url),
        loss_kinds=LOSS_KINDS,
        losses=lambda: reader.stats.as_dict(),
        overwrite=overwrite,
        flush_interval_s=flush_interval_s,
    )
    start = last_report = time.perf_counter()
    reported = 0
    try:
        for frame in reader.frames(max_frames=max_frames, duration_s=duration_s):
            writer.append(
                frame.counts,
                frame.device_time_s,
                frame.sequence,
                frame.host_time_s,
                device_time_us=frame.device_time_us,
            )
            now = time.perf_counter()
            if progress is not None and now - last_report >= progress_interval_s:
                rate = (len(writer) - reported) / (now - last_report)
                progress(len(writer), reader.stats, rate)
                last_report, reported = now, len(writer)
    except BaseException:
        _finish(reader, writer, progress, start)
        if len(writer) == 0:
            out.unlink(missing_ok=True)  # a failed or interrupted start leaves no empty file
        raise
    _finish(reader, writer, progress, start)
    return out


def _finish(reader, writer, progress, start: float) -> None:
    """Send STOP and wait briefly for END (its count settles the last frames' losses),
    then close the file with the final counters."""
    try:
        if hasattr(reader, "stop"):
            reader.stop(wait_s=STOP_WAIT_S)
    finally:
        writer.close()
        if progress is not None:
            elapsed = max(time.perf_counter() - start, 1e-9)
            progress(len(writer), reader.stats, len(writer) / elapsed)


STOP_WAIT_S = 0.5
"""How long the recorder waits for the device's END after sending STOP [s]."""
