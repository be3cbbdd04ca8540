"""Recordings: frames of A/D counts with their time stamps, sensor and scenario, in HDF5.

Layout of a recording file (format ``tactsense-recording``, version 2)::

    /                    attrs: format, format_version, tactsense_version, created,
                                sensor_toml, scenario_json, flaws, scan_rate_hz,
                                source (recorded streams: the URL)
    /frames              (T, rows, cols) counts       attrs: units = "counts"
    /time                (T,) frame start time        attrs: units = "s"
    /sample_offset       (rows, cols) sample instant within a frame, attrs: units = "s"
    /gains               (rows, cols) per-tactel gain used by the simulator (optional)
    /truth/...           what was applied, for simulated recordings (optional)
    /sequence            (T,) uint16 sequence number on the wire (recorded streams, v2)
    /host_time           (T,) arrival on the host, Unix time [s] (recorded streams, v2)
    /losses              (K,) int64 loss counters, attrs: kinds = comma list (v2)

Version 1 (no stream datasets) is still read. A recorded stream is written in HDF5's
single-writer/multiple-reader mode and flushed at least once a second: a recorder killed
mid-way leaves a file that :func:`read_recording` opens, holding every frame up to the
last flush (``Recording.closed_cleanly`` is then False).

Axis -2 of ``frames`` runs along the finger (row 0 under the tip), axis -1
around it (``docs/nomenclature.md``).
"""

from __future__ import annotations

import datetime as _dt
import json
import time
from dataclasses import dataclass, field
from pathlib import Path

import h5py
import numpy as np

from tactsense._validation import TactsenseInputError
from tactsense._version import __version__
from tactsense.sensor import SensorSpec, SensorSpecError

FORMAT = "tactsense-recording"
FORMAT_VERSION = 2


class RecordingError(TactsenseInputError):
    """Raised when a recording file is missing, malformed or of the wrong kind."""


@dataclass
class Recording:
    """Frames recorded from (or simulated for) one finger.

    Attributes
    ----------
    frames : ndarray, shape (T, rows, cols)
        A/D readings [counts].
    time_s : ndarray, shape (T,)
        Start of each frame's scan [s].
    sample_offset_s : ndarray, shape (rows, cols)
        When within a frame each tactel is sampled [s].
    sensor : SensorSpec
    scenario : dict
        What was applied (simulated) or a description (measured).
    flaws : tuple of str
        Flaws switched on in the simulation.
    truth : dict of arrays
        Ground truth of a simulated recording; empty for a measured one.
    gains : ndarray, shape (rows, cols), optional
        Per-tactel gains used by the simulator.
    sequence : ndarray of uint16, shape (T,), optional
        Sequence number of each frame on the wire (recorded streams).
    host_time_s : ndarray, shape (T,), optional
        Arrival of each frame on the host, Unix time [s] (recorded streams).
    losses : dict
        Loss counters of the stream it was recorded from (``tactsense.stream``).
    source : str
        Where the frames came from (the stream's URL), empty for a simulation.
    closed_cleanly : bool
        False when the writer did not close the file (it was killed): the frames are
        those up to its last flush.
    """

    frames: np.ndarray
    time_s: np.ndarray
    sample_offset_s: np.ndarray
    sensor: SensorSpec
    scenario: dict = field(default_factory=dict)
    flaws: tuple[str, ...] = ()
    truth: dict = field(default_factory=dict)
    gains: np.ndarray | None = None
    sequence: np.ndarray | None = None
    host_time_s: np.ndarray | None = None
    losses: dict = field(default_factory=dict)
    source: str = ""
    closed_cleanly: bool = True

    def __post_init__(self) -> None:
        frames = np.asarray(self.frames)
        shape = self.sensor.shape
        if frames.ndim != 3 or frames.shape[1:] != shape:
            raise RecordingError(
                f"frames have shape {frames.shape}; expected (T, {shape[0]}, {shape[1]}) "
                f"for sensor {self.sensor.name!r}"
            )
        if np.asarray(self.time_s).shape != (frames.shape[0],):
            raise RecordingError(
                f"time has shape {np.asarray(self.time_s).shape}; expected ({frames.shape[0]},)"
            )
        if np.asarray(self.sample_offset_s).shape != shape:
            raise RecordingError(
                f"sample_offset has shape {np.asarray(self.sample_offset_s).shape}; "
                f"expected {shape}"
            )

    def __len__(self) -> int:
        return int(self.frames.shape[0])

    def sample_step(self, row: int, col: int) -> np.ndarray:
        """Scenario step in force when tactel (row, col) was sampled, per frame (simulated only).

        ``truth["frame_step"]`` is the step at the middle of each frame's scan; a
        tactel sampled early or late in the scan may see the step before or after.
        """
        steps = self.scenario.get("steps")
        if not steps:
            raise RecordingError("this recording carries no scenario steps")
        bounds = np.cumsum([0.0] + [float(step["duration_s"]) for step in steps])
        instants = np.asarray(self.time_s) + float(self.sample_offset_s[row, col])
        return np.clip(np.searchsorted(bounds, instants, side="right") - 1, 0, len(steps) - 1)

    def last_loaded_frames(self, row: int, col: int) -> tuple[np.ndarray, np.ndarray]:
        """The last frame of every step that loads the finger, as tactel (row, col) saw it.

        Returns
        -------
        frames : ndarray of int
            Frame indices, one per loaded step (simulated recordings only).
        steps : ndarray of int
            The step each of those frames belongs to.
        """
        step = self.sample_step(row, col)
        loaded = np.asarray(self.truth["step_n_contacts"])[step] > 0
        last = np.flatnonzero(loaded & np.r_[step[1:] != step[:-1], True])
        return last, step[last]

    @property
    def baseline_frames(self) -> np.ndarray:
        """Indices of frames during which nothing touched (simulated recordings only)."""
        if "frame_step" not in self.truth:
            raise RecordingError("this recording carries no truth; find untouched frames yourself")
        counts = np.asarray(self.truth["step_n_contacts"])[np.asarray(self.truth["frame_step"])]
        return np.flatnonzero(counts == 0)


