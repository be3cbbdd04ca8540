"""A recording as a LeRobot dataset (codebase version 3.0), and back.

The layout is LeRobot's own (``lerobot/datasets/utils.py``, ``feature_utils.py``,
``dataset_metadata.py``, ``io_utils.py``; ``lerobot/utils/constants.py`` for the default
features)::

    meta/info.json                           codebase_version "v3.0", fps, features, ...
    meta/stats.json                          per feature: min, max, mean, std, count, q01..q99
    meta/tasks.parquet                       index "task" (str), column task_index
    meta/episodes/chunk-000/file-000.parquet one row per episode
    data/chunk-000/file-000.parquet          one row per frame
    meta/tactsense.json                      tactsense's own: the sensor, source, losses

Features of a row:

* ``observation.tactile``: the frame [counts], float32, shape ``[rows, cols]``, names
  ``["row", "col"]`` (row-major, as a tactsense frame);
* ``observation.state``: the contact estimate, float32. A finger's one contact: names
  ``contact.present`` (1 or 0), ``contact.axial_mm``, ``contact.angle_deg``,
  ``contact.force_n``, ``contact.row``, ``contact.col`` (0 without a contact; units in
  the names, tactels for row and col). A pad's or a point set's contacts, as ``locate``
  finds and tracks them (at most ``MAX_CONTACTS`` a frame, largest force first):
  ``contacts.count``, then per slot k ``contact{k}.present``, ``.id`` (the tracked id),
  ``.x_mm``, ``.y_mm``, ``.z_mm`` (the sensor's frame), ``.force_n`` and ``.flags``
  (:class:`~tactsense.estimate.Flag` bits; a contact whose force is unknown, a
  saturated one, has force 0 and its flag); 0 in an empty slot;
* ``frame_time``: the frame's recorded time [s] (float64; the device clock);
* LeRobot's ``timestamp`` (float32, ``frame_index / fps``: the time in the episode LeRobot
  assumes), ``frame_index``, ``episode_index``, ``index``, ``task_index``.

Rates: LeRobot keeps one rate per dataset (``fps``, a whole number). tactsense stores one
tactile frame per row and sets ``fps`` to the recording's scan rate, rounded to a whole
number; the recorded time of every frame is kept in ``frame_time``, so frames lost or
a rate that is not a whole number lose nothing. A dataset that joins the tactile
stream with slower cameras resamples it to theirs (LeRobot's ``delta_timestamps`` query
frames by time).
"""

from __future__ import annotations

import json
import os
import shutil
from pathlib import Path

import numpy as np

from tactsense._validation import TactsenseInputError
from tactsense.kinds import kind_of

CODEBASE_VERSION = "v3.0"
CHUNKS_SIZE = 1000
DATA_FILES_SIZE_IN_MB = 100
VIDEO_FILES_SIZE_IN_MB = 200
CHUNK_FILE_PATTERN = "chunk-{chunk_index:03d}/file-{file_index:03d}"
DATA_PATH = "data/" + CHUNK_FILE_PATTERN + ".parquet"
EPISODES_PATH = "meta/episodes/" + CHUNK_FILE_PATTERN + ".parquet"
VIDEO_PATH = "videos/{video_key}/" + CHUNK_FILE_PATTERN + ".mp4"
QUANTILES = (0.01, 0.10, 0.50, 0.90, 0.99)
STATE_NAMES = (
    "contact.present",
    "contact.axial_mm",
    "contact.angle_deg",
    "contact.force_n",
    "contact.row",
    "contact.col",
)
DEFAULT_TASK = "tactile recording"
MAX_CONTACTS = 8
"""Contact slots in a pad's or point set's ``observation.state``: ``locate`` finds at most
this many contacts a frame (``find_contacts``' ``max_contacts``), so none is dropped."""
SLOT_NAMES = ("present", "id", "x_mm", "y_mm", "z_mm", "force_n", "flags")


def contact_state_names(slots: int = MAX_CONTACTS) -> tuple[str, ...]:
    """The ``observation.state`` names of a pad or a point set: ``contacts.count`` and
    ``contact{k}.<field>`` for each slot."""
    slot_names = (f"contact{k}.{field}" for k in range(slots) for field in SLOT_NAMES)
    return ("contacts.count", *slot_names)


