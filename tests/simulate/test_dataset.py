"""Labelled data sets: episodes, their labels, the two formats, Dask, and the labels
against the frames (``tactsense dataset``, docs/datasets.md)."""

from __future__ import annotations

import json

import h5py
import numpy as np
import pyarrow.parquet as pq
import pytest
from typer.testing import CliRunner

from tactsense.cli import app
from tactsense.interop import datasets as ds
from tactsense.interop.dataset_check import DatasetCheckError, check_dataset
from tactsense.interop.lerobot import _stats
from tactsense.io.recording import read_recording
from tactsense.sensor import load_sensor
from tactsense.simulate.dataset import (
    KINETIC_RATIO,
    DatasetError,
    DatasetPlan,
    episode,
    episode_labels,
    surface_area,
)


@pytest.fixture(scope="module")
def pad16():
    return load_sensor("pad16")


@pytest.fixture(scope="module")
def written(pad16, tmp_path_factory):
    """One plan written in both formats (the LeRobot data in several files)."""
    folder = tmp_path_factory.mktemp("sets")
    plan = DatasetPlan(episodes=12, frames=80, seed=5)
    ds.write_dataset(pad16, plan, folder / "set", fmt="lerobot", file_mb=0.3)
    ds.write_dataset(pad16, plan, folder / "set.h5", fmt="hdf5", episodes_per_task=5)
    return plan, folder / "set", folder / "set.h5"


def test_an_episode_depends_on_the_seed_and_its_index_alone(pad16):
    plan = DatasetPlan(episodes=10, frames=60, seed=3)
    a, b = episode(pad16, plan, 4), episode(pad16, plan, 4)
    assert np.array_equal(a.frames, b.frames) and np.array_equal(a.position_mm, b.position_mm)
    other = episode(pad16, plan, 5)
    assert not np.array_equal(a.normal_force_n, other.normal_force_n)
    reseeded = episode(pad16, DatasetPlan(episodes=10, frames=60, seed=4), 4)
    assert not np.array_equal(a.frames, reseeded.frames)


@pytest.mark.parametrize("index", range(30))
def test_labels_follow_the_mechanics(pad16, index):
    plan = DatasetPlan(episodes=30, frames=150, seed=1)
    ep = episode_labels(pad16, plan, index)
    present = ep.present
    (x0, x1), (y0, y1) = surface_area(pad16)
    assert np.all((ep.position_mm[..., 0] >= x0 - 1e-9) & (ep.position_mm[..., 0] <= x1 + 1e-9))
    assert np.all((ep.position_mm[..., 1] >= y0 - 1e-9) & (ep.position_mm[..., 1] <= y1 + 1e-9))
    assert np.all(ep.normal_force_n <= plan.force_n[1] + 1e-12)
    assert np.array_equal(ep.contact_id, np.where(present, np.arange(3), -1))
    shear = np.linalg.norm(ep.tangential_force_n, axis=-1)
    # Coulomb: never beyond the static limit of the largest coefficient, and while
    # sliding the kinetic one: shear / normal the same constant in every slipping slot
    assert np.all(shear <= plan.friction[1] * ep.normal_force_n + 1e-12)
    sliding = ep.slip.astype(bool)
    if sliding.any():
        ratio = shear[sliding] / ep.normal_force_n[sliding]
        assert np.ptp(ratio) < 1e-9
        assert plan.friction[0] * KINETIC_RATIO - 1e-9 <= ratio[0]
        assert ratio[0] <= plan.friction[1] * KINETIC_RATIO + 1e-9
    # a contact moves exactly when it slips, at one speed within the plan's range
    step = np.linalg.norm(np.diff(ep.position_mm, axis=0), axis=-1)  # (T-1, K)
    moved = step > 1e-12
    assert not np.any(moved & ~sliding[:-1]), "a contact moved without slipping"
    if moved.any():
        speed = step[moved] / pad16.scan_period_s
        assert np.ptp(speed) < 1e-6 and speed[0] <= plan.speed_mm_s[1] + 1e-9
    if ep.task == "press":
        assert not shear.any() and not sliding.any() and present[:, 1:].sum() == 0
    if ep.task == "slide":
        first = np.argmax(sliding[:, 0])
        assert shear[first - 1, 0] > 0, "the drag builds up while the contact sticks"


def test_every_task_and_both_slip_outcomes_occur(pad16):
    plan = DatasetPlan(episodes=60, frames=100, seed=0)
    seen = {
        (e.task, bool(e.slip.any()))
        for e in map(lambda i: episode_labels(pad16, plan, i), range(60))
    }
    assert {("press", False), ("slide", True), ("grasp", True), ("grasp", False)} <= seen


