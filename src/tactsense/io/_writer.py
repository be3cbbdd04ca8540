"""A recording written frame by frame as a stream arrives (:class:`RecordingWriter`):
HDF5's single-writer/multiple-reader mode, flushed at least once a second, so a recorder
killed mid-way leaves a readable file. Re-exported by :mod:`tactsense.io.recording`."""

from __future__ import annotations

import datetime as _dt
import json
import time
from pathlib import Path

import h5py
import numpy as np

from tactsense._version import __version__
from tactsense.io._layout import FORMAT, FORMAT_VERSION, RecordingError, _checked_dataset
from tactsense.kinds import kind_of
from tactsense.sensor import SensorSpec


class RecordingWriter:
    """Append frames to a new recording as they arrive; crash-safe.

    The file is created at once at its final name, in HDF5's single-writer /
    multiple-reader mode, with resizable chunked datasets; :meth:`append` buffers and
    :meth:`flush` (called at least every ``flush_interval_s``) writes and flushes, so a
    writer killed at any moment leaves a file holding every frame up to its last flush,
    which :func:`read_recording` and ``tactsense info`` read. :meth:`close` ends it
    cleanly. Use it as a context manager.

    Parameters
    ----------
    path : path
        The new recording; an existing file is refused unless ``overwrite``.
    sensor : SensorSpec
    sample_offset_s : array_like, shape (rows, cols)
        When within a frame each tactel is sampled [s].
    source : str
        Where the frames come from (a stream's URL).
    loss_kinds : sequence of str
        Names of the loss counters kept with the recording.
    losses : callable() -> dict, optional
        Returns the current loss counters (by kind); read at every flush.
    flush_interval_s : float
        Longest time between flushes [s].
    """

    def __init__(
        self,
        path: str | Path,
        sensor: SensorSpec,
        sample_offset_s,
        *,
        source: str = "",
        loss_kinds=(),
        losses=None,
        overwrite: bool = False,
        flush_interval_s: float = 1.0,
        chunk_frames: int = 1024,
    ):
        path = Path(path)
        if path.exists() and not overwrite:
            raise FileExistsError(f"{path} exists; pass --force to replace it")
        if np.shape(sample_offset_s) != sensor.shape:
            raise RecordingError(
                f"sample_offset_s has shape {np.shape(sample_offset_s)}; expected {sensor.shape}"
            )
        if not path.parent.is_dir():
            raise RecordingError(f"folder {path.parent} does not exist")
        self.path = path
        self.sensor = sensor
        self._interval = float(flush_interval_s)
        self._last_flush = time.monotonic()
        self._loss_source = losses
        self._buffer: list[tuple] = []
        self._count = 0
        h5 = h5py.File(path, "w", libver="latest")
        try:
            h5.attrs["format"] = FORMAT
            h5.attrs["format_version"] = FORMAT_VERSION
            h5.attrs["tactsense_version"] = __version__
            h5.attrs["created"] = _dt.datetime.now(_dt.UTC).isoformat(timespec="seconds")
            h5.attrs["sensor_toml"] = sensor.to_toml_string()
            h5.attrs["scenario_json"] = json.dumps({"description": f"recorded from {source}"})
            h5.attrs["flaws"] = ""
            h5.attrs["scan_rate_hz"] = sensor.electronics.scan_rate_hz
            h5.attrs["source"] = source
            chunk = max(1, int(chunk_frames))
            self._frames = h5.create_dataset(
                "frames",
                (0, *sensor.frame_shape),
                np.uint16,
                maxshape=(None, *sensor.frame_shape),
                chunks=(chunk, *sensor.frame_shape),
                compression="gzip",
                compression_opts=1,
                fletcher32=True,
            )
            self._frames.attrs["units"] = "counts"
            self._frames.attrs["axes"] = kind_of(sensor).frame_axes
            self._time = h5.create_dataset(
                "time", (0,), float, maxshape=(None,), chunks=(chunk,), fletcher32=True
            )
            self._time.attrs["units"] = "s"
            self._sequence = h5.create_dataset(
                "sequence", (0,), np.uint16, maxshape=(None,), chunks=(chunk,), fletcher32=True
            )
            self._host = h5.create_dataset(
                "host_time", (0,), float, maxshape=(None,), chunks=(chunk,), fletcher32=True
            )
            self._host.attrs["units"] = "s"
            self._device_us = h5.create_dataset(
                "device_time_us", (0,), np.int64, maxshape=(None,), chunks=(chunk,),
                fletcher32=True,
            )  # fmt: skip
            self._device_us.attrs["units"] = "us"
            self._device_us.attrs["meaning"] = (
                "start of each frame's scan on the device clock, exactly as sent (-1: not known)"
            )
            offset = _checked_dataset(h5, "sample_offset", np.asarray(sample_offset_s, float))
            offset.attrs["units"] = "s"
            self._kinds = list(loss_kinds)
            self._losses = _checked_dataset(
                h5, "losses", np.zeros(max(len(self._kinds), 1), np.int64)
            )
            self._losses.attrs["kinds"] = ",".join(self._kinds)
            h5.swmr_mode = True
            h5.flush()
        except BaseException:
            h5.close()
            path.unlink(missing_ok=True)
            raise
        self._h5 = h5

    def __len__(self) -> int:
        return self._count + len(self._buffer)

    def append(
        self,
        counts,
        device_time_s: float,
        sequence: int,
        host_time_s: float,
        *,
        device_time_us: int = -1,
    ) -> None:
        """Add one frame; flushes when ``flush_interval_s`` has passed since the last.

        ``device_time_us`` is the device clock exactly as the frame carried it [us]
        (``/device_time_us``; ``/time`` holds it in seconds, a float).
        """
        if np.shape(counts) != tuple(self.sensor.frame_shape):
            raise RecordingError(
                f"a frame of shape {np.shape(counts)} for sensor {self.sensor.name!r}, whose "
                f"frames are {tuple(self.sensor.frame_shape)}"
            )
        self._buffer.append((counts, device_time_s, sequence, host_time_s, int(device_time_us)))
        if time.monotonic() - self._last_flush >= self._interval:
            self.flush()

    def flush(self) -> None:
        """Write the buffered frames and the loss counters, and flush the file."""
        if self._buffer:
            n, k = self._count, len(self._buffer)
            counts, times, seqs, hosts, device_us = zip(*self._buffer, strict=True)
            for dataset in (
                self._frames, self._time, self._sequence, self._host, self._device_us
            ):  # fmt: skip
                dataset.resize(n + k, axis=0)
            self._frames[n:] = np.stack(counts)
            self._time[n:] = times
            self._sequence[n:] = seqs
            self._host[n:] = hosts
            self._device_us[n:] = device_us
            self._count += k
            self._buffer.clear()
        if self._loss_source is not None and self._kinds:
            counters = self._loss_source()
            self._losses[:] = [int(counters.get(kind, 0)) for kind in self._kinds]
        self._h5.flush()
        self._last_flush = time.monotonic()

    def close(self) -> None:
        """Flush and close the file (idempotent)."""
        if self._h5.id.valid:
            self.flush()
            self._h5.close()

    def __enter__(self) -> RecordingWriter:
        return self

    def __exit__(self, *exc) -> None:
        self.close()
