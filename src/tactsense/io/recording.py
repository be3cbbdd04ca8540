"""Recordings: frames of A/D counts with their time stamps, sensor and scenario, in HDF5.

Layout of a recording file (format ``tactsense-recording``, version 1)::

    /                    attrs: format, format_version, tactsense_version, created,
                                sensor_toml, scenario_json, flaws, scan_rate_hz
    /frames              (T, rows, cols) counts       attrs: units = "counts"
    /time                (T,) frame start time        attrs: units = "s"
    /sample_offset       (rows, cols) sample instant within a frame, attrs: units = "s"
    /gains               (rows, cols) per-tactel gain used by the simulator (optional)
    /truth/...           what was applied, for simulated recordings (optional)

Axis -2 of ``frames`` runs along the finger (row 0 under the tip), axis -1
around it (``docs/nomenclature.md``).
"""

from __future__ import annotations

import datetime as _dt
import json
from dataclasses import dataclass, field
from pathlib import Path

import h5py
import numpy as np

from tactsense._validation import TactsenseInputError
from tactsense._version import __version__
from tactsense.sensor import SensorSpec, SensorSpecError

FORMAT = "tactsense-recording"
FORMAT_VERSION = 1


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
    """

    frames: np.ndarray
    time_s: np.ndarray
    sample_offset_s: np.ndarray
    sensor: SensorSpec
    scenario: dict = field(default_factory=dict)
    flaws: tuple[str, ...] = ()
    truth: dict = field(default_factory=dict)
    gains: np.ndarray | None = None

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
            chunks=(min(len(recording), 1024), *recording.sensor.shape),
        )
        frames.attrs["units"] = "counts"
        frames.attrs["axes"] = "time, row (along the finger, 0 = tip), col (around)"
        h5.create_dataset("time", data=np.asarray(recording.time_s, float)).attrs["units"] = "s"
        offset = h5.create_dataset("sample_offset", data=recording.sample_offset_s)
        offset.attrs["units"] = "s"
        if recording.gains is not None:
            h5.create_dataset("gains", data=recording.gains).attrs["units"] = "1"
        if recording.truth:
            group = h5.create_group("truth")
            units = {"step_axial_mm": "mm", "step_angle_deg": "deg", "step_force_n": "N"}
            for key, value in recording.truth.items():
                if isinstance(value, str):
                    group.attrs[key] = value
                else:
                    group.create_dataset(key, data=value).attrs["units"] = units.get(key, "1")
    partial.replace(path)
    return path


def read_recording(path: str | Path) -> Recording:
    """Open and validate a recording written by :func:`write_recording`.

    Raises
    ------
    RecordingError
        If the file is missing, not HDF5, not a tactsense recording, lacks a
        dataset, or has shapes that disagree with its sensor.
    """
    path = Path(path)
    if not path.exists():
        raise RecordingError(f"recording {path} does not exist")
    try:
        h5 = h5py.File(path, "r")
    except OSError as error:
        raise RecordingError(f"{path} is not a readable HDF5 file ({error})") from None
    with h5:
        if h5.attrs.get("format") != FORMAT:
            raise RecordingError(
                f"{path} is not a tactsense recording (format attribute "
                f"{h5.attrs.get('format')!r}, expected {FORMAT!r})"
            )
        version = int(h5.attrs.get("format_version", -1))
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
        frames = h5["frames"][()]
        if frames.ndim != 3 or frames.shape[1:] != sensor.shape:
            raise RecordingError(
                f"{path}: /frames has shape {frames.shape}; expected (T, {sensor.shape[0]}, "
                f"{sensor.shape[1]}) for its sensor {sensor.name!r}"
            )
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
        return Recording(
            frames=frames,
            time_s=h5["time"][()],
            sample_offset_s=h5["sample_offset"][()],
            sensor=sensor,
            scenario=scenario,
            flaws=flaws,
            truth=truth,
            gains=h5["gains"][()] if "gains" in h5 else None,
        )