class LeRobotError(TactsenseInputError):
    """A LeRobot dataset that cannot be written or read."""


def _pyarrow():
    import pyarrow as pa
    import pyarrow.parquet as pq

    return pa, pq


def features_of(shape: tuple[int, ...], state_names=STATE_NAMES) -> dict:
    """The ``features`` of ``meta/info.json`` for a sensor of this frame shape: ``(rows,
    cols)``, or ``(rows, cols, components)`` for taxels of several components (names
    ``row``, ``col``, ``component``; the components in the sensor's order, x, y, z).
    Without ``state_names`` (a kind that estimates no contacts) no ``observation.state``."""
    axes = ["row", "col", "component"][: len(shape)]
    state = {
        "observation.state": {
            "dtype": "float32",
            "shape": [len(state_names)],
            "names": list(state_names),
        }
    }
    return {
        "observation.tactile": {"dtype": "float32", "shape": list(shape), "names": axes},
        **(state if len(state_names) else {}),
        "frame_time": {"dtype": "float64", "shape": [1], "names": None},
        "timestamp": {"dtype": "float32", "shape": [1], "names": None},
        "frame_index": {"dtype": "int64", "shape": [1], "names": None},
        "episode_index": {"dtype": "int64", "shape": [1], "names": None},
        "index": {"dtype": "int64", "shape": [1], "names": None},
        "task_index": {"dtype": "int64", "shape": [1], "names": None},
    }


def _hf_features(features: dict) -> dict:
    """The ``datasets.Features`` JSON that ``datasets`` keeps in a parquet file's schema."""
    out = {}
    for key, ft in features.items():
        shape = ft["shape"]
        if len(shape) == 1 and shape[0] == 1:
            out[key] = {"dtype": ft["dtype"], "_type": "Value"}
        elif len(shape) == 1:
            out[key] = {
                "feature": {"dtype": ft["dtype"], "_type": "Value"},
                "length": shape[0],
                "_type": "Sequence",
            }
        else:  # datasets' Array2D, Array3D (a frame of three-axis taxels)
            out[key] = {"shape": list(shape), "dtype": ft["dtype"], "_type": f"Array{len(shape)}D"}
    return out


def _stats(values: np.ndarray, scalar: bool) -> dict:
    """LeRobot's statistics of one feature (``compute_stats.compute_episode_stats``).

    Over axis 0, and, as LeRobot's ``RunningQuantileStats`` takes every axis but the last
    as samples, over the rows too for a feature of shape ``[rows, cols]``: its statistics
    have shape ``(cols,)`` (LeRobot 0.4.4 gives ``(16,)`` for a ``[16, 16]`` feature), so
    that LeRobot's ``aggregate_stats`` can merge them with its own. ``count`` is the
    number of frames. Quantiles exact (``numpy.quantile``; LeRobot's are from a
    histogram).
    """
    values = np.asarray(values, dtype=np.float64)
    frames = len(values)
    if values.ndim == 1:
        values = values[:, None]
    values = values.reshape(-1, values.shape[-1])
    stats = {
        "min": values.min(axis=0),
        "max": values.max(axis=0),
        "mean": values.mean(axis=0),
        "std": values.std(axis=0),
        "count": np.array([frames]),
    }
    for q, value in zip(QUANTILES, np.quantile(values, QUANTILES, axis=0), strict=True):
        stats[f"q{round(q * 100):02d}"] = value  # one sort for every quantile
    return {k: (v if k == "count" else v.reshape(-1) if scalar else v) for k, v in stats.items()}


def _listed(stats: dict) -> dict:
    return {
        key: {name: np.asarray(v).tolist() for name, v in feature.items()}
        for key, feature in stats.items()
    }


def _write_json(path: Path, data) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(data, indent=4, ensure_ascii=False) + "\n", encoding="utf-8")


def _state(est, n: int) -> np.ndarray:
    from tactsense.estimate import Flag

    touching = ((est.flags & int(Flag.NO_CONTACT)) == 0) & np.isfinite(est.force_n)
    state = np.zeros((n, len(STATE_NAMES)), dtype=np.float32)
    state[:, 0] = touching
    for j, name in enumerate(("axial_mm", "angle_deg", "force_n", "row", "col"), start=1):
        state[:, j] = np.where(touching, np.nan_to_num(getattr(est, name)), 0.0)
    return state


