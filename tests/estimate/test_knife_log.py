"""The knife-edge fit from the lab's own stage log (``calibrate --knife REC --knife-log
LOG.csv``): the edge positions and the presses from a CSV of time, position and force,
not from a simulated scenario; the same fit as with the scenario's truth."""

import csv
import json

import numpy as np
import pytest
from typer.testing import CliRunner

import tactsense as ts
from tactsense.cli import app

runner = CliRunner()


def _stage_log(rec, path, rate_hz=250.0):
    """The stage's log at its own rate on the recording's clock: the edge's position
    (held where it was while lifted) and the force on it."""
    step_edges = np.cumsum([0.0] + [s["duration_s"] for s in rec.scenario["steps"]])
    times = np.arange(0.0, step_edges[-1], 1.0 / rate_hz)
    step = np.clip(np.searchsorted(step_edges, times, side="right") - 1, 0, None)
    position = np.asarray(rec.truth["step_axial_mm"], dtype=float)[step]
    force = np.nan_to_num(np.asarray(rec.truth["step_force_n"], dtype=float)[step])
    held = position.copy()
    held[: np.argmax(np.isfinite(held))] = held[np.isfinite(held)][0]  # waiting at the start
    for k in range(1, len(held)):  # lifted: the stage stays where it was
        if not np.isfinite(held[k]):
            held[k] = held[k - 1]
    with open(path, "w", newline="") as stream:
        writer = csv.writer(stream)
        writer.writerow(["time_s", "position_mm", "force_n"])
        writer.writerows(zip(times.round(6), held.round(6), force.round(6), strict=True))
    return path


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    folder = tmp_path_factory.mktemp("knifelog")
    spec = ts.fearing1990_initial()
    ts.write_recording(folder / "sweep.h5", ts.simulate(spec, ts.calibration_sweep(spec), rng=1))
    knife = ts.simulate(spec, ts.knife_edge_sweep(spec), rng=2)
    ts.write_recording(folder / "knife.h5", knife)
    _stage_log(knife, folder / "stage.csv")
    return folder


def test_the_stage_log_gives_the_fit_the_truth_gives(files):
    fits = {}
    for name, extra in (("truth", []), ("log", ["--knife-log", str(files / "stage.csv")])):
        out = files / f"{name}.json"
        line = ["calibrate", str(files / "sweep.h5"), "--knife", str(files / "knife.h5")]
        result = runner.invoke(app, [*line, *extra, "--out", str(out)])
        assert result.exit_code == 0, result.output
        fits[name] = json.loads(out.read_text())["model_fit"]
    # the same presses at the same positions; the frames differ where a press ends (the
    # log's force at the tactel's sample time against the scenario's step), and with
    # creep in every reading (no --steps here: docs/calibration.md says how it bends the
    # fit) that moves the fit a little: measured 0.09 mm and 0.04 apart
    assert fits["log"]["depth_mm"] == pytest.approx(fits["truth"]["depth_mm"], abs=0.15)
    assert fits["log"]["poisson_ratio"] == pytest.approx(fits["truth"]["poisson_ratio"], abs=0.05)


@pytest.mark.parametrize(
    "extra, message",
    [
        (["--knife-log", "STAGE"], "--knife-log goes with --knife"),
        (["--knife", "KNIFE", "--knife-log", "DIR/none.csv"], "cannot read"),
        (
            ["--knife", "KNIFE", "--knife-log", "DIR/cols.csv"],
            "needs the columns time_s, position_mm",
        ),
    ],
)
def test_bad_knife_log_is_one_line(files, tmp_path, extra, message):
    (tmp_path / "cols.csv").write_text("time_s,force_n\n0,1\n1,2\n")
    args = [a.replace("STAGE", str(files / "stage.csv")).replace("KNIFE", str(files / "knife.h5"))
            .replace("DIR", str(tmp_path)) for a in extra]  # fmt: skip
    out = tmp_path / "never.json"
    result = runner.invoke(app, ["calibrate", str(files / "sweep.h5"), *args, "--out", str(out)])
    said = " ".join(result.output.split())
    assert result.exit_code == 2, said
    assert message in said and "Traceback" not in said
    assert not out.exists()
