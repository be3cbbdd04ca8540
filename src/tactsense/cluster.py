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
from tactsense.kinds import kind_of
from tactsense.stream.reader import LOSS_KINDS

LOSS_COLUMNS = tuple(f"{kind}_frames" if kind == "lost" else kind for kind in LOSS_KINDS)
"""One column per loss counter of a recording (``tactsense.stream.LOSS_KINDS``): a lost
frame, a gap, a bad checksum, a truncation, a garbage run, its bytes and a timeout are different
things and are never summed. ``lost`` is named ``lost_frames``."""

SUMMARY_FIELDS = [
    "recording",
    "output",
    "status",
    "frames",
    "contacts",
    "saturated",
    "force_mean_n",
    "force_max_n",
    *LOSS_COLUMNS,
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
    threshold: float | None = None,
) -> dict:
    """One task: locate every frame of ``recording`` into ``output``; its summary.

    A finger: one row per frame (:func:`~tactsense.batch.locate_file`; ``threshold``
    default 0.005). A pad or a point set: every contact, tracked, as ``tactsense
    locate`` writes them (:func:`~tactsense.batch.contacts_file`, the baseline following
    drift with a 2-s time constant, ``threshold`` default the sensor's; a CSV's events in
    ``<name>.events.csv`` beside it); ``contacts`` then counts contacts, not frames.
    """
    from tactsense.batch import contacts_file, locate_file
    from tactsense.estimate.finger.locate import CONTACT_THRESHOLD
    from tactsense.estimate.output import events_sidecar

    start = time.perf_counter()
    output = Path(output)
    temporary = output.with_name(f".{output.stem}.{os.getpid()}.partial{output.suffix}")
    sidecar = events_sidecar(output) if output.suffix == ".csv" else None
    events = None if sidecar is None else temporary.with_name(temporary.name + ".events.csv")
    try:
        cal = _calibration(recording, calibration)
        if _multi_contact(recording):  # every contact, tracked
            found = contacts_file(recording, temporary, calibration=cal, threshold=threshold,
                                  drift_s=2.0, events_path=events)  # fmt: skip
            summary = {key: found[key] for key in ("frames", "saturated", "force_mean_n",
                                                   "force_max_n")}  # fmt: skip
            summary["contacts"] = found["rows"]
        else:  # the one contact of each frame
            threshold = CONTACT_THRESHOLD if threshold is None else threshold
            summary = locate_file(recording, temporary, calibration=cal, threshold=threshold)
        if events is not None and events.exists():
            os.replace(events, sidecar)
        os.replace(temporary, output)
    finally:
        temporary.unlink(missing_ok=True)
        if events is not None:
            events.unlink(missing_ok=True)
    summary.update(_losses(recording), seconds=time.perf_counter() - start)
    return summary


def _multi_contact(recording: str) -> bool:
    """Whether the recording's sensor finds and tracks many contacts a frame."""
    from tactsense.io.recording import RecordingReader

    with RecordingReader(recording) as reader:
        return kind_of(reader.sensor).multi_contact


def _calibration(recording: str, calibration: str | None):
    """The calibration file checked against the recording's sensor (None without one)."""
    if calibration is None:
        return None
    from tactsense.estimate.contacts.array_calibration import load_calibration
    from tactsense.io.recording import RecordingReader

    with RecordingReader(recording) as reader:
        return load_calibration(calibration, reader.sensor)  # a finger's or an array's


def range_end_state(recording: str, calibration: str, lo: int, hi: int):
    """Pass 1 of a split with creep compensation: the compensator's memories at the end
    of frames ``lo`` to ``hi``, started from zero (array (2, rows, cols)).

    The memories follow a linear recursion (``CreepCompensator.transition``): from
    memories ``s0`` the range ends in ``A^L s0`` plus this, so the start of every range
    follows from the ranges before it, and pass 2 (:func:`process_range`) runs all
    ranges at once with the memories the whole recording would have had there.
    """
    from tactsense.io.recording import RecordingReader

    cal = _calibration(recording, calibration)
    with RecordingReader(recording) as reader:
        compensator = cal.compensator(reader.sensor.scan_period_s, reader.sensor.shape)
        step = reader.chunk_frames
        for start in range(lo, hi, step):
            frames = reader.frames(start, min(hi, start + step))
            cal.apply(frames, reader.sensor, compensator=compensator)
    return compensator.state


def process_range(
    recording: str,
    part: str,
    lo: int,
    hi: int,
    threshold: float | None = None,
    calibration: str | None = None,
    before: list | None = None,
) -> dict:
    """One piece of a split recording: frames ``lo`` to ``hi`` into the Parquet file
    ``part``, with the numbers of the whole recording. Without a calibration the
    baseline is the median of the recording's first 5 frames and every frame is
    independent. With one, its creep compensation starts from the memories the
    recording has at ``lo``: ``before`` lists, for every earlier range, its
    :func:`range_end_state` and its length."""
    import numpy as np

    from tactsense.batch import Tally
    from tactsense.estimate import locate
    from tactsense.estimate.output import EstimatesWriter
    from tactsense.io.recording import RecordingReader

    cal = _calibration(recording, calibration)
    tally = Tally()
    with RecordingReader(recording) as reader, EstimatesWriter(part) as writer:
        sensor = reader.sensor
        options: dict = {"threshold": 0.005 if threshold is None else threshold}
        if cal is None:
            options["baseline"] = np.median(reader.frames(0, 5).astype(float), axis=0)
        else:
            options["calibration"] = cal
            compensator = cal.compensator(sensor.scan_period_s, sensor.shape)
            if compensator is not None:
                state = np.zeros((2, *sensor.shape))
                for end_state, length in before or []:
                    state = compensator.carry(state, length) + end_state
                compensator.state = state
                options["compensator"] = compensator
        step = reader.chunk_frames
        for start in range(lo, hi, step):
            stop = min(hi, start + step)
            estimates = locate(reader.frames(start, stop), sensor, **options)
            writer.write(start, reader.time_s(start, stop), estimates)
            tally.add(estimates)
    return {"part": part, "frames": hi - lo, "tally": tally}