def _contacts_state(table, start: int, n: int, slots: int = MAX_CONTACTS) -> np.ndarray:
    """``observation.state`` rows of ``n`` frames from a tracked contact table whose
    ``frame`` column counts from ``start`` (rows sorted by frame, then by rank)."""
    width = len(SLOT_NAMES)
    state = np.zeros((n, 1 + slots * width), dtype=np.float32)
    frame = np.asarray(table.frame, dtype=np.int64) - start
    rank = np.asarray(table.contact, dtype=np.int64)
    if len(frame) and (rank.max() >= slots):
        raise LeRobotError(f"a frame has more than {slots} contacts; the state has {slots} slots")
    state[:, 0] = np.bincount(frame, minlength=n)
    force = np.asarray(table.force_n, dtype=float)
    fields = (
        np.ones(len(frame)), table.id, table.x_mm, table.y_mm, table.z_mm,
        np.where(np.isfinite(force), force, 0.0), table.flags,
    )  # fmt: skip
    for j, values in enumerate(fields):
        state[frame, 1 + rank * width + j] = np.nan_to_num(np.asarray(values, dtype=float))
    return state


def write_dataset(
    folder: Path,
    *,
    sensor,
    frames: np.ndarray,
    frame_time: np.ndarray,
    state: np.ndarray,
    state_names=STATE_NAMES,
    episode_split: int | None = None,
    task: str = DEFAULT_TASK,
    fps: int | None = None,
    extra: dict | None = None,
) -> dict:
    """Write the dataset files into ``folder`` (which must be empty or new)."""
    pa, pq = _pyarrow()
    n = len(frames)
    rows, cols = sensor.shape
    if n == 0:
        raise LeRobotError("the recording has no frames")
    fps = int(fps or max(1, round(sensor.electronics.scan_rate_hz)))
    split = int(episode_split or n)
    if split < 1:
        raise LeRobotError(f"--episode-split must be at least 1 frame; got {split}")
    starts = list(range(0, n, split))
    episode = np.zeros(n, dtype=np.int64)
    frame_index = np.zeros(n, dtype=np.int64)
    for e, s in enumerate(starts):
        stop = min(n, s + split)
        episode[s:stop] = e
        frame_index[s:stop] = np.arange(stop - s)
    timestamp = (frame_index / fps).astype(np.float32)
    tactile = np.asarray(frames, dtype=np.float32)
    features = features_of(tuple(sensor.frame_shape), state_names)
    state = np.asarray(state, dtype=np.float32)
    if state.shape != (n, len(state_names)):
        raise LeRobotError(
            f"state has shape {state.shape}; expected ({n}, {len(state_names)}) for its names"
        )
    columns = {
        "observation.tactile": tactile,
        **({"observation.state": state} if len(state_names) else {}),
        "frame_time": np.asarray(frame_time, dtype=np.float64),
        "timestamp": timestamp,
        "frame_index": frame_index,
        "episode_index": episode,
        "index": np.arange(n, dtype=np.int64),
        "task_index": np.zeros(n, dtype=np.int64),
    }

    # data/chunk-000/file-000.parquet, with the datasets.Features LeRobot loads it with
    flat = pa.array(tactile.reshape(-1), type=pa.float32())
    if sensor.components > 1:  # ---- r8-triinterop: list<list<list<float32>>>, Array3D ----
        from tactsense.interop.components import nested_lists

        flat = nested_lists(pa, flat, sensor.components, n * rows * cols)
    inner = pa.FixedSizeListArray.from_arrays(flat, cols)
    arrays = {
        "observation.tactile": pa.ListArray.from_arrays(
            pa.array(np.arange(0, n * rows + 1, rows, dtype=np.int32)),
            inner.cast(pa.list_(flat.type)),
        ),
    }
    if len(state_names):
        arrays["observation.state"] = pa.FixedSizeListArray.from_arrays(
            pa.array(columns["observation.state"].reshape(-1)), len(state_names)
        )
    for key in ("frame_time", "timestamp", "frame_index", "episode_index", "index", "task_index"):
        arrays[key] = pa.array(columns[key])
    metadata = {"huggingface": json.dumps({"info": {"features": _hf_features(features)}})}
    table = pa.table(arrays).replace_schema_metadata(metadata)
    data_file = folder / DATA_PATH.format(chunk_index=0, file_index=0)
    data_file.parent.mkdir(parents=True, exist_ok=True)
    pq.write_table(table, data_file)

    # statistics, per episode and over the dataset
    numeric = [k for k in features if k != "observation.tactile"] + ["observation.tactile"]
    episode_rows = []
    for e, s in enumerate(starts):
        stop = min(n, s + split)
        stats = {k: _stats(columns[k][s:stop], features[k]["shape"] == [1]) for k in numeric}
        row = {
            "episode_index": e,
            "tasks": [task],
            "length": stop - s,
            "data/chunk_index": 0,
            "data/file_index": 0,
            "dataset_from_index": s,
            "dataset_to_index": stop,
            "meta/episodes/chunk_index": 0,
            "meta/episodes/file_index": 0,
        }
        for key, feature in _listed(stats).items():
            for name, value in feature.items():
                row[f"stats/{key}/{name}"] = value
        episode_rows.append(row)
    episodes_file = folder / EPISODES_PATH.format(chunk_index=0, file_index=0)
    episodes_file.parent.mkdir(parents=True, exist_ok=True)
    pq.write_table(pa.Table.from_pylist(episode_rows), episodes_file)
    stats = {k: _stats(columns[k], features[k]["shape"] == [1]) for k in numeric}
    _write_json(folder / "meta" / "stats.json", _listed(stats))

    write_tasks_parquet(folder / "meta" / "tasks.parquet", [task])

    info = lerobot_info(fps, features, episodes=len(starts), frames=n)
    _write_json(folder / "meta" / "info.json", info)
    _write_json(
        folder / "meta" / "tactsense.json",
        {
            "sensor_toml": sensor.to_toml_string(),
            "scan_rate_hz": float(sensor.electronics.scan_rate_hz),
            "frame_time_units": "s",
            **({"components": list(sensor.component_names)} if sensor.components > 1 else {}),
            **(extra or {}),
        },
    )
    return {"frames": n, "episodes": len(starts), "fps": fps}


