"""What the sensor-kind seam costs: finger and pad throughput of this tree against a
reference commit, measured in the same run (issue 33: within 5 % of before).

    python benchmarks/seam_overhead.py [--ref bb4ab76] [--current REF] [--repeats 5]
                                       [--frames 20000] [--live-frames 2000]

The reference commit (and ``--current``, a commit measured instead of the work tree) is
extracted with ``git archive`` into a temporary directory; each
measurement runs in its own subprocess (``python -c``, ``PYTHONPATH`` pointing at one tree's
``src``), the two trees alternating (current, reference, reference, current, ...) so that
a change in the machine's load touches both alike. The frames are the same for both: two
recordings simulated once by this tree's ``tactsense simulate`` (the paper's initial finger
under ``sweep-axial``, 154 frames; ``pad16`` under ``slide``, 367 frames), tiled to
``--frames``. Each worker times, best of 5 after a warm-up call:

* ``finger locate``: ``tactsense.locate`` on the whole batch (counts to estimates);
* ``finger per frame``: ``LiveLocator`` (``live`` and the view) one frame at a time;
* ``pad16 find_contacts``: every contact of the whole batch;
* ``pad16 per frame``: ``LiveContacts`` (segmentation and tracking) one frame at a time.

The table gives each tree's best rate over the repeats [frames/s], the ratio of the two
best rates, and the median of the ratios of the pairs (each run of the current tree over
the reference's run next to it in time: the figure least moved by the machine's load);
1.00 is no change, under 0.95 the 5 % slowdown the issue forbids.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

WORKER = r"""
import json, sys, time
import numpy as np
import tactsense as ts
from tactsense.estimate.contacts import find_contacts
from tactsense.stream.live import LiveContacts, LiveLocator
from tactsense.stream.reader import StreamFrame

finger_path, pad_path, n, n_live = sys.argv[1], sys.argv[2], int(sys.argv[3]), int(sys.argv[4])

def best(work, repeats=5):
    work()  # warm-up: compile or load the cache
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        work()
        times.append(time.perf_counter() - start)
    return min(times)

def tiled(frames, n):
    return np.resize(frames, (n, *frames.shape[1:]))

def per_frame(make, frames):
    def work():
        live = make()
        for i, counts in enumerate(frames):
            live(StreamFrame(i, i, 0.0, 0.0, 0.0, counts))
    return work

out = {}
rec = ts.read_recording(finger_path)
sensor, baseline = rec.sensor, ts.baseline_from(rec.frames)
frames = tiled(rec.frames, n)
out["finger locate"] = n / best(lambda: ts.locate(frames, sensor, baseline=baseline))
live = tiled(rec.frames, n_live)
make = lambda: LiveLocator(sensor, baseline=baseline)
out["finger per frame"] = n_live / best(per_frame(make, live))

rec = ts.read_recording(pad_path)
sensor, baseline = rec.sensor, ts.baseline_from(rec.frames)
frames = tiled(rec.frames, n)
out["pad16 find_contacts"] = n / best(lambda: find_contacts(frames, sensor, baseline=baseline))
live = tiled(rec.frames, n_live)
make = lambda: LiveContacts(sensor, baseline=baseline, drift_s=None)
out["pad16 per frame"] = n_live / best(per_frame(make, live))
print("RATES " + json.dumps(out))
"""


def run(src: Path, args: list[str]) -> dict[str, float]:
    """One worker on the tree whose package is in ``src``: its rates [frames/s]."""
    env = dict(os.environ, PYTHONPATH=str(src))
    done = subprocess.run(
        [sys.executable, "-c", WORKER, *args], env=env, capture_output=True, text=True
    )
    if done.returncode != 0:
        raise SystemExit(f"the worker failed on {src}:\n{done.stderr}")
    line = next(x for x in done.stdout.splitlines() if x.startswith("RATES "))
    return json.loads(line.removeprefix("RATES "))


def extract(ref: str, where: Path) -> Path:
    """The ``src`` of commit ``ref``, written under ``where`` (``git archive``)."""
    where.mkdir()
    archive = subprocess.run(
        ["git", "-C", str(ROOT), "archive", ref, "src"], capture_output=True, check=True
    )
    subprocess.run(["tar", "-x", "-C", str(where)], input=archive.stdout, check=True)
    return where


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--ref", default="bb4ab76", help="reference commit [bb4ab76]")
    parser.add_argument(
        "--current", default=None, help="measure this commit instead of the work tree"
    )
    parser.add_argument("--repeats", type=int, default=5, help="runs of each tree [5]")
    parser.add_argument("--frames", type=int, default=20_000, help="batch frames [20000]")
    parser.add_argument("--live-frames", type=int, default=2_000, help="per-frame [2000]")
    options = parser.parse_args(argv)
    current = ROOT / "src"
    with tempfile.TemporaryDirectory(prefix="seam_overhead_") as tmp:
        tmp = Path(tmp)
        reference = extract(options.ref, tmp / "ref")
        if options.current is not None:
            current = extract(options.current, tmp / "current") / "src"
        commit = subprocess.run(
            ["git", "-C", str(ROOT), "rev-parse", "--short", options.current or "HEAD"],
            capture_output=True, text=True, check=True,
        ).stdout.strip()  # fmt: skip
        what = commit if options.current else f"HEAD {commit} + work tree"
        env = dict(os.environ, PYTHONPATH=str(current))
        recordings = {"finger": ("initial", "sweep-axial"), "pad": ("pad16", "slide")}
        for name, (sensor, scenario) in recordings.items():
            subprocess.run(
                [sys.executable, "-m", "tactsense", "simulate", "--sensor", sensor,
                 "--scenario", scenario, "-o", str(tmp / f"{name}.h5")],
                env=env, check=True, capture_output=True,
            )  # fmt: skip
        args = [str(tmp / "finger.h5"), str(tmp / "pad.h5"), str(options.frames),
                str(options.live_frames)]  # fmt: skip
        trees = {"current": current, "reference": reference / "src"}
        rates: dict[str, list[dict[str, float]]] = {"current": [], "reference": []}
        start = time.perf_counter()
        for repeat in range(options.repeats):
            order = ("current", "reference") if repeat % 2 == 0 else ("reference", "current")
            for tree in order:
                rates[tree].append(run(trees[tree], args))
                print(f"  run {repeat + 1}/{options.repeats} {tree}: "
                      + ", ".join(f"{k} {v:,.0f}" for k, v in rates[tree][-1].items()),
                      file=sys.stderr, flush=True)  # fmt: skip
        load = os.getloadavg()[0]
    print(
        f"current tree ({what}) against {options.ref}, "
        f"{options.repeats} alternating runs each, {options.frames:,} frames a batch, "
        f"{options.live_frames:,} one at a time; best rate of each tree "
        f"({time.perf_counter() - start:.0f} s; load average {load:.1f} at the end)\n"
    )
    print(
        "| measure | current [frames/s] | reference [frames/s] | ratio of the best "
        "| median ratio of the pairs | pairs' ratios |"
    )
    print("|---|---|---|---|---|---|")
    for measure in rates["current"][0]:
        mine = [r[measure] for r in rates["current"]]
        theirs = [r[measure] for r in rates["reference"]]
        pairs = sorted(a / b for a, b in zip(mine, theirs, strict=True))
        print(
            f"| {measure} | {max(mine):,.0f} | {max(theirs):,.0f} | "
            f"{max(mine) / max(theirs):.3f} | {statistics.median(pairs):.3f} | "
            f"{pairs[0]:.2f}-{pairs[-1]:.2f} |"
        )


if __name__ == "__main__":
    main()
