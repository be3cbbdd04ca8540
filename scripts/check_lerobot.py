"""Load a tactsense-written LeRobot dataset with LeRobot's own reader, on CPU.

Run in an environment with ``lerobot`` (not a tactsense dependency)::

    python scripts/check_lerobot.py DATASET_FOLDER [RECORDING.h5] [--every N]

It loads ``LeRobotDataset(repo_id=..., root=DATASET_FOLDER)`` (no download), prints the
metadata LeRobot read, and compares every row's ``observation.tactile``, ``timestamp``,
``frame_index`` and ``episode_index`` with what the dataset should hold; given the
recording, the frames are compared with its frames too (``--every N``: every N-th item
and the last three, for a large dataset). Exit status 0 when all agree.

On a machine whose torchvision wheel was built for CUDA while torch is the CPU build,
torchvision's compiled operators do not load and its import fails registering them
(``operator torchvision::nms does not exist``); LeRobot imports torchvision for video
decoding only, which a tactile dataset does not use. ``--tolerate-torchvision-ops``
lets that registration fail quietly so that the import succeeds; nothing else changes.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np


def tolerate_missing_torchvision_ops() -> None:
    import torch.library

    original = torch.library.register_fake

    def register_fake(op, func=None, /, **kwargs):
        if func is not None:
            try:
                return original(op, func, **kwargs)
            except RuntimeError:
                return func
        try:
            inner = original(op, **kwargs)
        except RuntimeError:
            return lambda f: f

        def decorate(f):
            try:
                return inner(f)
            except RuntimeError:
                return f

        return decorate

    torch.library.register_fake = register_fake


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("dataset", type=Path)
    parser.add_argument("recording", type=Path, nargs="?")
    parser.add_argument("--tolerate-torchvision-ops", action="store_true")
    parser.add_argument(
        "--every",
        type=int,
        default=1,
        help="Read every N-th item (and the last three) instead of all: a large data set.",
    )
    args = parser.parse_args()
    if args.tolerate_torchvision_ops:
        tolerate_missing_torchvision_ops()

    import lerobot
    import torch
    from lerobot.datasets.lerobot_dataset import CODEBASE_VERSION, LeRobotDataset

    print(
        f"lerobot {getattr(lerobot, '__version__', '?')}, codebase {CODEBASE_VERSION}, "
        f"torch {torch.__version__}"
    )
    dataset = LeRobotDataset(repo_id=f"local/{args.dataset.name}", root=args.dataset)
    meta = dataset.meta
    print(
        f"fps {meta.fps}, episodes {meta.total_episodes}, frames {meta.total_frames}, "
        f"len(dataset) {len(dataset)}"
    )
    print(f"features {sorted(meta.features)}")
    # a recording's export has the contact estimates as observation.state; a simulated
    # data set (tactsense dataset) its ground truth as label.contacts
    state_key = "observation.state" if "observation.state" in meta.features else "label.contacts"
    names = meta.features[state_key]["names"]
    print(
        f"observation.tactile shape {meta.features['observation.tactile']['shape']}, "
        f"{state_key} names {names[:10]}{' ...' if len(names) > 10 else ''} ({len(names)})"
    )
    frames = []
    n = len(dataset)
    read = sorted({*range(0, n, max(1, args.every)), *range(max(0, n - 3), n)})
    for i in read:
        item = dataset[i]
        frames.append(item["observation.tactile"].numpy())
        assert int(item["index"]) == i
        assert abs(float(item["timestamp"]) - int(item["frame_index"]) / meta.fps) < 1e-4
    frames = np.stack(frames)
    print(f"read {len(read)} of {n} items")
    print(
        f"item 0: observation.tactile {tuple(frames[0].shape)} {frames.dtype}, "
        f"{state_key} {dataset[0][state_key].numpy().round(3).tolist()[:10]}"
    )
    print(f"item 0 task {dataset[0]['task']!r}")
    history = LeRobotDataset(
        repo_id=f"local/{args.dataset.name}", root=args.dataset,
        delta_timestamps={"observation.tactile": [-2 / meta.fps, -1 / meta.fps, 0.0]},
    )  # fmt: skip
    window = history[len(history) - 1]["observation.tactile"].numpy()
    assert np.array_equal(window, frames[-3:]), "delta_timestamps window"
    print(
        f"delta_timestamps: the last item's 3-frame window {tuple(window.shape)} equals "
        "the last 3 frames"
    )
    stats = meta.stats["observation.tactile"]
    print(f"stats of observation.tactile: mean shape {tuple(np.shape(stats['mean']))}")
    # the episodes' statistics merged by LeRobot's own aggregate_stats against stats.json
    from lerobot.datasets.compute_stats import aggregate_stats
    from lerobot.datasets.utils import EPISODES_DIR, load_nested_dataset

    prefix = "stats/observation.tactile/"
    episodes = load_nested_dataset(args.dataset / EPISODES_DIR)  # with the stats columns
    columns = [c for c in episodes.column_names if c.startswith(prefix)]
    per_episode = [
        {"observation.tactile": {c[len(prefix) :]: np.asarray(row[c]) for c in columns}}
        for row in episodes
    ]
    merged = aggregate_stats(per_episode)["observation.tactile"]
    for name in ("min", "max", "mean", "std", "count"):
        assert np.allclose(merged[name], np.asarray(stats[name]), rtol=1e-6, atol=1e-6), name
    print(
        f"aggregate_stats over the {len(per_episode)} episodes' statistics equals "
        "stats.json (min, max, mean, std, count)"
    )
    if args.recording is not None:
        import h5py

        with h5py.File(args.recording, "r") as h5:
            expected = np.stack([h5["frames"][i] for i in read]).astype(np.float32)
        same = np.array_equal(frames, expected)
        print(f"frames equal to {args.recording}'s: {same}")
        if not same:
            return 1
    print("LeRobotDataset loaded the dataset: OK")
    return 0


if __name__ == "__main__":
    sys.exit(main())
