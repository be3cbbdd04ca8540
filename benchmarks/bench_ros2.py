"""``live --ros2``: publish rate, latency to another process's callback, and losses.

A 16 x 16 pad (``pad16``) pressed by two probes (the ``two-probes`` scenario, 90
frames, looped) is estimated frame by frame (:class:`~tactsense.stream.live.LiveContacts`,
as ``live`` does) and published by :class:`~tactsense.interop.ros2.Ros2Publisher` on its
four topics, paced at ``--rate`` frames/s (default 1000) for ``--seconds``. Each frame's
"last byte" is the moment it is handed to the locator (``time.perf_counter``; the
frames come from memory, so the wire's own time is not in these figures:
``bench_stream.py`` has it). The independent subscriber of the tests
(``tests/interop/ros2_subscriber.py``, another process, sensor-data QoS: best effort,
keep last 5) stamps each sample's arrival in its listener's callback on the same
monotonic clock; latency = callback - last byte, matched by the header's stamp. Losses
= frames published - samples received, per topic. Also measured: the publish path
alone (encode + DDS write of the four messages of one frame, no subscriber), templates
against Cyclone DDS's own serialiser (the straightforward path) in the same run, and
the fastest unpaced rate (estimate + publish, as fast as the loop goes).

Last, ``tactsense live --ros2`` itself (a subprocess) reading the emulated pad16 over
TCP at ``--cli-speed`` times its 100 frames/s scan rate (default 10: 1,000 frames/s),
estimates written to a file: its rate from the stamps the subscriber received, the
latency from each frame's last byte (its stamp, wall clock) to the subscriber's callback
(wall clock), losses per topic, and what ``live`` printed.

DDS runs on 127.0.0.1 only, multicast off (the loopback configuration through
``CYCLONEDDS_URI``), on a domain of its own.

    PYTHONPATH=src python benchmarks/bench_ros2.py [--rate 1000] [--seconds 10] [--cli-speed 10]
        [--write-docs]
"""

from __future__ import annotations

import argparse
import os
import pickle
import re
import struct
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
SUBSCRIBER = ROOT / "tests" / "interop" / "ros2_subscriber.py"
STAMP = struct.Struct("<iI")


def frames_and_locator():
    import tactsense as ts
    from tactsense import flat_scenarios as fs
    from tactsense.stream.live import LiveContacts

    pad = ts.preset("pad16")
    rec = ts.simulate(pad, fs.two_probes(pad), rng=0)
    locator = LiveContacts(pad, baseline=rec.frames[0].astype(float))
    return pad, rec.frames, locator


def _frame(k, counts):
    from tactsense.stream.reader import StreamFrame

    return StreamFrame(k, k, k * 1e-3, time.time(), time.perf_counter(), counts)


def publish_path(pad, frames, locator, n=3000) -> dict:
    """Microseconds per frame of encode + write (four messages), templates vs serialiser."""
    from tactsense.interop.ros2 import Ros2Publisher

    estimates = [locator(_frame(k, frames[k % len(frames)])) for k in range(len(frames))]
    result = {}
    for fast in (True, False):
        publisher = Ros2Publisher(pad, namespace="/bench_path", fast=fast)
        try:
            start = time.perf_counter()
            for k in range(n):
                j = k % len(frames)
                publisher.publish(_frame(k, frames[j]), estimates[j])
            result[fast] = (time.perf_counter() - start) / n * 1e6
        finally:
            publisher.close()
    return result


def unpaced(pad, frames, locator, seconds=3.0) -> float:
    """Frames/s of estimate + publish, as fast as the loop goes."""
    from tactsense.interop.ros2 import Ros2Publisher

    publisher = Ros2Publisher(pad, namespace="/bench_unpaced")
    try:
        k, start = 0, time.perf_counter()
        while time.perf_counter() - start < seconds:
            frame = _frame(k, frames[k % len(frames)])
            publisher.publish(frame, locator(frame))
            k += 1
        return k / (time.perf_counter() - start)
    finally:
        publisher.close()


