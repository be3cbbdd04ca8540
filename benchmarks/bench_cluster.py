"""Many recordings: ``tactsense batch`` on a local Dask cluster of 1 and 2 workers.

Run: ``python benchmarks/bench_cluster.py [RECORDINGS] [FRAMES]`` (default 100
recordings of 50,000 frames: 5,000,000 frames, about 200 hours of the paper's finger).
Measured, wall clock, each from a fresh process and from a cold output folder:

* ``tactsense batch 'DIR/*.h5' --out OUT --workers 1`` and ``--workers 2`` (cluster
  start-up included: that is what a user waits for);
* the straightforward way in the same run: a shell loop of ``tactsense locate REC --out
  EST.parquet``, one process per recording (timed on the first 10 recordings and
  scaled to all of them: every call pays the same start-up);
* and, for the cost of Dask itself, one process calling ``tactsense.batch.locate_file``
  on every recording in turn.

Figures go to docs/performance.md.
"""

from __future__ import annotations

import dataclasses
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

import tactsense as ts

CLI = [sys.executable, "-m", "tactsense.cli"]

LOOP = r"""
import sys, time
from pathlib import Path
from tactsense.batch import locate_file
paths = sorted(Path(sys.argv[1]).glob("*.h5"))
out = Path(sys.argv[2])
start = time.perf_counter()
for path in paths:
    locate_file(path, out / (path.stem + ".parquet"))
print(time.perf_counter() - start)
"""


def make_recordings(folder: Path, count: int, n: int) -> None:
    spec = ts.fearing1990_initial()
    base = ts.simulate(spec, ts.probe_sweep(spec), rng=0)
    tiles = -(-n // len(base.frames))
    frames = np.tile(base.frames, (tiles, 1, 1))[:n]
    rec = dataclasses.replace(
        base, frames=frames, time_s=np.arange(n) * spec.scan_period_s, truth={}
    )
    first = folder / "rec000.h5"
    ts.write_recording(first, rec)
    for k in range(1, count):
        shutil.copyfile(first, folder / f"rec{k:03d}.h5")


def timed(command: list[str]) -> float:
    start = time.perf_counter()
    subprocess.run(command, check=True, capture_output=True)
    return time.perf_counter() - start


def main() -> None:
    count = int(sys.argv[1]) if len(sys.argv) > 1 else 100
    n = int(sys.argv[2]) if len(sys.argv) > 2 else 50_000
    total = count * n
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        data = tmp / "data"
        data.mkdir()
        make_recordings(data, count, n)
        print(f"{count} recordings of {n:,} frames ({total:,} frames)\n")
        print("| what | wall clock [s] | frames/s | vs the shell loop |")
        print("|---|---|---|---|")
        rows = []
        # the shell loop, on the first 10 recordings, scaled
        sample = sorted(data.glob("*.h5"))[:10]
        out = tmp / "loop"
        out.mkdir()
        start = time.perf_counter()
        for path in sample:
            subprocess.run(
                [*CLI, "locate", str(path), "--out", str(out / (path.stem + ".parquet"))],
                check=True,
                capture_output=True,
            )
        loop_s = (time.perf_counter() - start) * count / len(sample)
        rows.append((f"shell loop of `tactsense locate` (10 timed, x{count / 10:g})", loop_s))
        out = tmp / "inproc"
        out.mkdir()
        result = subprocess.run(
            [sys.executable, "-c", LOOP, str(data), str(out)],
            check=True,
            capture_output=True,
            text=True,
        )
        rows.append(("one process, `locate_file` per recording", float(result.stdout)))
        for workers in (1, 2):
            out = tmp / f"batch{workers}"
            seconds = timed(
                [*CLI, "batch", str(data / "*.h5"), "--out", str(out), "--workers",
                 str(workers), "--quiet"]
            )  # fmt: skip
            assert len(list(out.glob("*.parquet"))) == count
            rows.append((f"`tactsense batch --workers {workers}`", seconds))
        for label, seconds in rows:
            print(f"| {label} | {seconds:.1f} | {total / seconds:,.0f} | {loop_s / seconds:.1f}x |")


if __name__ == "__main__":
    main()
