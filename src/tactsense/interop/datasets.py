"""Labelled data sets at scale: simulated episodes to LeRobot v3 and HDF5, on Dask.

:func:`write_dataset` makes the episodes of a :class:`~tactsense.simulate.dataset.DatasetPlan`
(:mod:`tactsense.simulate.dataset`: presses, slides and grasps with their ground truth)
a few at a time as tasks on a Dask cluster (or in this process without one), and writes
them in episode order as they come back: at most ``window`` tasks are in flight, so
memory stays bounded however many episodes the set holds. Each task computes its
episodes' LeRobot statistics too; the writer merges them as LeRobot's
``aggregate_stats`` does.

Formats:

``lerobot``
    A LeRobot v3.0 dataset folder, the layout of :mod:`tactsense.interop.lerobot`
    (``observation.tactile``, ``frame_time`` and LeRobot's indices), the data split in
    files of about :data:`~tactsense.interop.lerobot.DATA_FILES_SIZE_IN_MB` MB as LeRobot
    splits them, one task per episode kind (``press``, ``slide``, ``grasp``), and the
    labels as the feature ``label.contacts`` (:func:`label_names`).
``hdf5``
    One tactsense recording (``tactsense locate``, ``view`` and every reader of
    recordings read it; the episodes back to back, ``time`` continuous) with the
    groups ``/episodes`` (``start``, ``length``, ``task_index``; the task names in its
    attribute ``tasks``) and ``/labels`` (``(frames, K)`` arrays, :data:`LABEL_UNITS`).
"""

from __future__ import annotations

import json
import os
import shutil
from collections import deque
from pathlib import Path

import numpy as np

from tactsense.interop.lerobot import (
    CHUNKS_SIZE,
    DATA_FILES_SIZE_IN_MB,
    DATA_PATH,
    EPISODES_PATH,
    LeRobotError,
    _hf_features,
    _listed,
    _stats,
    _write_json,
    features_of,
    lerobot_info,
    write_tasks_parquet,
)
from tactsense.simulate.dataset import MAX_CONTACTS, TASKS, DatasetError, DatasetPlan, episodes

FORMATS = ("lerobot", "hdf5")
LABEL_FIELDS = (
    "present", "id", "x_mm", "y_mm", "normal_force_n", "shear_x_n", "shear_y_n", "slip",
    "radius_mm",
)  # fmt: skip
LABEL_UNITS = {
    "position_mm": "mm",
    "normal_force_n": "N",
    "tangential_force_n": "N",
    "radius_mm": "mm",
    "slip": "1",
    "contact_id": "1",
}
LABEL_FEATURE = "label.contacts"


def label_names(slots: int = MAX_CONTACTS) -> tuple[str, ...]:
    """The names of ``label.contacts``: ``contacts.count`` then ``contact{k}.<field>``
    per slot (:data:`LABEL_FIELDS`; units in the names, id -1 in an empty slot)."""
    return ("contacts.count", *(f"contact{k}.{f}" for k in range(slots) for f in LABEL_FIELDS))


def label_rows(ep) -> np.ndarray:
    """An episode's labels as ``label.contacts`` rows, float32 ``(frames, 1 + 9 K)``."""
    n = len(ep.normal_force_n)
    present = ep.present
    fields = np.stack(
        [
            present, ep.contact_id, ep.position_mm[..., 0], ep.position_mm[..., 1],
            ep.normal_force_n, ep.tangential_force_n[..., 0], ep.tangential_force_n[..., 1],
            ep.slip, ep.radius_mm,
        ],
        axis=-1,
    ).astype(np.float32)  # fmt: skip
    fields = np.where(present[..., None], fields, 0.0)  # 0 in an empty slot, its id -1
    fields[..., 1] = ep.contact_id
    return np.concatenate([present.sum(axis=1, keepdims=True), fields.reshape(n, -1)], axis=1)


def _columns(ep, spec, fps: int) -> dict:
    """An episode's LeRobot columns; ``frame_time`` [s] runs on through the set, as the
    HDF5 set's ``time`` (every episode has the plan's length)."""
    n = len(ep.frames)
    frame_index = np.arange(n, dtype=np.int64)
    return {
        "observation.tactile": np.asarray(ep.frames, dtype=np.float32),
        LABEL_FEATURE: label_rows(ep),
        "frame_time": (ep.index * n + frame_index) * spec.scan_period_s,
        "timestamp": (frame_index / fps).astype(np.float32),
        "frame_index": frame_index,
    }