def paced(pad, frames, locator, rate, seconds, folder: Path, *, estimate_live=True) -> dict:
    """Publish at ``rate`` for ``seconds`` to the independent subscriber; latency, losses.

    ``estimate_live`` False: each frame's estimate was made beforehand (the publisher's
    share of the budget alone: DDS, encoding, the subscriber)."""
    from tactsense.interop.ros2 import Ros2Publisher

    n = int(rate * seconds)
    namespace = "/bench_live" if estimate_live else "/bench_publish"
    out = folder / f"received{namespace.replace('/', '_')}.pickle"
    subscriber = subprocess.Popen(
        [sys.executable, str(SUBSCRIBER), str(out), "--domain", os.environ["ROS_DOMAIN_ID"],
         "--namespace", namespace, "--count", str(n), "--seconds", str(seconds + 60)],
        stdout=subprocess.PIPE, text=True,
    )  # fmt: skip
    assert subscriber.stdout.readline().strip() == "ready"
    publisher = Ros2Publisher(pad, namespace=namespace)
    deadline = time.perf_counter() + 10
    while publisher.subscribers() < 1 and time.perf_counter() < deadline:
        time.sleep(0.01)  # discovery: a ROS 2 subscriber joining late misses the first frames
    time.sleep(0.2)
    ready = [locator(_frame(k, frames[k])) for k in range(len(frames))]
    arrival, contacts, late = {}, 0, 0
    period = 1.0 / rate
    start = time.perf_counter()
    try:
        for k in range(n):
            due = start + k * period
            now = time.perf_counter()
            if due > now:
                time.sleep(due - now)
            elif now - due > period:
                late += 1  # more than a period behind the schedule
            frame = _frame(k, frames[k % len(frames)])
            estimate = locator(frame) if estimate_live else ready[k % len(frames)]
            contacts += bool(estimate and estimate["n_contacts"])
            publisher.publish(frame, estimate)
            arrival[round(frame.host_time_s * 1e9)] = frame.arrival
        elapsed = time.perf_counter() - start
    finally:
        subscriber.wait(seconds + 120)
        sent, failed = sum(publisher.published.values()), publisher.failed
        publisher.close()
    received = pickle.loads(out.read_bytes())
    latency, lost = {}, {}
    for topic, samples in received["received"].items():
        ms = []
        # a TactileContacts has no header: its first contact's stamp (empty lists: none)
        offset = 8 if topic == "contact_states" else 4
        for when, _, raw in samples:
            if len(raw) < offset + STAMP.size:
                continue
            sec, nanosec = STAMP.unpack_from(raw, offset)
            key = sec * 10**9 + nanosec
            if key in arrival:
                ms.append((when - arrival[key]) * 1e3)
        latency[topic] = np.percentile(ms, [50, 99]) if ms else (np.nan, np.nan)
        lost[topic] = n - len(samples)
    return {
        "n": n, "rate": n / elapsed, "late": late, "contacts": contacts, "sent": sent,
        "failed": failed, "latency": latency, "lost": lost, "lost_dds": received["lost"],
    }  # fmt: skip


