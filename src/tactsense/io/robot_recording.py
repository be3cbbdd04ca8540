"""A recording of a robot's skin: one stream per patch, in one folder.

Layout (format ``tactsense-robot-recording``, version 1)::

    NAME/                      the recording (a folder)
      robot.json               manifest: format, version, skin name, streams, devices
      skin.toml                the robot skin (tactsense.robot's TOML form)
      streams/PATCH.h5         one tactsense recording per patch, as every command reads

Each stream is an ordinary recording (:mod:`tactsense.io.recording`): its own rate, its
device clock (``device_time_us``), host stamps, losses, crash-safe on its own, so
``tactsense info``, ``locate`` and the rest read a single patch's file as they read any.
The manifest says which device read which patches, each device's clock fit to the host
clock and whether the device dropped out (and when). It is written first (so a
recording killed while capturing still says what it holds) and again at the end.

Whole recordings (simulations) are written to ``NAME.partial`` and moved into place when
complete.
"""

from __future__ import annotations

import json
import os
import shutil
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from tactsense.io._layout import Recording, RecordingError, write_recording
from tactsense.io.recording import read_recording
from tactsense.robot import RobotSkin, RobotSkinError, skin_from_toml, skin_to_toml_string

ROBOT_FORMAT = "tactsense-robot-recording"
ROBOT_FORMAT_VERSION = 1
MANIFEST = "robot.json"
SKIN = "skin.toml"
STREAMS = "streams"


@dataclass
class RobotRecording:
    """Streams of several patches of one robot skin.

    Attributes
    ----------
    skin : RobotSkin
    streams : dict of str -> Recording
        One recording per patch (patch name -> frames on that patch's own clock and rate);
        a patch missing here recorded nothing.
    devices : dict of str -> dict
        Per device (board): ``patches`` (names), ``source`` (URL), ``clock`` (fit of the
        device clock to the host: ``offset_s``, ``drift_ppm``, ``residual_s``; empty for a
        simulation), ``status`` (``"ok"`` or ``"dropped"``), ``dropped_at_s`` (host time
        of its last frame when it dropped out, else None).
    description : str
        What was recorded (a simulation's scenario, or the sources).
    closed_cleanly : bool
        False when the manifest says capture never finished (the writer was killed).
    """

    skin: RobotSkin
    streams: dict[str, Recording]
    devices: dict[str, dict[str, Any]] = field(default_factory=dict)
    description: str = ""
    closed_cleanly: bool = True

    def __post_init__(self) -> None:
        for name, recording in self.streams.items():
            patch = self.skin.patch(name)
            if recording.sensor.shape != patch.sensor.shape:
                raise RecordingError(
                    f"stream {name!r} has frames of shape {recording.sensor.shape}; the skin's "
                    f"patch {name!r} has {patch.sensor.shape}"
                )
        if not self.devices:
            self.devices = {
                device: {"patches": list(names), "source": "", "clock": {}, "status": "ok",
                         "dropped_at_s": None}
                for device, names in self.skin.devices.items()
            }  # fmt: skip


def stream_path(path: str | Path, patch: str) -> Path:
    """Where a patch's stream lies in a robot recording."""
    return Path(path) / STREAMS / f"{patch}.h5"


def is_robot_recording(path: str | Path) -> bool:
    """Whether ``path`` is a robot recording's folder (it holds the manifest)."""
    return (Path(path) / MANIFEST).is_file()


def manifest(recording: RobotRecording, *, closed_cleanly: bool = True) -> dict[str, Any]:
    """The manifest's content for ``recording``."""
    return {
        "format": ROBOT_FORMAT,
        "format_version": ROBOT_FORMAT_VERSION,
        "skin": recording.skin.name,
        "description": recording.description,
        "streams": sorted(recording.streams),
        "devices": recording.devices,
        "closed_cleanly": closed_cleanly,
    }


def write_manifest(folder: str | Path, content: dict[str, Any]) -> None:
    """Write ``robot.json`` atomically (a temporary name, then moved into place)."""
    folder = Path(folder)
    partial = folder / (MANIFEST + ".partial")
    partial.write_text(json.dumps(content, indent=2, sort_keys=True) + "\n", encoding="utf-8")
    os.replace(partial, folder / MANIFEST)


def check_robot_output(path: str | Path, *, overwrite: bool = False) -> Path:
    """``path`` as a new robot recording's folder, or the error saying why it cannot be.

    Its parent must exist; an existing folder is refused unless ``overwrite``, and even
    then only a robot recording may be replaced (a folder that is not one never is).
    """
    path = Path(path)
    if not path.parent.is_dir():
        raise RecordingError(f"folder {path.parent} does not exist")
    if path.exists():
        if not overwrite:
            raise FileExistsError(f"{path} exists; pass overwrite=True (--force) to replace it")
        if not is_robot_recording(path):
            raise RecordingError(
                f"{path} exists and is not a robot recording; it is not replaced, whatever "
                "--force says"
            )
    return path


