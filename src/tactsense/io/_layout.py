"""A recording in memory (:class:`Recording`) and written whole to HDF5
(:func:`write_recording`): the file's layout, format and version. The layout is described
in :mod:`tactsense.io.recording`, which re-exports everything here."""

from __future__ import annotations

import datetime as _dt
import json
from dataclasses import dataclass, field
from pathlib import Path

import h5py
import numpy as np

from tactsense._validation import TactsenseInputError
from tactsense._version import __version__
from tactsense.kinds import kind_of
from tactsense.sensor import SensorSpec

FORMAT = "tactsense-recording"
FORMAT_VERSION = 2


class RecordingError(TactsenseInputError):
    """Raised when a recording file is missing, malformed or of the wrong kind."""


@dataclass
class Recording:
    """Frames recorded from (or simulated for) one finger.

    Attributes
    ----------
    frames : ndarray, shape (T, rows, cols) or (T, rows, cols, components)
        A/D readings [counts]: ``(T, *sensor.frame_shape)``, the component axis last
        (x, y, z for a three-axis taxel).
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
    device_time_us : ndarray of int64, shape (T,), optional
        Start of each frame's scan on the device clock, exactly as the wire carried it
        [us] (recorded streams; ``time_s`` holds it as float seconds).
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
    device_time_us: np.ndarray | None = None
    losses: dict = field(default_factory=dict)
    source: str = ""
    closed_cleanly: bool = True

    def __post_init__(self) -> None:
        frames = np.asarray(self.frames)
        shape = self.sensor.shape
        frame_shape = self.sensor.frame_shape
        if frames.ndim != 1 + len(frame_shape) or frames.shape[1:] != frame_shape:
            raise RecordingError(
                f"frames have shape {frames.shape}; expected (T, "
                f"{', '.join(str(n) for n in frame_shape)}) for sensor {self.sensor.name!r}"
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


def _checked_dataset(group, name: str, data, **options):
    """A chunked dataset with HDF5's Fletcher-32 checksum: damage is an error, not numbers."""
    data = np.asarray(data)
    if data.ndim == 0:  # a scalar cannot be chunked (none is written today)
        return group.create_dataset(name, data=data)
    if "chunks" not in options:
        row = int(np.prod(data.shape[1:], dtype=np.int64))
        options["chunks"] = (max(1, min(data.shape[0], 65_536 // max(row, 1))), *data.shape[1:])
    if data.shape[0] == 0 or 0 in data.shape[1:]:
        options["maxshape"] = (None, *data.shape[1:])
        options["chunks"] = tuple(max(1, n) for n in options["chunks"])
    return group.create_dataset(name, data=data, fletcher32=True, **options)


def _write_file(partial: Path, recording: Recording) -> None:
    # format v110: object headers, B-trees and the superblock carry checksums too
    with h5py.File(partial, "w", libver=("v110", "v110")) as h5:
        h5.attrs["format"] = FORMAT
        h5.attrs["format_version"] = FORMAT_VERSION
        h5.attrs["tactsense_version"] = __version__
        h5.attrs["created"] = _dt.datetime.now(_dt.UTC).isoformat(timespec="seconds")
        h5.attrs["sensor_toml"] = recording.sensor.to_toml_string()
        h5.attrs["scenario_json"] = json.dumps(recording.scenario)
        h5.attrs["flaws"] = ",".join(recording.flaws)
        h5.attrs["scan_rate_hz"] = recording.sensor.electronics.scan_rate_hz
        frames = _checked_dataset(
            h5,
            "frames",
            recording.frames,
            compression="gzip",
            chunks=(max(1, min(len(recording), 1024)), *recording.sensor.frame_shape),
            maxshape=(None, *recording.sensor.frame_shape),
        )
        frames.attrs["units"] = "counts"
        frames.attrs["axes"] = kind_of(recording.sensor).frame_axes
        time_s = _checked_dataset(h5, "time", np.asarray(recording.time_s, float))
        time_s.attrs["units"] = "s"
        offset = _checked_dataset(h5, "sample_offset", recording.sample_offset_s)
        offset.attrs["units"] = "s"
        if recording.gains is not None:
            _checked_dataset(h5, "gains", recording.gains).attrs["units"] = "1"
        h5.attrs["source"] = recording.source
        if recording.sequence is not None:
            _checked_dataset(h5, "sequence", np.asarray(recording.sequence, np.uint16))
        if recording.host_time_s is not None:
            host = _checked_dataset(h5, "host_time", np.asarray(recording.host_time_s, float))
            host.attrs["units"] = "s"
        if recording.device_time_us is not None:
            device = _checked_dataset(
                h5, "device_time_us", np.asarray(recording.device_time_us, np.int64)
            )
            device.attrs["units"] = "us"
        if recording.losses:
            losses = _checked_dataset(h5, "losses", np.array(list(recording.losses.values())))
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
                    dataset = _checked_dataset(group, key, value)
                    dataset.attrs["units"] = units.get(key, "1")
