"""A robot recording as one LeRobot v3 dataset, a feature per patch.

``tactsense export RUN/ --format lerobot --out DATASET``: the layout of
:mod:`tactsense.interop.lerobot` (LeRobot's own, codebase version 3.0), with features

* ``observation.tactile.<patch>``: the patch's frame [counts], float32, shape
  ``[rows, cols]``, names ``["row", "col"]`` (row-major, as a tactsense frame);
* ``observation.tactile.<patch>.frame_index``: which frame of the patch's stream that is
  (int64, exact);
* ``observation.tactile.<patch>.frame_time``: that frame's time [s] since the dataset's
  start (float64; LeRobot's reader hands float64 features over as float32);
* ``frame_time``: the row's time [s] since the dataset's start (float64), and LeRobot's
  ``timestamp``, ``frame_index``, ``episode_index``, ``index``, ``task_index``.

The start (the first row's time on the streams' clock: Unix time for a capture) is
``start_time_s`` in ``meta/tactsense.json``: times are kept relative to it because
float32 holds a Unix time to about two minutes only.

Rates: LeRobot keeps one rate per dataset (``fps``, a whole number) while a robot's
patches each scan at their own. The rows are at ``fps`` (default the fastest patch's
rate, rounded), from the latest first frame of all streams (so that every patch has a
frame in every row) to the last frame of any; each row holds every patch's LATEST frame
at or before the row's time (zero-order hold, what a controller reading the hand at that
instant sees), and ``<patch>.frame_index`` says which frame that was, so a slower patch's
repeated frames are visible and nothing is invented. The clock is the streams' host
arrival times when they all hold them (a capture), else their frame times.
``meta/tactsense.json`` keeps the skin (TOML), each patch's sensor and loss counters.
"""

from __future__ import annotations

import json
import os
import shutil
from pathlib import Path

import numpy as np

from tactsense.interop.lerobot import (
    DATA_PATH,
    DEFAULT_TASK,
    EPISODES_PATH,
    LeRobotError,
    _hf_features,
    _listed,
    _stats,
    _write_json,
    lerobot_info,
    write_tasks_parquet,
)

MAX_FPS = 10_000
"""Largest ``--fps`` [Hz]."""


def patch_feature(patch: str) -> str:
    return f"observation.tactile.{patch}"


def robot_features(skin, names: list[str]) -> dict:
    """The ``features`` of ``meta/info.json`` for these patches of a skin."""
    features: dict = {}
    for name in names:
        rows, cols = skin.patch(name).sensor.shape
        features[patch_feature(name)] = {
            "dtype": "float32",
            "shape": [rows, cols],
            "names": ["row", "col"],
        }
        features[patch_feature(name) + ".frame_index"] = {
            "dtype": "int64",
            "shape": [1],
            "names": None,
        }
        features[patch_feature(name) + ".frame_time"] = {
            "dtype": "float64",
            "shape": [1],
            "names": None,
        }
    for key, dtype in (
        ("frame_time", "float64"),
        ("timestamp", "float32"),
        ("frame_index", "int64"),
        ("episode_index", "int64"),
        ("index", "int64"),
        ("task_index", "int64"),
    ):
        features[key] = {"dtype": dtype, "shape": [1], "names": None}
    return features