def write_robot_recording(
    path: str | Path, recording: RobotRecording, *, overwrite: bool = False
) -> Path:
    """Write a whole robot recording; nothing is left behind if interrupted.

    An existing folder is refused unless ``overwrite``; even then only a robot recording is
    replaced (a folder that is not one is never removed).
    """
    path = check_robot_output(path, overwrite=overwrite)
    partial = path.with_name(path.name + ".partial")
    if partial.exists():
        shutil.rmtree(partial)
    try:
        (partial / STREAMS).mkdir(parents=True)
        (partial / SKIN).write_text(skin_to_toml_string(recording.skin), encoding="utf-8")
        for name, stream in recording.streams.items():
            write_recording(stream_path(partial, name), stream)
        write_manifest(partial, manifest(recording))
    except BaseException:
        shutil.rmtree(partial, ignore_errors=True)
        raise
    if path.exists():
        shutil.rmtree(path)
    partial.replace(path)
    return path


def read_manifest(path: str | Path) -> dict[str, Any]:
    """The manifest of a robot recording, checked, or RecordingError saying what is wrong."""
    path = Path(path)
    if not path.is_dir():
        raise RecordingError(f"{path} is not a robot recording (expected a folder)")
    try:
        content = json.loads((path / MANIFEST).read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise RecordingError(f"{path} is not a robot recording: it has no {MANIFEST}") from None
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as error:
        raise RecordingError(f"{path / MANIFEST}: unreadable ({error})") from None
    if not isinstance(content, dict) or content.get("format") != ROBOT_FORMAT:
        raise RecordingError(f"{path / MANIFEST}: not a {ROBOT_FORMAT} manifest")
    version = content.get("format_version")
    if version != ROBOT_FORMAT_VERSION:
        raise RecordingError(
            f"{path}: robot recording format version {version!r}; this tactsense reads "
            f"version {ROBOT_FORMAT_VERSION}"
        )
    return content


def read_robot_skin(path: str | Path) -> RobotSkin:
    """The skin a robot recording was made with."""
    try:
        return skin_from_toml(Path(path) / SKIN)
    except RobotSkinError as error:
        raise RecordingError(f"{path}: {error}") from None


def read_robot_recording(path: str | Path) -> RobotRecording:
    """A robot recording whole (every stream in memory; use the per-patch files' readers,
    :class:`tactsense.io.recording.RecordingReader`, for long ones)."""
    path = Path(path)
    content = read_manifest(path)
    skin = read_robot_skin(path)
    streams = {}
    for name in content.get("streams", []):
        skin.patch(name)
        file = stream_path(path, name)
        if file.exists():
            streams[name] = read_recording(file)
    return RobotRecording(
        skin=skin,
        streams=streams,
        devices=dict(content.get("devices", {})),
        description=str(content.get("description", "")),
        closed_cleanly=bool(content.get("closed_cleanly", False)),
    )


# ---- streaming writer (r7-capture) ----
class RobotRecordingWriter:
    """Write a robot recording as the frames arrive: a crash-safe stream per patch.

    The folder is made at once (not under a temporary name: a capture killed at any
    moment leaves every stream readable up to its last flush, as
    :class:`~tactsense.io.recording.RecordingWriter` does for one array), with the skin
    and a manifest that says ``closed_cleanly: false``; :meth:`close` writes the final
    manifest (clock fits, statuses, ``closed_cleanly: true``). A writer closed before any
    frame came removes what it made (:meth:`discard`).

    Parameters
    ----------
    path : path
        The new recording's folder. An existing one is refused unless ``overwrite``, and
        even then only a robot recording is replaced.
    skin : RobotSkin
    devices : dict of str -> dict
        The manifest's devices (``patches``, ``source``, ...) at the start; a stream is
        made for every patch of these devices.
    description : str
    losses : dict of str -> callable() -> dict, optional
        Per patch, its loss counters (``LOSS_KINDS`` of :mod:`tactsense.stream.reader`)
        when the file is flushed.
    loss_kinds : sequence of str
        The counters' names, in the order stored.
    flush_interval_s : float
        Each stream is flushed at least this often [s].
    """

    def __init__(
        self,
        path: str | Path,
        skin: RobotSkin,
        devices: dict[str, dict[str, Any]],
        *,
        description: str = "",
        losses: dict[str, Any] | None = None,
        loss_kinds=(),
        overwrite: bool = False,
        flush_interval_s: float = 1.0,
    ):
        from tactsense.io.recording import RecordingWriter
        from tactsense.physics.transduction import sample_offsets

        path = check_robot_output(path, overwrite=overwrite)
        if path.exists():
            shutil.rmtree(path)
        self.path = path
        self.skin = skin
        self.devices = {name: dict(entry) for name, entry in devices.items()}
        self.description = description
        self._writers: dict[str, Any] = {}
        losses = losses or {}
        (path / STREAMS).mkdir(parents=True)
        try:
            (path / SKIN).write_text(skin_to_toml_string(skin), encoding="utf-8")
            for entry in self.devices.values():
                for name in entry.get("patches", []):
                    sensor = skin.patch(name).sensor
                    self._writers[name] = RecordingWriter(
                        stream_path(path, name),
                        sensor,
                        sample_offsets(sensor),
                        source=str(entry.get("source", "")),
                        loss_kinds=tuple(loss_kinds),
                        losses=losses.get(name),
                        flush_interval_s=flush_interval_s,
                    )
            self.write_manifest(closed_cleanly=False)
        except BaseException:
            self._close_writers()
            shutil.rmtree(path, ignore_errors=True)
            raise
        self.closed = False

    @property
    def patches(self) -> tuple[str, ...]:
        """The patches with a stream, in the devices' order."""
        return tuple(self._writers)

    def frames(self, patch: str) -> int:
        """Frames written to a patch's stream so far."""
        return len(self._writers[patch])

    def append(
        self,
        patch: str,
        counts,
        device_time_s: float,
        sequence: int,
        host_time_s: float,
        *,
        device_time_us: int = -1,
    ) -> None:
        """Add one frame [counts] to a patch's stream (times [s]; ``device_time_us`` as
        the device sent it [us])."""
        self._writers[patch].append(
            counts, device_time_s, sequence, host_time_s, device_time_us=device_time_us
        )

    def write_manifest(self, *, closed_cleanly: bool) -> None:
        """Write the manifest as it stands (atomically)."""
        write_manifest(
            self.path,
            {
                "format": ROBOT_FORMAT,
                "format_version": ROBOT_FORMAT_VERSION,
                "skin": self.skin.name,
                "description": self.description,
                "streams": sorted(self._writers),
                "devices": self.devices,
                "closed_cleanly": closed_cleanly,
            },
        )

    def _close_writers(self) -> None:
        for writer in self._writers.values():
            writer.close()

    def close(self, devices: dict[str, dict[str, Any]] | None = None) -> None:
        """Close every stream and write the final manifest (``devices``: the devices'
        entries at the end: clock fits, statuses). Idempotent."""
        if self.closed:
            return
        if devices is not None:
            self.devices = {name: dict(entry) for name, entry in devices.items()}
        self._close_writers()
        self.write_manifest(closed_cleanly=True)
        self.closed = True

    def discard(self) -> None:
        """Close and remove the recording (a capture that ended before any frame)."""
        self._close_writers()
        self.closed = True
        shutil.rmtree(self.path, ignore_errors=True)

    def __len__(self) -> int:
        return sum(len(writer) for writer in self._writers.values())


def aligned_times(path: str | Path, patch: str):
    """A patch's frame times on the host clock, Unix time [s]: the device times mapped by
    its device's clock fit in the manifest (``offset_s + device / (1 + drift_ppm 1e-6)``);
    the host arrival times where the device sent no clock or has no fit.
    """
    import h5py
    import numpy as np

    content = read_manifest(path)
    clock: dict = {}
    for entry in content.get("devices", {}).values():
        if patch in entry.get("patches", []):
            clock = entry.get("clock") or {}
    with h5py.File(stream_path(path, patch), "r") as h5:
        device_us = np.asarray(h5["device_time_us"])
        host = np.asarray(h5["host_time"])
    if not clock or not len(device_us) or np.any(device_us < 0):
        return host
    return clock["offset_s"] + device_us * 1e-6 / (1.0 + clock["drift_ppm"] * 1e-6)


# ---- /streaming writer (r7-capture) ----


JOINT_STATES_FILE = "joint_states.csv"
"""A robot recording's joint states over time, where it holds them (the iCub import writes
one: ``time_s`` then one column per joint [rad or m])."""


def recorded_joint_state(path: str | Path) -> tuple[str, Any]:
    """The joint state a robot recording carries itself, for commands given none.

    Returns
    -------
    ("csv", Path)
        The folder's ``joint_states.csv`` (joint states over time).
    ("fixed", dict)
        The joint state a simulation wrote in its streams' scenario (a simulated grasp's
        ``joints`` [rad or m]).
    ("none", None)
        Neither: the commands' own default applies.
    """
    path = Path(path)
    table = path / JOINT_STATES_FILE
    if table.is_file():
        return "csv", table
    import h5py

    for file in sorted((path / STREAMS).glob("*.h5")):
        try:
            with h5py.File(file, "r") as h5:
                scenario = json.loads(str(h5.attrs.get("scenario_json", "{}")))
        except (OSError, ValueError):
            continue
        joints = scenario.get("joints") if isinstance(scenario, dict) else None
        if isinstance(joints, dict) and joints:
            return "fixed", {str(k): float(v) for k, v in joints.items()}
    return "none", None