def export_lerobot(
    recording: str | Path,
    out: str | Path,
    *,
    calibration=None,
    baseline_frames: int = 5,
    threshold: float | None = None,
    episode_split: int | None = None,
    task: str = DEFAULT_TASK,
    progress=None,
    drift_s: float | None = 2.0,
) -> dict:
    """Write a recording and its contact estimates as a LeRobot v3 dataset folder ``out``.

    A finger's contact as ``locate`` estimates it; a pad's or a point set's contacts as
    ``locate`` finds and tracks them (its long table; the baseline following drift with
    ``drift_s`` [s], as there). The dataset is written into a temporary folder beside
    ``out`` and moved into place when complete. Returns ``frames``, ``contacts`` (a
    finger: frames with a contact; a pad or a point set: contacts over all frames),
    ``episodes``, ``fps`` and the sensor's ``kind``.
    """
    from tactsense.batch import iter_locate
    from tactsense.estimate.finger.locate import CONTACT_THRESHOLD
    from tactsense.io.recording import RecordingReader

    out = Path(out)
    if out.exists():
        raise LeRobotError(f"{out} exists; choose a new folder for the dataset")
    if episode_split is not None and episode_split < 1:
        raise LeRobotError(f"--episode-split must be at least 1 frame; got {episode_split}")
    frames, times, states = [], [], []
    with RecordingReader(recording) as reader:
        sensor = reader.sensor
        losses = reader.losses
        if not kind_of(sensor).contact_estimation:  # ---- r8-triinterop: frames alone ----
            from tactsense.interop.components import refuse_contact_options

            refuse_contact_options(sensor, calibration, threshold)
            state_names = ()
            pieces = (
                (start, len(time_s), time_s, np.zeros((len(time_s), 0)))
                for start, _, time_s in reader.chunks()
            )
        elif kind_of(sensor).multi_contact:  # every contact, tracked, as locate's long table
            from tactsense.batch import iter_contacts
            from tactsense.interop.components import (
                component_contacts,
                refuse_contact_options,
                shear_state,
                shear_state_names,
            )

            # r8-triinterop: each slot's tangential force [N] on a shear-sensing kind
            sheared = MAX_CONTACTS if kind_of(sensor).senses_shear else 0
            state_names = contact_state_names() + shear_state_names(sheared)
            found = (
                component_contacts(reader, baseline_frames=baseline_frames,
                                   calibration=calibration, threshold=threshold,
                                   max_contacts=MAX_CONTACTS)
                if sensor.components > 1
                else iter_contacts(
                    reader, baseline_frames=baseline_frames, calibration=calibration,
                    threshold=threshold, max_contacts=MAX_CONTACTS, drift_s=drift_s,
                )
            )  # fmt: skip
            if found is None:  # the three-axis estimator is not installed: frames alone
                refuse_contact_options(sensor, calibration, threshold)
                state_names = ()
                found = ((start, len(t), t, None, None) for start, _, t in reader.chunks())
            pieces = (
                (start, n, time_s, np.zeros((n, 0)) if table is None else np.hstack(
                    [_contacts_state(table, start, n), shear_state(table, start, n, sheared)]))
                for start, n, time_s, table, _ in found
            )  # fmt: skip
        else:  # the one contact of each frame
            state_names = STATE_NAMES
            pieces = (
                (start, len(time_s), time_s, _state(est, len(time_s)))
                for start, time_s, est in iter_locate(
                    reader, baseline_frames=baseline_frames, calibration=calibration,
                    threshold=CONTACT_THRESHOLD if threshold is None else threshold,
                )
            )  # fmt: skip
        for start, n, time_s, state in pieces:
            frames.append(reader.frames(start, start + n))
            times.append(time_s)
            states.append(state)
            if progress is not None:
                progress(start + n, reader.n_frames)
    if not frames:
        raise LeRobotError(f"{recording} has no frames")
    state = np.concatenate(states)
    temporary = out.with_name(f".{out.name}.{os.getpid()}.partial")
    shutil.rmtree(temporary, ignore_errors=True)
    try:
        temporary.mkdir()
        counts = write_dataset(
            temporary,
            sensor=sensor,
            frames=np.concatenate(frames),
            frame_time=np.concatenate(times),
            state=state,
            state_names=state_names,
            episode_split=episode_split,
            task=task,
            extra={"source": str(recording), "losses": losses},
        )
        os.replace(temporary, out)
    except BaseException:
        shutil.rmtree(temporary, ignore_errors=True)
        raise
    # a finger: frames with a contact; a pad or a point set: contacts over all frames
    contacts = int(state[:, 0].sum()) if state.shape[1] else None  # None: not estimated
    return {**counts, "contacts": contacts, "kind": sensor.kind}


