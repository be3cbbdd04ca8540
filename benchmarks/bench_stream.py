"""The live system: reader throughput, latency to estimate, and the recorder's CPU.

Run: ``python benchmarks/bench_stream.py``. Three measurements, each against a separate
device process over a 127.0.0.1 TCP connection:

* **throughput**: a sender process writes 200,000 encoded 8x8 frames as fast as the
  socket takes them; ``StreamReader.read_batch`` decodes, checks and counts them. The
  straightforward reader in the same run: pyserial's ``read_until(b"\\0")`` per frame,
  then ``cobs.decode`` and ``zlib.crc32`` (the way a first driver is usually written);
* **latency**: ``tactsense emulate --speed 10`` (70 frames/s, 10x the paper's 7 Hz);
  from the arrival of a frame's last byte to its estimate by ``LiveLocator``;
* **CPU of ``tactsense record``** at the paper's rate (``--speed 1``), measured from
  /proc over 20 s of steady recording (start-up excluded).
"""

from __future__ import annotations

import multiprocessing
import signal
import socket
import subprocess
import sys
import tempfile
import time
import zlib
from pathlib import Path

import numpy as np
import serial
from cobs import cobs

import tactsense as ts
from tactsense.stream import LiveLocator, StreamReader
from tactsense.stream.protocol import encode_frame

FRAMES = 200_000
CLI = [sys.executable, "-m", "tactsense.cli"]


def _sender(port_queue, n_frames: int) -> None:
    spec = ts.fearing1990_initial()
    rng = np.random.default_rng(0)
    counts = rng.integers(1900, 2300, (1000, *spec.shape)).astype(np.uint16)
    period_us = spec.scan_period_s * 1e6
    # every frame encoded before the clock starts: the sender must not be the bottleneck
    wire = b"".join(
        encode_frame(k, round(k * period_us), counts[k % 1000]) for k in range(n_frames)
    )
    with socket.create_server(("127.0.0.1", 0)) as server:
        port_queue.put(server.getsockname()[1])
        conn, _ = server.accept()
        with conn:
            try:
                conn.sendall(wire)
                time.sleep(1.0)
            except (BrokenPipeError, ConnectionResetError):
                pass  # the reader had enough


def _start_sender():
    queue = multiprocessing.Queue()
    process = multiprocessing.Process(target=_sender, args=(queue, FRAMES), daemon=True)
    process.start()
    return process, queue.get(timeout=120)


def bench_reader(spec) -> float:
    process, port = _start_sender()
    with StreamReader(f"socket://127.0.0.1:{port}", sensor=spec, start=False) as stream:
        received = 0
        start = None
        while received < FRAMES:
            batch = stream.read_batch(10_000, wait_s=2.0)
            if not batch:
                break
            if start is None:
                start = batch[0].arrival
            received += len(batch)
        elapsed = time.perf_counter() - start
        stats = stream.stats
    process.join(5)
    print(f"reader: {received} frames in {elapsed:.2f} s, losses {stats.summary()}")
    return received / elapsed


def bench_naive(spec, n_frames: int = 50_000) -> float:
    process, port = _start_sender()
    port_ = serial.serial_for_url(f"socket://127.0.0.1:{port}", timeout=2.0)
    received = 0
    start = time.perf_counter()
    while received < n_frames:
        packet = port_.read_until(b"\x00")
        if not packet:
            break
        raw = cobs.decode(packet[:-1])
        if zlib.crc32(raw[:-4]) == int.from_bytes(raw[-4:], "little"):
            np.frombuffer(raw[14:-4], "<u2").reshape(spec.shape)
            received += 1
    elapsed = time.perf_counter() - start
    port_.close()
    process.terminate()
    return received / elapsed


def _emulator(*options):
    process = subprocess.Popen(
        [*CLI, "emulate", "--port", "0", "--loop", *options],
        stdout=subprocess.PIPE,
        stderr=subprocess.DEVNULL,
        text=True,
    )
    return process, process.stdout.readline().strip()


def bench_latency(seconds: float = 20.0) -> np.ndarray:
    process, url = _emulator("--speed", "10")
    latencies = []
    with StreamReader(url, start=False) as stream:
        locator = LiveLocator(stream.sensor)
        stream.start()
        for frame in stream.frames(duration_s=seconds):
            estimate = locator(frame)
            if estimate is not None:
                latencies.append(estimate["latency_ms"])
    process.send_signal(signal.SIGINT)
    process.wait(10)
    return np.array(latencies)


def _cpu_seconds(pid: int) -> float:
    fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / 100.0  # utime + stime, clock ticks


def bench_record_cpu(seconds: float = 20.0) -> float:
    process, url = _emulator("--speed", "1")
    with tempfile.TemporaryDirectory() as folder:
        recorder = subprocess.Popen(
            [*CLI, "record", url, "--out", str(Path(folder) / "r.h5"), "--quiet"],
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
        )
        time.sleep(8.0)  # start-up: imports, IDENTIFY, first flush
        before, t0 = _cpu_seconds(recorder.pid), time.perf_counter()
        time.sleep(seconds)
        after, t1 = _cpu_seconds(recorder.pid), time.perf_counter()
        recorder.send_signal(signal.SIGINT)
        recorder.wait(20)
    process.send_signal(signal.SIGINT)
    process.wait(10)
    return (after - before) / (t1 - t0)


def main() -> None:
    spec = ts.fearing1990_initial()
    fast = bench_reader(spec)
    naive = bench_naive(spec)
    print(f"StreamReader.read_batch over loopback TCP: {fast:,.0f} frames/s")
    print(f"straightforward read_until reader:          {naive:,.0f} frames/s")
    print(f"ratio: {fast / naive:.1f}x")
    latency = bench_latency()
    p50, p99 = np.percentile(latency, [50, 99])
    print(
        f"latency, last byte to estimate, {len(latency)} frames at 70 frames/s: "
        f"median {p50:.3f} ms, p99 {p99:.3f} ms, max {latency.max():.3f} ms"
    )
    cpu = bench_record_cpu()
    print(f"tactsense record at 7 frames/s: {100 * cpu:.2f} % of one core")


if __name__ == "__main__":
    main()
