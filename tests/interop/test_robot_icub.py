"""Real data: an iCub grasp trial (tests/data/icub_grasp, Copyright 2012 Harold Soh; its
licence in LICENSE_AND_README_upstream.txt) imported as ONE hand (tactsense.interop.
robot_icub): frames equal the file's lines, read here with plain string splitting."""

from __future__ import annotations

import csv
import re
import tarfile
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from tactsense.cli import app
from tactsense.interop.robot_icub import ICUB_ENCODERS, encoder_joints
from tactsense.io.robot_recording import read_robot_recording
from tactsense.robot import Joint, Patch, Pose, RobotSkin, skin_preset, skin_to_toml_string
from tactsense.sensor import preset

ROOT = Path(__file__).resolve().parents[2]
DATA = ROOT / "tests" / "data" / "icub_grasp" / "iCubGraspDataset.tar.xz"
FINGERS = ("thumb", "index", "middle", "ring", "little")
runner = CliRunner()


@pytest.fixture(scope="module")
def trials(tmp_path_factory):
    folder = tmp_path_factory.mktemp("icub")
    wanted = {"book_8.txt", "none_3.txt"}
    with tarfile.open(DATA) as tar:
        for member in tar.getmembers():
            if member.isfile() and Path(member.name).name in wanted:
                (folder / Path(member.name).name).write_bytes(tar.extractfile(member).read())
    return folder


def _by_hand(path: Path):
    """The file's slices: encoders (T, 9) and taxels (T, 5, 12), by plain splitting."""
    lines = [line.split() for line in path.read_text().splitlines() if line.strip()][1:]
    slices = [lines[k : k + 7] for k in range(0, len(lines), 7)]
    encoders = np.array([[float(x) for x in s[0]] for s in slices])
    taxels = np.array([[[float(x) for x in line] for line in s[2:7]] for s in slices])
    return encoders, taxels


def icub_like_skin() -> RobotSkin:
    """The five fingertips on a hand with icub-models' joint names (four revolute joints
    a finger, ``r_hand_<finger>_<k>_joint``), written here rather than taken from the
    preset, limits wide enough for every encoder angle."""
    tip = preset("icub_fingertip")
    links, joints, patches = ["r_hand"], [], []
    for finger in FINGERS:
        parent = "r_hand"
        for k in range(4):
            link = f"r_hand_{finger}_{k}"
            links.append(link)
            joints.append(
                Joint(name=f"{link}_joint", type="revolute", parent=parent, child=link,
                      origin=Pose((0.02, 0.0, 0.0)), axis=(0, 0, 1), lower=-4.0, upper=4.0)
            )  # fmt: skip
            parent = link
        patches.append(Patch(name=f"{finger}_tip", sensor=tip, link=parent, device="skin"))
    return RobotSkin(
        name="icub_like", base_link="r_hand", links=tuple(links), joints=tuple(joints),
        patches=tuple(patches),
    )  # fmt: skip