def test_bad_plans_are_refused():
    with pytest.raises(DatasetError, match="force_n range"):
        DatasetPlan(force_n=(1.0, 0.5))
    with pytest.raises(DatasetError, match="unknown task"):
        DatasetPlan(tasks=("poke",))
    with pytest.raises(DatasetError, match="has none"):
        surface_area(load_sensor("initial"))


def test_both_formats_hold_the_same_frames_and_labels(written, pad16):
    plan, lerobot, hdf5 = written
    recording = read_recording(hdf5)  # a recording: every reader of recordings reads it
    assert recording.frames.shape == (plan.total_frames, *pad16.shape)
    with h5py.File(hdf5) as h5:
        normal = h5["labels/normal_force_n"][()]
        position = h5["labels/position_mm"][()]
        starts = h5["episodes/start"][()]
        tasks = h5["episodes"].attrs["tasks"].split(",")
        task_index = h5["episodes/task_index"][()]
    table = pq.read_table(sorted((lerobot / "data").glob("*/*.parquet")))
    assert len(list((lerobot / "data").glob("*/*.parquet"))) > 1  # rolled over
    tactile = np.asarray(table.column("observation.tactile").to_pylist(), np.float32)
    assert np.array_equal(tactile, recording.frames.astype(np.float32))
    labels = np.asarray(table.column("label.contacts").to_pylist())
    slots = labels[:, 1:].reshape(len(labels), 3, 9)
    assert np.allclose(slots[..., 4], normal, rtol=1e-6, atol=0)
    present = normal > 0
    assert np.allclose(slots[..., 2:4][present], position[present], rtol=1e-6)
    # one episode each, in order, with its own task
    for e in range(plan.episodes):
        expected = episode_labels(pad16, plan, e)
        assert tasks[task_index[e]] == expected.task
        assert np.allclose(normal[starts[e] : starts[e] + plan.frames], expected.normal_force_n)


def test_lerobot_statistics_merge_as_lerobot_does(written):
    """The merged stats.json against statistics computed over the whole data at once
    (mean, std, min, max exact to rounding; quantiles are LeRobot's count-weighted
    average of the episodes', not the data's, so they are only bracketed)."""
    plan, lerobot, _ = written
    table = pq.read_table(sorted((lerobot / "data").glob("*/*.parquet")))
    stats = json.loads((lerobot / "meta" / "stats.json").read_text())
    tactile = np.asarray(table.column("observation.tactile").to_pylist())
    labels = np.asarray(table.column("label.contacts").to_pylist())
    for key, values, scalar in (
        ("observation.tactile", tactile, False),
        ("label.contacts", labels, False),
        ("frame_index", table.column("frame_index").to_numpy(), True),
        ("index", table.column("index").to_numpy(), True),
    ):
        whole = _stats(values, scalar)
        for name in ("min", "max", "mean", "std"):
            assert np.allclose(stats[key][name], whole[name], rtol=1e-9, atol=1e-9), (key, name)
        assert stats[key]["count"] == [plan.total_frames]
        assert np.all(np.asarray(stats[key]["q01"]) <= np.asarray(stats[key]["q99"]))
    info = json.loads((lerobot / "meta" / "info.json").read_text())
    assert info["total_frames"] == plan.total_frames and info["total_tasks"] == 3
    tasks = pq.read_table(lerobot / "meta" / "tasks.parquet").to_pandas()
    assert list(tasks.index) == list(plan.tasks)


def test_the_check_reads_both_formats_and_locate_agrees_with_the_labels(written):
    """Labels against frames: locate's largest contact on single-contact frames within
    half a pitch of the labelled centre (the taxel under it), median within 0.3 pitch,
    no bias beyond 0.1 pitch. pad16 is coarse for its layer (2.5-mm pitch): locate's
    own error on noiseless presses at exact positions is of that size (docs/datasets.md,
    "locate alone")."""
    for path in written[1:]:
        result = check_dataset(path, sample=1)
        pitch = result["pitch_mm"]
        assert result["frames"] == written[0].total_frames
        assert result["located"] > 200 and result["missed"] == 0
        assert result["error_max_mm"] <= 0.5 * pitch
        assert result["error_median_mm"] <= 0.3 * pitch
        assert abs(result["bias_x_mm"]) <= 0.1 * pitch and abs(result["bias_y_mm"]) <= 0.1 * pitch


def test_the_check_fails_labels_that_do_not_match_the_frames(written, tmp_path):
    """The negative controls: labels moved by a pitch and x/y swapped fail the locate
    tolerance; a wrong contact id fails the label check."""
    import shutil

    _, _, hdf5 = written
    for damage in ("shift", "swap", "id"):
        copy = tmp_path / f"{damage}.h5"
        shutil.copy(hdf5, copy)
        with h5py.File(copy, "r+") as h5:
            if damage == "id":
                h5["labels/contact_id"][5:10] = 7
            else:
                position = h5["labels/position_mm"]
                moved = position[()]
                position[...] = moved + 2.5 if damage == "shift" else moved[..., ::-1]
        if damage == "id":
            with pytest.raises(DatasetCheckError, match="contact id"):
                check_dataset(copy)
            continue
        result = check_dataset(copy, sample=1)
        assert result["error_max_mm"] > 0.5 * result["pitch_mm"]