def write_recording(path: str | Path, recording: Recording, *, overwrite: bool = False) -> Path:
    """Write a recording to an HDF5 file.

    An existing file is never replaced unless ``overwrite`` is true; the
    new file is written next to it first and moved in place only when
    complete, so an interrupted write loses nothing.
    """
    path = Path(path)
    if path.exists() and not overwrite:
        raise FileExistsError(f"{path} exists; pass overwrite=True (--force) to replace it")
    if not path.parent.exists():
        raise RecordingError(f"folder {path.parent} does not exist")
    partial = path.with_name(path.name + ".partial")
    try:
        _write_file(partial, recording)
    except BaseException:
        partial.unlink(missing_ok=True)  # interrupted: leave nothing behind
        raise
    partial.replace(path)
    return path


def _write_file(partial: Path, recording: Recording) -> None:
    with h5py.File(partial, "w") as h5:
        h5.attrs["format"] = FORMAT
        h5.attrs["format_version"] = FORMAT_VERSION
        h5.attrs["tactsense_version"] = __version__
        h5.attrs["created"] = _dt.datetime.now(_dt.UTC).isoformat(timespec="seconds")
        h5.attrs["sensor_toml"] = recording.sensor.to_toml_string()
        h5.attrs["scenario_json"] = json.dumps(recording.scenario)
        h5.attrs["flaws"] = ",".join(recording.flaws)
        h5.attrs["scan_rate_hz"] = recording.sensor.electronics.scan_rate_hz
        frames = h5.create_dataset(
            "frames",
            data=recording.frames,
            compression="gzip",
            chunks=(max(1, min(len(recording), 1024)), *recording.sensor.shape),
            maxshape=(None, *recording.sensor.shape),
        )
        frames.attrs["units"] = "counts"
        frames.attrs["axes"] = "time, row (along the finger, 0 = tip), col (around)"
        h5.create_dataset("time", data=np.asarray(recording.time_s, float)).attrs["units"] = "s"
        offset = h5.create_dataset("sample_offset", data=recording.sample_offset_s)
        offset.attrs["units"] = "s"
        if recording.gains is not None:
            h5.create_dataset("gains", data=recording.gains).attrs["units"] = "1"
        h5.attrs["source"] = recording.source
        if recording.sequence is not None:
            h5.create_dataset("sequence", data=np.asarray(recording.sequence, np.uint16))
        if recording.host_time_s is not None:
            host = h5.create_dataset("host_time", data=np.asarray(recording.host_time_s, float))
            host.attrs["units"] = "s"
        if recording.losses:
            losses = h5.create_dataset("losses", data=np.array(list(recording.losses.values())))
            losses.attrs["kinds"] = ",".join(recording.losses)
        if recording.truth:
            group = h5.create_group("truth")
            units = {
                "step_axial_mm": "mm",
                "step_angle_deg": "deg",
                "step_x_mm": "mm",
                "step_y_mm": "mm",
                "step_force_n": "N",
            }
            for key, value in recording.truth.items():
                if isinstance(value, str):
                    group.attrs[key] = value
                else:
                    group.create_dataset(key, data=value).attrs["units"] = units.get(key, "1")


