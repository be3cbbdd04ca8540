import re

import numpy as np
import pytest
from typer.testing import CliRunner

import tactsense as ts
from tactsense.cli import app

runner = CliRunner()


def plain(text: str) -> str:
    return re.sub(r"\x1b\[[0-9;]*m", "", text)


def test_simulate_writes_recording_and_plot(tmp_path):
    out, png = tmp_path / "s.h5", tmp_path / "s.png"
    result = runner.invoke(
        app,
        [
            "simulate",
            "--out",
            str(out),
            "--plot",
            str(png),
            "--increment",
            "2.0",
            "--dwell-s",
            "0.3",
        ],
    )
    assert result.exit_code == 0, result.output
    assert ts.read_recording(out).frames.shape[1:] == (8, 8)
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    again = runner.invoke(app, ["simulate", "--out", str(out)])
    assert again.exit_code == 2 and "--force" in plain(again.output)
    forced = runner.invoke(
        app,
        [
            "simulate",
            "--out",
            str(out),
            "--force",
            "--scenario",
            "repeated",
            "--repeats",
            "2",
            "--flaws",
            "none",
        ],
    )
    assert forced.exit_code == 0, forced.output


def test_simulate_help_explains_every_option():
    result = runner.invoke(app, ["simulate", "--help"])
    assert result.exit_code == 0
    text = plain(result.output)
    options = [
        "--out",
        "--sensor",
        "--scenario",
        "--row",
        "--col",
        "--force-g",
        "--increment",
        "--dwell-s",
        "--lift-s",
        "--repeats",
        "--flaws",
        "--seed",
        "--plot",
        "--force",
    ]
    for option in options:
        line = next(line for line in text.splitlines() if option in line)
        assert len(line.split(option, 1)[1].strip()) > 10, f"{option} lacks help"