def test_dask_gives_the_same_set_as_one_process(pad16, tmp_path, written):
    from dask.distributed import Client, LocalCluster

    plan, _, hdf5 = written
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=False,
                      dashboard_address=None) as cluster, Client(cluster) as client:  # fmt: skip
        ds.write_dataset(pad16, plan, tmp_path / "dask.h5", fmt="hdf5", client=client,
                         episodes_per_task=2)  # fmt: skip
    with h5py.File(hdf5) as one, h5py.File(tmp_path / "dask.h5") as other:
        assert np.array_equal(one["frames"][()], other["frames"][()])
        assert np.array_equal(one["labels/position_mm"][()], other["labels/position_mm"][()])


class _Future:
    def __init__(self, fn, args, client):
        self.value, self.client = fn(*args), client

    def result(self):
        return self.value

    def release(self):
        self.client.live -= 1


class _CountingClient:
    """A client that runs tasks at once and counts those not yet collected."""

    def __init__(self):
        self.live = self.most = 0

    def submit(self, fn, *args, **kwargs):
        self.live += 1
        self.most = max(self.most, self.live)
        return _Future(fn, args, self)


def test_tasks_in_flight_are_bounded_by_the_window(pad16, tmp_path):
    client = _CountingClient()
    plan = DatasetPlan(episodes=20, frames=20)
    ds.write_dataset(pad16, plan, tmp_path / "w.h5", fmt="hdf5", client=client,
                     episodes_per_task=1, window=3)  # fmt: skip
    assert client.most == 3 and client.live == 0


@pytest.mark.parametrize("fmt, name", [("lerobot", "set"), ("hdf5", "set.h5")])
def test_an_interruption_leaves_nothing(pad16, tmp_path, fmt, name):
    def stop(done, total):
        if done >= 40:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        ds.write_dataset(pad16, DatasetPlan(episodes=5, frames=20), tmp_path / name, fmt=fmt,
                         episodes_per_task=1, progress=stop)  # fmt: skip
    assert list(tmp_path.iterdir()) == []


def test_an_existing_output_is_refused(pad16, tmp_path):
    (tmp_path / "set").mkdir()
    with pytest.raises(DatasetError, match="exists"):
        ds.write_dataset(pad16, DatasetPlan(episodes=1, frames=10), tmp_path / "set")


def test_the_command_writes_a_set_the_check_accepts(tmp_path):
    out = tmp_path / "cli.h5"
    result = CliRunner().invoke(app, ["dataset", "--out", str(out), "--format", "hdf5",
                                      "--episodes", "3", "--frames", "40", "--workers", "0",
                                      "--tasks", "press", "--quiet"])  # fmt: skip
    assert result.exit_code == 0, result.output
    assert "120 frames in 3 episodes" in " ".join(result.output.split())
    assert check_dataset(out)["frames"] == 120
    with h5py.File(out) as h5:
        assert h5["episodes"].attrs["tasks"] == "press"


def test_tactsense_imports_the_lerobot_set_as_the_hdf5_one(written, tmp_path):
    """``tactsense import`` (LeRobot to a recording) gives the HDF5 set's frames and times."""
    _, lerobot, hdf5 = written
    result = CliRunner().invoke(app, ["import", str(lerobot), "--out", str(tmp_path / "in.h5")])
    assert result.exit_code == 0, result.output
    imported, direct = read_recording(tmp_path / "in.h5"), read_recording(hdf5)
    assert np.array_equal(imported.frames, direct.frames)
    assert np.allclose(imported.time_s, direct.time_s, rtol=0, atol=1e-9)


