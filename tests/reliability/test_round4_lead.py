"""Issue 32, found while merging: faults of real (noisy) arrays the helpers' matrices do
not cover."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from typer.testing import CliRunner

from tactsense.cli import app

runner = CliRunner()
ROOT = Path(__file__).resolve().parents[2]


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_a_held_press_on_a_noisy_array_is_not_taken_for_a_lift(tmp_path, seed):
    """``simulate --sensor fsr16 --scenario press`` then ``locate`` (read noise 1 % of
    full scale, threshold 5 sigma): a 50-g press held 0.5 s puts its peak taxel at 2-3
    thresholds, and single frames dip below RELEASE_SHARE of the noisiest peak by noise
    alone. Such a dip was taken as a lift and the held press re-zeroed: seed 0's force
    fell from 0.406 N over the first 10 loaded frames to 0.297 N over the last 10, and
    the lift read below the baseline in 8 frames, blamed on the first frames. Now the
    force holds within 10 % (noise: the per-frame force scatters by about 3 %)."""
    rec, out = tmp_path / "p.h5", tmp_path / "p.csv"
    made = runner.invoke(
        app, ["simulate", "--sensor", "fsr16", "--scenario", "press", "--seed", str(seed),
              "-o", str(rec)],
    )  # fmt: skip
    assert made.exit_code == 0, made.output
    located = runner.invoke(app, ["locate", str(rec), "-o", str(out)])
    assert located.exit_code == 0, located.output
    assert "below the baseline" not in located.output
    table = pd.read_csv(out)
    per_frame = np.bincount(table["frame"], minlength=120)
    assert (per_frame[20:70] == 1).all(), np.flatnonzero(per_frame[20:70] != 1) + 20
    force = table["force_n"].to_numpy()
    assert 0.9 < force[-10:].mean() / force[:10].mean() < 1.1, force


def test_the_creep_compensations_noise_gain_is_its_impulse_responses():
    """compensation_noise_gain (a Lyapunov solution) against the root sum of squares of
    CreepCompensator's own impulse response, run frame by frame for 20 creep time
    constants (independent: the compensator itself, not its coefficients)."""
    from tactsense.estimate.creep import CreepCompensator, compensation_noise_gain, described_creep
    from tactsense.sensor import load_sensor

    for name in ("pad16", "dome12"):
        sensor = load_sensor(name)
        model, dt = described_creep(sensor), sensor.scan_period_s
        compensator = CreepCompensator(model, dt)
        n = int(20 * model.creep_time_constant_s / dt)
        response = np.array([float(compensator(1.0 if k == 0 else 0.0)) for k in range(n)])
        assert compensation_noise_gain(model, dt) == pytest.approx(
            np.sqrt((response**2).sum()), rel=1e-6
        )


def test_a_noisy_stamp_through_locate_with_creep_compensation(tmp_path):
    """A pad16 reading 2 % of full scale of noise (82 counts), gain spread 20 %, a
    7.5-mm square stamp pressed 8 times: ``locate`` takes the simulation's creep out,
    which amplifies white noise 1.77 times at 100 Hz, and thresholded the result at 5
    sigma of the raw noise: one contact in 66 % of loaded frames, 356 ids, contacts in
    187 unloaded frames. With the threshold over the compensated noise: one contact in
    at least 98 % of loaded frames (issue 32's goal), none in unloaded frames, and at
    most 3 ids beyond the 8 presses (a frame that splits gives its piece an id)."""
    toml = tmp_path / "noisy16.toml"
    toml.write_text(
        'kind = "pad"\nextends = "pad16"\nname = "noisy16"\n'
        "[flaws]\ngain_spread_sd = 0.2\nread_noise_counts = 82.0\n"
    )
    rec, out = tmp_path / "stamp.h5", tmp_path / "stamp.csv"
    made = runner.invoke(
        app, ["simulate", "--sensor", str(toml), "--indenter", "square", "--size-mm", "7.5",
              "--force-g", "600", "--angle-deg", "20", "--repeats", "8", "--dwell-s", "0.4",
              "--lift-s", "0.6", "--seed", "4", "--out", str(rec)],
    )  # fmt: skip
    assert made.exit_code == 0, made.output
    located = runner.invoke(app, ["locate", str(rec), "--baseline-frames", "20", "-o", str(out)])
    assert located.exit_code == 0, located.output
    assert "creep: described (simulation)" in " ".join(located.output.split())
    from tactsense.io.recording import read_recording

    truth = read_recording(rec).truth
    loaded = np.asarray(truth["step_force_n"])[np.asarray(truth["frame_step"])] > 0
    table = pd.read_csv(out)
    per_frame = np.bincount(table["frame"], minlength=len(loaded))
    assert (per_frame[loaded] == 1).mean() >= 0.98
    assert (per_frame[~loaded] == 0).all()
    assert table["id"].nunique() <= 8 + 3


@pytest.fixture(scope="module")
def tip_weights(tmp_path_factory):
    """An iCub-like fingertip's weights series (20-160 g), as a lab's logger gives it:
    simulated, exported to CSV, imported."""
    folder = tmp_path_factory.mktemp("tip")
    toml = folder / "tip.toml"
    toml.write_text('extends = "icub_fingertip"\nname = "lab_tip"\n')
    sim, frames, rec = folder / "sim.h5", folder / "frames.csv", folder / "w.h5"
    for args in (
        ["simulate", "--sensor", str(toml), "--scenario", "loads", "--forces-g",
         "20,40,60,80,100,120,140,160", "--dwell-s", "2", "--lift-s", "2", "--seed", "1",
         "-o", str(sim)],
        ["export", str(sim), "--format", "csv", "-o", str(frames)],
        ["import", str(frames), "--sensor", str(toml), "-o", str(rec)],
    ):  # fmt: skip
        result = runner.invoke(app, args)
        assert result.exit_code == 0, result.output
    return folder, rec


def _weights(folder, name, header, masses):
    path = folder / name
    path.write_text(f"press,{header}\n" + "".join(f"{k + 1},{m}\n" for k, m in enumerate(masses)))
    return path


def test_weights_logged_out_of_order_are_said_so(tip_weights):
    """Two rows of the log swapped (80 g logged before 60 g): the totals fall from one
    load to the next, which the monotone fit pools; it said "add weights there, where
    the curve bends" (a leave-one-out error of 50 %), never that the log is out of
    order."""
    folder, rec = tip_weights
    log = _weights(folder, "swapped.csv", "mass_g", [20, 40, 80, 60, 100, 120, 140, 160])
    result = runner.invoke(
        app, ["calibrate", str(rec), "--force-log", str(log), "-o", str(folder / "c1.json")]
    )
    said = " ".join(result.output.replace("│", " ").split())
    assert "the totals fall from" in said, said
    assert "is the log in the order the weights were placed" in said, said


def test_grams_under_a_kilogram_header_are_questioned(tip_weights):
    """Grams written under ``mass_kg``: the curve went to 1569 N on a 144-mm^2 fingertip
    (10.9 MPa) without a word. A weight above 1 MPa over the whole array asks for the
    unit; a log in the right unit gets no such warning."""
    folder, rec = tip_weights
    masses = [20, 40, 60, 80, 100, 120, 140, 160]
    wrong = _weights(folder, "kg.csv", "mass_kg", masses)
    result = runner.invoke(
        app, ["calibrate", str(rec), "--force-log", str(wrong), "-o", str(folder / "c2.json")]
    )
    said = " ".join(result.output.split())
    assert "is 'mass_kg' the unit of the numbers" in said, said
    right = _weights(folder, "g.csv", "mass_g", masses)
    result = runner.invoke(
        app, ["calibrate", str(rec), "--force-log", str(right), "-o", str(folder / "c3.json")]
    )
    assert result.exit_code == 0 and "the unit of the numbers" not in result.output
    assert "holds for" in result.output


def test_weights_on_a_fingertip_described_with_the_wrong_polarity(tip_weights):
    """The fingertip's frames (falling under load) imported with a description that
    says rising: calibrate said only "found 6 presses ... lists 8 weights", phantom
    presses and no hint; now the message names the polarity to set (exit 2, no file)."""
    folder, _ = tip_weights
    toml = folder / "rising.toml"
    toml.write_text(
        'extends = "icub_fingertip"\nname = "lab_tip"\n[transduction]\npolarity = "rising"\n'
    )
    rec, out = folder / "rising.h5", folder / "rising.json"
    result = runner.invoke(
        app, ["import", str(folder / "frames.csv"), "--sensor", str(toml), "-o", str(rec)]
    )
    assert result.exit_code == 0, result.output
    log = _weights(folder, "g8.csv", "mass_g", [20, 40, 60, 80, 100, 120, 140, 160])
    result = runner.invoke(app, ["calibrate", str(rec), "--force-log", str(log), "-o", str(out)])
    said = " ".join(result.output.split())
    assert result.exit_code == 2 and not out.exists()
    assert "set [transduction] polarity = 'falling'" in said, said


def test_csv_times_in_milliseconds_are_questioned(tip_weights):
    """A logger's CSV with times in ms was imported silently (``info`` then showed a
    recording of 20180 s at 50 Hz); frames 1000 times the sensor's scan period apart now
    get a warning, and the same rows in seconds get none."""
    import csv

    folder, _ = tip_weights
    with open(folder / "frames.csv", newline="") as stream:
        rows = list(csv.reader(stream))
    column = rows[0].index("time")
    for name, scale in (("ms.csv", 1000.0), ("s.csv", 1.0)):
        with open(folder / name, "w", newline="") as stream:
            writer = csv.writer(stream)
            writer.writerow(rows[0])
            for row in rows[1:60]:
                writer.writerow([*row[:column], repr(float(row[column]) * scale),
                                 *row[column + 1:]])  # fmt: skip
    toml = folder / "tip.toml"
    said = {}
    for name in ("ms.csv", "s.csv"):
        result = runner.invoke(
            app, ["import", str(folder / name), "--sensor", str(toml),
                  "-o", str(folder / f"{name}.h5")],
        )  # fmt: skip
        assert result.exit_code == 0, result.output
        said[name] = " ".join(result.output.split())
    assert "are the times in seconds (not ms or us)?" in said["ms.csv"], said["ms.csv"]
    assert "warning" not in said["s.csv"]


@pytest.mark.parametrize(
    "preset, counts", [("fsr16", "205 counts"), ("icub_fingertip", "3 counts")]
)
def test_sensor_check_prints_the_contact_threshold(tmp_path, preset, counts):
    """``sensor check`` printed the blind-spot map's threshold (3 x the noise) and never
    the contact threshold ``locate`` uses (5 x the noise on a noisy array, 3 counts on an
    8-bit one), so a lab could not see why a light press found nothing. 205 = 5 x 41
    counts (1 % of 4095); 3 counts: the floor below 12 bits."""
    toml = tmp_path / "mine.toml"
    toml.write_text(f'extends = "{preset}"\nname = "mine"\n')
    result = runner.invoke(app, ["sensor", "check", str(toml)])
    assert result.exit_code == 0, result.output
    said = " ".join(result.output.replace("│", " ").split())
    assert f"contact threshold {counts} from the rest" in said, said


def test_a_short_real_trial_names_no_healthy_taxel_dead(tmp_path):
    """A grasp of nothing of the iCub dataset (``none_3``, 4 slices): 5 of its 12
    healthy taxels read one whole count throughout (noise of 0.3 counts, quantized), and
    locate named them "never changed ... dead". Four frames say nothing of that; over
    CONSTANT_FRAMES frames or more a constant taxel is still named (test_round4_devices)."""
    import tarfile

    archive = ROOT / "tests" / "data" / "icub_grasp" / "iCubGraspDataset.tar.xz"
    with tarfile.open(archive) as tar:
        member = tar.getmember("iCubGraspDataset/none_3.txt")
        (tmp_path / "none_3.txt").write_bytes(tar.extractfile(member).read())
    rec, out = tmp_path / "none_3.h5", tmp_path / "none_3.csv"
    result = runner.invoke(
        app, ["import", str(tmp_path / "none_3.txt"), "--finger", "index", "-o", str(rec)]
    )
    assert result.exit_code == 0, result.output
    result = runner.invoke(
        app, ["locate", str(rec), "--baseline-frames", "2", "--drift-s", "0", "-o", str(out)]
    )
    assert result.exit_code == 0, result.output
    assert "never changed" not in result.output, result.output
