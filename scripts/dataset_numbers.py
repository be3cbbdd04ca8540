"""A large labelled data set generated, read back and checked: the figures of
docs/datasets.md (and its block of docs/performance.md).

    python scripts/dataset_numbers.py [--episodes 1000] [--frames 1000] [--workers 2]
        [--folder /tmp/ts-million] [--lerobot-python /path/to/venv/bin/python]

Runs ``tactsense dataset`` as a command (LeRobot, then HDF5, the same plan) while a
thread samples the resident memory of its whole process tree (the command and its Dask
workers, psutil, every 0.2 s); then :func:`tactsense.interop.dataset_check.check_dataset`
on each set (memory sampled the same way); then, given a Python with ``lerobot``,
``scripts/check_lerobot.py`` on the LeRobot set (every ``--every``-th item, compared with
the HDF5 set's frames). The figures replace the marked blocks of the two docs.
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import subprocess
import sys
import threading
import time
from pathlib import Path

import psutil

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "scripts"))
from docblock import replace_block  # noqa: E402

BEGIN, END = "<!-- dataset-numbers -->", "<!-- /dataset-numbers -->"
PERF_BEGIN, PERF_END = "<!-- r6-data -->", "<!-- /r6-data -->"


class TreeMemory:
    """Peak resident memory [bytes] of a process and its descendants, summed, and of
    the largest one, sampled every ``period`` seconds."""

    def __init__(self, pid: int, period: float = 0.2):
        self.pid, self.period = pid, period
        self.peak_total = self.peak_one = 0
        self.largest = ""  # the command line of the largest process at its peak
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, daemon=True)
        self._thread.start()

    def _run(self):
        while not self._stop.is_set():
            try:
                root = psutil.Process(self.pid)
                procs = [root, *root.children(recursive=True)]
                rss = []
                for p in procs:
                    try:
                        rss.append((p.memory_info().rss, p))
                    except psutil.Error:
                        pass
                self.peak_total = max(self.peak_total, sum(r for r, _ in rss))
                biggest, proc = max(rss, key=lambda pair: pair[0], default=(0, None))
                if biggest > self.peak_one:
                    self.peak_one = biggest
                    self.largest = _role(proc)
            except psutil.Error:
                pass
            self._stop.wait(self.period)

    def stop(self):
        self._stop.set()
        self._thread.join()


def _role(proc) -> str:
    """What a process of the tree is: the command, a Dask worker or nanny, or other."""
    try:
        line = " ".join(proc.cmdline())
    except psutil.Error:
        return "?"
    if "tactsense" in line and "dataset" in line:
        return "the command"
    if "multiprocessing" in line or "spawn" in line:
        return "a Dask worker process"
    return line[:60]


def _run(args: list[str], env: dict) -> tuple[float, TreeMemory, str]:
    start = time.perf_counter()
    proc = subprocess.Popen(args, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                            text=True)  # fmt: skip
    memory = TreeMemory(proc.pid)
    out, _ = proc.communicate()
    memory.stop()
    if proc.returncode != 0:
        raise SystemExit(f"{' '.join(args)} failed ({proc.returncode}):\n{out}")
    return time.perf_counter() - start, memory, out


def _size(path: Path) -> int:
    if path.is_file():
        return path.stat().st_size
    return sum(p.stat().st_size for p in path.rglob("*") if p.is_file())


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--episodes", type=int, default=1000)
    parser.add_argument("--frames", type=int, default=1000)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--folder", type=Path, default=Path("/tmp/ts-dataset-numbers"))
    parser.add_argument("--lerobot-python", type=Path, default=None)
    parser.add_argument("--every", type=int, default=1000)
    parser.add_argument("--no-docs", action="store_true", help="Print, do not write docs.")
    args = parser.parse_args()

    env = {**os.environ, "PYTHONPATH": str(ROOT / "src")}
    shutil.rmtree(args.folder, ignore_errors=True)
    args.folder.mkdir(parents=True)
    total = args.episodes * args.frames
    results = {}
    for fmt, name in (("lerobot", "set"), ("hdf5", "set.h5")):
        out = args.folder / name
        seconds, memory, printed = _run(
            [sys.executable, "-m", "tactsense", "dataset", "--out", str(out), "--format", fmt,
             "--episodes", str(args.episodes), "--frames", str(args.frames),
             "--workers", str(args.workers), "--seed", "0", "--quiet"],
            env,
        )  # fmt: skip
        print(printed.strip())
        check_seconds, check_memory, check_out = _run(
            [sys.executable, "-c",
             "import json, sys; from tactsense.interop.dataset_check import check_dataset; "
             "print(json.dumps(check_dataset(sys.argv[1])))", str(out)],
            env,
        )  # fmt: skip
        check = json.loads(check_out.strip().splitlines()[-1])
        results[fmt] = {
            "seconds": seconds,
            "frames_per_s": total / seconds,
            "peak_tree_mb": memory.peak_total / 2**20,
            "peak_one_mb": memory.peak_one / 2**20,
            "largest": memory.largest,
            "bytes": _size(out),
            "check_seconds": check_seconds,
            "check_peak_mb": check_memory.peak_total / 2**20,
            "check": check,
        }
        print(fmt, json.dumps(results[fmt], indent=1))
    smaller = max(1, args.episodes // 10)  # memory bounded: the same peak for a tenth
    seconds, memory, _ = _run(
        [sys.executable, "-m", "tactsense", "dataset", "--out", str(args.folder / "tenth"),
         "--episodes", str(smaller), "--frames", str(args.frames),
         "--workers", str(args.workers), "--seed", "0", "--quiet"],
        env,
    )  # fmt: skip
    results["tenth"] = {
        "frames": smaller * args.frames,
        "seconds": seconds,
        "peak_tree_mb": memory.peak_total / 2**20,
        "peak_one_mb": memory.peak_one / 2**20,
        "largest": memory.largest,
    }
    print("tenth", results["tenth"])
    lerobot_lines = ["(not run: no Python with lerobot given)"]
    if args.lerobot_python is not None:
        seconds, memory, out = _run(
            [str(args.lerobot_python), str(ROOT / "scripts" / "check_lerobot.py"),
             str(args.folder / "set"), str(args.folder / "set.h5"), "--every", str(args.every),
             "--tolerate-torchvision-ops"],
            {**os.environ, "HF_DATASETS_CACHE": str(args.folder / "hf-cache")},
        )  # fmt: skip
        lines = [line for line in out.splitlines() if not line.startswith("WARNING")]
        lerobot_lines = [
            *lines,
            f"(in {seconds:.0f} s, peak memory {memory.peak_total / 2**20:.0f} MB)",
        ]
        print("\n".join(lerobot_lines))
    rate = worker_rate()
    print("worker blocks [s]", rate)
    results["worker"] = rate
    alone = locate_alone()
    print("locate alone", alone)
    text = _doc_block(args, total, results, lerobot_lines, alone)
    perf = _perf_block(args, total, results)
    print(text)
    if not args.no_docs:
        replace_block(ROOT / "docs" / "datasets.md", BEGIN, END, text)
        replace_block(ROOT / "docs" / "performance.md", PERF_BEGIN, PERF_END, perf)
    return 0


def locate_alone(n: int = 1000, seed: int = 1) -> dict:
    """locate's own error on pad16 [mm]: single noiseless presses (no flaws, a 1.6-mm
    sphere, 0.1 to 0.8 N) at exact positions a pitch inside the grid."""
    import numpy as np

    from tactsense.estimate.contacts import find_contacts
    from tactsense.sensor import load_sensor
    from tactsense.simulate.contact_frames import ContactBatch, frames_from_contacts

    spec = load_sensor("pad16")
    rng = np.random.default_rng(seed)
    pitch = spec.grid.row_pitch_mm
    high = (spec.shape[0] - 2) * pitch
    position = rng.uniform(pitch, high, size=(n, 1, 2))
    force = rng.uniform(0.1, 0.8, size=(n, 1))
    frames = frames_from_contacts(spec, ContactBatch(position, force), flaws="none")
    baseline = frames_from_contacts(spec, ContactBatch(position[:1], force[:1] * 0), flaws="none")
    table = find_contacts(frames.reshape(n, *spec.shape), spec,
                          baseline=baseline.reshape(spec.shape))  # fmt: skip
    first = table.contact == 0
    found = np.column_stack([table.x_mm[first], table.y_mm[first]])
    error = np.linalg.norm(found - position[table.frame[first], 0], axis=1)
    return {"n": n, "found": int(first.sum()), "median_mm": float(np.median(error)),
            "p95_mm": float(np.quantile(error, 0.95)), "max_mm": float(error.max()),
            "pitch_mm": pitch}  # fmt: skip


def worker_rate(blocks: int = 5, episodes: int = 20, frames: int = 1000) -> list[float]:
    """Seconds of each of ``blocks`` Dask tasks' work (``make_block``: labels, frames,
    LeRobot statistics) run one after the other in this process, as a worker runs them:
    the first ones build the layer's tables for the pressure radii they meet."""
    from tactsense.interop.datasets import make_block
    from tactsense.sensor import load_sensor
    from tactsense.simulate.dataset import DatasetPlan

    spec = load_sensor("pad16")
    plan = DatasetPlan(episodes=blocks * episodes, frames=frames)
    seconds = []
    for block in range(blocks):
        start = time.perf_counter()
        make_block(spec, plan, block * episodes, episodes, "lerobot")
        seconds.append(time.perf_counter() - start)
    return seconds