def _features(spec) -> dict:
    features = features_of(spec.shape)
    features.pop("observation.state")
    names = label_names()
    labels = {"dtype": "float32", "shape": [len(names)], "names": list(names)}
    return {"observation.tactile": features.pop("observation.tactile"), LABEL_FEATURE: labels,
            **features}  # fmt: skip


def _fps(spec) -> int:
    return int(max(1, round(spec.electronics.scan_rate_hz)))


def _frame_dtype(plan: DatasetPlan, fmt: str):
    """float32 for LeRobot (its ``observation.tactile``); for HDF5 uint16 counts when
    quantized (as the simulator writes them), else float64."""
    from tactsense.simulate.contact_frames import resolve_flaws

    if fmt == "lerobot":
        return np.float32
    return np.uint16 if "quantization" in resolve_flaws(plan.flaws) else np.float64


def make_block(spec, plan: DatasetPlan, first: int, count: int, fmt: str) -> list:
    """One Dask task: episodes ``first`` to ``first + count`` and, for LeRobot, each
    one's statistics (LeRobot's ``compute_episode_stats``)."""
    made = episodes(spec, plan, first, count)
    for ep in made:  # what the format stores, and a quarter of the bytes back from a worker
        ep.frames = ep.frames.astype(_frame_dtype(plan, fmt), copy=False)
    if fmt != "lerobot":
        return [(ep, None) for ep in made]
    features = _features(spec)
    out = []
    for ep in made:
        columns = _columns(ep, spec, _fps(spec))
        columns["task_index"] = np.full(len(ep.frames), plan.tasks.index(ep.task), np.int64)
        stats = {
            key: _stats(values, features[key]["shape"] == [1]) for key, values in columns.items()
        }
        out.append((ep, stats))
    return out


class _Merged:
    """Statistics of episodes merged as LeRobot's ``aggregate_feature_stats`` merges
    them: min of mins, max of maxes, count-weighted mean, the pooled variance, and
    count-weighted quantiles."""

    def __init__(self):
        self.parts: dict[str, dict] = {}

    def add(self, stats: dict) -> None:
        for key, ft in stats.items():
            count = float(ft["count"][0])
            mean = np.asarray(ft["mean"], float)
            acc = self.parts.setdefault(key, {"count": 0.0})
            if acc["count"] == 0:
                acc.update(min=ft["min"], max=ft["max"], sum=mean * 0, square=mean * 0)
                acc.update({q: np.zeros_like(mean) for q in ft if q.startswith("q")})
            acc["min"] = np.minimum(acc["min"], ft["min"])
            acc["max"] = np.maximum(acc["max"], ft["max"])
            acc["sum"] = acc["sum"] + count * mean
            acc["square"] = acc["square"] + count * (np.asarray(ft["std"], float) ** 2 + mean**2)
            for q in (q for q in ft if q.startswith("q")):
                acc[q] = acc[q] + count * np.asarray(ft[q], float)
            acc["count"] += count

    def result(self) -> dict:
        out = {}
        for key, acc in self.parts.items():
            n = acc["count"]
            mean = acc["sum"] / n
            std = np.sqrt(np.maximum(acc["square"] / n - mean**2, 0.0))
            ft = {"min": acc["min"], "max": acc["max"], "mean": mean, "std": std,
                  "count": np.array([int(n)])}  # fmt: skip
            ft.update({q: acc[q] / n for q in acc if q.startswith("q")})
            out[key] = ft
        return out