def combine_parts(parts: list[dict], recording: str, output: str) -> dict:
    """Join the parts of a split recording, in order, into ``output`` (any format); the
    recording's summary. Reads one part at a time."""
    import pyarrow.parquet as pq

    from tactsense.estimate.finger.locate import Estimates
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
        **_losses(recording),
        "seconds": time.perf_counter() - start_time,
    }


def _losses(recording: str) -> dict[str, int]:
    """The recording's loss counters, one column each (:data:`LOSS_COLUMNS`; 0 for a
    simulated recording or a counter its writer did not keep)."""
    from tactsense.io.recording import read_losses

    counts = read_losses(recording)
    return {column: int(counts.get(column.removesuffix("_frames"), 0)) for column in LOSS_COLUMNS}


def _has_creep(recording: Path, calibration: str) -> bool:
    """Whether the calibration compensates creep (False if it cannot be read: the task
    will fail and say why)."""
    try:
        return _calibration(str(recording), calibration).viscoelastic is not None
    except TactsenseInputError:
        return False


def _frames_of(recording: Path) -> int | None:
    """A finger's frames, for splitting; None for a pad or a point set, whose contacts
    are tracked through the whole recording in one task."""
    from tactsense.io.recording import RecordingReader

    try:
        with RecordingReader(recording) as reader:
            return None if kind_of(reader.sensor).multi_contact else reader.n_frames
    except TactsenseInputError:
        return None  # the task itself will fail and say why


def run_batch(
    recordings: list[Path],
    out_dir: Path,
    *,
    fmt: str = "parquet",
    calibration: Path | None = None,
    threshold: float | None = None,
    client=None,
    split_frames: int | None = None,
    progress: Callable[[int, int], None] | None = None,
) -> list[dict]:
    """Process every recording on ``client`` (a :class:`dask.distributed.Client`).

    A recording of more than ``split_frames`` frames is split into ranges of that many
    frames, one task each, joined in order by a last task: the same output as one
    process. With a creep calibration a first pass finds each range's end memories
    (:func:`range_end_state`, without estimation), so that every range starts from the
    memories the whole recording has there (equal to one process's to rounding).

    Returns one summary row per recording (:data:`SUMMARY_FIELDS`), in the order given:
    status ``done``, ``skipped`` (its output is complete and newer) or ``failed`` (with
    the reason).
    """
    from dask.distributed import as_completed

    rows: dict[Path, dict] = {}
    futures = {}
    earlier = read_summary(out_dir / "summary.csv")
    for recording in recordings:
        output = output_for(recording, out_dir, fmt)
        if is_done(recording, output):
            # its numbers are those of the run that wrote the output
            rows[recording] = {
                **(earlier or {}).get(_key(output), {}),
                "recording": str(recording),
                "output": str(output),
                "status": "skipped",
            }
            continue
        n = _frames_of(recording) if split_frames else None
        if n is not None and n > split_frames:
            stamp = recording.stat().st_mtime_ns
            cal = None if calibration is None else str(calibration)
            ranges = [(lo, min(n, lo + split_frames)) for lo in range(0, n, split_frames)]
            # with a creep calibration, pass 1: each range's end memories from zero
            states = []
            if cal is not None and _has_creep(recording, cal):
                states = [
                    client.submit(
                        range_end_state,
                        str(recording),
                        cal,
                        lo,
                        hi,
                        key=f"tactsense-{recording.stem}-{stamp}-state{k}",
                        pure=False,
                        retries=1,
                    )
                    for k, (lo, hi) in enumerate(ranges[:-1])
                ]
            parts = [
                client.submit(
                    process_range,
                    str(recording),
                    str(out_dir / f".{recording.stem}.part{k:05d}.parquet"),
                    lo,
                    hi,
                    threshold,
                    cal,
                    [(states[j], ranges[j][1] - ranges[j][0]) for j in range(min(k, len(states)))],
                    key=f"tactsense-{recording.stem}-{stamp}-range{k}",
                    pure=False,
                    retries=1,
                )
                for k, (lo, hi) in enumerate(ranges)
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


def _key(output: Path | str) -> str:
    # summary.csv lives beside the outputs, whose names are unique (see expand)
    return Path(output).name


def read_summary(path: Path) -> dict[str, dict]:
    """The rows of an earlier run's summary.csv that finished (status done or skipped),
    by their output's file name; empty if there is none or it cannot be read."""
    import pyarrow.csv as pa_csv

    try:
        table = pa_csv.read_csv(str(path))
    except (OSError, ValueError):
        return {}
    numeric = set(SUMMARY_FIELDS) - {"recording", "output", "status", "reason"}
    rows = {}
    for row in table.to_pylist():
        if row.get("status") not in ("done", "skipped") or not row.get("output"):
            continue
        kept = {key: row.get(key) for key in SUMMARY_FIELDS if key in numeric}
        if kept.get("frames") is None:
            continue  # a blank row of an older summary
        rows[_key(row["output"])] = kept
    return rows


def write_summary(path: Path, rows: list[dict]) -> None:
    """The batch's summary table as CSV (pyarrow)."""
    import pyarrow as pa
    import pyarrow.csv as pa_csv

    table = pa.table({key: [row.get(key) for row in rows] for key in SUMMARY_FIELDS})
    pa_csv.write_csv(table, str(path))
