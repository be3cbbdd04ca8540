"""``tactsense locate RUN/`` on a robot recording: the contacts and wrench tables."""

from __future__ import annotations

import numpy as np
import pyarrow.compute
import pyarrow.csv
import pyarrow.parquet
import pytest
from typer.testing import CliRunner

from tactsense.cli import app
from tactsense.estimate.robot import CONTACT_COLUMNS, WRENCH_COLUMNS
from tests.estimate._robot_sim import write_pressed_recording
from tests.estimate.test_robot_locate import small_skin

runner = CliRunner()


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    return write_pressed_recording(tmp_path_factory.mktemp("robot") / "run", small_skin())


def test_locate_writes_both_tables(run, tmp_path):
    out = tmp_path / "contacts.parquet"
    result = runner.invoke(
        app, ["locate", str(run), "--joints", "j1=0.3,j2=-0.2", "--out", str(out)]
    )
    assert result.exit_code == 0, result.output
    contacts = pyarrow.parquet.read_table(out)
    wrenches = pyarrow.parquet.read_table(tmp_path / "contacts_wrenches.parquet")
    assert contacts.column_names == list(CONTACT_COLUMNS)
    assert wrenches.column_names == list(WRENCH_COLUMNS)
    patch = contacts.column("patch").to_pylist()
    assert set(patch) == {"pad"} and len(patch) == 25  # pressed from frame 5 of 30
    assert "25 contact rows over 30 hand frames" in " ".join(result.output.split())
    total = wrenches.filter(pyarrow.compute.equal(wrenches.column("what"), "total"))
    assert total.num_rows == 30
    fz = np.asarray(total.column("force_x_n")) ** 2 + np.asarray(total.column("force_z_n")) ** 2
    assert (fz[5:] > 0).all() and (fz[:5] == 0).all()


def test_locate_csv_and_no_overwrite(run, tmp_path):
    out = tmp_path / "c.csv"
    wrenches = tmp_path / "w.csv"
    args = ["locate", str(run), "--out", str(out), "--wrenches", str(wrenches)]
    assert runner.invoke(app, args).exit_code == 0
    assert pyarrow.csv.read_csv(out).num_rows == 25
    assert pyarrow.csv.read_csv(wrenches).num_rows == 30 * 3  # link2, link3, total
    again = runner.invoke(app, args)
    assert again.exit_code == 2 and "exists" in again.output


def test_a_folder_read_block_by_block_equals_the_recording_in_memory(run):
    """Blocks of 7 hand frames read from the folder give the tables of the whole
    recording in memory, column for column (the held wrench carried across blocks)."""
    from tactsense.io.robot_recording import read_robot_recording
    from tactsense.robot_batch import locate_robot_recording

    joints = {"j1": 0.3}
    streamed = locate_robot_recording(run, joints=joints, block_frames=7)
    whole = locate_robot_recording(read_robot_recording(run), joints=joints)
    for table in ("contacts", "wrenches"):
        a, b = getattr(streamed, table), getattr(whole, table)
        assert a.keys() == b.keys()
        for key in a:
            np.testing.assert_array_equal(a[key], b[key], err_msg=key)


def _base_positions(path):
    table = pyarrow.parquet.read_table(path)
    return np.column_stack(
        [np.asarray(table.column(c)) for c in ("x_base_mm", "y_base_mm", "z_base_mm")]
    )


def test_locate_takes_the_recordings_own_joint_state(run, tmp_path):
    """Without a joint option, locate uses the joint state the recording carries (a
    simulation's, in its streams' scenario; or its joint_states.csv), not all zeros: the
    base-frame positions equal those of the same state given with --joints."""
    import shutil

    import h5py

    from tactsense.io.robot_recording import recorded_joint_state, stream_path

    explicit = tmp_path / "explicit.parquet"
    args = ["locate", str(run), "--joints", "j1=0.3,j2=-0.2", "--out", str(explicit)]
    assert runner.invoke(app, args).exit_code == 0
    zero = tmp_path / "zero.parquet"
    assert runner.invoke(app, ["locate", str(run), "--out", str(zero)]).exit_code == 0
    assert recorded_joint_state(run) == ("none", None)

    simulated = tmp_path / "simulated"
    shutil.copytree(run, simulated)
    with h5py.File(stream_path(simulated, "pad"), "r+") as h5:
        h5.attrs["scenario_json"] = '{"joints": {"j1": 0.3, "j2": -0.2}}'
    assert recorded_joint_state(simulated) == ("fixed", {"j1": 0.3, "j2": -0.2})
    own = tmp_path / "own.parquet"
    assert runner.invoke(app, ["locate", str(simulated), "--out", str(own)]).exit_code == 0
    np.testing.assert_allclose(_base_positions(own), _base_positions(explicit), atol=1e-9)
    assert np.abs(_base_positions(own) - _base_positions(zero)).max() > 1.0  # [mm]: it moved

    table = tmp_path / "table"
    shutil.copytree(run, table)
    (table / "joint_states.csv").write_text("time_s,j1,j2\n0,0.3,-0.2\n1,0.3,-0.2\n")
    assert recorded_joint_state(table)[0] == "csv"
    from_csv = tmp_path / "from_csv.parquet"
    assert runner.invoke(app, ["locate", str(table), "--out", str(from_csv)]).exit_code == 0
    np.testing.assert_allclose(_base_positions(from_csv), _base_positions(explicit), atol=1e-9)


