"""Throughput of ``tactsense export --format mcap``: CDR templates against the encoder.

Run: ``python benchmarks/bench_mcap.py [RECORDING.h5]`` (default: a simulated
repeated-load recording of 28,000 frames in a temporary folder). Times, in the same run
on the same recording:

* the writing alone (every frame and a contact for every touching frame through
  ``McapTactileWriter``), with the CDR templates (``fast=True``, the default) and with
  mcap-ros2-support's encoder called on a dictionary per message (``fast=False``, the
  straightforward way and the path before issue 21);
* the whole export (``export_mcap``: reading, estimating the contacts, writing) both ways;

and checks that both ways write the same bytes.
"""

from __future__ import annotations

import sys
import tempfile
import time
from pathlib import Path

import numpy as np

import tactsense as ts
from tactsense.interop.mcap import McapTactileWriter, export_mcap
from tactsense.io.recording import RecordingReader


def _write_only(path: Path, out: Path, fast: bool) -> tuple[float, int]:
    with RecordingReader(path) as reader:
        pieces = [(s, f, t) for s, f, t in reader.chunks()]
        sensor = reader.sensor
    touching = [(np.arange(len(t)) % 2 == 0) for _, _, t in pieces]
    start = time.perf_counter()
    with open(out, "wb") as stream:
        writer = McapTactileWriter(stream, sensor, fast=fast)
        for (s, frames, t), touch in zip(pieces, touching, strict=True):
            writer.frames_of(frames, t, np.arange(s, s + len(t)))
            n = len(t)
            writer.contacts_of(t, np.full(n, 12.0), np.zeros(n), np.full(n, 0.49), touch)
        writer.finish()
    return time.perf_counter() - start, writer.frames


def main(recording: str | None = None) -> None:
    with tempfile.TemporaryDirectory() as folder:
        folder = Path(folder)
        if recording is None:
            spec = ts.fearing1990_initial()
            recording = folder / "rec.h5"
            ts.simulate_to_file(spec, ts.repeated_load(spec, repeats=2000), recording, rng=0)
        recording = Path(recording)
        times = {}
        for fast in (True, False):
            times["write", fast], n = _write_only(recording, folder / f"w{fast}.mcap", fast)
        same = (folder / "wTrue.mcap").read_bytes() == (folder / "wFalse.mcap").read_bytes()
        for fast in (True, False):
            start = time.perf_counter()
            export_mcap(recording, folder / f"e{fast}.mcap", fast=fast)
            times["export", fast] = time.perf_counter() - start
        same_export = (folder / "eTrue.mcap").read_bytes() == (folder / "eFalse.mcap").read_bytes()
    print(f"recording: {n:,} frames")
    for what in ("write", "export"):
        fast, slow = times[what, True], times[what, False]
        print(
            f"{what:6s}: templates {fast:7.2f} s ({n / fast:>10,.0f} frames/s) | encoder "
            f"{slow:7.2f} s ({n / slow:>10,.0f} frames/s) | ratio {slow / fast:5.1f} x"
        )
    print(f"same bytes: write {same}, export {same_export}")


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else None)
