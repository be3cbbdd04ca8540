"""Foxglove live (``live``/``view --foxglove``): how fast frames go out, and what a client
gets.

Run: ``python benchmarks/bench_foxglove_live.py [--write-docs]``. Needs foxglove-sdk,
mcap-ros2-support, node and npm (the client of tests/interop/foxglove_node/ is installed
into a temporary folder with ``npm ci``). On a pad16 recording of two probes (the live
locator's estimates computed first, so only the publishing is timed), in one run:

* publishing alone, no client: :meth:`FoxgloveLive.push` (the MCAP writer's CDR
  templates) against the straightforward way (each message a dictionary encoded by
  mcap-ros2-support's encoder, then logged on the same channels) [frames/s], and their
  ratio;
* with the node client subscribed to the three channels, frames pushed at a steady rate
  (``RATE_HZ``) for ``SECONDS``: the rate achieved, messages received of those sent per
  topic (losses: the SDK drops a slow client's oldest messages past its backlog of 1024),
  and the latency from the push (each frame stamped with the host's clock just before
  it) to the client's message callback, p50 and p99 [ms].

``--write-docs`` puts the figures in the generated blocks of docs/foxglove.md and
docs/performance.md.
"""

from __future__ import annotations

import json
import platform
import shutil
import subprocess
import sys
import tempfile
import time
from importlib.metadata import version
from pathlib import Path

import numpy as np

import tactsense as ts
from tactsense.interop.foxglove_live import CHANNELS, FoxgloveLive
from tactsense.stream.reader import StreamFrame

ROOT = Path(__file__).resolve().parents[1]
NODE_PACKAGE = ROOT / "tests" / "interop" / "foxglove_node"
DOC = ROOT / "docs" / "foxglove.md"
PERFORMANCE = ROOT / "docs" / "performance.md"
BEGIN, END = "<!-- bench_foxglove_live: begin -->", "<!-- bench_foxglove_live: end -->"
RATE_HZ = 1000.0
SECONDS = 5.0
TOPICS = [topic for topic, _, _ in CHANNELS]


def recording_and_estimates(repeats: int):
    """pad16 frames of two probes, ``repeats`` times over, with the live estimates."""
    from tactsense.flat_scenarios import two_probes
    from tactsense.stream.live import LiveContacts

    spec = ts.preset("pad16")
    rec = ts.simulate(spec, two_probes(spec), rng=2)
    frames = np.concatenate([rec.frames] * repeats)
    locator = LiveContacts(spec, baseline_frames=5, drift_s=2.0)
    estimates = [
        locator(StreamFrame(k % 65536, k, k * spec.scan_period_s, 0.0, 0.0, counts))
        for k, counts in enumerate(frames)
    ]
    return spec, frames, estimates


class Straightforward:
    """Each message a dictionary, encoded by mcap-ros2-support's encoder, then logged."""

    def __init__(self, server: FoxgloveLive):
        from mcap_ros2._dynamic import serialize_dynamic

        from tactsense.interop.ros import tactile_contact, tactile_state

        self.server, self.state, self.contact = server, tactile_state, tactile_contact
        self.encode = {
            topic: serialize_dynamic(schema, definition)[schema]
            for topic, schema, definition in CHANNELS
        }
        self.normals = server.sensor.taxel_normals()
        self.positions = server.sensor.taxel_positions_mm()

    def push(self, frame, estimate) -> None:
        sensor, channels, t = self.server.sensor, self.server.channels, frame.host_time_s
        ns = round(t * 1e9)
        state = self.state(sensor, frame.counts, t, "finger")
        channels[TOPICS[0]].log(bytes(self.encode[TOPICS[0]](state)), log_time=ns)
        messages = []
        for c in [] if estimate is None else estimate["contacts"]:
            xyz = np.array([c["x_mm"], c["y_mm"], c["z_mm"]])
            nearest = np.argmin(((self.positions - xyz) ** 2).sum(axis=1))
            message = self.contact(sensor, t, xyz * 1e-3, self.normals[nearest], c["force_n"],
                                   "finger", name=f"{sensor.name}/{c['id']}")  # fmt: skip
            channels[TOPICS[1]].log(bytes(self.encode[TOPICS[1]](message)), log_time=ns)
            messages.append(message)
        lists = bytes(self.encode[TOPICS[2]]({"contacts": messages}))
        channels[TOPICS[2]].log(lists, log_time=ns)


def push_rate(pusher, frames, estimates) -> float:
    """Frames pushed per second (no client)."""
    start = time.perf_counter()
    for k, (counts, estimate) in enumerate(zip(frames, estimates, strict=True)):
        pusher.push(StreamFrame(k % 65536, k, 0.0, 1.8e9 + k * 1e-3, 0.0, counts), estimate)
    return len(frames) / (time.perf_counter() - start)


