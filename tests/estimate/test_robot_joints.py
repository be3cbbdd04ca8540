"""Joint states for the hand's estimator: --joints, a CSV, a JointState topic of a
rosbag2 bag, interpolated to the frames' times."""

from __future__ import annotations

import numpy as np
import pytest

from tactsense.estimate._robot_joints import (
    JointStateError,
    JointStates,
    parse_joints,
    read_joint_bag,
    read_joint_csv,
)
from tactsense.io._layout import Recording
from tactsense.io.robot_recording import RobotRecording
from tactsense.robot_batch import locate_robot_recording
from tactsense.simulate import ContactBatch, frames_from_contacts
from tests.estimate.test_robot_locate import independent_pose, small_skin


def test_parse_joints():
    assert parse_joints("j1=0.5, j2=-1e-1") == {"j1": 0.5, "j2": -0.1}


@pytest.mark.parametrize(
    "text, match",
    [("j1", "NAME=POSITION"), ("j1=abc", "NAME=POSITION"), ("=1", "NAME=POSITION"),
     ("j1=nan", "finite"), ("j1=1,j1=2", "twice"), (" , ", "empty")],
)  # fmt: skip
def test_parse_joints_refuses(text, match):
    with pytest.raises(JointStateError, match=match):
        parse_joints(text)


def test_csv_is_interpolated_linearly_and_held_at_the_ends(tmp_path):
    path = tmp_path / "joints.csv"
    path.write_text("time_s,j1,j3\n0.0,0.0,0.0\n1.0,1.0,0.01\n3.0,-1.0,0.02\n")
    states = read_joint_csv(path)
    got = states.at([-1.0, 0.25, 2.0, 5.0], ["j1", "j2", "j3"])
    # by hand: 0.25 of the way from 0 to 1; half way from 1 to -1; held outside; j2 absent: 0
    expected = [[0.0, 0, 0.0], [0.25, 0, 0.0025], [0.0, 0, 0.015], [-1.0, 0, 0.02]]
    np.testing.assert_allclose(got, expected, atol=1e-15)
    lines = states.coverage_warnings([-1.0, 0.5, 5.0])
    assert len(lines) == 2 and "2 hand frames outside" in lines[0]


@pytest.mark.parametrize(
    "text, match",
    [("", "empty"), ("t,j1\n0,1\n", "expected 'time_s'"), ("time_s\n0\n", "expected 'time_s'"),
     ("time_s,j1,j1\n0,1,2\n", "named twice"), ("time_s,j1\n0,x\n", "line 2: a cell is not"),
     ("time_s,j1\n0,1,3\n", "line 2: 3 cells"), ("time_s,j1\n", "no rows"),
     ("time_s,j1\n1,0\n0,1\n", "not strictly increasing"), ("time_s,j1\n0,inf\n", "non-finite")],
)  # fmt: skip
def test_csv_refuses(tmp_path, text, match):
    path = tmp_path / "joints.csv"
    path.write_text(text)
    with pytest.raises(JointStateError, match=match):
        read_joint_csv(path)


def test_check_against_the_skin():
    skin = small_skin()
    JointStates({"j1": ([0, 1], [0, 1])}).check(skin)
    with pytest.raises(JointStateError, match="'elbow' is not a movable joint"):
        JointStates({"elbow": ([0.0], [0.0])}, source="x.csv").check(skin)
    with pytest.raises(JointStateError, match=r"'j3' at 0.5 \(time 1.0 s\) is outside its limits"):
        JointStates({"j3": ([0.0, 1.0], [0.0, 0.5])}, source="x.csv").check(skin)


def _write_bag(path, samples):
    from rosbags.rosbag2 import Writer
    from rosbags.typesys import Stores, get_typestore

    store = get_typestore(Stores.ROS2_HUMBLE)
    joint_state = store.types["sensor_msgs/msg/JointState"]
    header = store.types["std_msgs/msg/Header"]
    stamp = store.types["builtin_interfaces/msg/Time"]
    with Writer(path, version=8) as writer:
        connection = writer.add_connection(
            "/joint_states", joint_state.__msgtype__, typestore=store
        )
        for time_s, names, positions in samples:
            message = joint_state(
                header=header(stamp=stamp(sec=int(time_s), nanosec=round(time_s % 1 * 1e9)),
                              frame_id=""),
                name=list(names), position=np.array(positions, float),
                velocity=np.zeros(0), effort=np.zeros(0),
            )  # fmt: skip
            writer.write(
                connection,
                int(time_s * 1e9),
                store.serialize_cdr(message, joint_state.__msgtype__),
            )


def test_joint_topic_of_a_bag(tmp_path):
    """A JointState topic written with rosbags' own writer reads back per joint (a joint
    missing from a message keeps its own samples)."""
    bag = tmp_path / "bag"
    _write_bag(bag, [(1.0, ["j1", "j2"], [0.1, 0.2]), (1.5, ["j1"], [0.3]),
                     (2.0, ["j1", "j2"], [0.5, 0.6])])  # fmt: skip
    states = read_joint_bag(bag)
    np.testing.assert_allclose(states.series["j1"][0], [1.0, 1.5, 2.0])
    np.testing.assert_allclose(states.series["j1"][1], [0.1, 0.3, 0.5])
    np.testing.assert_allclose(states.series["j2"][0], [1.0, 2.0])
    np.testing.assert_allclose(states.at([1.25], ["j1", "j2"]), [[0.2, 0.3]])
    with pytest.raises(JointStateError, match="no JointState topic '/other'"):
        read_joint_bag(bag, "/other")
    with pytest.raises(JointStateError, match="not a rosbag2 bag"):
        read_joint_bag(tmp_path)