def _open_validated(path: str | Path):
    """Open a recording and check it: (h5 file, sensor, number of frames, closed cleanly).

    The caller closes the file. Raises :class:`RecordingError` for everything
    :func:`read_recording` refuses.
    """
    path = Path(path)
    if not path.exists():
        raise RecordingError(f"recording {path} does not exist")
    closed_cleanly = True
    try:
        h5 = h5py.File(path, "r")
    except OSError as error:
        if "already open for write" not in str(error):
            raise RecordingError(f"{path} is not a readable HDF5 file ({error})") from None
        # a recorder still writing, or killed: SWMR readers see everything flushed
        closed_cleanly = False
        try:
            h5 = h5py.File(path, "r", swmr=True)
        except OSError as again:
            raise RecordingError(f"{path} is not a readable HDF5 file ({again})") from None
    try:
        if h5.attrs.get("format") != FORMAT:
            raise RecordingError(
                f"{path} is not a tactsense recording (format attribute "
                f"{h5.attrs.get('format')!r}, expected {FORMAT!r})"
            )
        try:
            version = int(h5.attrs.get("format_version", -1))
        except (TypeError, ValueError):
            raise RecordingError(
                f"{path}: format_version {h5.attrs.get('format_version')!r} is not a number"
            ) from None
        if version > FORMAT_VERSION:
            raise RecordingError(
                f"{path} has format version {version}; this tactsense reads up to "
                f"{FORMAT_VERSION}: upgrade tactsense"
            )
        for name in ("frames", "time", "sample_offset"):
            if name not in h5:
                raise RecordingError(f"{path} lacks the dataset /{name}")
        try:
            sensor = SensorSpec.from_toml_string(str(h5.attrs["sensor_toml"]))
        except (KeyError, SensorSpecError) as error:
            raise RecordingError(f"{path}: sensor description unreadable: {error}") from None
        for name in ("frames", "time", "sample_offset", "sequence", "host_time"):
            if name in h5 and h5[name].dtype.kind not in "uif":
                raise RecordingError(
                    f"{path}: /{name} holds {h5[name].dtype} values; expected numbers "
                    "(counts or fractional deflections for /frames, seconds for times)"
                )
        per_frame = [
            h5[name].shape[0]
            for name in ("frames", "time", "sequence", "host_time")
            if name in h5 and h5[name].ndim >= 1
        ]
        n = min(per_frame)  # a killed writer may have flushed one dataset further
        shape = h5["frames"].shape
        if len(shape) != 3 or shape[1:] != sensor.shape:
            raise RecordingError(
                f"{path}: /frames has shape {shape}; expected (T, {sensor.shape[0]}, "
                f"{sensor.shape[1]}) for its sensor {sensor.name!r}"
            )
    except BaseException:
        h5.close()
        raise
    return h5, sensor, n, closed_cleanly


def _losses(h5) -> dict[str, int]:
    """The /losses counters by kind (empty if the recording has none)."""
    if "losses" not in h5:
        return {}
    kinds = str(h5["losses"].attrs.get("kinds", "")).split(",")
    return {k: int(v) for k, v in zip(kinds, h5["losses"][()], strict=False) if k}


def read_recording(path: str | Path) -> Recording:
    """Open and validate a recording written by :func:`write_recording`.

    Raises
    ------
    RecordingError
        If the file is missing, not HDF5, not a tactsense recording, lacks a
        dataset, or has shapes that disagree with its sensor.
    """
    path = Path(path)
    h5, sensor, n, closed_cleanly = _open_validated(path)
    with h5:
        frames = h5["frames"][:n]
        truth: dict = {}
        if "truth" in h5:
            group = h5["truth"]
            truth = {key: group[key][()] for key in group}
            truth.update({key: str(value) for key, value in group.attrs.items()})
        try:
            scenario = json.loads(str(h5.attrs.get("scenario_json", "{}")))
        except json.JSONDecodeError as error:
            raise RecordingError(f"{path}: scenario metadata is not valid JSON ({error})") from None
        flaws = tuple(f for f in str(h5.attrs.get("flaws", "")).split(",") if f)
        losses = _losses(h5)
        return Recording(
            frames=frames,
            time_s=h5["time"][:n],
            sample_offset_s=h5["sample_offset"][()],
            sensor=sensor,
            scenario=scenario,
            flaws=flaws,
            truth=truth,
            gains=h5["gains"][()] if "gains" in h5 else None,
            sequence=h5["sequence"][:n] if "sequence" in h5 else None,
            host_time_s=h5["host_time"][:n] if "host_time" in h5 else None,
            losses=losses,
            source=str(h5.attrs.get("source", "")),
            closed_cleanly=closed_cleanly,
        )