def export_robot_lerobot(
    path: str | Path,
    out: str | Path,
    *,
    fps: int | None = None,
    episode_split: int | None = None,
    task: str = DEFAULT_TASK,
) -> dict:
    """Write a robot recording as a LeRobot v3 dataset folder ``out`` (new).

    Parameters
    ----------
    path : path
        The robot recording (folder).
    out : path
        The dataset folder (must not exist; written beside it and moved into place).
    fps : int, optional
        Rows per second [Hz], 1 to :data:`MAX_FPS` (default: the fastest patch's rate).
    episode_split : int, optional
        Rows per episode (default: one episode).

    Returns
    -------
    dict
        ``rows``, ``episodes``, ``fps``, ``patches``, ``held`` (per patch, rows that
        repeat the previous row's frame) and ``empty`` (streams without a frame, left
        out).
    """
    import pyarrow as pa
    import pyarrow.parquet as pq

    from tactsense.io.recording import read_recording
    from tactsense.io.robot_recording import read_manifest, read_robot_skin, stream_path
    from tactsense.robot import skin_to_toml_string

    path, out = Path(path), Path(out)
    if out.exists():
        raise LeRobotError(f"{out} exists; choose a new folder for the dataset")
    if fps is not None and not 1 <= int(fps) <= MAX_FPS:
        raise LeRobotError(f"--fps must be 1 to {MAX_FPS} Hz; got {fps}")
    if episode_split is not None and episode_split < 1:
        raise LeRobotError(f"--episode-split must be at least 1 row; got {episode_split}")
    manifest = read_manifest(path)
    skin = read_robot_skin(path)
    names = [
        p.name
        for p in skin.patches
        if p.name in manifest.get("streams", []) and stream_path(path, p.name).is_file()
    ]
    if not names:
        raise LeRobotError(f"{path}: the robot recording holds no stream")
    streams = {name: read_recording(stream_path(path, name)) for name in names}
    empty = [name for name, s in streams.items() if len(s) == 0]  # a device that never sent
    names = [name for name in names if name not in empty]
    streams = {name: streams[name] for name in names}
    if not names:
        raise LeRobotError(f"{path}: every stream of the robot recording is empty")
    host = all(s.host_time_s is not None for s in streams.values())
    times = {
        name: np.asarray(s.host_time_s if host else s.time_s, float) for name, s in streams.items()
    }
    rate = max(s.sensor.electronics.scan_rate_hz for s in streams.values())
    fps = int(fps or max(1, round(rate)))
    start = max(t[0] for t in times.values())
    stop = max(t[-1] for t in times.values())
    n = int(np.floor((stop - start) * fps + 1e-9)) + 1
    since_start = np.arange(n) / fps
    row_time = start + since_start
    split = int(episode_split or n)
    starts = list(range(0, n, split))
    episode = np.repeat(np.arange(len(starts)), [min(n, s + split) - s for s in starts])
    frame_index = np.concatenate([np.arange(min(n, s + split) - s) for s in starts])
    columns: dict[str, np.ndarray] = {}
    held = {}
    for name in names:
        # the latest frame at or before each row (every row is at or after its first)
        pick = np.searchsorted(times[name], row_time + 1e-9, side="right") - 1
        columns[patch_feature(name)] = np.asarray(streams[name].frames[pick], np.float32)
        columns[patch_feature(name) + ".frame_index"] = pick.astype(np.int64)
        columns[patch_feature(name) + ".frame_time"] = times[name][pick] - start
        held[name] = int(np.count_nonzero(np.diff(pick) == 0))
    columns["frame_time"] = since_start
    columns["timestamp"] = (frame_index / fps).astype(np.float32)
    columns["frame_index"] = frame_index.astype(np.int64)
    columns["episode_index"] = episode.astype(np.int64)
    columns["index"] = np.arange(n, dtype=np.int64)
    columns["task_index"] = np.zeros(n, dtype=np.int64)
    features = robot_features(skin, names)

    temporary = out.with_name(f".{out.name}.{os.getpid()}.partial")
    shutil.rmtree(temporary, ignore_errors=True)
    try:
        temporary.mkdir()
        arrays = {}
        for key, values in columns.items():
            if values.ndim == 3:  # a frame: a list of rows, each a list of cols
                rows, cols = values.shape[1:]
                inner = pa.FixedSizeListArray.from_arrays(
                    pa.array(values.reshape(-1), type=pa.float32()), cols
                )
                arrays[key] = pa.ListArray.from_arrays(
                    pa.array(np.arange(0, n * rows + 1, rows, dtype=np.int32)),
                    inner.cast(pa.list_(pa.float32())),
                )
            else:
                arrays[key] = pa.array(values)
        metadata = {"huggingface": json.dumps({"info": {"features": _hf_features(features)}})}
        data_file = temporary / DATA_PATH.format(chunk_index=0, file_index=0)
        data_file.parent.mkdir(parents=True)
        pq.write_table(pa.table(arrays).replace_schema_metadata(metadata), data_file)
        episode_rows = []
        for e, s in enumerate(starts):
            end = min(n, s + split)
            stats = {k: _stats(columns[k][s:end], features[k]["shape"] == [1]) for k in features}
            row = {
                "episode_index": e, "tasks": [task], "length": end - s,
                "data/chunk_index": 0, "data/file_index": 0,
                "dataset_from_index": s, "dataset_to_index": end,
                "meta/episodes/chunk_index": 0, "meta/episodes/file_index": 0,
            }  # fmt: skip
            for key, feature in _listed(stats).items():
                for stat, value in feature.items():
                    row[f"stats/{key}/{stat}"] = value
            episode_rows.append(row)
        episodes_file = temporary / EPISODES_PATH.format(chunk_index=0, file_index=0)
        episodes_file.parent.mkdir(parents=True)
        pq.write_table(pa.Table.from_pylist(episode_rows), episodes_file)
        stats = {k: _stats(columns[k], features[k]["shape"] == [1]) for k in features}
        _write_json(temporary / "meta" / "stats.json", _listed(stats))
        write_tasks_parquet(temporary / "meta" / "tasks.parquet", [task])
        _write_json(
            temporary / "meta" / "info.json",
            lerobot_info(fps, features, episodes=len(starts), frames=n, robot_type=skin.name),
        )
        _write_json(
            temporary / "meta" / "tactsense.json",
            {
                "skin_toml": skin_to_toml_string(skin),
                "patches": {
                    name: {
                        "sensor_toml": streams[name].sensor.to_toml_string(),
                        "scan_rate_hz": float(streams[name].sensor.electronics.scan_rate_hz),
                        "losses": streams[name].losses,
                    }
                    for name in names
                },
                "clock": "host" if host else "recording",
                "start_time_s": float(start),
                "frame_time_units": "s",
                "source": str(path),
            },
        )
        os.replace(temporary, out)
    except BaseException:
        shutil.rmtree(temporary, ignore_errors=True)
        raise
    return {
        "rows": n, "episodes": len(starts), "fps": fps, "patches": names, "held": held,
        "empty": empty,
    }  # fmt: skip
