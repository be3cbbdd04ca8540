"""Version-2 FRAMEs (three components per taxel) through the reader, against version 1.

Run: ``python benchmarks/bench_triaxial_wire.py [FRAMES]``. In one run, each against a
separate sender process over a 127.0.0.1 TCP connection that writes pre-encoded frames
as fast as the socket takes them:

* ``StreamReader.read_batch`` on ``FRAMES`` version-2 frames of ``mag4x4`` (4 x 4 x 3
  counts: 115 bytes before COBS) and on as many version-1 frames of a scalar 8 x 6 pad
  (48 counts, the same number of values: 114 bytes), to show what the version-2 layout
  costs the reader;
* the straightforward reader of version-2 frames in the same run: pyserial's
  ``read_until(b"\\0")`` per frame, then ``cobs.decode``, ``zlib.crc32`` and
  ``numpy.frombuffer`` (the way a first driver is usually written), on 20,000 frames.

Prints a table with the machine's load average (other jobs share it); ``--write-docs``
puts it in docs/performance.md (the block ``bench_triaxial_wire``).
"""

from __future__ import annotations

import multiprocessing
import os
import socket
import sys
import time
import zlib
from pathlib import Path

import numpy as np
import serial
from cobs import cobs

from tactsense.sensor import load_sensor
from tactsense.stream import StreamReader
from tactsense.stream.protocol import Kind, encode_control, encode_frame

NAIVE_FRAMES = 20_000


def _sender(port_queue, shape, n_frames: int) -> None:
    rng = np.random.default_rng(0)
    counts = (32768 + rng.integers(-3000, 3000, (1000, *shape))).astype(np.uint16)
    # every frame encoded before the clock starts: the sender must not be the bottleneck
    wire = b"".join(encode_frame(k, k * 10_000, counts[k % 1000]) for k in range(n_frames))
    with socket.create_server(("127.0.0.1", 0)) as server:
        port_queue.put(server.getsockname()[1])
        conn, _ = server.accept()
        with conn:
            try:
                conn.recv(64)  # the host's START: sent once its line is open
                conn.sendall(wire)
                conn.recv(1)  # open until the reader closes: a loaded machine reads late
            except (BrokenPipeError, ConnectionResetError):
                pass  # the reader had enough


def _start_sender(shape, n_frames: int):
    queue = multiprocessing.Queue()
    process = multiprocessing.Process(target=_sender, args=(queue, shape, n_frames), daemon=True)
    process.start()
    return process, queue.get(timeout=300)


def bench_reader(spec, n_frames: int) -> float:
    """Frames per second of ``StreamReader.read_batch`` (after the first batch)."""
    process, port = _start_sender(spec.frame_shape, n_frames)
    # the sender waits for START (pyserial's socket:// drops what arrives while it
    # opens); the rate is over the frames after the first batch's
    with StreamReader(f"socket://127.0.0.1:{port}", sensor=spec) as stream:
        received, start, give_up = 0, None, time.perf_counter() + 120
        while received < n_frames and time.perf_counter() < give_up:
            batch = stream.read_batch(10_000, wait_s=2.0)
            if not batch:
                continue
            if start is None:
                start, first = batch[0].arrival, len(batch)
            received += len(batch)
            shape = batch[-1].counts.shape
        elapsed = time.perf_counter() - start
        lost = stream.stats.lost + stream.stats.bad_check
    process.terminate()
    assert shape == spec.frame_shape and lost == 0 and received == n_frames, received
    return (received - first) / elapsed


def bench_naive(spec) -> float:
    """Frames per second of a reader of one ``read_until`` per frame."""
    process, port = _start_sender(spec.frame_shape, NAIVE_FRAMES)
    line = serial.serial_for_url(f"socket://127.0.0.1:{port}", timeout=2.0)
    line.write(encode_control(Kind.START))
    received = 0
    start = time.perf_counter()
    while received < NAIVE_FRAMES:
        packet = line.read_until(b"\x00")
        if not packet:
            break
        raw = cobs.decode(packet[:-1])
        if zlib.crc32(raw[:-4]) == int.from_bytes(raw[-4:], "little"):
            np.frombuffer(raw[15:-4], "<u2").reshape(spec.frame_shape)
            received += 1
    elapsed = time.perf_counter() - start
    line.close()
    process.terminate()
    return received / elapsed


ROOT = Path(__file__).resolve().parents[1]
PERFORMANCE = ROOT / "docs" / "performance.md"
BEGIN, END = "<!-- bench_triaxial_wire: begin -->", "<!-- bench_triaxial_wire: end -->"


def main(n_frames: int, write_docs: bool) -> None:
    mag = load_sensor("mag4x4")
    scalar = load_sensor("pad16").replace(grid__rows=8, grid__cols=6)
    before = os.getloadavg()[0]
    v2 = bench_reader(mag, n_frames)
    v1 = bench_reader(scalar, n_frames)
    naive = bench_naive(mag)
    after = os.getloadavg()[0]
    text = "\n".join(
        [
            BEGIN,
            f"One run of `python benchmarks/bench_triaxial_wire.py {n_frames} --write-docs`, "
            f"the machine's 1-minute load average {before:.1f} before and {after:.1f} after "
            "on its 2 cores (other jobs running: read the ratios).",
            "",
            "| reader | frames/s |",
            "|---|---|",
            f"| `StreamReader.read_batch`, version 2, `mag4x4` (4 x 4 x 3 counts) | "
            f"**{v2:,.0f}** |",
            f"| the same, version 1, a scalar 8 x 6 pad (48 counts) | {v1:,.0f} |",
            f"| version 2 / version 1 | {v2 / v1:.2f} |",
            f"| straightforward reader of version 2 (`read_until`, `cobs.decode`, `zlib.crc32`,"
            f" `numpy.frombuffer`; {NAIVE_FRAMES:,} frames) | {naive:,.0f} |",
            f"| `StreamReader` / straightforward | {v2 / naive:.0f}x |",
            END,
        ]
    )
    print(text)
    if write_docs:
        sys.path.insert(0, str(ROOT / "scripts"))
        from docblock import replace_block

        replace_block(PERFORMANCE, BEGIN, END, text)


if __name__ == "__main__":
    numbers = [a for a in sys.argv[1:] if a.isdigit()]
    main(int(numbers[0]) if numbers else 100_000, "--write-docs" in sys.argv[1:])
