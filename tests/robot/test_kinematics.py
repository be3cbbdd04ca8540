"""Forward kinematics of a skin, checked against closed forms and an independent reader.

Reference values: a planar two-link arm's closed form (written out by hand), scipy's
Euler-angle rotations for URDF's roll-pitch-yaw, and yourdfpy's forward kinematics of the
URDF tactsense writes (an independent implementation of URDF's joint semantics).
"""

import math

import numpy as np
import pytest
import yourdfpy
from scipy.spatial.transform import Rotation

from tactsense.interop.robot_urdf import robot_skin_to_urdf
from tactsense.robot import (
    Joint,
    Patch,
    Pose,
    RobotSkin,
    RobotSkinError,
    rotation_matrix,
    rpy_from_matrix,
    skin_preset,
)
from tactsense.sensor import preset

L1, L2 = 0.05, 0.03


def _arm(extra_joints=(), extra_links=()):
    """A planar arm: base -> (revolute z) upper -> at L1 (revolute z) fore; a pad4 at L2."""
    joints = (
        Joint("shoulder", "revolute", "base", "upper", axis=(0, 0, 1), lower=-3, upper=3),
        Joint("elbow", "revolute", "upper", "fore", Pose((L1, 0, 0)), (0, 0, 1), lower=-3, upper=3),
        *extra_joints,
    )
    return RobotSkin(
        name="arm",
        base_link="base",
        links=("base", "upper", "fore", *extra_links),
        joints=joints,
        patches=(Patch("pad", preset("pad4"), "fore", Pose((L2, 0, 0))),),
    )


@pytest.mark.parametrize("q1, q2", [(0.0, 0.0), (0.3, -1.1), (-2.5, 2.9), (math.pi / 2, 0.0)])
def test_planar_two_link_arm_matches_its_closed_form(q1, q2):
    skin = _arm()
    pose = skin.patch_pose("pad", {"shoulder": q1, "elbow": q2})
    # closed form of the planar arm: the pad's origin and its x axis
    x = L1 * math.cos(q1) + L2 * math.cos(q1 + q2)
    y = L1 * math.sin(q1) + L2 * math.sin(q1 + q2)
    np.testing.assert_allclose(pose[:3, 3], [x, y, 0.0], atol=1e-15)
    np.testing.assert_allclose(pose[:3, 0], [math.cos(q1 + q2), math.sin(q1 + q2), 0], atol=1e-15)
    # the pad's taxel (row 1, col 0) sits 5 mm along the pad's x
    positions, normals = skin.taxels_in_base({"shoulder": q1, "elbow": q2})["pad"]
    np.testing.assert_allclose(positions[4], pose[:3, 3] + 0.005 * pose[:3, 0], atol=1e-15)
    np.testing.assert_allclose(normals, np.tile([0.0, 0.0, 1.0], (16, 1)), atol=1e-15)


def test_prismatic_and_fixed_joints_move_as_urdf_defines():
    slide = Joint(
        "slide", "prismatic", "fore", "carriage", Pose((0.01, 0, 0), (0, 0, math.pi / 2)),
        (1, 0, 0), lower=0.0, upper=0.1,
    )  # fmt: skip
    tip = Joint("bolt", "fixed", "carriage", "tip", Pose((0, 0.02, 0)))
    skin = _arm((slide, tip), ("carriage", "tip"))
    poses = skin.link_poses({"shoulder": 0.0, "elbow": 0.0, "slide": 0.04})
    # the carriage frame is turned 90 deg about z: its x (the slide's axis) is the base's y
    np.testing.assert_allclose(poses["carriage"][:3, 3], [L1 + 0.01, 0.04, 0.0], atol=1e-15)
    # the fixed tip is 20 mm along the carriage's y = the base's -x
    np.testing.assert_allclose(poses["tip"][:3, 3], [L1 + 0.01 - 0.02, 0.04, 0.0], atol=1e-15)


def test_rpy_is_urdf_fixed_axis_roll_pitch_yaw_and_inverts():
    rng = np.random.default_rng(3)
    for _ in range(200):
        rpy = rng.uniform([-math.pi, -1.5, -math.pi], [math.pi, 1.5, math.pi])
        expected = Rotation.from_euler("xyz", rpy).as_matrix()  # extrinsic x, y, z
        np.testing.assert_allclose(rotation_matrix(tuple(rpy)), expected, atol=1e-14)
        np.testing.assert_allclose(rpy_from_matrix(expected), rpy, atol=1e-9)
    locked = rotation_matrix((0.3, math.pi / 2, -0.4))  # gimbal lock: the same rotation
    np.testing.assert_allclose(rotation_matrix(rpy_from_matrix(locked)), locked, atol=1e-12)


