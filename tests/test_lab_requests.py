"""What a lab asked for first (issue 31, item 14): ``sensor list``, where and along
which axis ``two-probes`` presses, and a ``loads`` scenario whose force log calibrates
the force curve (simulate -> calibrate --force-log -> locate)."""

import numpy as np
import pandas as pd
import pytest
from typer.testing import CliRunner

import tactsense as ts
from tactsense import flat_scenarios as fs
from tactsense.cli import app
from tactsense.estimate.contacts.array_calibration import read_force_log
from tactsense.physics.contact import grams_force

runner = CliRunner()


def _cli(*args, cwd=None):
    result = runner.invoke(app, [str(a) for a in args])
    assert result.exit_code == 0, result.output
    return result.output


def test_sensor_list_names_every_preset_with_its_size_and_pitch():
    out = _cli("sensor", "list")
    lines = {line.split("│")[1].strip(): line for line in out.splitlines() if "│" in line}
    assert set(ts.sensor.PRESETS) <= set(lines)
    # the numbers come from the presets themselves
    for name in ("pad4", "pad16", "pad12x32"):
        g = ts.preset(name).grid
        assert f"{g.rows} x {g.cols} taxels" in lines[name]
        assert f"{g.row_pitch_mm:g} x {g.col_pitch_mm:g} mm" in lines[name]
    initial = ts.preset("initial")
    assert f"{initial.array.spacing_axial_mm:g} mm" in lines["initial"]
    assert "finger" in lines["initial"] and "points" in lines["dome12"]


@pytest.mark.parametrize("angle, along", [(0.0, "x"), (90.0, "y")])
def test_two_probes_centre_and_axis(angle, along):
    pad = ts.preset("pad16")
    scene = fs.two_probes(pad, x_mm=10.0, y_mm=20.0, separation_mm=5.0, angle_deg=angle)
    first, second = scene.steps[1].contacts
    np.testing.assert_allclose([(first.x_mm + second.x_mm) / 2, (first.y_mm + second.y_mm) / 2],
                               [10.0, 20.0], atol=1e-12)  # fmt: skip
    dx, dy = second.x_mm - first.x_mm, second.y_mm - first.y_mm
    np.testing.assert_allclose((dx, dy), (5.0, 0.0) if along == "x" else (0.0, 5.0), atol=1e-12)


def test_two_probes_on_the_command_line_peak_under_each_probe(tmp_path):
    out = tmp_path / "two.h5"
    # the pair about taxel (4, 10) along x, 10 mm apart: peaks at rows 2 and 6, column 10
    _cli("simulate", "--sensor", "pad16", "--scenario", "two-probes", "--x-mm", 10,
         "--y-mm", 25, "--angle-deg", 0, "--separation-mm", 10, "--flaws", "none",
         "--out", out)  # fmt: skip
    rec = ts.read_recording(out)
    frame = rec.frames[rec.truth["step_n_contacts"][rec.truth["frame_step"]] == 2][-1]
    signal = frame - rec.frames[0]
    column = signal[:, 10]
    assert set(np.argsort(column)[-2:]) == {2, 6}
    assert signal.max(axis=0).argmax() == 10


def test_loads_scenario_presses_each_force_in_turn():
    pad = ts.preset("pad4")
    forces = [grams_force(g) for g in (20, 50, 100)]
    scene = fs.loads(pad, forces_n=forces, repeats=2)
    pressed = [s.contacts[0] for s in scene.steps if s.contacts]
    assert [p.force_n for p in pressed] == forces * 2
    # on the taxel nearest the middle: (1, 1) of the 4x4, 5 mm pitch
    assert {(p.x_mm, p.y_mm) for p in pressed} == {(5.0, 5.0)}
    places = fs.loads(pad, forces_n=forces, places=[(0.0, 0.0), (5.0, 10.0)])
    assert [(s.contacts[0].x_mm, s.contacts[0].y_mm) for s in places.steps if s.contacts] == [
        (0.0, 0.0), (5.0, 10.0), (0.0, 0.0)]  # fmt: skip


def test_force_log_is_what_calibrate_reads_and_holds_the_applied_force(tmp_path):
    out, log = tmp_path / "loads.h5", tmp_path / "loads.csv"
    _cli("simulate", "--sensor", "pad4", "--scenario", "loads", "--forces-g", "20,60,120",
         "--out", out, "--force-log", log)  # fmt: skip
    t, f = read_force_log(log)  # calibrate's own reader
    rec = ts.read_recording(out)
    np.testing.assert_allclose(t, rec.time_s)
    applied = np.asarray(rec.truth["step_force_n"])[rec.truth["frame_step"]]
    np.testing.assert_allclose(f, applied, rtol=1e-8)
    # three presses, each near its nominal load (the twin's 1-g force jitter)
    step = rec.truth["frame_step"]
    loaded = [np.median(f[step == k]) for k in np.unique(step)]
    loaded = [v for v in loaded if v > 0]
    np.testing.assert_allclose(loaded, [grams_force(g) for g in (20, 60, 120)], atol=0.03)


def test_round_trip_loads_calibrate_locate(tmp_path):
    """simulate loads -> calibrate --force-log -> locate: the forces of a second,
    independent ramp (other forces, other seed) at the same place.

    Tolerance 20 % on every press: with every flaw on, the twin's 1-g force jitter,
    0.05-mm position jitter and, above all, the creep of the presses before (creep
    fraction 1.14 over 20 s, which differs between a 12-press and a 4-press ramp)
    remain; measured 4-13 %. Without the curve the same presses read 39-62 % low.
    """
    folder = tmp_path
    common = ("--sensor", "pad4", "--scenario", "loads", "--x-mm", 5, "--y-mm", 5)
    _cli("simulate", "--sensor", "pad4", "--scenario", "calibration", "--out", folder / "r.h5")
    _cli("simulate", *common, "--forces-g", "10:200:12", "--out", folder / "l.h5",
         "--force-log", folder / "l.csv")  # fmt: skip
    _cli("calibrate", folder / "r.h5", "--loads", folder / "l.h5", "--force-log",
         folder / "l.csv", "--out", folder / "c.json")  # fmt: skip
    _cli("simulate", *common, "--forces-g", "25:175:4", "--seed", 7, "--out", folder / "t.h5")
    _cli("locate", folder / "t.h5", "--calibration", folder / "c.json", "--out", folder / "e.csv")
    _cli("locate", folder / "t.h5", "--out", folder / "raw.csv")
    rec = ts.read_recording(folder / "t.h5")
    step, force = rec.truth["frame_step"], np.asarray(rec.truth["step_force_n"])
    last = np.flatnonzero(np.r_[step[1:] != step[:-1], True])
    last = last[force[step[last]] > 0]
    assert len(last) == 4

    def errors(name):
        got = pd.read_csv(folder / name).groupby("frame").force_n.sum()
        return np.array([got.get(i, 0.0) / force[step[i]] - 1 for i in last])

    calibrated, raw = errors("e.csv"), errors("raw.csv")
    assert np.abs(calibrated).max() < 0.20, calibrated
    assert np.abs(raw).min() > 2 * np.abs(calibrated).max(), (raw, calibrated)
