"""A whole hand's contacts and wrenches: throughput of the compiled whole-skin call
(tactsense.estimate.robot.HandLocator) against a straightforward per-sensor loop
(LiveContacts per patch, then each contact placed and its r x F summed in Python),
measured in the same run, on two skins:

* ``hand4``, the preset as it stands in this tree (its patches and taxels printed);
* ``pads4000``, built here: the same kind of hand (four fingers of four joints) with
  20 pad patches and 4,000 taxels (per finger three phalanx pads and a fingertip pad of
  10 x 16 taxels at 1.5 mm, and four palm pads of 18 x 20 at 2 mm: 16 x 160 + 4 x 360).

Frames: each patch's frames from ``tactsense.simulate.frames_from_contacts`` (its own
flaws and noise), a grasp-like load: every hand frame presses 1-2 contacts of 0.3-1.5 N
on 60 % of the patches. ``N_UNIQUE`` distinct hand frames are simulated and tiled.

Also checks the fast path against the per-patch estimator (``find_contacts``) on the
distinct frames: the same contacts, the largest position and force differences.

    python benchmarks/bench_hand.py [N_FRAMES] [--skin hand4|pads4000|both]
"""

from __future__ import annotations

import argparse
import dataclasses
import math
import os
import sys
import time

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(__file__), ".."))

from tests.estimate._robot_sim import hand_frames

from tactsense.estimate.robot import HandLocator, locate_robot_reference
from tactsense.robot import Joint, Patch, Pose, RobotSkin, skin_preset
from tactsense.sensor import Grid, preset
from tactsense.stream.live import LiveContacts
from tactsense.stream.reader import StreamFrame

N_UNIQUE = 200


def _pad(name, rows, cols, pitch_mm):
    spec = preset("pad16").replace(
        grid=Grid(rows=rows, cols=cols, row_pitch_mm=pitch_mm, col_pitch_mm=pitch_mm,
                  electrode_x_mm=0.8 * pitch_mm, electrode_y_mm=0.8 * pitch_mm),
    )  # fmt: skip
    return dataclasses.replace(spec, name=name)