def import_lerobot(folder: str | Path, *, sensor=None):
    """A LeRobot dataset with an ``observation.tactile`` feature, as a recording.

    The sensor is the one in ``meta/tactsense.json`` (a dataset tactsense wrote), else
    ``sensor`` (its shape must be the feature's). Times: ``frame_time`` where the dataset
    has it, else ``timestamp`` (made continuous across episodes from ``fps``).
    """
    from tactsense.interop._build import build_recording
    from tactsense.sensor import SensorSpecError, load_sensor, sensor_from_dict

    pa, pq = _pyarrow()
    folder = Path(folder)
    try:
        info = json.loads((folder / "meta" / "info.json").read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as error:
        raise LeRobotError(f"{folder}/meta/info.json is not readable JSON ({error})") from None
    if not isinstance(info, dict):
        raise LeRobotError(f"{folder}/meta/info.json holds no table; expected LeRobot's info")
    if not str(info.get("codebase_version", "")).startswith("v3"):
        raise LeRobotError(
            f"{folder}: codebase_version {info.get('codebase_version')!r}; this reads LeRobot "
            "v3 datasets"
        )
    feature = info.get("features", {}).get("observation.tactile")
    if not feature:
        raise LeRobotError(f"{folder}: no observation.tactile feature in meta/info.json")
    shape = tuple(feature.get("shape", ()))
    losses = {}
    own = folder / "meta" / "tactsense.json"
    if sensor is None and own.is_file():
        import tomllib

        try:
            meta = json.loads(own.read_text(encoding="utf-8"))
            spec = sensor_from_dict(tomllib.loads(meta["sensor_toml"]), source=str(own))
            losses = {str(k): int(v) for k, v in (meta.get("losses") or {}).items()}
        except (OSError, ValueError, KeyError, TypeError, SensorSpecError) as error:
            raise LeRobotError(f"{own}: unreadable ({error})") from None
    elif sensor is None:
        raise LeRobotError(
            f"{folder}: not written by tactsense (no meta/tactsense.json); pass --sensor"
        )
    else:
        try:
            spec = load_sensor(sensor)
        except SensorSpecError as error:
            raise LeRobotError(f"--sensor: {error}") from None
    if shape != tuple(spec.frame_shape):
        raise LeRobotError(
            f"{folder}: observation.tactile has shape {list(shape)}; sensor {spec.name!r} "
            f"has {list(spec.frame_shape)}"
        )
    paths = sorted((folder / "data").glob("*/*.parquet"))
    if not paths:
        raise LeRobotError(f"{folder}: no data/chunk-*/file-*.parquet files")
    frames, times = [], []
    for path in paths:
        try:
            table = pq.read_table(path)
        except (OSError, pa.ArrowInvalid) as error:
            raise LeRobotError(f"{path} is not a readable parquet file ({error})") from None
        if "index" in table.column_names:
            table = table.sort_by("index")
        tactile = np.asarray(table.column("observation.tactile").to_pylist(), dtype=np.float64)
        frames.append(tactile.reshape(-1, *spec.frame_shape))
        if "frame_time" in table.column_names:
            times.append(table.column("frame_time").to_numpy())
        else:
            times.append(np.asarray(table.column("index").to_numpy(), float) / float(info["fps"]))
    return build_recording(
        spec, list(np.concatenate(frames)), np.concatenate(times), source=str(folder),
        description=f"imported from the LeRobot dataset {folder}", losses=losses,
    )  # fmt: skip


def lerobot_info(
    fps: float,
    features: dict,
    *,
    episodes: int,
    frames: int,
    tasks: int = 1,
    robot_type: str | None = None,
) -> dict:
    """LeRobot v3's ``meta/info.json``: one data file per chunk, no video, one split."""
    return {
        "codebase_version": CODEBASE_VERSION,
        "fps": fps,
        "features": features,
        "total_episodes": episodes,
        "total_frames": frames,
        "total_tasks": tasks,
        "chunks_size": CHUNKS_SIZE,
        "data_files_size_in_mb": DATA_FILES_SIZE_IN_MB,
        "video_files_size_in_mb": VIDEO_FILES_SIZE_IN_MB,
        "data_path": DATA_PATH,
        "video_path": None,
        "robot_type": robot_type,
        "splits": {"train": f"0:{episodes}"},
    }  # fmt: skip


def write_tasks_parquet(path: Path, tasks: list[str]) -> None:
    """``meta/tasks.parquet`` as pandas writes a frame indexed by ``task`` (LeRobot reads
    it with ``pandas.read_parquet``): the metadata that makes ``task`` the index, without
    pandas here; task ``i`` has ``task_index`` i."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    pandas_meta = {
        "index_columns": ["task"],
        "column_indexes": [
            {"name": None, "field_name": None, "pandas_type": "unicode",
             "numpy_type": "object", "metadata": {"encoding": "UTF-8"}}
        ],
        "columns": [
            {"name": "task_index", "field_name": "task_index", "pandas_type": "int64",
             "numpy_type": "int64", "metadata": None},
            {"name": "task", "field_name": "task", "pandas_type": "unicode",
             "numpy_type": "object", "metadata": None},
        ],
        "creator": {"library": "pyarrow", "version": pa.__version__},
    }  # fmt: skip
    table = pa.table(
        {
            "task_index": pa.array(range(len(tasks)), pa.int64()),
            "task": pa.array(tasks, pa.string()),
        }
    ).replace_schema_metadata({"pandas": json.dumps(pandas_meta)})
    pq.write_table(table, path)