@pytest.mark.parametrize("name", ["book_8.txt", "none_3.txt"])
def test_a_trial_imports_as_one_hand(trials, tmp_path, name):
    skin_file = tmp_path / "icub_like.toml"
    skin_file.write_text(skin_to_toml_string(icub_like_skin()))
    out = tmp_path / "hand"
    result = runner.invoke(
        app, ["import", str(trials / name), "--skin", str(skin_file), "--out", str(out)]
    )
    assert result.exit_code == 0, result.output
    encoders, taxels = _by_hand(trials / name)
    recording = read_robot_recording(out)
    assert sorted(recording.streams) == sorted(f"{f}_tip" for f in FINGERS)
    for k, finger in enumerate(FINGERS):
        stream = recording.streams[f"{finger}_tip"]
        np.testing.assert_array_equal(stream.frames.reshape(-1, 12), taxels[:, k, :])
        np.testing.assert_array_equal(stream.time_s, np.arange(len(taxels)))
    # counts printed = counts kept = the file's taxel lines
    printed = re.search(r"\((\d+) taxel lines read, (\d+) frames kept\)", result.output)
    assert printed is not None, result.output
    kept = sum(len(s) for s in recording.streams.values())
    assert int(printed[1]) == int(printed[2]) == kept == taxels.shape[0] * 5
    assert f"{len(taxels)} slices of 5 fingertips" in result.output
    # the encoders kept whole [deg]; the joints they drive as joint states [rad]
    with open(out / "icub_encoders.csv") as stream:
        rows = list(csv.reader(stream))
    assert rows[0] == ["time_s", *(f"{e}_deg" for e in ICUB_ENCODERS)]
    np.testing.assert_array_equal(np.array(rows[1:], float)[:, 1:], encoders)
    with open(out / "joint_states.csv") as stream:
        rows = list(csv.reader(stream))
    values = np.array(rows[1:], float)
    column = {name: j for j, name in enumerate(rows[0])}

    def joint(name):
        return values[:, column[f"r_hand_{name}_joint"]]

    # iCub's joints 8-15 (columns 1-8 of the encoders): oppose, proximal, distal (halved
    # over two joints), ..., pinky (a third to each of six joints)
    np.testing.assert_allclose(joint("thumb_0"), np.deg2rad(encoders[:, 1]))
    np.testing.assert_allclose(joint("thumb_1"), np.deg2rad(encoders[:, 2]))
    np.testing.assert_allclose(joint("thumb_2") + joint("thumb_3"), np.deg2rad(encoders[:, 3]))
    np.testing.assert_allclose(joint("index_1"), np.deg2rad(encoders[:, 4]))
    np.testing.assert_allclose(joint("index_3"), np.deg2rad(encoders[:, 5]) / 2)
    np.testing.assert_allclose(joint("middle_1"), np.deg2rad(encoders[:, 6]))
    np.testing.assert_allclose(joint("middle_2"), np.deg2rad(encoders[:, 7]) / 2)
    for k in (1, 2, 3):
        np.testing.assert_allclose(joint(f"ring_{k}"), np.deg2rad(encoders[:, 8]) / 3)
        np.testing.assert_allclose(joint(f"little_{k}"), np.deg2rad(encoders[:, 8]) / 3)
    assert "r_hand_index_0_joint" not in column  # hand_finger: not mapped
    assert len(column) == 1 + 16  # time, thumb 0-3, and joints 1-3 of the four fingers


def test_encoder_mapping_by_joint_names():
    """A left hand's joints are found too; a skin without iCub's joints maps none."""
    tip = preset("icub_fingertip")
    joints = tuple(
        Joint(name=f"l_hand_{name}_joint", type="revolute", parent="hand", child=f"l{k}",
              axis=(0, 0, 1), lower=-3, upper=3)
        for k, name in enumerate(("thumb_0", "index_2", "little_3"))
    )  # fmt: skip
    skin = RobotSkin(
        name="t", base_link="hand", links=("hand", "l0", "l1", "l2"), joints=joints,
        patches=(Patch(name="p", sensor=tip, link="l0"),),
    )  # fmt: skip
    assert encoder_joints(skin) == {
        "thumb_oppose": [("l_hand_thumb_0_joint", 1.0)],
        "index_distal": [("l_hand_index_2_joint", 0.5)],
        "pinky": [("l_hand_little_3_joint", pytest.approx(1 / 3))],
    }
    assert encoder_joints(skin_preset("hand4")) == {}


def test_a_skin_without_the_fingertips_is_refused(trials, tmp_path):
    result = runner.invoke(
        app, ["import", str(trials / "book_8.txt"), "--skin", "hand4", "--out",
              str(tmp_path / "h")],
    )  # fmt: skip
    assert result.exit_code == 2
    assert "no patch" in result.output and "little_tip" in result.output
    assert not (tmp_path / "h").exists()