class LeRobotEpisodesWriter:
    """A LeRobot v3.0 dataset written an episode at a time (bounded memory).

    Data files roll over at about ``file_mb`` MB, after a whole episode, as LeRobot's
    own writer does; ``close`` writes the episodes' metadata, the merged statistics,
    the tasks and ``info.json``.
    """

    def __init__(
        self, folder: Path, spec, plan: DatasetPlan, *, file_mb: float = DATA_FILES_SIZE_IN_MB
    ):
        import pyarrow as pa

        self.folder, self.spec, self.plan = Path(folder), spec, plan
        self.file_bytes = int(file_mb * 1024 * 1024)
        self.fps = _fps(spec)
        self.features = _features(spec)
        metadata = {"huggingface": json.dumps({"info": {"features": _hf_features(self.features)}})}
        self.schema = pa.schema(
            [
                ("observation.tactile", pa.list_(pa.list_(pa.float32()))),
                (LABEL_FEATURE, pa.list_(pa.float32(), len(label_names()))),
                ("frame_time", pa.float64()),
                ("timestamp", pa.float32()),
                ("frame_index", pa.int64()),
                ("episode_index", pa.int64()),
                ("index", pa.int64()),
                ("task_index", pa.int64()),
            ],
            metadata=metadata,
        )
        self.chunk = self.file = 0
        self.writer = None
        self.file_written = 0
        self.frames = 0
        self.episode_rows: list[dict] = []
        self.stats = _Merged()

    def _path(self) -> Path:
        return self.folder / DATA_PATH.format(chunk_index=self.chunk, file_index=self.file)

    def add(self, ep, stats: dict) -> None:
        import pyarrow as pa
        import pyarrow.parquet as pq

        n = len(ep.frames)
        rows, cols = self.spec.shape
        columns = _columns(ep, self.spec, self.fps)
        task_index = self.plan.tasks.index(ep.task)
        if self.writer is None:
            self._path().parent.mkdir(parents=True, exist_ok=True)
            self.writer = pq.ParquetWriter(self._path(), self.schema)
        flat = pa.array(columns["observation.tactile"].reshape(-1), type=pa.float32())
        inner = pa.FixedSizeListArray.from_arrays(flat, cols).cast(pa.list_(pa.float32()))
        offsets = pa.array(np.arange(0, n * rows + 1, rows, dtype=np.int32))
        labels = columns[LABEL_FEATURE]
        arrays = [
            pa.ListArray.from_arrays(offsets, inner),
            pa.FixedSizeListArray.from_arrays(pa.array(labels.reshape(-1)), labels.shape[1]),
            pa.array(columns["frame_time"]),
            pa.array(columns["timestamp"]),
            pa.array(columns["frame_index"]),
            pa.array(np.full(n, ep.index, np.int64)),
            pa.array(np.arange(self.frames, self.frames + n, dtype=np.int64)),
            pa.array(np.full(n, task_index, np.int64)),
        ]
        table = pa.Table.from_arrays(arrays, schema=self.schema)
        self.writer.write_table(table)
        self.file_written += table.nbytes  # in memory, as LeRobot's writer measures a file
        row = {
            "episode_index": ep.index,
            "tasks": [ep.task],
            "length": n,
            "data/chunk_index": self.chunk,
            "data/file_index": self.file,
            "dataset_from_index": self.frames,
            "dataset_to_index": self.frames + n,
            "meta/episodes/chunk_index": 0,
            "meta/episodes/file_index": 0,
        }
        stats = {**stats, "episode_index": _stats(np.full(n, ep.index), True),
                 "index": _stats(np.arange(self.frames, self.frames + n), True)}  # fmt: skip
        for key, feature in _listed(stats).items():
            for name, value in feature.items():
                row[f"stats/{key}/{name}"] = value
        self.episode_rows.append(row)
        self.stats.add(stats)
        self.frames += n
        if self.file_written >= self.file_bytes:  # the next episode: a new file
            self.writer.close()
            self.writer, self.file_written = None, 0
            self.file += 1
            if self.file >= CHUNKS_SIZE:
                self.chunk, self.file = self.chunk + 1, 0

    def close(self) -> dict:
        import pyarrow as pa
        import pyarrow.parquet as pq

        if self.writer is not None:
            self.writer.close()
        episodes_file = self.folder / EPISODES_PATH.format(chunk_index=0, file_index=0)
        episodes_file.parent.mkdir(parents=True, exist_ok=True)
        pq.write_table(pa.Table.from_pylist(self.episode_rows), episodes_file)
        _write_json(self.folder / "meta" / "stats.json", _listed(self.stats.result()))
        write_tasks_parquet(self.folder / "meta" / "tasks.parquet", list(self.plan.tasks))
        info = lerobot_info(
            self.fps, self.features, episodes=len(self.episode_rows), frames=self.frames,
            tasks=len(self.plan.tasks),
        )  # fmt: skip
        _write_json(self.folder / "meta" / "info.json", info)
        _write_json(
            self.folder / "meta" / "tactsense.json",
            {
                "sensor_toml": self.spec.to_toml_string(),
                "scan_rate_hz": float(self.spec.electronics.scan_rate_hz),
                "frame_time_units": "s",
                "source": "simulated data set",
                "plan": self.plan.to_dict(),
                "labels": {
                    "feature": LABEL_FEATURE,
                    "names": list(label_names()),
                    "units": "in the names; id -1 in an empty slot",
                },
            },
        )
        files = len(list((self.folder / "data").glob("*/*.parquet")))
        return {"frames": self.frames, "episodes": len(self.episode_rows), "fps": self.fps,
                "data_files": files}  # fmt: skip


