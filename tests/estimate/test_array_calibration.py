"""Calibration of a pad from a lab's own data: per-taxel gains from a probe on every taxel
(or a uniform press), a force curve from a load cell's log, stored in JSON and applied
by find_contacts, locate, live and view."""

import csv
import json

import numpy as np
import pytest
from typer.testing import CliRunner

import tactsense as ts
from tactsense import flat_scenarios as fs
from tactsense.cli import app
from tactsense.estimate.contacts import find_contacts
from tactsense.estimate.contacts.array_calibration import (
    ArrayCalibration,
    ArrayCalibrationError,
    calibrate_array,
    force_curve,
    load_calibration,
    read_force_log,
)
from tactsense.physics.indenters import SphereProbe
from tactsense.simulate import Scenario, Step

runner = CliRunner()


def _loads(pad, rng=1):
    """24 presses of 0.1-1 N at random places: what a lab records with a probe on a stage
    over a load cell."""
    r = np.random.default_rng(rng)
    g = pad.grid
    steps = [Step((), 0.2, "baseline")]
    for f in np.linspace(0.1, 1.0, 24):
        x = r.uniform(1, g.rows - 2) * g.row_pitch_mm
        y = r.uniform(1, g.cols - 2) * g.col_pitch_mm
        steps += [Step((SphereProbe(x, y, float(f)),), 0.2, ""), Step((), 0.2, "lifted")]
    return ts.simulate(pad, Scenario(tuple(steps)), rng=rng)


def _log(rec, path):
    """The load cell's log: the force actually applied (jitter included), at the frames'
    times, as the lab's CSV."""
    force = np.asarray(rec.truth["step_force_n"])[rec.truth["frame_step"]]
    with open(path, "w", newline="") as stream:
        writer = csv.writer(stream)
        writer.writerow(["time_s", "force_n", "stage_x_mm"])
        for t, f in zip(rec.time_s, np.nan_to_num(force), strict=True):
            writer.writerow([f"{t:.6f}", f"{f:.6f}", "0"])
    return path


@pytest.fixture(scope="module")
def bench(tmp_path_factory):
    folder = tmp_path_factory.mktemp("arraycal")
    pad = ts.preset("pad4")
    rec = ts.simulate(pad, fs.raster(pad), rng=1)  # a 50-g probe on every taxel in turn
    ts.write_recording(folder / "bench.h5", rec)
    loads = _loads(pad)
    ts.write_recording(folder / "loads.h5", loads)
    _log(loads, folder / "loads.csv")
    _log(rec, folder / "one_load.csv")  # the raster's own log: 50 g every time
    ts.write_recording(folder / "press.h5", ts.simulate(pad, fs.press(pad), rng=2))
    return folder, pad, rec, loads


def test_gains_from_a_probe_on_every_taxel_undo_the_spread(bench):
    _, pad, rec, _ = bench
    cal = calibrate_array(rec.frames, pad)
    true = rec.gains / np.median(rec.gains)
    # the twin's gain spread (28 % here) left at the jitter of one press per taxel (1 g
    # of 50, 0.05 mm) and the creep of the presses before it: measured 8 % RMS, 15 % worst
    assert np.std(true) > 0.2
    residual = cal.gains / true
    residual /= np.median(residual)
    assert np.std(residual) < 0.1 and np.abs(residual - 1).max() < 0.2
    assert not cal.dead.any()


def test_the_force_curve_brings_forces_to_the_load_cell(bench):
    folder, pad, rec, loads = bench
    t, f = read_force_log(folder / "loads.csv")
    cal = calibrate_array(rec.frames, pad, loads=(loads.frames, loads.time_s), force_log=(t, f))
    x, y = cal.force_curve
    assert len(x) >= 2 and np.all(np.diff(x) > 0) and np.all(np.diff(y) >= 0)

    def errors(presses):
        """Median force error of the last frame of each press, without calibration and
        with gains and curve (against the force applied)."""
        step = presses.truth["frame_step"]
        force = np.asarray(presses.truth["step_force_n"])
        last = np.flatnonzero(np.r_[step[1:] != step[:-1], True])
        last = last[np.isfinite(force[step[last]]) & (force[step[last]] > 0)]
        assert len(last) == 24
        truth = force[step[last]]
        base = np.median(presses.frames[:5].astype(float), axis=0)
        own = ArrayCalibration(cal.sensor_toml, base, cal.gains, cal.dead, cal.force_curve)

        def error(table):
            return np.median(np.abs(table.force_n / truth[table.frame] - 1))

        frames = presses.frames[last]
        raw = error(find_contacts(frames, pad, baseline=base, max_contacts=1))
        return raw, error(find_contacts(frames, pad, calibration=own, max_contacts=1))

    # on the presses it was fitted to (a fit, not a prediction) the median error falls to
    # half or less (measured 0.50 -> 0.18)
    raw, curve = errors(loads)
    assert curve < 0.5 * raw, (raw, curve)
    # held out: 24 other presses (other places, noise and jitter: another seed) the
    # calibration never saw; measured 0.50 -> 0.22 (seed 7; seeds 2, 3, 11: ratios
    # 0.36-0.44)
    raw, curve = errors(_loads(pad, rng=7))
    assert curve < 0.5 * raw, (raw, curve)


