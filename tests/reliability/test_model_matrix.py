"""The model commands' bad-input and small-sensor matrix (issue 21, items 3 and 10).

Bad input: exit status 2, one message naming what was wrong, no traceback, nothing at
any output name. Small sensors: every scenario of ``simulate`` runs on the sensor it is
given and loads the tactel it names.
"""

import numpy as np
import pytest
from typer.testing import CliRunner

import tactsense as ts
from tactsense._validation import TactsenseInputError
from tactsense.cli import app
from tactsense.interop.urdf import sensor_from_urdf

runner = CliRunner()


def _check(result, names: str):
    message = " ".join(result.output.split())  # rich wraps long lines at the terminal width
    assert result.exit_code == 2, message
    assert "Traceback" not in message
    assert names in message, message


BAD = [
    # (command line, what the message must say); OUT and PLOT must not be written
    ("simulate --out OUT --plot DIR/p1.txt", "--plot DIR/p1.txt: matplotlib cannot write '.txt'"),
    ("simulate --out OUT --plot DIR/p1", "matplotlib cannot write no extension"),
    ("simulate --out OUT --plot DIR/p1.pgf", "matplotlib cannot write '.pgf'"),
    ("design sweep --depth 3.8 --spacing 3.8 --out OUT --plot DIR/d1.txt", "cannot write '.txt'"),
    ("simulate --dwell-s 0.001 --out OUT", "give at least 0.1429 s"),
    ("simulate --dwell-s 0.1 --out OUT", "--dwell-s 0.1 s is shorter than one scan period"),
    ("simulate --scenario repeated --dwell-s 0.01 --out OUT", "0.1429 s at 7 Hz"),
    ("simulate --lift-s 0.05 --out OUT", "--lift-s 0.05 s is shorter than one scan period"),
    ("simulate --scenario sweep-around --row 8 --out OUT", "row 8 is outside the 8x8 array"),
    ("simulate --col 8 --out OUT", "column 8 is outside the 8x8 array"),
]


@pytest.mark.parametrize("line, names", BAD, ids=[line for line, _ in BAD])
def test_bad_model_input(tmp_path, line, names):
    out, plots = tmp_path / "never.h5", tmp_path / "never.nc"
    line = line.replace("OUT", str(out if "simulate" in line else plots))
    result = runner.invoke(app, line.replace("DIR", str(tmp_path)).split())
    _check(result, names.replace("DIR", str(tmp_path)))
    assert list(tmp_path.iterdir()) == []  # neither the recording, the map nor the plot


def test_a_dwell_of_one_scan_period_is_accepted(tmp_path):
    """The minimum the message gives is accepted when typed back."""
    out = tmp_path / "ok.h5"
    result = runner.invoke(
        app, ["simulate", "--dwell-s", "0.1429", "--increment", "10", "--out", str(out)]
    )
    assert result.exit_code == 0, result.output
    rec = ts.read_recording(out)
    loaded = np.asarray(rec.truth["step_n_contacts"])[rec.truth["frame_step"]] > 0
    assert loaded.sum() >= 1  # every position held for at least one frame


URDF = (
    '<robot name="r"><link name="l"/><sensor name="{name}" update_rate="{rate}">'
    '<parent link="l"/><tactile><array rows="{rows}" cols="{cols}" size="0.003 0.003" '
    'spacing="0.0038 0.004"/></tactile></sensor></robot>'
)
SCENARIOS = ["sweep-axial", "sweep-around", "repeated", "calibration", "knife-edge"]
SHAPES = [(4, 6, 7), (2, 2, 7), (5, 1, 7), (4, 6, 1)]  # rows, cols, scan rate [Hz]


def _sensor(folder, rows, cols, rate):
    name = f"s{rows}x{cols}at{rate}"
    urdf = folder / f"{name}.urdf"
    urdf.write_text(URDF.format(name=name, rows=rows, cols=cols, rate=rate))
    path = folder / f"{name}.toml"
    sensor_from_urdf(urdf).to_toml(path)
    return path