class HDF5EpisodesWriter:
    """The episodes as one tactsense recording with ``/episodes`` and ``/labels``,
    written an episode at a time (chunked, gzip, Fletcher-32 as the simulator's)."""

    CHUNK = 1024

    def __init__(self, path: Path, spec, plan: DatasetPlan):
        import datetime as _dt

        import h5py

        from tactsense._version import __version__
        from tactsense.io.recording import FORMAT, FORMAT_VERSION
        from tactsense.physics.transduction import sample_offsets
        from tactsense.simulate.contact_frames import resolve_flaws

        self.spec, self.plan = spec, plan
        flaws = resolve_flaws(plan.flaws)
        self.dtype = _frame_dtype(plan, "hdf5")
        self.h5 = h5 = h5py.File(path, "w", libver=("earliest", "latest"))
        h5.attrs["format"] = FORMAT
        h5.attrs["format_version"] = FORMAT_VERSION
        h5.attrs["tactsense_version"] = __version__
        h5.attrs["created"] = _dt.datetime.now(_dt.UTC).isoformat(timespec="seconds")
        h5.attrs["sensor_toml"] = spec.to_toml_string()
        h5.attrs["scenario_json"] = json.dumps({"dataset": plan.to_dict()})
        h5.attrs["flaws"] = ",".join(flaws)  # those applied: the per-frame flaws
        h5.attrs["scan_rate_hz"] = spec.electronics.scan_rate_hz
        h5.attrs["source"] = "simulated data set"
        shape, k = spec.shape, MAX_CONTACTS

        def grow(name, tail, dtype, group=h5, units=None, compress=True):
            ds = group.create_dataset(
                name, (0, *tail), dtype, chunks=(self.CHUNK, *tail), maxshape=(None, *tail),
                compression="gzip" if compress else None, fletcher32=True,
            )  # fmt: skip
            if units:
                ds.attrs["units"] = units
            return ds

        self.frames = grow("frames", shape, self.dtype, units="counts")
        self.frames.attrs["axes"] = ("row", "col")
        self.time = grow("time", (), float, units="s", compress=False)
        h5.create_dataset("sample_offset", data=sample_offsets(spec)).attrs["units"] = "s"
        labels = h5.create_group("labels")
        labels.attrs["contact_slots"] = k
        self.labels = {
            "position_mm": grow("position_mm", (k, 2), np.float32, labels, "mm"),
            "normal_force_n": grow("normal_force_n", (k,), np.float32, labels, "N"),
            "tangential_force_n": grow("tangential_force_n", (k, 2), np.float32, labels, "N"),
            "radius_mm": grow("radius_mm", (k,), np.float32, labels, "mm"),
            "slip": grow("slip", (k,), np.uint8, labels, "1"),
            "contact_id": grow("contact_id", (k,), np.int32, labels, "1"),
            "episode_index": grow("episode_index", (), np.int64, labels, "1"),
            "frame_index": grow("frame_index", (), np.int64, labels, "1"),
        }
        self.starts: list[int] = []
        self.tasks: list[int] = []
        self.n = 0

    def add(self, ep, stats=None) -> None:
        n, lo = len(ep.frames), self.n
        hi = lo + n
        for ds in (self.frames, self.time, *self.labels.values()):
            ds.resize(hi, axis=0)
        self.frames[lo:hi] = np.asarray(ep.frames).astype(self.dtype, copy=False)
        self.time[lo:hi] = np.arange(lo, hi) * self.spec.scan_period_s
        for name in ("position_mm", "normal_force_n", "tangential_force_n", "radius_mm", "slip",
                     "contact_id"):  # fmt: skip
            self.labels[name][lo:hi] = getattr(ep, name)
        self.labels["episode_index"][lo:hi] = ep.index
        self.labels["frame_index"][lo:hi] = np.arange(n)
        self.starts.append(lo)
        self.tasks.append(self.plan.tasks.index(ep.task))
        self.n = hi

    def close(self) -> dict:
        group = self.h5.create_group("episodes")
        starts = np.asarray(self.starts, np.int64)
        group.create_dataset("start", data=starts).attrs["units"] = "frames"
        lengths = np.diff(np.append(starts, self.n))
        group.create_dataset("length", data=lengths).attrs["units"] = "frames"
        group.create_dataset("task_index", data=np.asarray(self.tasks, np.int64))
        group.attrs["tasks"] = ",".join(self.plan.tasks)
        self.h5.close()
        return {"frames": self.n, "episodes": len(starts), "fps": _fps(self.spec)}

    def abort(self) -> None:
        self.h5.close()