def test_json_round_trip_and_checks(bench, tmp_path):
    _, pad, rec, _ = bench
    cal = calibrate_array(rec.frames, pad)
    path = cal.save(tmp_path / "cal.json")
    back = load_calibration(path, pad)
    assert isinstance(back, ArrayCalibration)
    np.testing.assert_array_equal(back.gains, cal.gains)
    with pytest.raises(ArrayCalibrationError, match="belongs to sensor 'pad4'"):
        load_calibration(path, ts.preset("pad16"))
    data = json.loads(path.read_text())
    data["gains"][1][2] = -1.0
    (tmp_path / "bad.json").write_text(json.dumps(data))
    with pytest.raises(ArrayCalibrationError, match="gains of 1 taxel"):
        load_calibration(tmp_path / "bad.json")


def test_force_curve_is_monotone_through_bin_medians():
    rng = np.random.default_rng(0)
    measured = rng.uniform(0.1, 1.0, 400)
    estimated = 0.6 * measured**1.2 + rng.normal(0, 0.01, 400)
    x, y = force_curve(estimated, measured, bins=8)
    # each knot is a bin's median of both: on the true inverse within the noise
    inverse = (np.asarray(x) / 0.6) ** (1 / 1.2)
    np.testing.assert_allclose(y, inverse, atol=0.03)
    with pytest.raises(ArrayCalibrationError, match="need at least 16"):
        force_curve(estimated[:10], measured[:10], bins=8)


def test_command_line_calibrate_then_locate(bench, tmp_path):
    folder = bench[0]
    out = tmp_path / "cal.json"
    result = runner.invoke(app, ["calibrate", str(folder / "bench.h5"), "--out", str(out),
                                 "--force-log", str(folder / "loads.csv"),
                                 "--loads", str(folder / "loads.h5")])  # fmt: skip
    assert result.exit_code == 0, result.output
    assert "force curve" in result.output and "dead taxels" in result.output
    assert isinstance(load_calibration(out), ArrayCalibration)
    est = tmp_path / "est.csv"
    result = runner.invoke(app, ["locate", str(folder / "bench.h5"), "--calibration", str(out),
                                 "--out", str(est)])  # fmt: skip
    assert result.exit_code == 0, result.output
    assert est.exists()


@pytest.fixture(scope="module")
def finger_files(tmp_path_factory):
    folder = tmp_path_factory.mktemp("fingercal")
    finger = ts.fearing1990_initial()
    ts.write_recording(folder / "finger.h5",
                       ts.simulate(finger, ts.calibration_sweep(finger), rng=0))  # fmt: skip
    result = runner.invoke(app, ["calibrate", str(folder / "finger.h5"), "--out",
                                 str(folder / "finger_cal.json")])  # fmt: skip
    assert result.exit_code == 0, result.output
    return folder


BAD = [
    ("calibrate PAD --steps PAD --out OUT", "--steps is for fingers"),
    ("calibrate PAD --loads PAD --out OUT", "--loads goes with --force-log"),
    ("calibrate BENCH/press.h5 --out OUT", "this is not a probe pressed on every taxel"),
    ("calibrate PAD --force-log BENCH/one_load.csv --out OUT", "the log holds one load"),
    ("calibrate PAD --force-log DIR/missing.csv --out OUT", "cannot read"),
    (
        "calibrate PAD --force-log DIR/nocolumns.csv --out OUT",
        "needs the columns time_s and force_n",
    ),
    ("calibrate PAD --force-log DIR/backwards.csv --out OUT", "time_s must increase"),
    ("calibrate PAD --press --out OUT", "a uniform press needs frames where most taxels"),
    ("calibrate FINGER --press --out OUT", "--press is for pads and point sets"),
    (
        "locate PAD --calibration FDIR/finger_cal.json --out DIR/never.csv",
        "is a finger's calibration",
    ),
]


@pytest.mark.parametrize("line, message", BAD, ids=[b[0] for b in BAD])
def test_bad_calibration_input_is_one_line(bench, finger_files, tmp_path, line, message):
    folder = bench[0]
    (tmp_path / "nocolumns.csv").write_text("t,f\n0,1\n1,2\n")
    (tmp_path / "backwards.csv").write_text("time_s,force_n\n1,0\n0,1\n")
    out = tmp_path / "never.json"
    args = (line.replace("PAD", str(folder / "bench.h5")).replace("BENCH", str(folder))
            .replace("FINGER", str(finger_files / "finger.h5"))
            .replace("FDIR", str(finger_files)).replace("DIR", str(tmp_path))
            .replace("OUT", str(out)).split())  # fmt: skip
    result = runner.invoke(app, args)
    said = " ".join(result.output.split())
    assert result.exit_code == 2, said
    assert message in said, said
    assert "Traceback" not in said
    assert not out.exists() and not (tmp_path / "never.csv").exists()
