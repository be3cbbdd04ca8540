"""A simulated grasp written to a robot recording folder as its frames are made.

The folder is :mod:`tactsense.io.robot_recording`'s (``robot.json``, ``skin.toml``,
``streams/PATCH.h5``), each stream the layout :func:`tactsense.io.recording.write_recording`
writes (read by :func:`~tactsense.io.recording.read_recording` and every command), filled
one block of frames at a time (:meth:`GraspPlan.blocks`), so memory holds one block of
one patch whatever the course's length. The folder is made under ``NAME.partial`` and
moved into place when whole; interrupted (Ctrl-C included), it is removed.
"""

from __future__ import annotations

import datetime as _dt
import json
import shutil
from collections.abc import Callable
from pathlib import Path

import h5py
import numpy as np

from tactsense._version import __version__
from tactsense.io.recording import FORMAT, FORMAT_VERSION
from tactsense.io.robot_recording import (
    SKIN,
    STREAMS,
    RobotRecording,
    check_robot_output,
    manifest,
    stream_path,
    write_manifest,
)
from tactsense.kinds import kind_of
from tactsense.physics.transduction import sample_offsets
from tactsense.robot import skin_to_toml_string
from tactsense.simulate._grasp_truth import TIME_KEYS
from tactsense.simulate.contact_frames import resolve_flaws

TRUTH_UNITS = {
    "contact_position_mm": "mm",
    "contact_position_base_m": "m",
    "contact_normal_force_n": "N",
    "contact_tangential_force_n": "N",
    "contact_tangential_force_base_n": "N",
    "contact_radius_mm": "mm",
}
"""Units of the truth's datasets (the others: 1)."""


def write_grasp_folder(
    path: str | Path,
    plan,
    *,
    overwrite: bool = False,
    progress: Callable[[int, int], None] | None = None,
) -> Path:
    """Write ``plan`` (a :class:`~tactsense.simulate.grasp.GraspPlan`) as a robot
    recording folder at ``path``; ``progress(frames done, frames)`` after each block.

    An existing folder is refused unless ``overwrite``, and even then only a robot
    recording is replaced (as :func:`~tactsense.io.robot_recording.write_robot_recording`).
    """
    path = check_robot_output(path, overwrite=overwrite)
    skin = plan.skin
    partial = path.with_name(path.name + ".partial")
    if partial.exists():
        shutil.rmtree(partial)
    total = sum(plan.n_frames(p.name) for p in skin.patches)
    done = 0
    try:
        (partial / STREAMS).mkdir(parents=True)
        (partial / SKIN).write_text(skin_to_toml_string(skin), encoding="utf-8")
        for patch in skin.patches:
            for written in _write_stream(stream_path(partial, patch.name), plan, patch.name):
                done += written
                if progress is not None:
                    progress(done, total)
        content = manifest(RobotRecording(skin, {}, description=plan.scenario["description"]))
        content["streams"] = sorted(p.name for p in skin.patches)
        write_manifest(partial, content)
    except BaseException:
        shutil.rmtree(partial, ignore_errors=True)
        raise
    if path.exists():
        shutil.rmtree(path)
    partial.replace(path)
    return path


def _write_stream(file: Path, plan, name: str):
    """Write patch ``name``'s recording block by block; yield the frames of each block."""
    spec = plan.skin.patch(name).sensor
    n = plan.n_frames(name)
    active = resolve_flaws(plan.grasp.flaws)
    dtype = np.uint16 if "quantization" in active else np.float64
    chunk = max(1, min(n, 1024))
    with h5py.File(file, "w", libver=("v110", "v110")) as h5:
        h5.attrs["format"] = FORMAT
        h5.attrs["format_version"] = FORMAT_VERSION
        h5.attrs["tactsense_version"] = __version__
        h5.attrs["created"] = _dt.datetime.now(_dt.UTC).isoformat(timespec="seconds")
        h5.attrs["sensor_toml"] = spec.to_toml_string()
        h5.attrs["scenario_json"] = json.dumps(plan.scenario)
        h5.attrs["flaws"] = ",".join(active)
        h5.attrs["scan_rate_hz"] = spec.electronics.scan_rate_hz
        h5.attrs["source"] = ""
        frames = h5.create_dataset(
            "frames", (n, *spec.shape), dtype, chunks=(chunk, *spec.shape),
            maxshape=(None, *spec.shape), compression="gzip", fletcher32=True,
        )  # fmt: skip
        frames.attrs["units"] = "counts"
        frames.attrs["axes"] = kind_of(spec).frame_axes
        times = h5.create_dataset("time", (n,), float, chunks=(chunk,), fletcher32=True)
        times.attrs["units"] = "s"
        h5.create_dataset("sample_offset", data=sample_offsets(spec)).attrs["units"] = "s"
        h5.create_dataset("gains", data=plan.gains(name)).attrs["units"] = "1"
        group = h5.create_group("truth")
        for first, last, block, truth in plan.blocks(name):
            frames[first:last] = block.astype(dtype, copy=False)
            times[first:last] = np.arange(first, last) / spec.electronics.scan_rate_hz
            for key, value in truth.items():
                if isinstance(value, str):
                    group.attrs[key] = value
                elif key not in TIME_KEYS:
                    if key not in group:
                        group.create_dataset(key, data=value).attrs["units"] = "1"
                else:
                    if key not in group:
                        dataset = group.create_dataset(
                            key, (n, *value.shape[1:]), value.dtype,
                            chunks=(chunk, *value.shape[1:]), fletcher32=True,
                        )  # fmt: skip
                        dataset.attrs["units"] = TRUTH_UNITS.get(key, "1")
                    group[key][first:last] = value
            yield last - first