def test_bad_inputs_give_clear_errors(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text('extends = "initial"\n[array]\nspacing_axial_mm = -1\n')
    result = runner.invoke(app, ["simulate", "--sensor", str(bad), "--out", str(tmp_path / "x.h5")])
    assert result.exit_code == 2 and "spacing_axial_mm must be positive" in plain(result.output)
    result = runner.invoke(
        app, ["simulate", "--flaws", "gremlins", "--out", str(tmp_path / "y.h5")]
    )
    assert result.exit_code == 2 and "unknown flaw" in plain(result.output)
    result = runner.invoke(app, ["info", str(bad)])
    assert result.exit_code == 2 and "not a readable HDF5" in plain(result.output)


def test_sensor_show_and_check(tmp_path):
    path = tmp_path / "improved.toml"
    result = runner.invoke(app, ["sensor", "show", "--sensor", "improved", "--out", str(path)])
    assert result.exit_code == 0
    assert ts.SensorSpec.from_toml(path) == ts.fearing1990_improved()
    result = runner.invoke(app, ["sensor", "check", str(path)])
    assert result.exit_code == 0 and "valid" in plain(result.output)
    shown = runner.invoke(app, ["sensor", "show"])
    assert "spacing_axial_mm = 3.8" in shown.output


def test_design_strip_json_matches_the_python_function():
    import json

    from tactsense.analysis import strip_capacitor_design

    result = runner.invoke(
        app,
        [
            "design",
            "strip",
            "--thickness",
            "3.8",
            "--separation",
            "0.5",
            "--load",
            "200",
            "--width",
            "3",
            "--json",
        ],
    )
    assert result.exit_code == 0, result.output
    data = json.loads(result.output)
    want = strip_capacitor_design(3.8e-3, 0.5e-3, 200.0, 3e-3)
    assert data["gain"] == want["gain"]
    assert data["closing_m"] == want["closing"]
    assert data["bottom_plate_deflection_m"] == 0.0
    table = runner.invoke(app, ["design", "strip", "--backing", "1.2"])
    assert table.exit_code == 0 and "gain" in table.output
    bad = runner.invoke(app, ["design", "strip", "--separation", "5"])
    assert bad.exit_code == 2 and "separation" in plain(bad.output)
    help_text = plain(runner.invoke(app, ["design", "strip", "--help"]).output)
    for option in (
        "--thickness",
        "--separation",
        "--load",
        "--width",
        "--backing",
        "--modulus",
        "--poisson",
        "--model",
        "--json",
    ):
        assert option in help_text


def test_locate_writes_csv_with_units(tmp_path):
    import csv

    rec, out = tmp_path / "s.h5", tmp_path / "e.csv"
    assert (
        runner.invoke(
            app,
            ["simulate", "--out", str(rec), "--increment", "1.5", "--flaws", "noise,quantization"],
        ).exit_code
        == 0
    )
    result = runner.invoke(app, ["locate", str(rec), "--out", str(out)])
    assert result.exit_code == 0, result.output
    rows = list(csv.reader(out.open()))
    assert rows[0][:6] == [
        "frame",
        "time_s",
        "row",
        "col",
        "axial_mm",
        "angle_deg",
    ]
    recording = ts.read_recording(rec)
    assert len(rows) == len(recording) + 1
    assert rows[1][-1] == "NO_CONTACT"  # the untouched start
    touched = [r for r in rows[1:] if r[-1] == ""]
    assert len(touched) > 0.7 * len(recording)
    again = runner.invoke(app, ["locate", str(rec), "--out", str(out)])
    assert again.exit_code == 2 and "--force" in plain(again.output)


def test_design_aliasing_json():
    import json

    result = runner.invoke(
        app, ["design", "aliasing", "--depth", "3.8", "--spacing", "3.8", "--json"]
    )
    assert result.exit_code == 0, result.output
    data = json.loads(result.output)
    assert data["xi"] == pytest.approx(0.0317, abs=2e-4)
    assert runner.invoke(app, ["design", "aliasing"]).exit_code == 0
    assert runner.invoke(app, ["design", "aliasing", "--poisson", "0.7"]).exit_code == 2


def test_calibrate_then_locate_with_the_calibration(tmp_path):
    spec = ts.fearing1990_initial()
    sweep, steps, knife = tmp_path / "sweep.h5", tmp_path / "steps.h5", tmp_path / "knife.h5"
    ts.write_recording(sweep, ts.simulate(spec, ts.calibration_sweep(spec, increment=1.2), rng=1))
    ts.write_recording(steps, ts.simulate(spec, ts.force_steps(spec, repeats=3), rng=2))
    ts.write_recording(knife, ts.simulate(spec, ts.knife_edge_sweep(spec), rng=3))
    out = tmp_path / "cal.json"
    result = runner.invoke(
        app,
        ["calibrate", str(sweep), "--out", str(out), "--steps", str(steps), "--knife", str(knife)],
    )
    assert result.exit_code == 0, result.output
    calibration = ts.estimate.Calibration.load(out, spec)
    assert calibration.viscoelastic is not None and calibration.model_fit is not None
    estimates = tmp_path / "e.csv"
    result = runner.invoke(
        app, ["locate", str(steps), "--calibration", str(out), "--out", str(estimates)]
    )
    assert result.exit_code == 0, result.output
    # what the CLI wrote is what the API computes with that calibration, and on the
    # frames where the steps' load is on, the force is the applied load to within the
    # paper's 20 % (section 8)
    table = np.genfromtxt(estimates, delimiter=",", names=True)
    rec = ts.read_recording(steps)
    api = ts.locate(rec.frames, spec, calibration=calibration, frame_period_s=spec.scan_period_s)
    np.testing.assert_allclose(table["force_n"], api.force_n, rtol=1e-5, equal_nan=True)
    applied = rec.truth["step_force_n"][rec.truth["frame_step"]]
    loaded = applied > 0
    assert loaded.sum() > 10
    assert np.all(np.abs(table["force_n"][loaded] / applied[loaded] - 1) < 0.2)
    other = tmp_path / "other.h5"
    improved = ts.fearing1990_improved()
    ts.write_recording(other, ts.simulate(improved, ts.force_steps(improved, repeats=1)))
    result = runner.invoke(
        app, ["locate", str(other), "--calibration", str(out), "--out", str(tmp_path / "x.csv")]
    )
    assert result.exit_code == 2 and "belongs to sensor" in plain(result.output)


def test_reproduce_quick_from_the_command_line(tmp_path):
    out = tmp_path / "paper"
    result = runner.invoke(app, ["reproduce", "--out", str(out), "--quick"])
    assert result.exit_code == 0, result.output
    assert (out / "report.html").exists() and (out / "results.json").exists()
    assert "predictions agree with the paper" in " ".join(plain(result.output).split())
    again = runner.invoke(app, ["reproduce", "--out", str(out), "--quick"])
    assert again.exit_code == 2 and "--force" in plain(again.output)


def test_design_bound_json():
    import json

    from tactsense.analysis.bound import cramer_rao_bound

    result = runner.invoke(
        app, ["design", "bound", "--axial", "12", "--angle", "10", "--force-g", "50", "--json"]
    )
    assert result.exit_code == 0, result.output
    data = json.loads(result.output)
    want = cramer_rao_bound(ts.fearing1990_initial(), 12.0, 10.0, ts.grams_force(50))
    assert data["bound"]["axial_mm"] == pytest.approx(want["axial_mm"], rel=1e-12)
    assert runner.invoke(app, ["design", "bound", "--sensor", "improved"]).exit_code == 0


def test_calibration_workflow_from_the_command_line_alone(tmp_path):
    sweep, knife, steps = tmp_path / "sweep.h5", tmp_path / "knife.h5", tmp_path / "steps.h5"
    for args in (
        ["--scenario", "calibration", "--increment", "1.2", "--out", str(sweep)],
        ["--scenario", "knife-edge", "--out", str(knife)],
        # creep of 15 s needs steps of seconds: 3 x 1 s leaves it unidentifiable (refused)
        ["--scenario", "repeated", "--repeats", "5", "--dwell-s", "3", "--out", str(steps)],
    ):
        result = runner.invoke(app, ["simulate", *args])
        assert result.exit_code == 0, result.output
    out = tmp_path / "cal.json"
    result = runner.invoke(
        app,
        ["calibrate", str(sweep), "--knife", str(knife), "--steps", str(steps), "--out", str(out)],
    )
    assert result.exit_code == 0, result.output
    fit = ts.estimate.Calibration.load(out).model_fit
    assert fit.depth_mm == pytest.approx(3.8, abs=0.4)
    bad = runner.invoke(
        app,
        [
            "simulate",
            "--scenario",
            "knife-edge",
            "--plot",
            str(tmp_path / "k.png"),
            "--out",
            str(tmp_path / "k.h5"),
        ],
    )
    assert bad.exit_code == 2 and "--plot" in plain(bad.output)
