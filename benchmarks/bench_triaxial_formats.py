"""Throughput of three-axis frames into MCAP: the per-component CDR template against the
encoder (issue 35 item 3).

A three-axis frame is a ``TactileState`` of three channels (``<sensor>/x``, ``/y``,
``/z``); :class:`tactsense.interop._state_bytes.ComponentStateBytes` fills the bytes of
one message the encoder made with the stamp and each channel's values. Times, in the
same run on the same frames: writing every frame through ``McapTactileWriter`` with the
template (``fast=True``) and with mcap-ros2-support's encoder on a dictionary per message
(``fast=False``, the straightforward way); the two files are compared byte for byte.

Run: ``python benchmarks/bench_triaxial_formats.py [--frames N] [--sensor mag4x4]
[--write-docs]`` (frames: the simulated press repeated to N frames).
"""

from __future__ import annotations

import argparse
import platform
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

import tactsense as ts
from tactsense.interop.mcap import McapTactileWriter

BEGIN, END = "<!-- bench_triaxial_formats: begin -->", "<!-- bench_triaxial_formats: end -->"


def _frames(sensor_name: str, n: int, folder: Path):
    from typer.testing import CliRunner

    from tactsense.cli import app

    path = folder / "press.h5"
    result = CliRunner().invoke(
        app, ["simulate", "--sensor", sensor_name, "--scenario", "press", "-o", str(path)]
    )
    if result.exit_code != 0:
        raise SystemExit(result.output)
    rec = ts.read_recording(path)
    reps = -(-n // len(rec))
    frames = np.concatenate([rec.frames] * reps)[:n]
    times = np.arange(n) * rec.sensor.scan_period_s
    return rec.sensor, frames, times


def _write(sensor, frames, times, out: Path, fast: bool) -> float:
    start = time.perf_counter()
    with open(out, "wb") as stream:
        writer = McapTactileWriter(stream, sensor, fast=fast)
        for s in range(0, len(times), 4096):
            stop = min(len(times), s + 4096)
            writer.frames_of(frames[s:stop], times[s:stop], np.arange(s, stop))
        writer.finish()
    return time.perf_counter() - start


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--frames", type=int, default=20_000, help="frames to write")
    parser.add_argument("--sensor", default="mag4x4", help="a three-axis preset")
    parser.add_argument("--write-docs", action="store_true", help="update docs/performance.md")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as folder:
        folder = Path(folder)
        sensor, frames, times = _frames(args.sensor, args.frames, folder)
        fast = _write(sensor, frames, times, folder / "fast.mcap", True)
        slow = _write(sensor, frames, times, folder / "slow.mcap", False)
        same = (folder / "fast.mcap").read_bytes() == (folder / "slow.mcap").read_bytes()
    n = len(times)
    rows = [
        ("frames", f"{n:,} of {sensor.name} ({' x '.join(map(str, sensor.frame_shape))})"),
        ("template (a channel per component)", f"{n / fast:,.0f} frames/s ({fast:.2f} s)"),
        ("encoder, a dictionary per message", f"{n / slow:,.0f} frames/s ({slow:.2f} s)"),
        ("ratio", f"{slow / fast:.1f} x"),
        ("the same bytes", "yes" if same else "NO"),
    ]
    head = (
        f"{platform.machine()}, Python {platform.python_version()}; "
        f"`python benchmarks/bench_triaxial_formats.py --frames {n} --sensor {args.sensor}`."
    )
    lines = ["| measure | value |", "| --- | --- |"] + [f"| {a} | {b} |" for a, b in rows]
    text = f"{BEGIN}\n{head}\n\n" + "\n".join(lines) + f"\n{END}"
    print(text)
    if not same:
        raise SystemExit("the template's bytes differ from the encoder's")
    if args.write_docs:
        sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "scripts"))
        from docblock import replace_block

        replace_block(Path(__file__).resolve().parents[1] / "docs/performance.md", BEGIN, END, text)


if __name__ == "__main__":
    main()