class RecordingReader:
    """A recording read in pieces, for recordings larger than memory.

    Validated as :func:`read_recording` validates, but nothing but the metadata is read
    until asked for. Use as a context manager.

    Examples
    --------
    >>> with RecordingReader("long.h5") as reader:  # doctest: +SKIP
    ...     for start, frames, time_s in reader.chunks():
    ...         ...
    """

    def __init__(self, path: str | Path):
        self.path = Path(path)
        self._h5, self.sensor, self.n_frames, self.closed_cleanly = _open_validated(self.path)

    def __enter__(self) -> RecordingReader:
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def close(self) -> None:
        self._h5.close()

    @property
    def chunk_frames(self) -> int:
        """Frames per piece: the HDF5 chunk length (a multiple of it near 65,536)."""
        chunks = self._h5["frames"].chunks
        if not chunks:
            return 65_536
        return max(chunks[0], (65_536 // chunks[0]) * chunks[0])

    def frames(self, start: int, stop: int) -> np.ndarray:
        """Frames ``start`` to ``stop`` (exclusive) [counts]."""
        return self._h5["frames"][start : min(stop, self.n_frames)]

    def time_s(self, start: int, stop: int) -> np.ndarray:
        """Their times [s]."""
        return self._h5["time"][start : min(stop, self.n_frames)]

    @property
    def losses(self) -> dict[str, int]:
        """Frames lost by kind, as the recorder counted them (empty if none recorded)."""
        return _losses(self._h5)

    def chunks(self, chunk_frames: int | None = None):
        """Yield ``(start, frames, time_s)`` for consecutive pieces of the recording."""
        size = int(chunk_frames or self.chunk_frames)
        if size < 1:
            raise TactsenseInputError(f"chunk_frames must be at least 1; got {size}")
        for start in range(0, self.n_frames, size):
            yield start, self.frames(start, start + size), self.time_s(start, start + size)


def read_losses(path: str | Path) -> dict[str, int]:
    """A recording's loss counters alone, without reading its frames."""
    with RecordingReader(path) as reader:
        return reader.losses


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
        rows, cols = sensor.shape
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
                (0, rows, cols),
                np.uint16,
                maxshape=(None, rows, cols),
                chunks=(chunk, rows, cols),
                compression="gzip",
                compression_opts=1,
            )
            self._frames.attrs["units"] = "counts"
            self._frames.attrs["axes"] = "time, row (along the finger, 0 = tip), col (around)"
            self._time = h5.create_dataset("time", (0,), float, maxshape=(None,), chunks=(chunk,))
            self._time.attrs["units"] = "s"
            self._sequence = h5.create_dataset(
                "sequence", (0,), np.uint16, maxshape=(None,), chunks=(chunk,)
            )
            self._host = h5.create_dataset(
                "host_time", (0,), float, maxshape=(None,), chunks=(chunk,)
            )
            self._host.attrs["units"] = "s"
            offset = h5.create_dataset("sample_offset", data=np.asarray(sample_offset_s, float))
            offset.attrs["units"] = "s"
            self._kinds = list(loss_kinds)
            self._losses = h5.create_dataset(
                "losses", data=np.zeros(max(len(self._kinds), 1), np.int64)
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

    def append(self, counts, device_time_s: float, sequence: int, host_time_s: float) -> None:
        """Add one frame; flushes when ``flush_interval_s`` has passed since the last."""
        self._buffer.append((counts, device_time_s, sequence, host_time_s))
        if time.monotonic() - self._last_flush >= self._interval:
            self.flush()

    def flush(self) -> None:
        """Write the buffered frames and the loss counters, and flush the file."""
        if self._buffer:
            n, k = self._count, len(self._buffer)
            counts, times, seqs, hosts = zip(*self._buffer, strict=True)
            for dataset in (self._frames, self._time, self._sequence, self._host):
                dataset.resize(n + k, axis=0)
            self._frames[n:] = np.stack(counts)
            self._time[n:] = times
            self._sequence[n:] = seqs
            self._host[n:] = hosts
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
