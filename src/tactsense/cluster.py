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
    with RecordingReader(recording) as reader:
        losses = reader._h5["losses"][()].sum() if "losses" in reader._h5 else 0
    summary.update(losses=int(losses), seconds=time.perf_counter() - start)
    return summary


def run_batch(
    recordings: list[Path],
    out_dir: Path,
    *,
    fmt: str = "parquet",
    calibration: Path | None = None,
    threshold: float = 0.005,
    client=None,
    progress: Callable[[int, int], None] | None = None,
) -> list[dict]:
    """Process every recording on ``client`` (a :class:`dask.distributed.Client`).

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
