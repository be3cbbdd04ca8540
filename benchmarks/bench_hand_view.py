"""The hand's browser view: what a second of a whole hand costs the server.

Run: ``python benchmarks/bench_hand_view.py [--skin hand4] [--seconds 2] [--write-docs]``.

A robot recording of the skin is simulated here (every patch at rest with its read noise,
one pad pressed from the middle on, at each patch's own scan rate), then played through
the view's feed (:class:`tactsense.view.robot_feed.RobotRecordingFeed`) in this process,
without a server or a page: each display tick takes every patch's newest frame, finds the
contacts (the robot estimator, one compiled call a tick; or each patch's own single-array
estimator) and encodes the whole hand's message (JSON), as the feed's thread does. The
straightforward way, every frame of every patch through its own estimator at its own rate
(and the message once a display tick), runs on the same recording in the same run. All
are given as CPU seconds per second of recording (one core), with their ratios.
"""

from __future__ import annotations

import argparse
import json
import platform
import tempfile
import time
from pathlib import Path

import numpy as np

from tactsense.io._layout import Recording
from tactsense.io.robot_recording import RobotRecording, write_robot_recording
from tactsense.robot import load_skin
from tactsense.simulate import ContactBatch, frames_from_contacts
from tactsense.stream.reader import StreamFrame
from tactsense.view.robot_feed import DISPLAY_HZ, RobotRecordingFeed
from tactsense.view.robot_state import HandState

BEGIN, END = "<!-- bench_hand_view: begin -->", "<!-- bench_hand_view: end -->"


def simulated(skin, seconds: float, path: Path) -> Path:
    pressed = next(p.name for p in skin.patches if p.sensor.shape[0] > 1)  # a pad
    streams = {}
    for k, patch in enumerate(skin.patches):
        spec = patch.sensor
        n = round(seconds * spec.electronics.scan_rate_hz)
        force = np.zeros((n, 1))
        if patch.name == pressed:
            force[n // 2 :] = 1.0
        centre = spec.taxel_positions_mm()[:, :2].mean(axis=0)
        frames = frames_from_contacts(
            spec,
            ContactBatch(np.broadcast_to(centre, (n, 1, 2)).copy(), force, radius_mm=3.0),
            rng=k,
        )
        streams[patch.name] = Recording(
            frames=np.asarray(frames).reshape(n, *spec.shape),
            time_s=np.arange(n) / spec.electronics.scan_rate_hz,
            sample_offset_s=np.zeros(spec.shape),
            sensor=spec,
        )
    return write_robot_recording(path, RobotRecording(skin, streams))


def view_way(
    path: Path, seconds: float, *, each_patch: bool = False
) -> tuple[float, int, int, str]:
    """CPU seconds of the feed's ticks over the recording; ticks; bytes of a message; the
    estimator. ``each_patch``: every patch through its own estimator instead of the robot
    estimator."""
    feed = RobotRecordingFeed(path)
    if each_patch:
        baselines = {
            name: np.median(s.file.frames(0, 5).astype(float), axis=0)
            for name, s in feed.streams.items()
        }
        feed.state = HandState(feed.skin, baselines=baselines, frame_period_s=feed.period_s)
    feed._publish = lambda text: sizes.append(len(text))
    sizes: list[int] = []
    ticks = int(seconds * DISPLAY_HZ)
    start = time.process_time()
    for tick in range(ticks):
        feed.time_s = feed.start_s + tick / DISPLAY_HZ
        feed._tick()
    spent = time.process_time() - start
    feed.close_streams()
    return spent, ticks, max(sizes), feed.state.estimator


def every_frame_way(path: Path, seconds: float) -> tuple[float, int]:
    """CPU seconds of every frame through its estimator at its own rate; frames."""
    from tactsense.io.robot_recording import read_robot_recording

    recording = read_robot_recording(path)
    baselines = {
        name: np.median(r.frames[:5].astype(float), axis=0) for name, r in recording.streams.items()
    }
    state = HandState(recording.skin, baselines=baselines)
    events = sorted(
        (float(t), name, i)
        for name, r in recording.streams.items()
        for i, t in enumerate(r.time_s)
    )  # fmt: skip
    start = time.process_time()
    next_tick = 0.0
    for t, name, i in events:
        r = recording.streams[name]
        state.update(name, StreamFrame(i % 65536, i, t, 0.0, 0.0, r.frames[i]))
        if t >= next_tick:
            json.dumps(state.message(0, t), allow_nan=False)
            next_tick += 1.0 / DISPLAY_HZ
    return time.process_time() - start, len(events)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--skin", default="hand4", help="robot skin (preset or TOML)")
    parser.add_argument("--seconds", type=float, default=2.0, help="recording length [s]")
    parser.add_argument("--write-docs", action="store_true", help="update docs/performance.md")
    args = parser.parse_args()
    skin = load_skin(args.skin)
    with tempfile.TemporaryDirectory() as folder:
        path = simulated(skin, args.seconds, Path(folder) / "run")
        view_s, ticks, size, estimator = view_way(path, args.seconds)
        patch_s, _, _, _ = view_way(path, args.seconds, each_patch=True)
        every_s, frames = every_frame_way(path, args.seconds)
    rates = sorted({p.sensor.electronics.scan_rate_hz for p in skin.patches})
    rows = [
        ("the view's contacts from", estimator),
        ("patch frames in the recording", f"{frames:,} ({frames / args.seconds:,.0f} a second)"),
        ("view: display ticks", f"{ticks} ({DISPLAY_HZ:g} a second)"),
        ("view, robot estimator: CPU per second of recording", f"{view_s / args.seconds:.3f} s"),
        (f"view, robot estimator: CPU per tick ({len(skin.patches)} patches + JSON)",
         f"{1e3 * view_s / ticks:.2f} ms"),
        ("view, each patch's own estimator: CPU per second of recording",
         f"{patch_s / args.seconds:.3f} s"),
        ("every frame of every patch through its own estimator: CPU per second of recording",
         f"{every_s / args.seconds:.3f} s"),
        ("ratio (each patch's own / robot estimator, both at the display rate)",
         f"{patch_s / view_s:.1f} x"),
        ("ratio (every frame / view with the robot estimator)", f"{every_s / view_s:.1f} x"),
        ("largest message", f"{size / 1024:.0f} KiB"),
    ]  # fmt: skip
    head = (
        f"{skin.name}: {len(skin.patches)} patches, {skin.n_taxels:,} taxels, scan rates "
        f"{', '.join(f'{r:g}' for r in rates)} Hz; {args.seconds:g} s simulated; "
        f"{platform.machine()}, Python {platform.python_version()}; one core (process "
        f"CPU time); `python benchmarks/bench_hand_view.py --skin {args.skin} "
        f"--seconds {args.seconds:g}`."
    )
    lines = ["| measure | value |", "| --- | --- |"] + [f"| {a} | {b} |" for a, b in rows]
    table = "\n".join(lines)
    text = f"{BEGIN}\n{head}\n\n{table}\n{END}"
    print(text)
    if args.write_docs:
        import sys

        sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "scripts"))
        from docblock import replace_block

        replace_block(Path(__file__).resolve().parents[1] / "docs/performance.md", BEGIN, END, text)


if __name__ == "__main__":
    main()