def pads4000() -> RobotSkin:
    """Four fingers (abduction + three flexion joints each) with a pad on every phalanx
    and one on the fingertip (10 x 16 at 1.5 mm), four palm pads (18 x 20 at 2 mm):
    20 patches, 4,000 taxels."""
    finger_pad = _pad("finger_pad", 10, 16, 1.5)
    palm_pad = _pad("palm_pad", 18, 20, 2.0)
    links, joints, patches = ["palm"], [], []
    lengths = (0.054, 0.0384, 0.0267)
    for i, finger in enumerate(("thumb", "index", "middle", "ring")):
        base = f"{finger}_base"
        links.append(base)
        knuckle = Pose((0.095, -0.045 + 0.03 * i, 0.0))
        joints.append(Joint(f"{finger}_abduction", "revolute", "palm", base, knuckle,
                            (0, 0, 1), -0.5, 0.5))  # fmt: skip
        parent, offset = base, 0.0
        for j, length in enumerate(lengths):
            link = f"{finger}_link{j + 1}"
            links.append(link)
            joints.append(Joint(f"{finger}_joint{j + 1}", "revolute", parent, link,
                                Pose((offset, 0, 0)), (0, 1, 0), -0.2, 1.6))  # fmt: skip
            patches.append(Patch(f"{finger}_pad{j + 1}", finger_pad, link,
                                 Pose((0.005, -0.012, -0.008), (math.pi, 0, 0)),
                                 device=f"board_{finger}"))  # fmt: skip
            parent, offset = link, length
        patches.append(Patch(f"{finger}_tip", finger_pad, parent,
                             Pose((lengths[-1], -0.012, 0.0), (0, math.pi / 2, 0)),
                             device=f"board_{finger}"))  # fmt: skip
    for k in range(4):
        patches.append(Patch(f"palm_{k}", palm_pad, "palm",
                             Pose((0.02 + 0.037 * (k // 2), -0.04 + 0.04 * (k % 2), -0.01),
                                  (math.pi, 0, 0)), device="board_palm"))  # fmt: skip
    return RobotSkin("pads4000", "palm", tuple(links), tuple(joints), tuple(patches))


def straightforward(skin, frames, baselines, joints, n):
    """LiveContacts per patch, each contact placed in its link and the base frame and
    its r x F summed per link, in Python, frame by frame."""
    live = {
        p.name: LiveContacts(p.sensor, baseline=baselines[p.name], drift_s=None)
        for p in skin.patches
    }
    poses = skin.link_poses(joints)
    origin = {p.name: p.origin.matrix() for p in skin.patches}
    normals = {p.name: np.asarray(p.sensor.taxel_normals(), float) for p in skin.patches}
    rows = 0
    start = time.perf_counter()
    for f in range(n):
        wrench = {}
        for patch in skin.patches:
            frame = StreamFrame(f, f, f * 0.004, f * 0.004, time.perf_counter(),
                                frames[patch.name][f % len(frames[patch.name])])  # fmt: skip
            out = live[patch.name](frame)
            w = wrench.setdefault(patch.link, np.zeros(6))
            pose = poses[patch.link]
            for contact in out["contacts"]:
                point = np.array([contact["x_mm"], contact["y_mm"], contact["z_mm"]])
                in_link = origin[patch.name][:3, :3] @ point + 1e3 * origin[patch.name][:3, 3]
                _ = pose[:3, :3] @ in_link + 1e3 * pose[:3, 3]
                normal = origin[patch.name][:3, :3] @ normals[patch.name][0]
                force = -contact["force_n"] * normal
                if np.isfinite(contact["force_n"]):
                    w[:3] += force
                    w[3:] += np.cross(in_link, force)
                rows += 1
    return n / (time.perf_counter() - start), rows


def measure(name, skin, n_frames, repeats=3):
    n_taxels = skin.n_taxels
    print(f"\n{name}: {len(skin.patches)} patches, {n_taxels} taxels "
          f"({', '.join(sorted({p.sensor.name for p in skin.patches}))})")  # fmt: skip
    sim = hand_frames(skin, N_UNIQUE, seed=1)
    frames = {k: v[0] for k, v in sim.items()}
    baselines = {k: v[1] for k, v in sim.items()}
    joints = {skin.movable_joints[1]: 0.4, skin.movable_joints[2]: 0.6}
    locator = HandLocator(skin, baselines)
    unique = locator.pack(frames)
    counts = np.tile(unique, (math.ceil(n_frames / N_UNIQUE), 1))[:n_frames]
    q = locator.joint_array(joints, 1000)
    best = 0.0
    for _ in range(repeats):
        start = time.perf_counter()
        rows = 0
        for lo in range(0, n_frames, 1000):
            block = counts[lo : lo + 1000]
            rows += len(locator.locate(block, q[: len(block)], first_frame=lo).contacts["frame"])
        best = max(best, n_frames / (time.perf_counter() - start))
    print(f"  HandLocator.locate, blocks of 1,000 hand frames: {best:,.0f} hand frames/s "
          f"(best of {repeats}; {rows / n_frames:.1f} contacts a hand frame)")  # fmt: skip
    times = []
    for f in range(min(n_frames, 2000)):
        start = time.perf_counter()
        locator.locate(counts[f : f + 1], q[:1])
        times.append(time.perf_counter() - start)
    one = np.array(times)
    print(f"  one call per hand frame: {1 / one.mean():,.0f} hand frames/s; median "
          f"{np.median(one) * 1e3:.3f} ms, p99 {np.percentile(one, 99) * 1e3:.3f} ms")  # fmt: skip
    n_ref = min(n_frames, 100)
    reference_rate, _ = straightforward(skin, frames, baselines, joints, n_ref)
    print(f"  straightforward loop (LiveContacts per patch, Python placement and r x F): "
          f"{reference_rate:,.0f} hand frames/s ({n_ref} frames)")  # fmt: skip
    print(f"  ratio, blocks against the loop: {best / reference_rate:,.0f}x; one call per "
          f"frame against the loop: {1 / one.mean() / reference_rate:,.0f}x")  # fmt: skip
    fast = locator.locate(unique, joints).contacts
    ref = locate_robot_reference(skin, frames, baselines, joints=joints)
    key = lambda *row: (int(row[0]), str(row[1]), int(row[2]))  # noqa: E731
    mine = {key(*r): i for i, r in enumerate(zip(fast["frame"], fast["patch"], fast["contact"],
                                                 strict=True))}  # fmt: skip
    theirs = [key(*r) for r in zip(ref["frame"], ref["patch"], ref["contact"], strict=True)]
    same = set(mine) == set(theirs)
    order = np.array([mine.get(k, 0) for k in theirs])
    base = np.column_stack([fast[f"{a}_base_mm"] for a in "xyz"])[order]
    dx = np.abs(base - ref["base_xyz"]).max() if len(order) else 0.0
    df = np.nanmax(np.abs(fast["force_n"][order] - ref["force_n"])) if len(order) else 0.0
    print(f"  against find_contacts per patch on {N_UNIQUE} hand frames: "
          f"{'the same' if same else 'DIFFERENT'} {len(theirs)} contacts; largest "
          f"difference {dx:.1e} mm in the base frame, {df:.1e} N")  # fmt: skip
    return best


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("frames", nargs="?", type=int, default=20_000)
    parser.add_argument("--skin", choices=("hand4", "pads4000", "both"), default="both")
    args = parser.parse_args()
    print(f"numpy {np.__version__}; {args.frames:,} hand frames; one core (no parallel loops)")
    if args.skin in ("hand4", "both"):
        measure("hand4", skin_preset("hand4"), args.frames)
    if args.skin in ("pads4000", "both"):
        measure("pads4000", pads4000(), args.frames)


if __name__ == "__main__":
    main()
