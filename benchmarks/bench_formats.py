"""Readers of the other wire formats (docs/devices.md) beside the native protocol's.

Run: ``python benchmarks/bench_formats.py [FRAMES]``. For each format a sender process
writes FRAMES (default 100,000) pre-encoded 8x8 frames of the initial finger as fast as
a 127.0.0.1 TCP connection takes them; the reader (``open_source(...).read_batch``)
splits, decodes and counts them, from the first frame's arrival to the last. In the same
run, a straightforward reader of each format on 5,000 frames: pyserial's ``readline()``
or ``read_until(delimiter)`` per frame, then ``int()`` per value or
``numpy.frombuffer``, as a first driver is usually written.
"""

from __future__ import annotations

import multiprocessing
import socket
import sys
import time

import numpy as np
import serial

import tactsense as ts
from tactsense.stream.protocol import encode_frame
from tactsense.stream.sources import open_source, parse_format

FORMATS = ["native", "text", "marker,width=16", "marker", "justfloat"]
SIMPLE_FRAMES = 5_000


def _frames(spec, n_frames: int, fmt: str) -> bytes:
    rng = np.random.default_rng(0)
    counts = rng.integers(1900, 2300, (1000, *spec.shape)).astype(np.uint16)
    if fmt == "native":
        period_us = spec.scan_period_s * 1e6
        return b"".join(
            encode_frame(k, round(k * period_us), counts[k % 1000]) for k in range(n_frames)
        )
    wire_format = parse_format(fmt)
    counts = wire_format.prepare(counts)
    one = [wire_format.encode(c) for c in counts]
    return b"".join(one[k % 1000] for k in range(n_frames))


def _sender(port_queue, fmt: str, n_frames: int) -> None:
    wire = _frames(ts.fearing1990_initial(), n_frames, fmt)  # before the clock starts
    with socket.create_server(("127.0.0.1", 0)) as server:
        port_queue.put(server.getsockname()[1])
        conn, _ = server.accept()
        with conn:
            time.sleep(0.3)  # pyserial discards what arrives while it opens the line
            try:
                conn.sendall(wire)
                time.sleep(1.0)
            except (BrokenPipeError, ConnectionResetError):
                pass


def _start(fmt: str, n_frames: int):
    queue = multiprocessing.Queue()
    process = multiprocessing.Process(target=_sender, args=(queue, fmt, n_frames), daemon=True)
    process.start()
    return process, queue.get(timeout=300)


def bench_reader(spec, fmt: str, n_frames: int) -> tuple[float, str]:
    process, port = _start(fmt, n_frames)
    url = f"socket://127.0.0.1:{port}"
    source = url if fmt == "native" else f"{fmt}:{url}"
    with open_source(source, sensor=spec, start=False) as stream:
        received, start = 0, None
        while received < n_frames:
            batch = stream.read_batch(10_000, wait_s=3.0)
            if not batch:
                break
            if start is None:
                start = batch[0].arrival
            received += len(batch)
        elapsed = time.perf_counter() - start
        summary = stream.stats.summary()
    process.join(5)
    assert received == n_frames, summary
    return (received - 1) / elapsed, summary  # frames after the first, over their time


def bench_simple(spec, fmt: str, n_frames: int) -> float:
    process, port = _start(fmt, n_frames)
    port_ = serial.serial_for_url(f"socket://127.0.0.1:{port}", timeout=3)
    rows, cols = spec.shape
    n = rows * cols
    got = 0
    start = None
    name = fmt.split(",")[0]
    while got < n_frames:
        if name == "text":
            line = port_.readline()
            counts = np.array([int(v) for v in line.strip().split(b",")], np.uint16)
        elif name == "marker":
            width = 2 if "width=16" in fmt else 1
            port_.read_until(b"\xaa\x55")
            counts = np.frombuffer(port_.read(n * width), np.uint8 if width == 1 else "<u2")
        else:
            raw = port_.read_until(bytes.fromhex("0000807f"))[:-4]
            counts = np.frombuffer(raw, "<f4").astype(np.uint16)
        if counts.size != n:
            continue
        if start is None:
            start = time.perf_counter()
        got += 1
    elapsed = time.perf_counter() - start
    port_.close()
    process.join(5)
    return (got - 1) / elapsed


def main() -> None:
    n_frames = int(sys.argv[1]) if len(sys.argv) > 1 else 100_000
    spec = ts.fearing1990_initial()
    print(f"{n_frames} frames of {spec.shape[0]}x{spec.shape[1]} over 127.0.0.1 TCP")
    for fmt in FORMATS:
        rate, summary = bench_reader(spec, fmt, n_frames)
        line = f"{fmt:18s} reader {rate:10,.0f} frames/s ({summary})"
        if fmt != "native":
            simple = bench_simple(spec, fmt, SIMPLE_FRAMES)
            line += f"; straightforward {simple:9,.0f} frames/s; ratio {rate / simple:5.1f}x"
        print(line, flush=True)


if __name__ == "__main__":
    main()
