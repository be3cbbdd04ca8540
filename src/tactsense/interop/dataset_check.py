"""Reading a labelled data set back and checking it, a piece at a time (bounded memory).

:func:`check_dataset` reads a data set written by
:func:`tactsense.interop.datasets.write_dataset` (a LeRobot v3 folder with pyarrow, or
the HDF5 recording with h5py) batch by batch and checks:

* structure: the frame and episode counts of the metadata; LeRobot's ``index``
  consecutive from 0, every episode's rows where its ``dataset_from_index`` /
  ``dataset_to_index`` say, ``frame_index`` counting from 0 in each, ``timestamp`` =
  ``frame_index / fps``; the HDF5 ``/episodes`` and ``/labels`` indices alike;
* frames: finite, within the A/D range ``[0, 2^bits - 1]`` [counts];
* labels: ``contacts.count`` the number of present slots, a present slot's id its
  slot and an empty one's -1, forces >= 0 and a slip only where a contact is present;
* LeRobot's ``meta/stats.json``: ``min``, ``max`` and ``count`` of
  ``observation.tactile`` equal to those of the data read back;
* labels against frames: on every ``sample``-th frame with exactly one contact of at
  least ``min_force_n`` [N] whose centre is ``margin`` pitches inside the grid, the
  position ``locate`` finds (:func:`~tactsense.estimate.contacts.find_contacts`, the
  largest contact, the baseline the median of frames without contact) against the
  labelled one: the error distribution [mm] and its mean (a bias) are returned.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from tactsense._validation import TactsenseInputError
from tactsense.kinds import kind_of
from tactsense.simulate.dataset import surface_area


class DatasetCheckError(TactsenseInputError):
    """A data set that fails a check: the first failure, in words."""


def _require(ok, message: str) -> None:
    if not bool(ok):
        raise DatasetCheckError(message)


def _in_range(frames, full_scale: int) -> bool:
    return bool(np.all(np.isfinite(frames)) and frames.min() >= 0 and frames.max() <= full_scale)


def _check_labels(present, ids, normal, slip, count=None, where="") -> None:
    k = present.shape[1]
    _require(np.all(normal >= 0), f"{where}: a negative normal force")
    expected = np.where(present, np.arange(k), -1)
    _require(np.array_equal(ids, expected), f"{where}: a contact id is not its slot (-1 if empty)")
    _require(np.all(slip[~present] == 0), f"{where}: a slip flag on an empty slot")
    if count is not None:
        _require(np.array_equal(count, present.sum(axis=1)), f"{where}: contacts.count wrong")


class _Sampler:
    """Frames picked for the locate check, and the frames without contact for its
    baseline (at most ``keep`` of each)."""

    def __init__(self, spec, sample: int, min_force_n: float, margin: float, keep=20_000):
        self.spec, self.sample, self.min_force_n, self.keep = spec, sample, min_force_n, keep
        (x0, x1), (y0, y1) = surface_area(spec)
        (row_pitch, _), (col_pitch, _) = kind_of(spec).surface_grid(spec)
        self.box = (x0 + margin * row_pitch, x1 - margin * row_pitch,
                    y0 + margin * col_pitch, y1 - margin * col_pitch)  # fmt: skip
        self.frames, self.truth, self.empty = [], [], []
        self.kept = self.empty_kept = 0

    def add(self, first: int, frames, present, position, normal) -> None:
        index = np.arange(first, first + len(frames))
        if self.empty_kept < self.keep:
            none = np.flatnonzero(~present.any(axis=1))[: self.keep - self.empty_kept]
            self.empty.append(np.asarray(frames[none], float))
            self.empty_kept += len(none)
        one = present.sum(axis=1) == 1
        slot = np.argmax(present, axis=1)
        rows = np.arange(len(frames))
        where = position[rows, slot]
        x0, x1, y0, y1 = self.box
        inside = (
            (where[:, 0] >= x0) & (where[:, 0] <= x1) & (where[:, 1] >= y0) & (where[:, 1] <= y1)
        )
        pick = one & inside & (normal[rows, slot] >= self.min_force_n) & (index % self.sample == 0)
        pick = np.flatnonzero(pick)[: max(0, self.keep - self.kept)]
        self.frames.append(np.asarray(frames[pick], float))
        self.truth.append(where[pick])
        self.kept += len(pick)

    def errors(self) -> np.ndarray:
        from tactsense.estimate.contacts import find_contacts

        if not self.kept or not self.empty_kept:
            return np.zeros((0, 2))
        frames = np.concatenate(self.frames)
        truth = np.concatenate(self.truth)
        baseline = np.median(np.concatenate(self.empty), axis=0)
        table = find_contacts(frames, self.spec, baseline=baseline)
        found = np.full((len(frames), 2), np.nan)
        first = table.contact == 0  # the largest contact of each frame
        found[table.frame[first]] = np.column_stack([table.x_mm[first], table.y_mm[first]])
        return found - truth  # NaN: nothing found


def _lerobot(folder: Path, sampler: _Sampler, spec, progress) -> dict:
    import pyarrow.parquet as pq

    info = json.loads((folder / "meta" / "info.json").read_text(encoding="utf-8"))
    stats = json.loads((folder / "meta" / "stats.json").read_text(encoding="utf-8"))
    episodes = pq.read_table(sorted((folder / "meta" / "episodes").glob("*/*.parquet"))).to_pydict()
    fps, total = int(info["fps"]), int(info["total_frames"])
    _require(len(episodes["episode_index"]) == info["total_episodes"], "episode count")
    starts = np.asarray(episodes["dataset_from_index"])
    stops = np.asarray(episodes["dataset_to_index"])
    _require(starts[0] == 0 and np.array_equal(starts[1:], stops[:-1]) and stops[-1] == total,
             "episodes do not tile the frames")  # fmt: skip
    names = info["features"]["label.contacts"]["names"]
    k = (len(names) - 1) // 9
    full_scale = 2**spec.electronics.adc_bits - 1
    low = np.full(spec.shape[1], np.inf)
    high = np.full(spec.shape[1], -np.inf)
    seen = 0
    for path in sorted((folder / "data").glob("*/*.parquet")):
        for batch in pq.ParquetFile(path).iter_batches(batch_size=8192):
            n = batch.num_rows
            column = batch.column("observation.tactile").flatten().flatten()
            tactile = np.asarray(column.to_numpy()).reshape(n, *spec.shape)
            labels = np.asarray(batch.column("label.contacts").flatten().to_numpy()).reshape(n, -1)
            index = batch.column("index").to_numpy()
            episode = batch.column("episode_index").to_numpy()
            frame_index = batch.column("frame_index").to_numpy()
            timestamp = batch.column("timestamp").to_numpy()
            _require(
                np.array_equal(index, np.arange(seen, seen + n)), f"{path}: index not consecutive"
            )
            _require(np.array_equal(index - starts[episode], frame_index),
                     f"{path}: frame_index disagrees with the episodes' from-index")  # fmt: skip
            _require(np.allclose(timestamp, frame_index / fps, atol=1e-4), f"{path}: timestamp")
            _require(_in_range(tactile, full_scale), f"{path}: a frame off the A/D range")
            slots = labels[:, 1:].reshape(n, k, 9)
            present = slots[..., 0] > 0
            _check_labels(present, slots[..., 1].astype(int), slots[..., 4], slots[..., 7],
                          labels[:, 0], where=str(path))  # fmt: skip
            low = np.minimum(low, tactile.min(axis=(0, 1)))
            high = np.maximum(high, tactile.max(axis=(0, 1)))
            sampler.add(seen, tactile, present, slots[..., 2:4], slots[..., 4])
            seen += n
            if progress is not None:
                progress(seen, total)
    _require(seen == total, f"{seen} frames read; info.json says {total}")
    tactile_stats = stats["observation.tactile"]
    _require(np.array_equal(np.asarray(tactile_stats["min"], float), low), "stats.json min")
    _require(np.array_equal(np.asarray(tactile_stats["max"], float), high), "stats.json max")
    _require(tactile_stats["count"] == [total], "stats.json count")
    return {"frames": seen, "episodes": len(starts)}


def _hdf5(path: Path, sampler: _Sampler, spec, progress) -> dict:
    import h5py

    from tactsense.io.recording import RecordingReader

    with RecordingReader(path) as reader:  # a recording every reader of them reads
        total = reader.n_frames
    full_scale = 2**spec.electronics.adc_bits - 1
    with h5py.File(path, "r") as h5:
        starts = h5["episodes/start"][()]
        lengths = h5["episodes/length"][()]
        tiled = np.array_equal(np.append(starts, total), np.append(0, starts + lengths))
        _require(tiled, "episodes do not tile the frames")
        labels = h5["labels"]
        step = 16 * h5["frames"].chunks[0]
        for lo in range(0, total, step):
            hi = min(total, lo + step)
            frames = h5["frames"][lo:hi]
            normal = labels["normal_force_n"][lo:hi]
            present = normal > 0
            episode = labels["episode_index"][lo:hi]
            expected = np.arange(lo, hi) - starts[episode]
            _require(np.array_equal(labels["frame_index"][lo:hi], expected),
                     f"{path}: frame_index disagrees with /episodes/start")  # fmt: skip
            _require(_in_range(frames, full_scale), f"{path}: a frame off the A/D range")
            _check_labels(present, labels["contact_id"][lo:hi], normal, labels["slip"][lo:hi],
                          where=str(path))  # fmt: skip
            sampler.add(lo, frames, present, labels["position_mm"][lo:hi], normal)
            if progress is not None:
                progress(hi, total)
    return {"frames": total, "episodes": len(starts)}


def check_dataset(
    path: str | Path,
    *,
    sample: int = 97,
    min_force_n: float = 0.1,
    margin: float = 1.0,
    progress=None,
) -> dict:
    """Check a data set (a LeRobot folder or an HDF5 file) as the module says; raise
    :class:`DatasetCheckError` at the first failure.

    Returns ``frames``, ``episodes``, ``located`` (frames of the locate check),
    ``missed`` (of those, frames where locate found nothing), ``error_median_mm``,
    ``error_p95_mm``, ``error_max_mm`` (the distance found - labelled), ``bias_x_mm``,
    ``bias_y_mm`` (its mean along x and y) and ``pitch_mm``.
    """
    from tactsense.sensor import SensorSpec

    path = Path(path)
    if path.is_dir():
        meta = json.loads((path / "meta" / "tactsense.json").read_text(encoding="utf-8"))
        spec = SensorSpec.from_toml_string(meta["sensor_toml"])
    else:
        from tactsense.io.recording import RecordingReader

        with RecordingReader(path) as reader:
            spec = reader.sensor
    sampler = _Sampler(spec, sample, min_force_n, margin)
    counts = (_lerobot if path.is_dir() else _hdf5)(path, sampler, spec, progress)
    signed = sampler.errors()
    errors = np.linalg.norm(signed, axis=1) if len(signed) else np.zeros(0)
    found = errors[np.isfinite(errors)]
    bias = np.nanmean(signed, axis=0) if len(found) else np.full(2, np.nan)
    (row_pitch, _), (col_pitch, _) = kind_of(spec).surface_grid(spec)
    return {
        **counts,
        "located": len(errors),
        "missed": int(np.sum(~np.isfinite(errors))),
        "error_median_mm": float(np.median(found)) if len(found) else float("nan"),
        "error_p95_mm": float(np.quantile(found, 0.95)) if len(found) else float("nan"),
        "error_max_mm": float(found.max()) if len(found) else float("nan"),
        "bias_x_mm": float(bias[0]),
        "bias_y_mm": float(bias[1]),
        "pitch_mm": float(min(row_pitch, col_pitch)),
    }