# ---- round 7 fixes (r7-fixa) ----


@pytest.mark.parametrize("flag", ["--out", "--wrenches"])
@pytest.mark.parametrize("force", [False, True])
def test_an_output_never_replaces_the_joint_csv(run, tmp_path, flag, force):
    """Trial 36 item 1: the joint-state CSV is an input: --out or --wrenches naming it is
    refused, --force or not, and the file is left as it was."""
    joints = tmp_path / "j.csv"
    text = "time_s,j1\n0,0.1\n100,0.1\n"
    joints.write_text(text)
    outputs = {"--out": tmp_path / "c.csv", "--wrenches": tmp_path / "w.csv", flag: joints}
    args = ["locate", str(run), "--joints-csv", str(joints)]
    args += [part for name, path in outputs.items() for part in (name, str(path))]
    result = runner.invoke(app, args + (["--force"] if force else []))
    assert result.exit_code == 2, result.output
    assert "never replaces an input" in " ".join(result.output.split())
    assert joints.read_text() == text


def test_an_output_never_replaces_or_enters_the_joint_bag(run, tmp_path):
    """Trial 36 item 1, --joints-bag: a bag file named as --out, or an output inside a
    rosbag2 bag's folder, is refused before any work."""
    bag_file = tmp_path / "j.parquet"  # an MCAP file is known by its magic, not its name
    bag_file.write_bytes(b"\x89MCAP0\r\n")
    result = runner.invoke(app, ["locate", str(run), "--joints-bag", str(bag_file),
                                 "--out", str(bag_file), "--force"])  # fmt: skip
    assert result.exit_code == 2 and "never replaces an input" in result.output
    assert bag_file.read_bytes() == b"\x89MCAP0\r\n"
    folder = tmp_path / "bag"
    folder.mkdir()
    (folder / "metadata.yaml").write_text("")
    result = runner.invoke(app, ["locate", str(run), "--joints-bag", str(folder),
                                 "--out", str(folder / "c.parquet")])  # fmt: skip
    assert result.exit_code == 2
    assert "inside the input" in " ".join(result.output.split())


def test_the_closing_line_says_the_force_is_a_probes_once(run, tmp_path):
    """Trial 36 item 4: with contacts found, one note after the summary says the force is
    a 1.6-mm probe's amplitude and points to --method joint; not on every line."""
    out = tmp_path / "c.parquet"
    result = runner.invoke(app, ["locate", str(run), "--out", str(out)])
    assert result.exit_code == 0, result.output
    text = " ".join(result.output.split())
    assert text.count("1.6-mm probe") == 1 and "--method joint" in text


def test_locate_and_exports_contacts_share_frames_on_a_simulated_press(run):
    """docs/robot.md (trial 36 item 9): on a simulated press (no drift, no dead or
    saturated taxels) locate RUN/'s estimator and the exports' tracked one find contacts
    in the same frames of the pressed patch (their values are not claimed equal)."""
    from tactsense.interop.robot_contacts import iter_patch_contacts
    from tactsense.io.recording import RecordingReader
    from tactsense.io.robot_recording import read_robot_skin, stream_path
    from tactsense.robot_batch import locate_robot_recording

    hand = locate_robot_recording(run, joints={"j1": 0.0})
    skin = read_robot_skin(run)
    touched = 0
    for patch in skin.patches:
        with RecordingReader(stream_path(run, patch.name)) as reader:
            exported = sorted(
                {int(piece.start + f) for piece in iter_patch_contacts(reader, patch)
                 for f in piece.frame}
            )  # fmt: skip
        mine = hand.contacts["patch"] == patch.name
        assert sorted(set(hand.contacts["frame"][mine].tolist())) == exported, patch.name
        touched += len(exported)
    assert touched == 25  # the pad, pressed from frame 5 of 30
