"""The C library for firmware authors (firmware/tactsense.c) against the Python encoder.

Run: ``python benchmarks/bench_firmware.py``. Compiles ``firmware/tactsense.c`` with the
test driver ``tests/firmware/ts_driver.c`` (``cc -std=c99 -O2``) and measures, in the same
run, frames encoded per second (COBS, CRC-32, packing, delimiter) for an 8x8 and a 16x16
frame:

* C, ``ts_encode_frame`` into a buffer;
* C, ``ts_send_frame`` through a write callback (the streaming API a device uses);
* C, ``ts_encode_frame`` built with ``-DTS_CRC_BYTE_TABLE`` (a 1-KB CRC table instead of
  the default 64 bytes);
* Python, ``tactsense.stream.protocol.encode_frame`` (``cobs`` and ``zlib`` in C under it).

Each figure is the best of three runs; frames cycle through 64 precomputed readings in
1,900..2,300 counts (the C driver uses xorshift32, Python NumPy: the same range).
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from tactsense.stream.protocol import encode_frame

ROOT = Path(__file__).resolve().parents[1]
SHAPES = [(8, 8), (16, 16)]


def build(folder: Path, *defines: str) -> Path:
    cc = shutil.which("cc") or shutil.which("gcc")
    if cc is None:
        sys.exit("error: no C compiler (cc or gcc) on PATH")
    exe = folder / ("ts_driver" + "".join(defines))
    sources = [ROOT / "firmware" / "tactsense.c", ROOT / "tests" / "firmware" / "ts_driver.c"]
    include = f"-I{ROOT / 'firmware'}"
    subprocess.run(
        [cc, "-std=c99", "-O2", *defines, include, *map(str, sources), "-o", str(exe)], check=True
    )
    return exe


def bench_c(exe: Path, mode: str, rows: int, cols: int, n: int) -> float:
    best = 0.0
    for _ in range(3):
        out = subprocess.run(
            [str(exe), "bench", mode, str(rows), str(cols), str(n)],
            capture_output=True,
            text=True,
            check=True,
        )
        best = max(best, float(out.stdout.split()[0]))
    return best


def bench_python(rows: int, cols: int, n: int) -> float:
    counts = np.random.default_rng(0).integers(1900, 2300, (64, rows, cols)).astype(np.uint16)
    best = 0.0
    for _ in range(3):
        start = time.perf_counter()
        for k in range(n):
            encode_frame(k, 142857 * k, counts[k & 63])
        best = max(best, n / (time.perf_counter() - start))
    return best


def main() -> None:
    with tempfile.TemporaryDirectory() as folder:
        exe = build(Path(folder))
        fast = build(Path(folder), "-DTS_CRC_BYTE_TABLE")
        print("load average before: {:.2f} {:.2f} {:.2f}".format(*os.getloadavg()))
        header = "| frame | C `ts_encode_frame` | C `ts_send_frame` | C, 1-KB CRC table |"
        print(header + " Python `encode_frame` | C / Python | C per byte on the wire |")
        print("|---|---|---|---|---|---|---|")
        for rows, cols in SHAPES:
            n_c = 2_000_000 // (rows * cols // 64)
            buffer = bench_c(exe, "buffer", rows, cols, n_c)
            stream = bench_c(exe, "stream", rows, cols, n_c)
            table = bench_c(fast, "buffer", rows, cols, n_c)
            python = bench_python(rows, cols, 100_000 // (rows * cols // 64))
            wire = len(encode_frame(0, 0, np.full((rows, cols), 2000)))
            print(
                f"| {rows}x{cols} | {buffer:,.0f} frames/s | {stream:,.0f} frames/s | "
                f"{table:,.0f} frames/s | {python:,.0f} frames/s | {buffer / python:.1f}x | "
                f"{1e9 / buffer / wire:.1f} ns ({wire} bytes) |"
            )
        print("load average after: {:.2f} {:.2f} {:.2f}".format(*os.getloadavg()))


if __name__ == "__main__":
    main()
