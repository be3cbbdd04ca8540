"""``tactsense info`` on a long recording: time and peak memory, streamed against whole.

Run: ``python benchmarks/bench_info.py [FRAMES]`` (default 2,000,000 frames, about 80
hours of the paper's finger at 7 Hz). It writes a recording of that many frames (a
simulated sweep repeated, written by ``write_recording``: chunked, gzip, Fletcher-32)
and a 154-frame one, then measures, each in a fresh process so that peak memory (the
child's maximum resident set) is that run's alone:

* ``tactsense info`` (streams the file in blocks of its chunks);
* the straightforward reference: ``read_recording`` of the whole file and the same
  minimum, maximum and NaN count over it (what ``info`` did before);
* the structure check alone (the child process every opening of a recording runs,
  importing h5py alone).

Figures go to docs/performance.md.
"""

from __future__ import annotations

import dataclasses
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

import tactsense as ts
from tactsense.io.recording import _CHECK_CODE

WHOLE = r"""
import sys, numpy as np, tactsense as ts
rec = ts.read_recording(sys.argv[1])  # info before it streamed, line for line
frames = np.asarray(rec.frames)
finite = np.isfinite(frames) if frames.dtype.kind == "f" else np.ones(frames.shape, bool)
print(len(rec), frames[finite].min(), frames[finite].max(), (~finite.all(axis=(1, 2))).sum())
"""

MEASURE = r"""
import resource, subprocess, sys, time
start = time.perf_counter()
done = subprocess.run(sys.argv[1:], capture_output=True, text=True)
seconds = time.perf_counter() - start
assert done.returncode == 0, done.stderr
print(seconds, resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss)
"""


def run(args: list[str]) -> tuple[float, float]:
    """Seconds and peak resident memory [MB] of one fresh process (and its children),
    measured by a fresh wrapper so that no earlier run's peak counts."""
    out = subprocess.run(
        [sys.executable, "-c", MEASURE, *args], capture_output=True, text=True, check=True
    ).stdout.split()
    return float(out[0]), float(out[1]) / 1024


def main(n_frames: int = 2_000_000) -> None:
    spec = ts.fearing1990_initial()
    short = ts.simulate(spec, ts.probe_sweep(spec), rng=0)
    with tempfile.TemporaryDirectory() as folder:
        small = Path(folder) / "small.h5"
        big = Path(folder) / "big.h5"
        ts.write_recording(small, short)
        index = np.arange(n_frames) % len(short)
        long = dataclasses.replace(
            short,
            frames=short.frames[index],
            time_s=np.arange(n_frames) * spec.scan_period_s,
            truth={},
        )
        ts.write_recording(big, long)
        del long, index
        print(f"{n_frames:,} frames: {big.stat().st_size / 1e6:.1f} MB on disk")
        cli = [sys.executable, "-m", "tactsense_launcher", "info"]
        check = [sys.executable, "-c", _CHECK_CODE]  # the child process alone
        rows = [
            ("structure check alone, 154 frames", [*check, str(small), "60"]),
            (
                f"structure check alone, {n_frames:,} frames",
                [*check, str(big), "60"],
            ),
            ("tactsense info, 154 frames", [*cli, str(small)]),
            (f"tactsense info, {n_frames:,} frames (streamed)", [*cli, str(big)]),
            (
                f"reference: read_recording whole, {n_frames:,} frames",
                [sys.executable, "-c", WHOLE, str(big)],
            ),
        ]
        for label, args in rows:
            seconds, peak = run(args)
            print(f"{label:55s} {seconds:6.2f} s  peak {peak:7.0f} MB")


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 2_000_000)
