"""The figures of docs/robot.md's "Out and in": a hand4 recording exported to MCAP and
LeRobot and imported back, and every iCub grasp trial imported as one hand.

    PYTHONPATH=src python scripts/robot_io_numbers.py [--write]

The hand4 recording: every patch of the preset, 2 s at each patch's own rate, frames from
``tactsense.simulate.frames_from_contacts`` (two pads pressed with 1 N over the second
second). Times are wall-clock on this machine (2 cores, shared with other work): the
order of magnitude, not a benchmark.
"""

from __future__ import annotations

import argparse
import re
import sys
import tarfile
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
DOC = ROOT / "docs" / "robot.md"
BEGIN, END = "<!-- robot-io-numbers -->", "<!-- /robot-io-numbers -->"
DATA = ROOT / "tests" / "data" / "icub_grasp" / "iCubGraspDataset.tar.xz"


def hand_recording(duration_s: float = 2.0):
    from tactsense.io.recording import Recording
    from tactsense.io.robot_recording import RobotRecording
    from tactsense.physics.transduction import sample_offsets
    from tactsense.robot import skin_preset
    from tactsense.simulate import ContactBatch, frames_from_contacts

    skin = skin_preset("hand4")
    rng = np.random.default_rng(0)
    pressed = {"index_distal_pad": (4.5, 10.5), "thumb_distal_pad": (3.0, 6.0)}
    streams = {}
    for patch in skin.patches:
        sensor = patch.sensor
        rate = sensor.electronics.scan_rate_hz
        n = round(duration_s * rate)
        time_s = np.arange(n) / rate
        position = np.zeros((n, 1, 2))
        force = np.zeros((n, 1))
        if patch.name in pressed:
            position[:, 0] = pressed[patch.name]
            force[time_s >= duration_s / 2, 0] = 1.0
        frames = frames_from_contacts(
            sensor, ContactBatch(position_mm=position, normal_force_n=force), rng=rng
        )
        frames = np.rint(frames).clip(0, 65535).astype(np.uint16).reshape(n, *sensor.shape)
        streams[patch.name] = Recording(
            frames=frames, time_s=time_s, sample_offset_s=sample_offsets(sensor), sensor=sensor
        )
    return RobotRecording(skin=skin, streams=streams, description="hand4, two pads pressed")


def hand_numbers(folder: Path) -> list[str]:
    from tactsense.interop.robot_bag import read_robot_bag
    from tactsense.interop.robot_lerobot import export_robot_lerobot
    from tactsense.interop.robot_mcap import export_robot_mcap
    from tactsense.io.robot_recording import write_robot_recording

    recording = hand_recording()
    run = write_robot_recording(folder / "hand", recording)
    frames = sum(len(s) for s in recording.streams.values())
    taxels = recording.skin.n_taxels
    start = time.perf_counter()
    export_robot_mcap(run, folder / "first.mcap", start_time_s=1.7e9)
    first_s = time.perf_counter() - start  # with the estimators' first (compiling) calls
    start = time.perf_counter()
    counts = export_robot_mcap(run, folder / "hand.mcap", start_time_s=1.7e9)
    export_s = time.perf_counter() - start
    start = time.perf_counter()
    back, summary = read_robot_bag(folder / "hand.mcap")
    import_s = time.perf_counter() - start
    same = all(
        np.array_equal(back.streams[n].frames, s.frames)
        and back.streams[n].frames.dtype == s.frames.dtype
        and np.array_equal(back.streams[n].time_s, s.time_s)
        for n, s in recording.streams.items()
    )
    start = time.perf_counter()
    lerobot = export_robot_lerobot(run, folder / "ds")
    lerobot_s = time.perf_counter() - start
    size_mb = (folder / "hand.mcap").stat().st_size / 1e6
    return [
        f"hand4 ({len(recording.streams)} patches, {taxels} taxels), 2 s simulated: "
        f"{frames} patch frames",
        f"export to MCAP: {export_s:.1f} s ({frames / export_s:,.0f} patch frames/s, contacts "
        f"of every patch included; the first export in a process {first_s:.1f} s, numba "
        f"compiling), {size_mb:.1f} MB, {sum(counts['contacts'].values())} contacts in "
        f"{counts['messages']} TactileContacts",
        f"import back: {import_s:.1f} s, {summary['messages']} messages; frames, dtypes and "
        f"times equal to the original's: {same}",
        f"export to LeRobot: {lerobot_s:.1f} s, {lerobot['rows']} rows at {lerobot['fps']} fps, "
        f"{sum(lerobot['held'].values())} patch frames held from the row before",
    ]


def icub_numbers(folder: Path) -> list[str]:
    from tactsense.interop.icub_grasp import read_trial
    from tactsense.interop.robot_icub import icub_hand_recording, outside_limits

    with tarfile.open(DATA) as tar:
        for member in tar.getmembers():
            if member.isfile() and member.name.endswith(".txt"):
                name = Path(member.name).name
                (folder / name).write_bytes(tar.extractfile(member).read())
    trials = sorted(p for p in folder.glob("*.txt") if re.match(r".+_\d+\.txt$", p.name))
    slices = frames = equal = 0
    encoders = []
    outside: dict[str, int] = {}
    mapping = None
    for path in trials:
        trial = read_trial(path)
        recording, joints = icub_hand_recording(trial, "icub_hand")
        lines = [line.split() for line in path.read_text().splitlines() if line.strip()][1:]
        by_hand = np.array(
            [
                [float(x) for x in lines[k + 2 + f]]
                for k in range(0, len(lines), 7)
                for f in range(5)
            ]
        ).reshape(-1, 5, 12)
        fingers = ("thumb", "index", "middle", "ring", "little")
        equal += all(
            np.array_equal(recording.streams[f"{f}_tip"].frames.reshape(-1, 12), by_hand[:, k])
            for k, f in enumerate(fingers)
        )
        slices += len(trial)
        encoders.append(trial.encoders_deg)
        frames += sum(len(s) for s in recording.streams.values())
        mapping = joints["mapping"]
        for joint, bad in outside_limits(recording.skin, joints["positions_rad"]).items():
            outside[joint] = outside.get(joint, 0) + bad
    mapped = "; ".join(
        f"{e} -> " + ", ".join(f"{j} x{share:.3g}" for j, share in driven)
        for e, driven in (mapping or {}).items()
    )
    said = ", ".join(f"{j} {n}" for j, n in outside.items()) or "none"
    from tactsense.interop.robot_icub import ICUB_ENCODERS

    encoders = np.concatenate(encoders)
    ranges = ", ".join(
        f"{name} {low:.2f} to {high:.2f}"
        for name, low, high in zip(ICUB_ENCODERS, encoders.min(0), encoders.max(0), strict=True)
    )
    return [
        f"iCub grasp dataset: {len(trials)} trials imported as icub_hand, {slices} slices, "
        f"{frames} fingertip frames (5 per slice); trials whose every frame equals the "
        f"file's line: {equal} of {len(trials)}",
        f"encoders mapped to icub_hand's joints: {mapped or 'none'}",
        f"slices outside the skin's joint limits, per joint: {said}",
        f"encoder readings over the dataset [deg]: {ranges}",
    ]


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--write", action="store_true", help="Replace the block in the doc.")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        lines = hand_numbers(Path(tmp)) + icub_numbers(Path(tmp))
    text = "\n".join(
        [BEGIN, "Measured by `scripts/robot_io_numbers.py`:", "", "```", *lines, "```", END]
    )
    print(text)
    if args.write:
        sys.path.insert(0, str(Path(__file__).parent))
        from docblock import replace_block

        replace_block(DOC, BEGIN, END, text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
