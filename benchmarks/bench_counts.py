"""``tactsense.locate`` from uint16 counts in memory: frames per second, 1 or 2 workers.

Run: ``python benchmarks/bench_counts.py [WORKERS]``. 400,000 frames of the initial
finger (a simulated axial sweep repeated), baseline from the first 5; best of 15 calls
after a warm-up. To compare two versions in one session, run it alternately from this
checkout and from a ``git worktree`` of the other commit with
``PYTHONPATH=<worktree>/src`` (docs/performance.md).
"""

import sys
import time

import numpy as np

import tactsense as ts


def frames_per_second(frames, spec, baseline, workers: int = 1, calls: int = 15) -> float:
    """``tactsense.locate`` on ``frames`` (counts): best of ``calls`` after a warm-up."""
    ts.locate(frames[:20_000], spec, baseline=baseline, workers=workers)
    best = np.inf
    for _ in range(calls):
        start = time.perf_counter()
        ts.locate(frames, spec, baseline=baseline, workers=workers)
        best = min(best, time.perf_counter() - start)
    return len(frames) / best


def main() -> None:
    workers = int(sys.argv[1]) if len(sys.argv) > 1 else 1
    spec = ts.fearing1990_initial()
    base = ts.simulate(spec, ts.probe_sweep(spec), rng=0)
    n = 400_000
    frames = np.tile(base.frames, (-(-n // len(base.frames)), 1, 1))[:n]
    rate = frames_per_second(frames, spec, ts.baseline_from(frames, 5), workers)
    print(f"{rate:,.0f} frames/s with {workers} worker(s)")


if __name__ == "__main__":
    main()
