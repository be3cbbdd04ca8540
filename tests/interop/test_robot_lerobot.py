"""A robot recording as a LeRobot v3 dataset, a feature per patch
(tactsense.interop.robot_lerobot). The parquet is read back with pyarrow and every row
checked against the streams by a loop written here (the latest frame at or before the
row's time); LeRobot's own reader: scripts/check_robot_lerobot.py (docs/robot.md)."""

from __future__ import annotations

import json

import numpy as np
import pyarrow.parquet as pq
import pytest
from typer.testing import CliRunner

from tactsense.cli import app
from tactsense.interop.lerobot import LeRobotError
from tactsense.interop.robot_lerobot import export_robot_lerobot

from .robot_helpers import PATCHES, robot_recording, write

runner = CliRunner()


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    folder = tmp_path_factory.mktemp("robot") / "run"
    recording = robot_recording(host0=1_763_900_000.0, rng=7)
    write(folder, recording)
    return folder, recording


def _latest(times, t):
    """Index of the last time <= t (a plain loop)."""
    k = -1
    for i, value in enumerate(times):
        if value <= t + 1e-9:
            k = i
    return k


def test_a_feature_per_patch_holding_the_latest_frame(run, tmp_path):
    folder, recording = run
    out = tmp_path / "ds"
    result = runner.invoke(app, ["export", str(folder), "--format", "lerobot", "--out", str(out)])
    assert result.exit_code == 0, result.output
    info = json.loads((out / "meta" / "info.json").read_text())
    assert info["codebase_version"] == "v3.0" and info["fps"] == 250  # the fastest patch's
    for name in PATCHES:
        feature = info["features"][f"observation.tactile.{name}"]
        assert feature["shape"] == list(recording.skin.patch(name).sensor.shape)
    table = pq.read_table(out / "data" / "chunk-000" / "file-000.parquet")
    meta = json.loads((out / "meta" / "tactsense.json").read_text())
    start = meta["start_time_s"]
    hosts = {n: recording.streams[n].host_time_s for n in PATCHES}
    assert start == max(h[0] for h in hosts.values())
    assert table.num_rows == info["total_frames"]
    row_time = table.column("frame_time").to_numpy()
    np.testing.assert_allclose(row_time, np.arange(table.num_rows) / 250, atol=1e-9)
    assert start + row_time[-1] <= max(h[-1] for h in hosts.values())
    assert start + row_time[-1] + 1 / 250 > max(h[-1] for h in hosts.values())
    for name in PATCHES:
        frames = np.array(table.column(f"observation.tactile.{name}").to_pylist())
        index = table.column(f"observation.tactile.{name}.frame_index").to_numpy()
        for i in range(table.num_rows):
            k = _latest(hosts[name], start + row_time[i])
            assert index[i] == k
            np.testing.assert_array_equal(frames[i], recording.streams[name].frames[k])
    assert meta["patches"]["palm_pad"]["losses"] == {"lost": 3, "gaps": 1}
    assert "a feature per patch (4 patches" in result.output


def test_fps_and_episodes(run, tmp_path):
    folder, _ = run
    counts = export_robot_lerobot(folder, tmp_path / "ds", fps=50, episode_split=7)
    assert counts["fps"] == 50 and counts["episodes"] == -(-counts["rows"] // 7)
    episodes = pq.read_table(
        tmp_path / "ds" / "meta" / "episodes" / "chunk-000" / "file-000.parquet"
    )
    assert sum(episodes.column("length").to_pylist()) == counts["rows"]
    table = pq.read_table(tmp_path / "ds" / "data" / "chunk-000" / "file-000.parquet")
    for name in PATCHES:  # "held": rows that repeat the row before's frame
        index = table.column(f"observation.tactile.{name}.frame_index").to_numpy()
        assert counts["held"][name] == sum(index[1:] == index[:-1])
    # at 50 rows/s the 250 Hz pad is sampled: about every fifth frame
    pad = table.column("observation.tactile.distal_pad.frame_index").to_numpy()
    assert np.median(np.diff(pad)) == 5


def test_refusals(run, tmp_path):
    folder, _ = run
    (tmp_path / "there").mkdir()
    with pytest.raises(LeRobotError, match="exists"):
        export_robot_lerobot(folder, tmp_path / "there")
    with pytest.raises(LeRobotError, match="--fps"):
        export_robot_lerobot(folder, tmp_path / "x", fps=0)
    assert not (tmp_path / "x").exists()