def live_command(rate_scale: float, seconds: float, folder: Path) -> dict:
    """``tactsense live --ros2`` itself on the emulated pad16 (``emulate --speed``: frames
    at ``rate_scale`` times its 100 frames/s scan rate, over TCP), estimates to a file;
    the independent subscriber counts the samples. Latency: the subscriber's callback on
    the wall clock minus the header's stamp, the frame's last byte on the same clock."""
    cli = [sys.executable, "-m", "tactsense"]
    emulator = subprocess.Popen(
        [*cli, "emulate", "--sensor", "pad16", "--scenario", "two-probes", "--loop",
         "--speed", f"{rate_scale:g}", "--port", "0"],
        stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True,
    )  # fmt: skip
    url = emulator.stdout.readline().strip()
    out = folder / "received_cli.pickle"
    subscriber = subprocess.Popen(
        [sys.executable, str(SUBSCRIBER), str(out), "--domain", os.environ["ROS_DOMAIN_ID"],
         "--namespace", "/bench_cli", "--seconds", str(seconds + 20)],
        stdout=subprocess.PIPE, text=True,
    )  # fmt: skip
    assert subscriber.stdout.readline().strip() == "ready"
    try:
        done = subprocess.run(
            [*cli, "live", url, "--ros2", "--namespace", "/bench_cli", "--duration",
             f"{seconds:g}", "--out", str(folder / "live.jsonl")],
            capture_output=True, text=True, timeout=seconds + 120,
        )  # fmt: skip
    finally:
        emulator.terminate()
        emulator.wait(10)
    subscriber.wait(seconds + 60)
    summary = " ".join(done.stderr.split())
    frames = int(re.search(r"ROS 2: (\d+) frames", summary).group(1))
    received = pickle.loads(out.read_bytes())["received"]
    states = received["tactile_states"]
    stamps = np.array(
        [sum(STAMP.unpack_from(raw, 4) * np.array([1.0, 1e-9])) for *_, raw in states]
    )
    latency_ms = np.array([wall for _, wall, _ in states]) * 1e3 - stamps * 1e3
    return {
        "frames": frames, "rate": (len(stamps) - 1) / (stamps[-1] - stamps[0]),
        "latency": np.percentile(latency_ms, [50, 99]),
        "lost": {topic: frames - len(samples) for topic, samples in received.items()},
        "summary": summary,
    }  # fmt: skip


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rate", type=float, default=1000.0, help="frames/s to publish")
    parser.add_argument("--seconds", type=float, default=10.0, help="how long [s]")
    parser.add_argument(
        "--cli-speed", type=float, default=10.0, help="emulator speed for the live run (x 100/s)"
    )
    parser.add_argument("--write-docs", action="store_true", help="update docs/ros2.md's block")
    args = parser.parse_args()
    from tactsense.interop.ros2 import loopback_config

    with tempfile.TemporaryDirectory() as tmp:
        os.environ["CYCLONEDDS_URI"] = f"file://{loopback_config(tmp)}"
        os.environ["ROS_DOMAIN_ID"] = str(150 + os.getpid() % 80)
        pad, frames, locator = frames_and_locator()
        path = publish_path(pad, frames, locator)
        fastest = unpaced(pad, frames, locator)
        runs = {
            "estimated as the frames come (live)": paced(
                pad, frames, locator, args.rate, args.seconds, Path(tmp)
            ),
            "estimates made beforehand (the publishing alone)": paced(
                pad, frames, locator, args.rate, args.seconds, Path(tmp), estimate_live=False
            ),
        }
        cli = live_command(args.cli_speed, args.seconds, Path(tmp))
    stream = re.search(r"\d+ estimates.*?(?=ROS 2:)", cli["summary"])
    lines = [
        f"publish path (encode + write, 4 messages, pad16, no subscriber): templates "
        f"{path[True]:.1f} us/frame, Cyclone DDS serialiser {path[False]:.1f} us/frame "
        f"(ratio {path[False] / path[True]:.1f} x)",
        f"unpaced, estimate + publish: {fastest:,.0f} frames/s",
    ]
    for what, run in runs.items():
        lines.append(
            f"paced at {args.rate:g} frames/s for {args.seconds:g} s, {what}: {run['n']:,} "
            f"frames ({run['contacts']:,} with contacts) published at {run['rate']:,.0f} "
            f"frames/s, {run['late']} more than a period late; {run['sent']:,} samples "
            f"sent, {run['failed']} not sent"
        )
        for topic, (p50, p99) in run["latency"].items():
            lines.append(
                f"  {topic:15s} last byte -> subscriber callback: p50 {p50:.3f} ms, p99 "
                f"{p99:.3f} ms; lost {run['lost'][topic]} of {run['n']:,} "
                f"(DDS sample-lost status {run['lost_dds'][topic]})"
            )
    p50, p99 = cli["latency"]
    lines.append(
        f"tactsense live --ros2 on the emulated pad16 at {100 * args.cli_speed:g} frames/s "
        f"for {args.seconds:g} s: {cli['frames']:,} frames published at "
        f"{cli['rate']:,.0f} frames/s (from the stamps); last byte -> subscriber callback "
        f"(wall clock) p50 {p50:.3f} ms, p99 {p99:.3f} ms; lost per topic "
        + ", ".join(f"{t} {n}" for t, n in cli["lost"].items())
        + (f"; live said: {stream.group(0).strip()}" if stream else "")
    )
    lines.append(f"load average at the end (2 cores, shared): {os.getloadavg()[0]:.2f}")
    text = "\n".join(lines)
    print(text)
    if args.write_docs:
        sys.path.insert(0, str(ROOT / "scripts"))
        from docblock import replace_block

        begin, end = "<!-- bench_ros2 -->", "<!-- /bench_ros2 -->"
        command = (
            f"python benchmarks/bench_ros2.py --rate {args.rate:g} --seconds {args.seconds:g} "
            f"--cli-speed {args.cli_speed:g}"
        )
        block = f"{begin}\n```text\n$ {command}\n{text}\n```\n{end}"
        for doc in ("docs/ros2.md", "docs/performance.md"):
            replace_block(ROOT / doc, begin, end, block)


if __name__ == "__main__":
    main()