@pytest.mark.parametrize("scenario", SCENARIOS)
@pytest.mark.parametrize("rows, cols, rate", SHAPES, ids=[f"{r}x{c}@{f}Hz" for r, c, f in SHAPES])
def test_every_scenario_fits_a_small_sensor(tmp_path, rows, cols, rate, scenario):
    """A sensor imported from URDF runs every scenario with its defaults (a 4x6 array
    refused the default scenario: tactel (4, 0) outside it), and the named tactel is
    loaded: its deflection reaches a tenth of the largest on the array."""
    sensor = _sensor(tmp_path, rows, cols, rate)
    out = tmp_path / "rec.h5"
    args = ["simulate", "--sensor", str(sensor), "--scenario", scenario, "--out", str(out)]
    if scenario == "repeated":
        args += ["--repeats", "2"]
    result = runner.invoke(app, args)
    assert result.exit_code == 0, result.output
    rec = ts.read_recording(out)
    assert rec.frames.shape[1:] == (rows, cols)
    params = rec.scenario["parameters"]
    frames = rec.frames.astype(float)
    base = frames[rec.baseline_frames].mean(axis=0)
    deflection = 1.0 - base / np.where(frames > 0, frames, np.nan)  # counts fall as C rises
    deflection = np.abs(np.nan_to_num(deflection))
    if scenario == "sweep-axial":
        swept = deflection[:, :, params["col"]]
    elif scenario == "sweep-around":
        swept = deflection[:, params["row"], :]
    elif scenario == "calibration":
        swept = deflection
    else:
        swept = deflection[:, params["row"], params["col"]]
        assert params["row"] == min(4, rows // 2)
    loaded = np.asarray(rec.truth["step_n_contacts"])[rec.truth["frame_step"]] > 0
    assert loaded.any()
    assert swept[loaded].max() > 0.1 * deflection.max() > 0


def test_default_row_is_the_papers_on_the_papers_finger():
    spec = ts.fearing1990_initial()
    assert ts.repeated_load(spec).parameters["row"] == 4
    assert ts.probe_sweep(spec, along="around").parameters["row"] == 4


def test_a_sweep_checks_only_the_index_it_uses():
    """A sweep along reads the column alone: an unused row outside the array is no
    error (the default row 4 on a 4-row array was refused)."""
    spec = sensor_from_urdf_text(4, 6)
    scene = ts.probe_sweep(spec, along="axial", row=9, col=5)
    assert scene.parameters["col"] == 5
    with pytest.raises(TactsenseInputError, match="column 6 is outside the 4x6 array"):
        ts.probe_sweep(spec, along="axial", col=6)


def sensor_from_urdf_text(rows, cols, rate=7):
    import pathlib
    import tempfile

    with tempfile.TemporaryDirectory() as folder:
        path = pathlib.Path(folder) / "s.urdf"
        path.write_text(URDF.format(name="s", rows=rows, cols=cols, rate=rate))
        return sensor_from_urdf(path)


def test_calibrate_partial_does_not_call_an_unreached_tactel_dead(tmp_path):
    """A sweep along column 0 leaves columns 1-7 unreached: those tactels are
    uncalibrated (gain 1, listed), not dead. Dead are the two the twin made dead, one in
    the swept column and one outside it; one unreached tactel was called dead before."""
    import json

    spec = ts.fearing1990_initial().replace(flaws__dead_tactels=((2, 0), (3, 5)))
    rec = tmp_path / "sweep.h5"
    ts.write_recording(rec, ts.simulate(spec, ts.probe_sweep(spec), rng=0))
    out = tmp_path / "cal.json"
    result = runner.invoke(app, ["calibrate", str(rec), "--partial", "--out", str(out)])
    assert result.exit_code == 0, result.output
    data = json.loads(out.read_text())
    dead = {tuple(t) for t in np.argwhere(np.array(data["dead"])).tolist()}
    assert dead == {(2, 0), (3, 5)}
    unreached = {tuple(t) for t in data["notes"]["uncalibrated_tactels"]}
    assert len(unreached - dead) >= 50  # the other columns: never deflected, yet alive
    assert "2 / 0 / 0" in result.output  # the printed count is the count kept