def _ordered_results(client, spec, plan, fmt, per_task, window):
    """The tasks' results in episode order, at most ``window`` tasks in flight."""
    firsts = iter(range(0, plan.episodes, per_task))
    if client is None:
        for first in firsts:
            yield make_block(spec, plan, first, per_task, fmt)
        return
    pending: deque = deque()

    def submit(first):
        pending.append(client.submit(make_block, spec, plan, first, per_task, fmt,
                                     pure=False, retries=1))  # fmt: skip

    for first in firsts:
        submit(first)
        if len(pending) >= window:
            break
    while pending:
        future = pending.popleft()
        result = future.result()
        future.release()
        nxt = next(firsts, None)
        if nxt is not None:
            submit(nxt)
        yield result


def write_dataset(
    spec,
    plan: DatasetPlan,
    out: str | Path,
    *,
    fmt: str = "lerobot",
    client=None,
    episodes_per_task: int | None = None,
    window: int | None = None,
    progress=None,
    file_mb: float = DATA_FILES_SIZE_IN_MB,
) -> dict:
    """Generate the plan's episodes and write them to ``out`` (a new folder for
    ``lerobot``, a new ``.h5`` file for ``hdf5``), under a temporary name moved into
    place when complete (an interruption leaves nothing).

    ``client``: a :class:`dask.distributed.Client` to make the episodes on (None: in
    this process). ``episodes_per_task``: episodes per Dask task (default: about 20,000
    frames a task). ``window``: tasks in flight (default: twice the workers, at least
    4), which bounds memory. ``progress(done_frames, total_frames)`` after each task.
    Returns ``frames``, ``episodes``, ``fps``, ``episodes_per_task`` (the episodes of
    each task as drawn) and the format's counts.
    """
    if fmt not in FORMATS:
        raise DatasetError(f"format {fmt!r}: choose from {', '.join(FORMATS)}")
    out = Path(out)
    if out.exists():
        raise DatasetError(f"{out} exists; choose a new name for the data set")
    if fmt == "hdf5" and out.suffix.lower() not in (".h5", ".hdf5"):
        raise DatasetError(f"{out}: an HDF5 data set is a file named .h5 (or .hdf5)")
    per_task = int(episodes_per_task or max(1, 20_000 // plan.frames))
    if window is None:
        workers = len(client.scheduler_info().get("workers", {})) if client is not None else 1
        window = max(4, 2 * workers)
    temporary = out.with_name(f".{out.stem}.{os.getpid()}.partial{out.suffix}")
    _remove(temporary)
    writer = None
    try:
        if fmt == "lerobot":
            temporary.mkdir()
            writer = LeRobotEpisodesWriter(temporary, spec, plan, file_mb=file_mb)
        else:
            writer = HDF5EpisodesWriter(temporary, spec, plan)
        done = 0
        drawn = dict.fromkeys(plan.tasks, 0)  # episodes of each task, as drawn
        for block in _ordered_results(client, spec, plan, fmt, per_task, window):
            for ep, stats in block:
                writer.add(ep, stats)
                done += len(ep.frames)
                drawn[ep.task] += 1
            if progress is not None:
                progress(done, plan.total_frames)
        summary = writer.close()
        writer = None
        os.replace(temporary, out)
    except BaseException:
        if isinstance(writer, HDF5EpisodesWriter):
            writer.abort()
        _remove(temporary)
        raise
    return {**summary, "format": fmt, "tasks": list(plan.tasks), "episodes_per_task": drawn}


def _remove(path: Path) -> None:
    if path.is_dir():
        shutil.rmtree(path, ignore_errors=True)
    else:
        path.unlink(missing_ok=True)


__all__ = [
    "FORMATS",
    "LABEL_FIELDS",
    "TASKS",
    "HDF5EpisodesWriter",
    "LeRobotEpisodesWriter",
    "LeRobotError",
    "label_names",
    "label_rows",
    "make_block",
    "write_dataset",
]
