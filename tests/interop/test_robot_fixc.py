"""An MCAP export of a robot recording keeps each stream's scenario, flaws and truth and
the recording's joint_states.csv; the import gives them back (trial 36 item 10a)."""

import dataclasses

import numpy as np
from typer.testing import CliRunner

from tactsense.cli import app
from tactsense.io.robot_recording import JOINT_STATES_FILE, read_robot_recording

from .robot_helpers import robot_recording, write

runner = CliRunner()


def test_mcap_round_trip_keeps_scenario_truth_and_joint_states(tmp_path):
    recording = robot_recording()
    streams = {}
    for k, (name, stream) in enumerate(recording.streams.items()):
        n = len(stream)
        truth = {
            "contact_position_mm": np.full((n, 1, 2), float(k)),
            "contact_normal_force_n": np.where(np.arange(n) % 2, np.nan, 0.5 * k)[:, None],
        }
        streams[name] = dataclasses.replace(
            stream, truth=truth, flaws=("noise",),
            scenario={"description": f"grasp {name}", "joints": {"j1": 0.25}},
        )  # fmt: skip
    recording = dataclasses.replace(recording, streams=streams)
    folder = tmp_path / "run"
    write(folder, recording)
    joints = "time_s,j1\n0,0.1\n0.4,0.3\n"
    (folder / JOINT_STATES_FILE).write_text(joints)
    out, back = tmp_path / "run.mcap", tmp_path / "back"
    result = runner.invoke(app, ["export", str(folder), "--out", str(out), "-q"])
    assert result.exit_code == 0, result.output
    result = runner.invoke(app, ["import", str(out), "--out", str(back)])
    assert result.exit_code == 0, result.output
    again = read_robot_recording(back)
    assert set(again.streams) == set(streams)
    for name, stream in streams.items():
        got = again.streams[name]
        assert got.scenario == stream.scenario
        assert got.flaws == stream.flaws
        assert set(got.truth) == set(stream.truth)
        for key, value in stream.truth.items():  # stored as they are: bit for bit, NaN too
            assert np.array_equal(np.asarray(got.truth[key]), value, equal_nan=True), key
    assert (back / JOINT_STATES_FILE).read_text() == joints


def test_import_of_a_robot_lerobot_export_says_what_import_reads(tmp_path):
    folder = tmp_path / "run"
    write(folder, robot_recording())
    dataset = tmp_path / "ds"
    result = runner.invoke(
        app, ["export", str(folder), "--format", "lerobot", "--out", str(dataset)]
    )
    assert result.exit_code == 0, result.output
    for extra in ([], ["--skin", "hand4"]):
        result = runner.invoke(app, ["import", str(dataset), *extra, "--out", str(tmp_path / "b")])
        text = " ".join(result.output.split())
        assert result.exit_code == 2 and "Traceback" not in text, text
        assert "is a robot LeRobot dataset" in text and "--format mcap" in text, text
        assert not (tmp_path / "b").exists()


def test_mcap_export_has_a_joint_state_topic_locate_reads(tmp_path):
    from tactsense.estimate._robot_joints import read_joint_bag

    folder = tmp_path / "run"
    write(folder, robot_recording())
    (folder / JOINT_STATES_FILE).write_text("time_s,j1\n0,0.1\n0.4,0.3\n")
    out = tmp_path / "run.mcap"
    result = runner.invoke(app, ["export", str(folder), "--out", str(out), "-q"])
    assert result.exit_code == 0, result.output
    states = read_joint_bag(out)
    times, values = states.series["j1"]
    assert np.allclose(times, [0, 0.4]) and np.allclose(values, [0.1, 0.3])
