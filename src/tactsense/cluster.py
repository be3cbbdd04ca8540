"""Many recordings on a Dask cluster: ``tactsense batch``.

Each recording is one task (:func:`process_recording`): locate every frame piece by
piece (:func:`tactsense.batch.locate_file`), write ``OUT/<name>.<format>`` under a
temporary name and move it into place, and return a summary. The batch runs on a local
cluster of worker processes (:class:`dask.distributed.LocalCluster`) or on an existing
scheduler; it is resumable (an output newer than its recording is skipped), a failed
recording is listed with its reason and does not stop the others, and a worker that
dies takes no result with it: Dask runs its tasks again elsewhere, and since every task
writes only its own output, atomically, the batch completes with the same files.
"""

from __future__ import annotations

import glob
import os
import time
from collections.abc import Callable
from dataclasses import fields
from pathlib import Path

from tactsense._validation import TactsenseInputError

SUMMARY_FIELDS = [
    "recording",
    "output",
    "status",
    "frames",
    "contacts",
    "saturated",
    "force_mean_n",
    "force_max_n",
    "losses",
    "seconds",
    "reason",
]


def expand(patterns: list[str]) -> list[Path]:
    """Recordings named by paths or glob patterns, each once, in order; a pattern that
    matches nothing is an error."""
    found: list[Path] = []
    for pattern in patterns:
        matches = sorted(glob.glob(pattern)) if glob.has_magic(pattern) else [pattern]
        if not matches or not Path(matches[0]).exists():
            raise TactsenseInputError(f"no recording matches {pattern!r}")
        found += [Path(m) for m in matches if Path(m) not in found]
    stems = [p.stem for p in found]
    twins = {s for s in stems if stems.count(s) > 1}
    if twins:
        raise TactsenseInputError(
            f"recordings with the same name would share an output: {', '.join(sorted(twins))}"
        )
    return found


def output_for(recording: Path, out_dir: Path, fmt: str) -> Path:
    return out_dir / f"{recording.stem}.{fmt}"


def is_done(recording: Path, output: Path) -> bool:
    """An output exists only once complete (it is moved into place); it counts as done
    if it is not older than its recording."""
    return output.exists() and output.stat().st_mtime >= recording.stat().st_mtime


def process_recording(
    recording: str,
    output: str,
    calibration: str | None = None,
    threshold: float = 0.005,
) -> dict:
    """One task: locate every frame of ``recording`` into ``output``; its summary."""
    from tactsense.batch import locate_file
    from tactsense.estimate import Calibration
    from tactsense.io.recording import RecordingReader

    start = time.perf_counter()
    output = Path(output)
    temporary = output.with_name(f".{output.stem}.{os.getpid()}.partial{output.suffix}")
    try:
        cal = None
        if calibration is not None:
            with RecordingReader(recording) as reader:
                cal = Calibration.load(calibration, reader.sensor)
        summary = locate_file(recording, temporary, calibration=cal, threshold=threshold)
        os.replace(temporary, output)
    finally:
        temporary.unlink(missing_ok=True)
    summary.update(losses=_losses(recording), seconds=time.perf_counter() - start)
    return summary


def process_range(recording: str, part: str, lo: int, hi: int, threshold: float = 0.005) -> dict:
    """One piece of a split recording: frames ``lo`` to ``hi`` into the Parquet file
    ``part`` (the same numbers as the whole recording: the baseline is the median of the
    recording's first 5 frames, and without creep compensation every frame is
    independent)."""
    import numpy as np

    from tactsense.batch import Tally
    from tactsense.estimate import locate
    from tactsense.estimate.output import EstimatesWriter
    from tactsense.io.recording import RecordingReader

    tally = Tally()
    with RecordingReader(recording) as reader, EstimatesWriter(part) as writer:
        baseline = np.median(reader.frames(0, 5).astype(float), axis=0)
        step = reader.chunk_frames
        for start in range(lo, hi, step):
            stop = min(hi, start + step)
            estimates = locate(
                reader.frames(start, stop), reader.sensor, baseline=baseline, threshold=threshold
            )
            writer.write(start, reader.time_s(start, stop), estimates)
            tally.add(estimates)
    return {"part": part, "frames": hi - lo, "tally": tally}


