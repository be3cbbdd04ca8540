"""Load a robot recording's LeRobot export with LeRobot's own reader and compare it.

Run in an environment with ``lerobot`` and ``h5py`` (not a tactsense dependency)::

    python scripts/check_robot_lerobot.py DATASET_FOLDER RUN_FOLDER [--tolerate-torchvision-ops]

It loads ``LeRobotDataset(repo_id=..., root=DATASET_FOLDER)`` (no download) and, for
every item and every patch, checks ``observation.tactile.<patch>`` against the frame of
the robot recording's stream ``RUN_FOLDER/streams/<patch>.h5`` that the export says it
held (the latest at or before the row's time, read here from the HDF5 file with h5py,
independently of tactsense), and ``timestamp`` against ``frame_index / fps``. It also
asks for a ``delta_timestamps`` window of every patch. Exit status 0 when all agree.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))
from check_lerobot import tolerate_missing_torchvision_ops


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("dataset", type=Path)
    parser.add_argument("run", type=Path)
    parser.add_argument("--tolerate-torchvision-ops", action="store_true")
    args = parser.parse_args()
    if args.tolerate_torchvision_ops:
        tolerate_missing_torchvision_ops()

    import h5py
    import lerobot
    from lerobot.datasets.lerobot_dataset import LeRobotDataset

    dataset = LeRobotDataset(repo_id=f"local/{args.dataset.name}", root=args.dataset)
    meta = dataset.meta
    patches = sorted(
        k.removeprefix("observation.tactile.")
        for k in meta.features
        if k.startswith("observation.tactile.") and k.count(".") == 2
    )
    print(
        f"lerobot {lerobot.__version__}: fps {meta.fps}, episodes {meta.total_episodes}, "
        f"rows {len(dataset)}, patches {len(patches)}"
    )
    streams = {}
    for patch in patches:
        with h5py.File(args.run / "streams" / f"{patch}.h5", "r") as h5:
            host = "host_time" in h5
            streams[patch] = (h5["frames"][:], h5["host_time" if host else "time"][:])
    # the rows: fps apart from the latest first frame of all streams (float64 here)
    start = max(times[0] for _, times in streams.values())
    checked = 0
    for i in range(len(dataset)):
        item = dataset[i]
        assert abs(float(item["timestamp"]) - int(item["frame_index"]) / meta.fps) < 1e-4
        row_time = start + i / meta.fps
        for patch in patches:
            frames, times = streams[patch]
            k = int(np.searchsorted(times, row_time + 1e-9, side="right")) - 1
            got = item[f"observation.tactile.{patch}"].numpy()
            if int(item[f"observation.tactile.{patch}.frame_index"]) != k:
                print(f"row {i} patch {patch}: frame_index is not {k}")
                return 1
            if not np.array_equal(got, frames[k].astype(np.float32)):
                print(f"row {i} patch {patch}: not the frame {k} of its stream")
                return 1
            checked += 1
    print(f"{checked} patch frames in {len(dataset)} rows equal the streams' frames")
    keys = [f"observation.tactile.{p}" for p in patches]
    window = LeRobotDataset(
        repo_id=f"local/{args.dataset.name}", root=args.dataset,
        delta_timestamps={k: [-1 / meta.fps, 0.0] for k in keys},
    )[len(dataset) - 1]  # fmt: skip
    last = dataset[len(dataset) - 1]
    for key in keys:
        assert window[key].shape[0] == 2, key
        assert np.array_equal(window[key][-1].numpy(), last[key].numpy()), key
    print("delta_timestamps windows of every patch: OK")
    print("LeRobotDataset loaded the robot dataset: OK")
    return 0


if __name__ == "__main__":
    sys.exit(main())