# ---- fix38 (r6-fix38) ----
@pytest.mark.parametrize(
    "workers, when",
    [(0, "writing"), (2, "writing"), (2, "starting")],
    ids=["workers0-writing", "workers2-writing", "workers2-cluster-starting"],
)
def test_fix38_one_sigint_stops_a_dataset_run(tmp_path, workers, when):
    """One SIGINT to the process alone (``kill -INT PID``) stops the run: one line, exit
    status 1, no data set and no partial folder; also when the signal lands while the
    Dask cluster starts (then held until it has started, and the cluster closed). (A
    command started with SIGINT ignored, a script's background job, keeps it ignored, as
    the shell's convention wants: SIGTERM stops it.)"""
    import os
    import signal
    import subprocess
    import sys
    import time

    out = tmp_path / "ds"
    cli = [sys.executable, "-m", "tactsense_launcher", "dataset", "--out", str(out),
           "--episodes", "2000", "--frames", "500", "--workers", str(workers), "-q"]  # fmt: skip
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)}
    process = subprocess.Popen(
        cli, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env,
        cwd=tmp_path,
    )  # fmt: skip
    deadline = time.monotonic() + 120
    if when == "writing":  # the temporary folder is there: the episodes are being written
        while not any(".partial" in p for p in os.listdir(tmp_path)):
            assert process.poll() is None and time.monotonic() < deadline
            time.sleep(0.05)
        time.sleep(0.5)
    else:
        time.sleep(2.5)  # after the imports (about 1-2 s), while the workers spawn
    process.send_signal(signal.SIGINT)
    _, err = process.communicate(timeout=120)
    assert process.returncode == 1, err
    assert err.strip().splitlines()[-1] == (
        "error: interrupted; no output was left half-written"
    ), err
    assert "Traceback" not in err and "Exception ignored" not in err, err
    assert not out.exists()
    assert not [p for p in os.listdir(tmp_path) if ".partial" in p]


@pytest.mark.parametrize("fmt, name", [("lerobot", "set"), ("hdf5", "set.h5")])
def test_fix38_the_final_name_appears_only_when_complete(pad16, tmp_path, fmt, name):
    """While the episodes are written, nothing is at the final name (a folder with
    data/ but no meta/ was reported once); the work is under a hidden .partial name,
    moved into place whole at the end."""
    out = tmp_path / name
    seen = []

    def look(done, total):
        assert not out.exists()
        seen.append([p.name for p in tmp_path.iterdir()])

    ds.write_dataset(pad16, DatasetPlan(episodes=4, frames=20), out, fmt=fmt,
                     episodes_per_task=1, progress=look)  # fmt: skip
    assert len(seen) == 4 and all(len(n) == 1 and ".partial" in n[0] for n in seen), seen
    assert [p.name for p in tmp_path.iterdir()] == [name]
    if fmt == "lerobot":
        assert (out / "meta" / "info.json").is_file() and (out / "data").is_dir()


def test_fix38_the_summary_counts_the_tasks_drawn(tmp_path):
    """The summary line gives the episodes of each task as drawn (not the tasks asked
    for), the counts the file's task_index holds."""
    import re

    out = tmp_path / "drawn.h5"
    result = CliRunner().invoke(app, ["dataset", "--out", str(out), "--format", "hdf5",
                                      "--episodes", "12", "--frames", "20", "--workers", "0",
                                      "--quiet"])  # fmt: skip
    assert result.exit_code == 0, result.output
    text = " ".join(result.output.split())
    printed = {task: int(n) for n, task in re.findall(r"(\d+) (press|slide|grasp)", text)}
    with h5py.File(out) as h5:
        index = h5["episodes/task_index"][:]
        names = h5["episodes"].attrs["tasks"].split(",")
    counts = {name: int(np.sum(index == i)) for i, name in enumerate(names)}
    assert printed == counts and sum(printed.values()) == 12, (text, counts)
    assert "12 episodes (" in text


def test_fix38_below_baseline_warning_says_what_is_true(pad16, tmp_path):
    """A data set's first frames are untouched (the first press starts at frame 6), yet
    locate warned "the first frames, which make the baseline, were probably touched":
    its baseline follows a slow unload as the creep after a lift, and the unload's end
    reads below that moved baseline. Now the warning says so, and keeps "probably
    touched" for frames below the first frames' own baseline (a baseline taken under
    the press: --baseline-frames 40)."""
    rec = tmp_path / "set.h5"
    ds.write_dataset(pad16, DatasetPlan(episodes=2, frames=200, seed=0), rec, fmt="hdf5")
    frames = read_recording(rec).frames.reshape(400, -1).astype(float)
    assert np.ptp(frames[:5] - frames[0], axis=1).max() <= 5  # untouched: noise only
    assert np.ptp(frames[30] - frames[0]) > 100  # pressed by frame 30

    def locate(*extra):
        out = tmp_path / f"est{len(extra)}.csv"
        result = CliRunner().invoke(app, ["locate", str(rec), "--method", "fit", "--out",
                                          str(out), "-q", *extra])  # fmt: skip
        assert result.exit_code == 0, result.output
        return " ".join(result.output.split())

    untouched = locate()
    assert "below the baseline" in untouched  # the moved baseline: still flagged
    assert "none below the first frames' own" in untouched
    assert "probably touched" not in untouched
    touched = locate("--baseline-frames", "40")
    assert "probably touched" in touched and "below the first frames' own)" in touched


# ---- /r6-fix38 ----
