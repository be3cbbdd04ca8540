"""`tactsense simulate` on pads and point sets, from the command line to the recording."""

import numpy as np
import pytest
from typer.testing import CliRunner

import tactsense as ts
import tactsense.flat_scenarios
from tactsense.cli import app
from tactsense.flat_scenarios import press

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


def test_a_pad_exports_its_frames_to_mcap_as_tactile_state(tmp_path):
    """No contacts yet on pads: every frame as a TactileState, values equal to the counts
    (read back with mcap's reader and the ROS 2 decoder)."""
    from mcap.reader import make_reader
    from mcap_ros2.decoder import DecoderFactory

    pad = ts.preset("pad4")
    rec_path, out = tmp_path / "pad.h5", tmp_path / "pad.mcap"
    ts.write_recording(rec_path, ts.simulate(pad, press(pad), rng=2))
    result = runner.invoke(app, ["export", str(rec_path), "--out", str(out)])
    assert result.exit_code == 0, result.output
    recording = ts.read_recording(rec_path)
    with open(out, "rb") as stream:
        reader = make_reader(stream, decoder_factories=[DecoderFactory()])
        values = [
            np.asarray(message.sensors[0].values)
            for _, _, _, message in reader.iter_decoded_messages(topics=["/tactile_states"])
        ]
    assert len(values) == len(recording.frames)
    np.testing.assert_array_equal(np.stack(values), recording.frames.reshape(len(values), -1))
    assert f"{len(values)} frames, 0 with a contact" in result.output


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
    assert recorded.sensor == ts.preset("pad16")
    simulated = ts.simulate(
        ts.preset("pad16"), ts.flat_scenarios.two_probes(ts.preset("pad16")), rng=0
    )
    np.testing.assert_array_equal(recorded.frames, simulated.frames[:60])