def _random_state(skin, rng):
    state = {}
    for joint in skin.joints:
        if joint.type == "fixed":
            continue
        low = joint.lower if math.isfinite(joint.lower) else -math.pi
        high = joint.upper if math.isfinite(joint.upper) else math.pi
        state[joint.name] = float(rng.uniform(low, high))
    return state


@pytest.mark.parametrize("name", ["hand4", "icub_hand"])
def test_forward_kinematics_equal_yourdfpys(tmp_path, name):
    """yourdfpy reads the URDF we write and computes every link's pose itself: equal to
    ours within 1e-12 m / 1e-12 (the URDF carries every number in full, repr)."""
    skin = skin_preset(name)
    path = tmp_path / f"{name}.urdf"
    path.write_text(robot_skin_to_urdf(skin))
    robot = yourdfpy.URDF.load(str(path), load_meshes=False, build_collision_scene_graph=False)
    assert set(robot.link_map) == set(skin.links)
    assert set(robot.joint_map) == {j.name for j in skin.joints}
    rng = np.random.default_rng(7)
    for _ in range(20):
        state = _random_state(skin, rng)
        robot.update_cfg(state)
        ours = skin.link_poses(state)
        for link in skin.links:
            theirs = robot.get_transform(frame_to=link, frame_from=skin.base_link)
            np.testing.assert_allclose(ours[link], theirs, atol=1e-12, err_msg=link)


def test_taxels_in_base_are_the_patch_pose_applied_to_the_sensor_frame():
    skin = skin_preset("hand4")
    state = _random_state(skin, np.random.default_rng(1))
    placed = skin.taxels_in_base(state)
    for patch in skin.patches:
        pose = skin.patch_pose(patch.name, state)
        local = np.asarray(patch.sensor.taxel_positions_mm()) * 1e-3
        np.testing.assert_allclose(placed[patch.name][0], local @ pose[:3, :3].T + pose[:3, 3])
        np.testing.assert_allclose(
            placed[patch.name][1], np.asarray(patch.sensor.taxel_normals()) @ pose[:3, :3].T
        )


@pytest.mark.parametrize(
    "state, message",
    [
        ({"wrist": 0.1}, "not a movable joint"),
        ({"shoulder": 4.0}, "outside its limits"),
        ({"shoulder": float("nan")}, "outside its limits"),
    ],
)
def test_bad_joint_states_are_refused(state, message):
    with pytest.raises(RobotSkinError, match=message):
        _arm().link_poses(state)


@pytest.mark.parametrize("seed", range(5))
def test_random_trees_agree_with_yourdfpy(tmp_path, seed):
    """Random trees (every joint type, random origins, axes, limits) against yourdfpy."""
    rng = np.random.default_rng(seed)
    links, joints = ["l0"], []
    for i in range(1, 12):
        kind = ("fixed", "revolute", "continuous", "prismatic")[int(rng.integers(4))]
        low = float(rng.uniform(-2, 0))
        joints.append(
            Joint(
                f"j{i}",
                kind,
                links[int(rng.integers(len(links)))],
                f"l{i}",
                Pose(tuple(rng.uniform(-0.1, 0.1, 3)), tuple(rng.uniform(-3, 3, 3))),
                tuple(rng.normal(size=3)),
                lower=low if kind in ("revolute", "prismatic") else -math.inf,
                upper=low + 2.5 if kind in ("revolute", "prismatic") else math.inf,
            )
        )
        links.append(f"l{i}")
    skin = RobotSkin(
        name="random",
        base_link="l0",
        links=tuple(links),
        joints=tuple(joints),
        patches=(Patch("pad", preset("pad4"), links[-1]),),
    )
    path = tmp_path / "random.urdf"
    path.write_text(robot_skin_to_urdf(skin))
    robot = yourdfpy.URDF.load(str(path), load_meshes=False, build_collision_scene_graph=False)
    for _ in range(10):
        state = _random_state(skin, rng)
        robot.update_cfg(state)
        ours = skin.link_poses(state)
        for link in links:
            theirs = robot.get_transform(frame_to=link, frame_from="l0")
            np.testing.assert_allclose(ours[link], theirs, atol=1e-12, err_msg=link)
