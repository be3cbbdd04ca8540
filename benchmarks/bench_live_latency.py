"""``tactsense live``'s latency at the start of a run, on a cold and a warm compile cache.

A twin of the 16x16 pad (``tactsense emulate --sensor pad16 --scenario press --loop``,
100 frames/s) speaks tactsense's native protocol (COBS packets, streaming after START)
or, with ``--format text``, text lines (streaming as soon as a host connects);
``tactsense live`` reads it and writes one estimate per frame. The cache is a fresh
``NUMBA_CACHE_DIR`` (cold: everything compiles), then the same directory again (warm).
Reported per run: the latency of the first estimate, the largest, the median, and the
first contact's latency beside the median (a stall while the contact path compiles),
each "from the frame's last byte to its estimate" as ``live`` prints it; and the spread
of ``host_time_s`` against the frame index (frames queued behind a stall keep their own
arrival, so a stall shows in the latency, not only in the host times).

    PYTHONPATH=src python benchmarks/bench_live_latency.py [--method fit] [--format native]
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

CLI = [sys.executable, "-m", "tactsense.cli"]
WIRES = ("native", "text")
"""The emulator's wire formats: the native COBS protocol (START, IDENTIFY) and text lines."""


def run_live(cache: str, method: str, wire: str = "text", frames: int = 300) -> list[dict]:
    env = {**os.environ, "NUMBA_CACHE_DIR": cache}
    emulator = subprocess.Popen(
        [*CLI, "emulate", "--sensor", "pad16", "--scenario", "press",
         *([] if wire == "native" else ["--format", wire]), "--port", "0", "--loop"],
        stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True, env=env,
    )  # fmt: skip
    url = emulator.stdout.readline().strip()
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "live.jsonl"
        try:
            subprocess.run(
                [*CLI, "live", url, "--sensor", "pad16", "--frames", str(frames),
                 "--method", method, "--out", str(out)],
                check=True, capture_output=True, env=env, timeout=300,
            )  # fmt: skip
        finally:
            emulator.terminate()
            emulator.wait(10)
        return [json.loads(line) for line in out.read_text().splitlines()]


def summary(estimates: list[dict]) -> str:
    latency = np.array([e["latency_ms"] for e in estimates])
    median = float(np.median(latency))
    touched = [e["latency_ms"] for e in estimates if e["n_contacts"]]
    first_contact = touched[0] if touched else float("nan")
    return (
        f"{len(latency)} estimates: first {latency[0]:.1f} ms, max {latency.max():.1f} ms, "
        f"median {median:.2f} ms; first contact {first_contact:.1f} ms "
        f"({first_contact - median:+.1f} ms beside the median)"
    )


def main() -> None:
    method = sys.argv[sys.argv.index("--method") + 1] if "--method" in sys.argv else "interpolate"
    wires = [sys.argv[sys.argv.index("--format") + 1]] if "--format" in sys.argv else WIRES
    for wire in wires:
        with tempfile.TemporaryDirectory() as cache:
            for label in ("cold", "warm"):
                estimates = run_live(cache, method, wire)
                print(f"{wire}, {label} cache, --method {method}: {summary(estimates)}")


if __name__ == "__main__":
    main()