def _machine() -> str:
    import platform

    cpu = platform.processor() or platform.machine()
    return f"{os.cpu_count()} cores, {cpu}, Python {platform.python_version()}"


def _doc_block(args, total, results, lerobot_lines, alone) -> str:
    lo, h5 = results["lerobot"], results["hdf5"]
    rows = []
    for fmt, r in (("LeRobot v3 (folder)", lo), ("HDF5 (recording)", h5)):
        c = r["check"]
        rows.append(
            f"| {fmt} | {r['seconds']:.0f} s | {r['frames_per_s']:,.0f} | "
            f"{r['peak_tree_mb']:.0f} MB ({r['peak_one_mb']:.0f} MB) | "
            f"{r['bytes'] / 2**20:,.0f} MB | "
            f"{r['check_seconds']:.0f} s, {r['check_peak_mb']:.0f} MB | "
            f"{c['located']:,} / {c['missed']} | {c['error_median_mm']:.2f} / "
            f"{c['error_p95_mm']:.2f} / {c['error_max_mm']:.2f} mm | "
            f"{c['bias_x_mm']:+.3f}, {c['bias_y_mm']:+.3f} mm |"
        )
    return "\n".join(
        [
            BEGIN,
            f"`python scripts/dataset_numbers.py --episodes {args.episodes} --frames "
            f"{args.frames} --workers {args.workers}`: {total:,} frames of pad16 "
            f"({args.episodes:,} episodes of {args.frames:,} frames, seed 0, all flaws), "
            f"on {_machine()}, other work sharing the machine.",
            "",
            "| format | generated in | frames/s | peak memory: all processes (largest) | size "
            "| read back and checked | located / missed | locate error median / p95 / max "
            "| bias x, y |",
            "|---|---|---|---|---|---|---|---|---|",
            *rows,
            "",
            f"Memory does not grow with the set: the LeRobot set of a tenth of the frames "
            f"({results['tenth']['frames']:,}) peaked at {results['tenth']['peak_tree_mb']:.0f} MB "
            f"for all processes, {results['tenth']['peak_one_mb']:.0f} MB for the largest "
            f"({results['tenth']['largest']}; in the full run: {lo['largest']}), in "
            f"{results['tenth']['seconds']:.0f} s.",
            "",
            "Where the time goes: one worker's tasks (20 episodes, 20,000 frames each) "
            "run one after the other took "
            + ", ".join(f"{v:.1f}" for v in results["worker"])
            + " s: a worker builds the layer's response tables (docs/batch-frames.md) once "
            "for each grain of pressure radius its episodes reach, then makes "
            f"{20_000 / min(results['worker']):,.0f} labelled frames/s with their statistics.",
            "",
            f"Locate alone (no flaws, exact positions, {alone['found']:,} of {alone['n']:,} "
            f"single 1.6-mm presses of 0.1-0.8 N located): error median "
            f"{alone['median_mm']:.2f} mm ({alone['median_mm'] / alone['pitch_mm']:.2f} pitch), "
            f"p95 {alone['p95_mm']:.2f} mm, max {alone['max_mm']:.2f} mm "
            f"({alone['max_mm'] / alone['pitch_mm']:.2f} pitch).",
            "",
            "LeRobot's own reader on the LeRobot set (`scripts/check_lerobot.py`, every "
            f"{args.every}-th item compared with the HDF5 set's frame):",
            "",
            "```text",
            *lerobot_lines,
            "```",
            END,
        ]
    )


def _perf_block(args, total, results) -> str:
    lo, h5 = results["lerobot"], results["hdf5"]
    return "\n".join(
        [
            PERF_BEGIN,
            "## Labelled data sets: `tactsense dataset` (issue 38, item 3)",
            "",
            f"{total:,} pad16 frames with labels ({args.episodes:,} episodes), "
            f"{args.workers} Dask workers, `scripts/dataset_numbers.py` (docs/datasets.md): "
            f"LeRobot v3 in {lo['seconds']:.0f} s ({lo['frames_per_s']:,.0f} frames/s, peak "
            f"memory of all processes {lo['peak_tree_mb']:.0f} MB), HDF5 in "
            f"{h5['seconds']:.0f} s ({h5['frames_per_s']:,.0f} frames/s, "
            f"{h5['peak_tree_mb']:.0f} MB); read back and checked in "
            f"{lo['check_seconds']:.0f} s and {h5['check_seconds']:.0f} s.",
            PERF_END,
        ]
    )


if __name__ == "__main__":
    sys.exit(main())
