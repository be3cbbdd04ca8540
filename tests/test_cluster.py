"""`tactsense batch` on a real Dask LocalCluster of 2 worker processes."""

import dataclasses
import logging
import os
import signal
import threading
import time

import numpy as np
import pyarrow.parquet as pq
import pytest
from typer.testing import CliRunner

import tactsense as ts
from tactsense.batch import locate_file
from tactsense.cli import app
from tests._calibrations import creep_calibration

runner = CliRunner()


@pytest.fixture(scope="module")
def recordings(tmp_path_factory):
    folder = tmp_path_factory.mktemp("lab")
    spec = ts.fearing1990_initial()
    paths = []
    for k in range(6):
        rec = ts.simulate(spec, ts.probe_sweep(spec), rng=k)
        # 150,000 frames each: long enough that a task is still running when its worker dies
        tiles = -(-150_000 // len(rec.frames))
        frames = np.tile(rec.frames, (tiles, 1, 1))
        long = dataclasses.replace(
            rec, frames=frames, time_s=np.arange(len(frames)) * spec.scan_period_s, truth={}
        )
        path = folder / f"finger{k}.h5"
        ts.write_recording(path, long)
        paths.append(path)
    return folder, paths


def test_batch_survives_a_killed_worker_with_identical_results(recordings, tmp_path):
    from dask.distributed import Client, LocalCluster

    from tactsense.cluster import run_batch

    _, paths = recordings
    out = tmp_path / "out"
    out.mkdir()
    with (
        LocalCluster(
            n_workers=2,
            threads_per_worker=1,
            processes=True,
            dashboard_address="127.0.0.1:0",
            silence_logs=logging.ERROR,
        ) as cluster,
        Client(cluster) as client,
    ):
        result = {}
        runner_thread = threading.Thread(
            target=lambda: result.update(rows=run_batch(paths, out, client=client))
        )
        runner_thread.start()
        deadline = time.time() + 60
        busy = {}
        while not busy and time.time() < deadline:
            busy = {w: tasks for w, tasks in client.processing().items() if tasks}
            time.sleep(0.05)
        assert busy, "no task ever started"
        victim = next(iter(busy))
        pid = client.run(os.getpid, workers=[victim])[victim]
        os.kill(pid, signal.SIGKILL)  # the worker process dies mid-task
        runner_thread.join(timeout=300)
        assert not runner_thread.is_alive()
    rows = result["rows"]
    assert [row["status"] for row in rows] == ["done"] * len(paths)
    # identical to one process, file by file
    for path, row in zip(paths, rows, strict=True):
        alone = tmp_path / f"{path.stem}.alone.parquet"
        summary = locate_file(path, alone)
        assert row["frames"] == summary["frames"] and row["contacts"] == summary["contacts"]
        batch_table, alone_table = pq.read_table(row["output"]), pq.read_table(alone)
        assert batch_table.column_names == alone_table.column_names
        for name in batch_table.column_names:  # NaN == NaN here: bit-identical columns
            np.testing.assert_array_equal(
                batch_table[name].to_numpy(), alone_table[name].to_numpy(), err_msg=name
            )
    assert not [p for p in out.iterdir() if ".partial" in p.name]


def test_one_recording_split_across_workers_gives_the_same_output(recordings, tmp_path):
    """A recording larger than --split-frames runs as ranges on both workers, joined in
    order: the file must equal one process's, column by column."""
    _, paths = recordings
    alone = tmp_path / "alone.h5"
    summary = locate_file(paths[0], alone)
    out = tmp_path / "split"
    result = runner.invoke(
        app,
        [
            "batch",
            str(paths[0]),
            "--out",
            str(out),
            "--format",
            "h5",
            "--split-frames",
            "40000",
            "--workers",
            "2",
            "--quiet",
        ],
    )
    assert result.exit_code == 0, result.output
    import h5py
    import pyarrow.csv as pa_csv

    with h5py.File(out / f"{paths[0].stem}.h5") as split, h5py.File(alone) as whole:
        assert sorted(split) == sorted(whole)
        for name in whole:
            np.testing.assert_array_equal(split[name][()], whole[name][()], err_msg=name)
    row = pa_csv.read_csv(out / "summary.csv").to_pylist()[0]
    assert row["frames"] == summary["frames"] and row["contacts"] == summary["contacts"]
    assert row["force_mean_n"] == pytest.approx(summary["force_mean_n"], rel=1e-9)
    assert not [p for p in out.iterdir() if p.name.startswith(".")]  # parts removed


def _has_bokeh():
    from importlib.util import find_spec

    return find_spec("bokeh") is not None


def test_batch_command_lists_failures_and_resumes(tmp_path):
    small = tmp_path / "in"
    small.mkdir()
    spec = ts.fearing1990_initial()
    for k in range(2):
        ts.write_recording(small / f"r{k}.h5", ts.simulate(spec, ts.probe_sweep(spec), rng=k))
    (small / "broken.h5").write_bytes(b"not hdf5")
    out = tmp_path / "res"
    result = runner.invoke(app, ["batch", str(small / "*.h5"), "--out", str(out), "--quiet"])
    text = " ".join(result.output.split())
    assert result.exit_code == 1, text  # one recording failed
    assert "1 failed" in text
    # the address is printed only where it is served (bokeh installed)
    assert ("Dask dashboard: http://127.0.0.1:" in text) == _has_bokeh()
    import pyarrow.csv as pa_csv

    summary = pa_csv.read_csv(out / "summary.csv").to_pylist()
    status = {os.path.basename(row["recording"]): row["status"] for row in summary}
    assert status == {"broken.h5": "failed", "r0.h5": "done", "r1.h5": "done"}
    reasons = {os.path.basename(row["recording"]): row["reason"] for row in summary}
    assert "not a readable HDF5 file" in reasons["broken.h5"]
    first = (out / "r0.parquet").stat().st_mtime_ns
    again = runner.invoke(app, ["batch", str(small / "r*.h5"), "--out", str(out), "--quiet"])
    assert again.exit_code == 0, again.output
    done = {row["recording"]: row for row in summary if row["status"] == "done"}
    summary = pa_csv.read_csv(out / "summary.csv").to_pylist()
    assert [row["status"] for row in summary] == ["skipped", "skipped"]
    # a skipped recording keeps the numbers of the run that wrote its output
    for row in summary:
        for key in ("frames", "contacts", "force_mean_n", "lost_frames", "bad_check"):
            assert row[key] == done[row["recording"]][key], key
    assert (out / "r0.parquet").stat().st_mtime_ns == first


@pytest.mark.parametrize(
    "args, message",
    [
        (["nothing*.h5"], "no recording matches"),
        (["REC", "--scheduler", "localhost:1"], "is not a scheduler address"),
        (["REC", "--workers", "0"], "--workers"),
        (["REC", "--out", "FILE"], "is a file; expected a folder"),
        (["REC", "--calibration", "MISSING"], "is not a file"),
    ],
)
def test_batch_bad_input(recordings, tmp_path, args, message):
    _, paths = recordings
    (tmp_path / "f").write_text("x")
    line = ["batch"] + [
        {"REC": str(paths[0]), "FILE": str(tmp_path / "f"), "MISSING": str(tmp_path / "m")}.get(
            a, a
        )
        for a in args
    ]
    if "--out" not in line:
        line += ["--out", str(tmp_path / "o")]
    result = runner.invoke(app, line)
    assert result.exit_code == 2, result.output
    assert message in " ".join(result.output.split())


def test_split_with_a_creep_calibration_equals_one_process(tmp_path):
    """Ranges start from the creep memories the whole recording has there (pass 1 finds
    each range's end memories, A^L carries them on): the estimates equal one process's to
    rounding (the memories are summed in another order: tolerance 1e-9 relative), and
    restarting the memories at each range would differ (the test can fail)."""

    spec = ts.fearing1990_initial()
    rec = ts.simulate(spec, ts.repeated_load(spec, row=4, col=3, repeats=260), rng=3)
    path = tmp_path / "steps.h5"
    ts.write_recording(path, rec)
    calibration = creep_calibration(spec, ts.baseline_from(rec.frames, 5))
    cal_path = calibration.save(tmp_path / "cal.json")
    alone = tmp_path / "alone.parquet"
    locate_file(path, alone, calibration=calibration)
    out = tmp_path / "split"
    n = len(rec)
    result = runner.invoke(
        app,
        ["batch", str(path), "--out", str(out), "--calibration", str(cal_path),
         "--split-frames", "1000", "--workers", "2", "--quiet"],
    )  # fmt: skip
    assert n > 3000  # at least four ranges
    assert result.exit_code == 0, result.output
    split = pq.read_table(out / "steps.parquet")
    whole = pq.read_table(alone)
    assert split.num_rows == whole.num_rows == n
    for name in ("force_n", "axial_mm", "angle_deg", "peak_deflection"):
        np.testing.assert_allclose(
            split[name].to_numpy(), whole[name].to_numpy(), rtol=1e-9, atol=1e-12,
            equal_nan=True, err_msg=name,
        )  # fmt: skip
    np.testing.assert_array_equal(split["flags"].to_numpy(), whole["flags"].to_numpy())
    restarted = np.concatenate(
        [
            ts.locate(rec.frames[k : k + 1000], spec, calibration=calibration,
                      frame_period_s=spec.scan_period_s).force_n
            for k in range(0, n, 1000)
        ]
    )  # fmt: skip
    assert not np.allclose(restarted, whole["force_n"].to_numpy(), equal_nan=True)
