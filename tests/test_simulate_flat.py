"""`tactsense simulate` on pads and point sets, from the command line to the recording."""

import numpy as np
import pandas as pd
import pytest
from typer.testing import CliRunner

import tactsense as ts
import tactsense.flat_scenarios
from tactsense.cli import app
from tactsense.flat_scenarios import two_probes

runner = CliRunner()


def test_two_probes_on_a_pad_peak_under_each_probe(tmp_path):
    out = tmp_path / "two.h5"
    result = runner.invoke(
        app,
        ["simulate", "--sensor", "pad16", "--scenario", "two-probes", "--separation-mm",
         "7.5", "--flaws", "none", "--out", str(out)],
    )  # fmt: skip
    assert result.exit_code == 0, result.output
    assert "frames of 16x16 counts" in result.output
    recording = ts.read_recording(out)
    assert recording.sensor.kind == "pad"
    pressed = recording.frames[recording.truth["frame_step"] == 1]
    assert len(pressed) > 0
    frame = pressed[-1].astype(float) - recording.sensor.electronics.nominal_counts
    # the probes sit at y = 18.75 -/+ 3.75 mm on row x = 18.75: columns 6 and 9, row 7.5
    # (between rows 7 and 8: both read alike); the two columns are the two maxima
    by_column = frame.max(axis=0)
    assert set(np.argsort(by_column)[-2:]) == {6, 9}
    assert by_column[7] < by_column[6] and by_column[8] < by_column[9]  # two, not one blob
    printed = int(result.output.split("wrote ")[1].split(":")[1].split()[0])
    assert printed == len(recording.frames)


def test_point_set_press_reads_under_the_pressed_taxel(tmp_path):
    out = tmp_path / "dome.h5"
    result = runner.invoke(
        app, ["simulate", "--sensor", "dome12", "--flaws", "none", "--out", str(out)]
    )
    assert result.exit_code == 0, result.output
    recording = ts.read_recording(out)
    assert recording.frames.shape[1:] == (1, 12)
    rise = recording.frames.max(axis=0)[0] - recording.sensor.electronics.nominal_counts
    assert int(np.argmax(rise)) == 0  # pressed at taxel 0, the apex


@pytest.mark.parametrize(
    "line, message",
    [
        ("--sensor pad16 --scenario sweep-axial", "is for fingers; 'pad16' is a pad"),
        ("--scenario press", "is for pads and point sets"),
        ("--sensor pad16 --row 3", "--row does not apply to --scenario press"),
        ("--sensor pad4 --x-mm 100", "off the 4x4 pad 'pad4'"),
        ("--sensor pad4 --indenter hammer", "unknown indenter 'hammer'"),
        ("--sensor pad4 --scenario two-probes --separation-mm 80", "off the 4x4 pad"),
        ("--sensor pad4 --scenario slide --speed-mm-s 0", "--speed-mm-s"),
        ("--sensor pad4 --size-mm 0", "--size-mm"),
        ("--sensor pad4 --scenario knife-edge --angle-deg 400", "--angle-deg"),
        ("--sensor pad4 --scenario punch --plot p.png", "--plot draws a finger's sweeps"),
    ],
)
def test_bad_pad_scenarios_are_one_line(tmp_path, monkeypatch, line, message):
    monkeypatch.chdir(tmp_path)
    result = runner.invoke(app, ["simulate", *line.split(), "--out", "x.h5"])
    assert result.exit_code == 2, result.output
    assert message in result.output
    assert "Traceback" not in result.output
    assert not (tmp_path / "x.h5").exists()


def test_a_pad_exports_its_frames_and_contacts_to_mcap(tmp_path):
    """Every frame as a TactileState, values equal to the counts, and every contact of
    every frame as a TactileContact at the position and force ``locate`` gives (read back
    with mcap's reader and the ROS 2 decoder)."""
    from mcap.reader import make_reader
    from mcap_ros2.decoder import DecoderFactory

    pad = ts.preset("pad16")
    rec_path, out = tmp_path / "pad.h5", tmp_path / "pad.mcap"
    ts.write_recording(rec_path, ts.simulate(pad, two_probes(pad), rng=2))
    result = runner.invoke(app, ["export", str(rec_path), "--out", str(out)])
    assert result.exit_code == 0, result.output
    recording = ts.read_recording(rec_path)
    with open(out, "rb") as stream:
        reader = make_reader(stream, decoder_factories=[DecoderFactory()])
        values, contacts = [], []
        for _, channel, _, message in reader.iter_decoded_messages():
            if channel.topic == "/tactile_states":
                values.append(np.asarray(message.sensors[0].values))
            elif channel.topic == "/tactile_contacts":
                contacts.append(message)
    assert len(values) == len(recording.frames)
    np.testing.assert_array_equal(np.stack(values), recording.frames.reshape(len(values), -1))
    # the contacts are locate's long table, row for row (metres in the message)
    assert (
        runner.invoke(app, ["locate", str(rec_path), "--out", str(tmp_path / "c.csv")]).exit_code
        == 0
    )
    table = pd.read_csv(tmp_path / "c.csv")
    assert len(contacts) == len(table) > 0
    got = np.array([[m.position.x, m.position.y, m.wrench.force.z] for m in contacts])
    np.testing.assert_allclose(got[:, 0], table["x_mm"] * 1e-3, rtol=1e-9)
    np.testing.assert_allclose(got[:, 1], table["y_mm"] * 1e-3, rtol=1e-9)
    np.testing.assert_allclose(-got[:, 2], table["force_n"], rtol=1e-9)  # along -normal
    assert all(m.normal.z == 1.0 for m in contacts)
    said = " ".join(result.output.split())
    assert f"{len(values)} frames, {len(contacts)} contacts" in said


def test_an_emulated_pad_records_bit_identical_to_its_simulation(tmp_path):
    """`emulate --sensor pad16` plays the twin's pad frames over TCP; `record` keeps them
    exactly (the same frames `simulate` writes for the same scenario and seed)."""
    import subprocess
    import sys

    cli = [sys.executable, "-m", "tactsense_launcher"]
    emulator = subprocess.Popen(
        [*cli, "emulate", "--sensor", "pad16", "--scenario", "two-probes", "--port", "0",
         "--speed", "1e6"],
        stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True,
    )  # fmt: skip
    try:
        url = emulator.stdout.readline().strip()
        assert url.startswith("socket://127.0.0.1:"), url
        out = tmp_path / "live.h5"
        done = subprocess.run(
            [*cli, "record", url, "--out", str(out), "--frames", "60"],
            capture_output=True, text=True, timeout=120,
        )  # fmt: skip
        assert done.returncode == 0, done.stderr
    finally:
        emulator.terminate()
        emulator.wait(timeout=30)
    recorded = ts.read_recording(out)
    # the twin playing the device says its creep is its own ([flaws] creep_known), so that
    # live and record take it out as locate does on the simulation; nothing else differs
    import dataclasses

    pad16 = ts.preset("pad16")
    known = dataclasses.replace(pad16, flaws=dataclasses.replace(pad16.flaws, creep_known=True))
    assert recorded.sensor == known
    simulated = ts.simulate(
        ts.preset("pad16"), ts.flat_scenarios.two_probes(ts.preset("pad16")), rng=0
    )
    np.testing.assert_array_equal(recorded.frames, simulated.frames[:60])
