"""Large recordings: throughput and peak memory of ``tactsense locate`` end to end.

Run: ``python benchmarks/bench_batch.py [FRAMES]`` (default 2,000,000 frames, about 80
hours of the paper's finger at 7 Hz). It writes a recording of that many frames (a
simulated sweep repeated), then measures, each in a fresh process so that peak memory
(VmHWM) is that command's alone:

* ``tactsense.batch.locate_file`` to Parquet and to CSV, 1 and 2 workers (pieces of the
  HDF5 chunk size; bounded memory);
* the straightforward reference: ``read_recording`` of the whole file, one ``locate``
  call, and a per-row ``csv.writer`` loop (what ``tactsense locate`` did before);

and, in this process, ``tactsense.locate`` from uint16 counts already in memory with 1
and 2 workers. Figures go to docs/performance.md.
"""

from __future__ import annotations

import dataclasses
import json
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

import tactsense as ts

# run as a script (python benchmarks/bench_batch.py): its folder is on the path
from bench_counts import frames_per_second

CHILD = r"""
import json, sys, time
path, out, mode, workers = sys.argv[1], sys.argv[2], sys.argv[3], int(sys.argv[4])
import numpy as np
import tactsense as ts
from tactsense.batch import locate_file
warm = ts.simulate(ts.fearing1990_initial(), ts.repeated_load(ts.fearing1990_initial(), repeats=2))
ts.locate(warm.frames, warm.sensor, baseline=warm.frames[0], workers=workers)
start = time.perf_counter()
if mode == "reference":
    rec = ts.read_recording(path)
    est = ts.locate(rec.frames, rec.sensor, baseline=ts.baseline_from(rec.frames, 5))
    import csv
    with open(out, "w", newline="") as handle:
        writer = csv.writer(handle)
        names = ["row", "col", "axial_mm", "angle_deg", "peak_deflection", "force_n", "skew"]
        columns = [getattr(est, n) for n in names]
        for k in range(len(est)):
            writer.writerow([k, repr(float(rec.time_s[k]))] + [f"{c[k]:.6g}" for c in columns]
                            + [int(est.iterations[k]), bool(est.converged[k]), int(est.flags[k])])
    frames = len(est)
else:
    frames = locate_file(path, out, workers=workers)["frames"]
seconds = time.perf_counter() - start
status = open("/proc/self/status").read().splitlines()
peak_kb = [int(line.split()[1]) for line in status if line.startswith("VmHWM")][0]
print(json.dumps({"frames": frames, "seconds": seconds, "peak_mb": peak_kb / 1024}))
"""


def make_recording(path: Path, n: int) -> None:
    spec = ts.fearing1990_initial()
    base = ts.simulate(spec, ts.probe_sweep(spec), rng=0)
    tiles = -(-n // len(base.frames))
    frames = np.tile(base.frames, (tiles, 1, 1))[:n]
    rec = dataclasses.replace(
        base, frames=frames, time_s=np.arange(n) * spec.scan_period_s, truth={}
    )
    ts.write_recording(path, rec)


def child(path: Path, out: Path, mode: str, workers: int) -> dict:
    result = subprocess.run(
        [sys.executable, "-c", CHILD, str(path), str(out), mode, str(workers)],
        capture_output=True,
        text=True,
        check=True,
    )
    return json.loads(result.stdout.strip().splitlines()[-1])


def main() -> None:
    n = int(sys.argv[1]) if len(sys.argv) > 1 else 2_000_000
    with tempfile.TemporaryDirectory() as folder:
        folder = Path(folder)
        path = folder / "big.h5"
        make_recording(path, n)
        print(f"recording: {n:,} frames of 8 x 8, {path.stat().st_size / 2**20:.0f} MB\n")
        print("| what | workers | frames/s | peak memory [MB] |")
        print("|---|---|---|---|")
        results = {}
        runs = [
            ("reference", ".csv", 1),
            ("batch", ".csv", 1),
            ("batch", ".parquet", 1),
            ("batch", ".parquet", 2),
        ]
        if n > 3_000_000:  # the reference holds everything in memory: skip it
            runs = runs[1:]
        for mode, suffix, workers in runs:
            out = folder / f"out{suffix}"
            out.unlink(missing_ok=True)
            r = child(path, out, mode, workers)
            results[(mode, suffix, workers)] = r
            label = (
                "read all, locate, per-row csv.writer (before)"
                if mode == "reference"
                else f"tactsense.batch.locate_file -> {suffix}"
            )
            rate = r["frames"] / r["seconds"]
            print(f"| {label} | {workers} | {rate:,.0f} | {r['peak_mb']:.0f} |")
        if ("reference", ".csv", 1) in results:
            ref = results[("reference", ".csv", 1)]
            new = results[("batch", ".csv", 1)]
            print(
                f"\nCSV end to end: {ref['seconds'] / new['seconds']:.1f}x the reference, "
                f"{ref['peak_mb'] / new['peak_mb']:.1f}x less memory"
            )
        spec = ts.fearing1990_initial()
        if n > 3_000_000:
            return
        rec = ts.read_recording(path)
        frames, baseline = rec.frames, ts.baseline_from(rec.frames, 5)
        print("\nFrom uint16 counts in memory (ts.locate):\n")
        for workers in (1, 2):
            rate = frames_per_second(frames, spec, baseline, workers, calls=3)
            print(f"- workers={workers}: {rate:,.0f} frames/s (best of 3)")


if __name__ == "__main__":
    main()