def node_version() -> str:
    return subprocess.run(["node", "--version"], capture_output=True, text=True).stdout.strip()


def install_client(folder: Path) -> Path:
    for name in ("package.json", "package-lock.json", "client.js"):
        shutil.copy(NODE_PACKAGE / name, folder / name)
    subprocess.run(["npm", "ci", "--no-audit", "--no-fund", "--loglevel=error"], cwd=folder,
                   check=True, capture_output=True, timeout=300)  # fmt: skip
    return folder / "client.js"


def with_client(client: Path, spec, frames, estimates) -> dict:
    """Push at RATE_HZ for SECONDS with the node client subscribed; what it received."""
    n = int(RATE_HZ * SECONDS)
    frames, estimates = frames[:n], estimates[:n]
    sent = {TOPICS[0]: n, TOPICS[2]: n,
            TOPICS[1]: sum(len(e["contacts"]) for e in estimates if e is not None)}  # fmt: skip
    with FoxgloveLive(spec, port=0) as server:
        process = subprocess.Popen(
            ["node", str(client), server.url, "foxglove.sdk.v1", json.dumps(sent),
             str(int((SECONDS + 30) * 1000)), "timing"],
            stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True,
        )  # fmt: skip
        while not all(channel.has_sinks() for channel in server.channels.values()):
            time.sleep(0.01)
        stamps = {}
        start = time.perf_counter()
        for k, (counts, estimate) in enumerate(zip(frames, estimates, strict=True)):
            due = start + k / RATE_HZ
            while (now := time.perf_counter()) < due:
                if due - now > 0.002:
                    time.sleep(due - now - 0.001)
            t = time.time()
            stamps[round(t * 1e9)] = t
            server.push(StreamFrame(k % 65536, k, 0.0, t, 0.0, counts), estimate)
        elapsed = time.perf_counter() - start
        out, _ = process.communicate(timeout=SECONDS + 60)
    received = {topic: 0 for topic in TOPICS}
    latency = []
    for line in out.splitlines():
        message = json.loads(line)
        if message["op"] != "message":
            continue
        received[message["topic"]] += 1
        if message["topic"] == TOPICS[0]:
            latency.append(message["received_ms"] - int(message["timestamp"]) / 1e6)
    p50, p99 = np.percentile(latency, [50, 99]) if latency else (np.nan, np.nan)
    return {"rate_hz": n / elapsed, "sent": sent, "received": received,
            "p50_ms": float(p50), "p99_ms": float(p99)}  # fmt: skip


def main(write_docs: bool = False) -> None:
    spec, frames, estimates = recording_and_estimates(repeats=60)
    contacts = sum(len(e["contacts"]) for e in estimates if e is not None)
    with FoxgloveLive(spec, port=0) as server:
        push_rate(server, frames[:500], estimates[:500])  # warm
        fast = push_rate(server, frames, estimates)
        slow = push_rate(Straightforward(server), frames, estimates)
    with tempfile.TemporaryDirectory() as folder:
        client = install_client(Path(folder))
        live = with_client(client, spec, frames, estimates)
    lines = [
        BEGIN,
        f"pad16, two probes: {len(frames)} frames, {contacts / len(frames):.2f} contacts a "
        f"frame; {platform.machine()}, Python {platform.python_version()}, foxglove-sdk "
        f"{version('foxglove-sdk')}, node {node_version()}; "
        "`python benchmarks/bench_foxglove_live.py`.",
        "",
        "| measure | value |",
        "| --- | --- |",
        f"| push, no client (CDR templates) | {fast:,.0f} frames/s |",
        f"| push, no client (a dictionary per message, mcap-ros2-support's encoder) | "
        f"{slow:,.0f} frames/s |",
        f"| ratio | {fast / slow:.1f} x |",
        f"| with the node client subscribed: rate held | {live['rate_hz']:,.0f} frames/s "
        f"(asked {RATE_HZ:,.0f}, for {SECONDS:g} s) |",
    ]
    for topic in TOPICS:
        lost = live["sent"][topic] - live["received"][topic]
        lines.append(
            f"| {topic}: received of sent | {live['received'][topic]:,} of "
            f"{live['sent'][topic]:,} ({lost:,} lost) |"
        )
    lines += [
        f"| latency push -> client callback, p50 | {live['p50_ms']:.2f} ms |",
        f"| latency push -> client callback, p99 | {live['p99_ms']:.2f} ms |",
        END,
    ]
    text = "\n".join(lines)
    print(text)
    if write_docs:
        sys.path.insert(0, str(ROOT / "scripts"))
        from docblock import replace_block

        replace_block(DOC, BEGIN, END, text)
        replace_block(PERFORMANCE, BEGIN, END, text)


if __name__ == "__main__":
    main(write_docs="--write-docs" in sys.argv[1:])