def combine_parts(parts: list[dict], recording: str, output: str) -> dict:
    """Join the parts of a split recording, in order, into ``output`` (any format); the
    recording's summary. Reads one part at a time."""
    import pyarrow.parquet as pq

    from tactsense.estimate.locate import Estimates
    from tactsense.estimate.output import EstimatesWriter

    start_time = time.perf_counter()
    output = Path(output)
    temporary = output.with_name(f".{output.stem}.{os.getpid()}.partial{output.suffix}")
    names = [f.name for f in fields(Estimates)]
    try:
        with EstimatesWriter(temporary) as writer:
            for part in parts:
                table = pq.read_table(part["part"])
                estimates = Estimates(*(table[name].to_numpy() for name in names))
                writer.write(int(table["frame"][0].as_py()), table["time_s"].to_numpy(), estimates)
        os.replace(temporary, output)
    finally:
        temporary.unlink(missing_ok=True)
        for part in parts:
            Path(part["part"]).unlink(missing_ok=True)
    from tactsense.batch import Tally

    tally = Tally()
    for part in parts:
        tally.merge(part["tally"])
    return {
        "frames": sum(p["frames"] for p in parts),
        **tally.summary(),
        "losses": _losses(recording),
        "seconds": time.perf_counter() - start_time,
    }


def _losses(recording: str) -> int:
    """Frames the recording's writer counted as lost (0 for a simulated recording)."""
    from tactsense.io.recording import read_losses

    return sum(read_losses(recording).values())


def _frames_of(recording: Path) -> int | None:
    from tactsense.io.recording import RecordingReader

    try:
        with RecordingReader(recording) as reader:
            return reader.n_frames
    except TactsenseInputError:
        return None  # the task itself will fail and say why


def run_batch(
    recordings: list[Path],
    out_dir: Path,
    *,
    fmt: str = "parquet",
    calibration: Path | None = None,
    threshold: float = 0.005,
    client=None,
    split_frames: int | None = None,
    progress: Callable[[int, int], None] | None = None,
) -> list[dict]:
    """Process every recording on ``client`` (a :class:`dask.distributed.Client`).

    A recording of more than ``split_frames`` frames is split into ranges of that many
    frames, one task each, joined in order by a last task: the same output as one
    process (not with a calibration, whose creep compensation runs through the whole
    recording in order).

    Returns one summary row per recording (:data:`SUMMARY_FIELDS`), in the order given:
    status ``done``, ``skipped`` (its output is complete and newer) or ``failed`` (with
    the reason).
    """
    from dask.distributed import as_completed

    rows: dict[Path, dict] = {}
    futures = {}
    for recording in recordings:
        output = output_for(recording, out_dir, fmt)
        if is_done(recording, output):
            rows[recording] = {
                "recording": str(recording),
                "output": str(output),
                "status": "skipped",
            }
            continue
        n = _frames_of(recording) if split_frames and calibration is None else None
        if n is not None and n > split_frames:
            stamp = recording.stat().st_mtime_ns
            parts = [
                client.submit(
                    process_range,
                    str(recording),
                    str(out_dir / f".{recording.stem}.part{k:05d}.parquet"),
                    lo,
                    min(n, lo + split_frames),
                    threshold,
                    key=f"tactsense-{recording.stem}-{stamp}-range{k}",
                    pure=False,
                    retries=1,
                )
                for k, lo in enumerate(range(0, n, split_frames))
            ]
            future = client.submit(
                combine_parts,
                parts,
                str(recording),
                str(output),
                key=f"tactsense-{recording.stem}-{stamp}-join",
                pure=False,
                retries=1,
            )
            futures[future] = (recording, output)
            continue
        future = client.submit(
            process_recording,
            str(recording),
            str(output),
            None if calibration is None else str(calibration),
            threshold,
            key=f"tactsense-{recording.stem}-{recording.stat().st_mtime_ns}",
            pure=False,
            retries=1,
        )
        futures[future] = (recording, output)
    done = len(rows)
    if progress is not None:
        progress(done, len(recordings))
    for future in as_completed(list(futures)):
        recording, output = futures[future]
        row = {"recording": str(recording), "output": str(output)}
        try:
            row.update(future.result(), status="done")
        except Exception as error:  # a failed recording is listed, the others go on
            row.update(status="failed", reason=f"{type(error).__name__}: {error}")
        rows[recording] = row
        done += 1
        if progress is not None:
            progress(done, len(recordings))
    return [{key: rows[r].get(key) for key in SUMMARY_FIELDS} for r in recordings]


def write_summary(path: Path, rows: list[dict]) -> None:
    """The batch's summary table as CSV (pyarrow)."""
    import pyarrow as pa
    import pyarrow.csv as pa_csv

    table = pa.table({key: [row.get(key) for row in rows] for key in SUMMARY_FIELDS})
    pa_csv.write_csv(table, str(path))