def test_recording_follows_the_joint_csv(tmp_path):
    """A pad pressed at one place while j1 turns from 0 to 1 rad (a CSV of two rows): each
    contact's base-frame point is the independent chain's at j1 interpolated to its
    frame's time, to within the estimator's sensor-frame point (1e-9 mm)."""
    skin = small_skin()
    rng = np.random.default_rng(4)
    streams = {}
    for patch in skin.patches:
        force = np.zeros((30, 1))
        position = np.zeros((30, 1, 2))
        if patch.name == "pad":
            force[5:] = 1.0
            position[:] = 15.0
        frames = frames_from_contacts(patch.sensor, ContactBatch(position, force), rng=rng)
        streams[patch.name] = Recording(
            frames=frames.reshape(30, *patch.sensor.shape), time_s=np.arange(30) * 0.01,
            sample_offset_s=np.zeros(patch.sensor.shape), sensor=patch.sensor,
        )  # fmt: skip
    path = tmp_path / "joints.csv"
    path.write_text("time_s,j1\n0.0,0.0\n0.29,1.0\n")
    states = read_joint_csv(path)
    result = locate_robot_recording(RobotRecording(skin=skin, streams=streams), joints=states)
    c = result.contacts
    assert (c["patch"] == "pad").sum() == 25
    for k in range(len(c["frame"])):
        q1 = c["time_s"][k] / 0.29
        pose, _ = independent_pose((q1, 0.0, 0.0))
        sensor = np.array([c["x_mm"][k], c["y_mm"][k], c["z_mm"][k]]) * 1e-3
        expected = (pose[:3, :3] @ sensor + pose[:3, 3]) * 1e3
        got = np.array([c[f"{a}_base_mm"][k] for a in "xyz"])
        np.testing.assert_allclose(got, expected, atol=1e-9)


JOINT_STATE_MSGDEF = """std_msgs/Header header
string[] name
float64[] position
float64[] velocity
float64[] effort
================================================================================
MSG: std_msgs/Header
builtin_interfaces/Time stamp
string frame_id
================================================================================
MSG: builtin_interfaces/Time
int32 sec
uint32 nanosec
"""  # sensor_msgs/msg/JointState as ROS 2 defines it, with its dependencies


def test_joint_topic_of_a_plain_mcap_file(tmp_path):
    """A bare MCAP file (no rosbag2 metadata) written with mcap_ros2's writer; the stamp
    of zero takes the log time."""
    from mcap_ros2.writer import Writer

    path = tmp_path / "joints.mcap"
    with open(path, "wb") as stream:
        writer = Writer(stream)
        schema = writer.register_msgdef("sensor_msgs/msg/JointState", JOINT_STATE_MSGDEF)
        for sec, log_ns, position in ((3, 0, 0.25), (0, 4_500_000_000, 0.75)):
            header = {"stamp": {"sec": sec, "nanosec": 0}, "frame_id": ""}
            message = {"header": header, "name": ["j1"], "position": [position],
                       "velocity": [], "effort": []}  # fmt: skip
            writer.write_message("/joint_states", schema, message, log_time=log_ns)
        writer.finish()
    states = read_joint_bag(path)
    np.testing.assert_allclose(states.series["j1"][0], [3.0, 4.5])
    np.testing.assert_allclose(states.at([3.75], ["j1"]), [[0.5]])
    with pytest.raises(JointStateError, match="no JointState topic '/x'"):
        read_joint_bag(path, "/x")


# ---- round 7 fixes (r7-fixa) ----


def test_a_readable_mcap_without_a_joint_topic_says_so_not_unreadable(tmp_path):
    """Trial 36 item 10b: a readable MCAP with no JointState topic is not 'not a readable
    MCAP file'; the message names what it lacks."""
    from mcap_ros2.writer import Writer

    path = tmp_path / "other.mcap"
    with open(path, "wb") as stream:
        writer = Writer(stream)
        schema = writer.register_msgdef("std_msgs/msg/String", "string data\n")
        writer.write_message("/chat", schema, {"data": "hi"}, log_time=1)
        writer.finish()
    with pytest.raises(JointStateError) as caught:
        read_joint_bag(path)
    message = str(caught.value)
    assert "not a readable" not in message
    assert "0 JointState topics (none)" in message


def test_coverage_warning_says_the_recordings_clock(tmp_path):
    """Trial 36 item 14: joint times from 0 against a capture's Unix-second frames: the
    warning says the recording's span and that a capture's times are Unix seconds."""
    path = tmp_path / "joints.csv"
    path.write_text("time_s,j1\n0.0,0.0\n0.3,0.1\n")
    states = read_joint_csv(path)
    capture = states.coverage_warnings([1.7e9, 1.7e9 + 1.0])
    assert len(capture) == 1
    assert "span [1.7e+09, 1.7e+09] s" in capture[0]
    assert "Unix seconds on the host clock" in capture[0]
    simulation = states.coverage_warnings([0.1, 2.0])
    assert "from 0" in simulation[0] and "Unix" not in simulation[0]
