"""The hand's estimator (tactsense.estimate.robot): the compiled whole-skin path against
the per-patch estimator, contacts in the base frame against an independent forward
kinematics, wrenches by hand, recordings at several rates."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from tactsense._validation import TactsenseInputError
from tactsense.estimate.robot import (
    CONTACT_COLUMNS,
    WRENCH_COLUMNS,
    HandLocator,
    hand_frame_grid,
    locate_robot_reference,
)
from tactsense.io._layout import Recording
from tactsense.io.robot_recording import RobotRecording
from tactsense.robot import Joint, Patch, Pose, RobotSkin, RobotSkinError, skin_preset
from tactsense.robot_batch import locate_robot_recording
from tactsense.sensor import preset
from tactsense.simulate import ContactBatch, frames_from_contacts
from tests.estimate._robot_sim import hand_frames


def small_skin() -> RobotSkin:
    """A three-link chain (revolute z, revolute about a tilted y, prismatic x) with a
    16 x 16 pad on the second link and a 12-taxel dome on the third."""
    return RobotSkin(
        name="chain",
        base_link="base",
        links=("base", "link1", "link2", "link3"),
        joints=(
            Joint("j1", "revolute", "base", "link1", Pose((0.05, 0.0, 0.0)), (0, 0, 1), -2, 2),
            Joint(
                "j2",
                "revolute",
                "link1",
                "link2",
                Pose((0.04, 0, 0.01), (0.1, 0, 0)),
                (0, 1, 0),
                -2,
                2,
            ),
            Joint("j3", "prismatic", "link2", "link3", Pose((0.03, 0, 0)), (1, 0, 0), 0, 0.02),
        ),
        patches=(
            Patch("pad", preset("pad16"), "link2", Pose((0.01, 0.002, 0.005), (math.pi, 0.2, 0.3))),
            Patch("dome", preset("dome12"), "link3", Pose((0.0, 0.0, 0.004), (0.0, 0.3, 0.0))),
        ),
    )


def independent_pose(q):
    """The pad's and dome's sensor frames in the base frame, chained by hand with
    scipy's rotations (URDF: origin's fixed-axis rpy = intrinsic z-y'-x'', i.e. extrinsic
    'xyz'; a revolute joint's motion a rotation vector about its axis)."""

    def h(xyz=(0, 0, 0), rpy=(0, 0, 0), rotvec=(0, 0, 0)):
        out = np.eye(4)
        out[:3, :3] = (Rotation.from_euler("xyz", rpy) * Rotation.from_rotvec(rotvec)).as_matrix()
        out[:3, 3] = xyz
        return out

    link1 = h((0.05, 0, 0), rotvec=(0, 0, q[0]))
    link2 = link1 @ h((0.04, 0, 0.01), (0.1, 0, 0)) @ h(rotvec=(0, q[1], 0))
    link3 = link2 @ h((0.03 + q[2], 0, 0))
    return link2 @ h((0.01, 0.002, 0.005), (math.pi, 0.2, 0.3)), link3 @ h(
        (0, 0, 0.004), (0, 0.3, 0)
    )


def rest_baselines(skin, rng):
    out = {}
    for patch in skin.patches:
        rest = frames_from_contacts(
            patch.sensor, ContactBatch(np.zeros((5, 1, 2)), np.zeros((5, 1))), rng=rng
        )
        out[patch.name] = np.median(rest, axis=0).reshape(patch.sensor.shape)
    return out


@pytest.mark.parametrize("name", ["hand4", "icub_hand"])
def test_fast_path_equals_the_per_patch_estimator(name):
    """The compiled whole-skin call finds the contacts find_contacts finds on each patch
    (same patches, frames and ranks) at the same places and forces: both run the same
    arithmetic, so to rounding (1e-9 mm, 1e-9 N)."""
    skin = skin_preset(name)
    sim = hand_frames(skin, 60, seed=3)
    frames = {k: v[0] for k, v in sim.items()}
    baselines = {k: v[1] for k, v in sim.items()}
    joints = {skin.movable_joints[0]: 0.3, skin.movable_joints[-1]: 0.5}
    locator = HandLocator(skin, baselines)
    fast = locator.locate(locator.pack(frames), joints).contacts
    reference = locate_robot_reference(skin, frames, baselines, joints=joints)
    assert len(reference["frame"]) > 60  # the simulation touched many patches
    key = lambda f, p, c: (int(f), str(p), int(c))  # noqa: E731
    mine = {
        key(*row): i
        for i, row in enumerate(zip(fast["frame"], fast["patch"], fast["contact"], strict=True))
    }
    theirs = [
        key(*row)
        for row in zip(reference["frame"], reference["patch"], reference["contact"], strict=True)
    ]
    assert set(mine) == set(theirs)
    order = np.array([mine[k] for k in theirs])
    base = np.column_stack([fast[f"{a}_base_mm"] for a in "xyz"])[order]
    link = np.column_stack([fast[f"{a}_link_mm"] for a in "xyz"])[order]
    np.testing.assert_allclose(base, reference["base_xyz"], atol=1e-9)
    np.testing.assert_allclose(link, reference["link_xyz"], atol=1e-9)
    np.testing.assert_allclose(fast["force_n"][order], reference["force_n"], atol=1e-9)
    assert set(fast) == set(CONTACT_COLUMNS)


def test_a_contact_comes_back_where_it_was_pressed_in_the_base_frame():
    """A contact simulated on the pad of a chain at a known joint state: its base-frame
    point equals the independent chain (scipy rotations) applied to the estimator's own
    sensor-frame point to 1e-9 mm, and lies within 1 mm of the pressed place (0.4 of the
    2.5-mm pitch: the single-array estimator's own error with the pad's flaws, gain
    spread and read noise, reached 0.63 mm on these three), with the normal the pad's z
    axis in the base frame."""
    skin = small_skin()
    rng = np.random.default_rng(7)
    baselines = rest_baselines(skin, rng)
    locator = HandLocator(skin, baselines)
    q = (0.7, -0.4, 0.015)
    truth = np.array([[[14.3, 20.6]], [[22.8, 9.1]], [[7.4, 30.2]]])
    pad = skin.patch("pad")
    counts = frames_from_contacts(pad.sensor, ContactBatch(truth, np.full((3, 1), 1.2)), rng=rng)
    frames = {"pad": counts, "dome": np.tile(baselines["dome"].ravel(), (3, 1))}
    result = locator.locate(locator.pack(frames), {"j1": q[0], "j2": q[1], "j3": q[2]}).contacts
    assert list(result["patch"]) == ["pad"] * 3
    pose_pad, _ = independent_pose(q)
    sensor = np.column_stack([result["x_mm"], result["y_mm"], result["z_mm"]]) * 1e-3
    expected = (sensor @ pose_pad[:3, :3].T + pose_pad[:3, 3]) * 1e3
    base = np.column_stack([result[f"{a}_base_mm"] for a in "xyz"])
    np.testing.assert_allclose(base, expected, atol=1e-9)
    pressed = np.column_stack([truth[:, 0], np.zeros(3)]) * 1e-3
    pressed = (pressed @ pose_pad[:3, :3].T + pose_pad[:3, 3]) * 1e3
    assert np.linalg.norm(base - pressed, axis=1).max() < 1.0
    normal = np.column_stack([result[f"n{a}_base"] for a in "xyz"])
    np.testing.assert_allclose(normal, np.tile(pose_pad[:3, 2], (3, 1)), atol=1e-12)
    force = np.column_stack([result[f"f{a}_base_n"] for a in "xyz"])
    np.testing.assert_allclose(force, -result["force_n"][:, None] * normal, atol=1e-12)


def test_link_poses_equal_the_independent_chain():
    """The compiled forward kinematics against scipy's rotations chained by hand, at
    random joint states (through the dome's contacts' frame: its sensor pose)."""
    from tactsense.estimate._robot_kernel import link_poses_into

    skin = small_skin()
    locator = HandLocator(skin, rest_baselines(skin, np.random.default_rng(0)))
    rng = np.random.default_rng(11)
    for _ in range(20):
        q = np.array([rng.uniform(-2, 2), rng.uniform(-2, 2), rng.uniform(0, 0.02)])
        poses = np.empty((4, 4, 4))
        link_poses_into(q, locator._parent, locator._jtype, locator._origin, locator._axis,
                        locator._column, poses)  # fmt: skip
        pad, dome = independent_pose(q)
        links = list(locator.links)
        np.testing.assert_allclose(poses[links.index("link2")] @ skin.patch("pad").origin.matrix(),
                                   pad, atol=1e-12)  # fmt: skip
        np.testing.assert_allclose(
            poses[links.index("link3")] @ skin.patch("dome").origin.matrix(), dome, atol=1e-12
        )


def test_wrench_is_the_sum_of_r_cross_f_by_hand():
    """Two contacts on the pad of link2: the link's wrench is sum(r x F) about its origin
    with r the contacts' link-frame points and F = -f n; written out by hand (the pad
    frame's z axis is n), and the grasp's total is that wrench moved to the base."""
    skin = small_skin()
    rng = np.random.default_rng(5)
    baselines = rest_baselines(skin, rng)
    locator = HandLocator(skin, baselines)
    pad = skin.patch("pad")
    truth = np.array([[[8.0, 9.0], [27.0, 26.0]]])
    counts = frames_from_contacts(pad.sensor, ContactBatch(truth, np.array([[0.8, 1.5]])), rng=rng)
    frames = {"pad": counts, "dome": baselines["dome"].reshape(1, 1, -1)}
    q = {"j1": 0.3, "j2": 0.9, "j3": 0.01}
    out = locator.locate(locator.pack(frames), q)
    c, w = out.contacts, out.wrenches
    assert len(c["frame"]) == 2
    n = pad.origin.matrix()[:3, 2]  # the pad's normal in link2's frame
    torque = np.zeros(3)
    force = np.zeros(3)
    for k in range(2):
        r = np.array([c["x_link_mm"][k], c["y_link_mm"][k], c["z_link_mm"][k]])
        f = -c["force_n"][k] * n
        force += f
        torque += [r[1] * f[2] - r[2] * f[1], r[2] * f[0] - r[0] * f[2], r[0] * f[1] - r[1] * f[0]]
    row = list(w["link"]).index("link2")
    assert w["what"][row] == "link" and w["contacts"][row] == 2
    got = np.array([w[name][row] for name in WRENCH_COLUMNS[5:]])
    np.testing.assert_allclose(got[:3], force, atol=1e-12)
    np.testing.assert_allclose(got[3:], torque, atol=1e-9)
    total = list(w["what"]).index("total")
    pose = skin.link_poses(q)["link2"]
    rotation, origin = pose[:3, :3], pose[:3, 3] * 1e3
    f_base = rotation @ force
    t_base = rotation @ torque + np.cross(origin, f_base)
    got = np.array([w[name][total] for name in WRENCH_COLUMNS[5:]])
    np.testing.assert_allclose(got, np.concatenate([f_base, t_base]), atol=1e-9)


def test_recording_at_several_rates_holds_each_patch_own_frames():
    """A pad at 100 Hz and a dome at 40 Hz: hand frames at the pad's frames, the dome's
    contacts written once per frame of its own (at its time), its wrench held between."""
    skin = small_skin()
    rng = np.random.default_rng(2)
    streams = {}
    n = {"pad": 50, "dome": 20}
    period = {"pad": 0.01, "dome": 0.025}
    for patch in skin.patches:
        touched = np.zeros((n[patch.name], 1))
        touched[10:] = 1.0
        position = np.zeros((n[patch.name], 1, 2))
        if patch.name == "pad":
            position[:] = 12.0
        frames = frames_from_contacts(patch.sensor, ContactBatch(position, touched), rng=rng)
        streams[patch.name] = Recording(
            frames=frames.reshape(-1, *patch.sensor.shape),
            time_s=np.arange(n[patch.name]) * period[patch.name],
            sample_offset_s=np.zeros(patch.sensor.shape),
            sensor=patch.sensor,
        )
    recording = RobotRecording(skin=skin, streams=streams)
    result = locate_robot_recording(recording, joints={"j1": 0.2})
    c, w = result.contacts, result.wrenches
    assert result.n_frames == 50
    dome = c["patch"] == "dome"
    dome_times = c["time_s"][dome]
    assert len(np.unique(dome_times)) == dome.sum() == 10  # frames 10-19 of the dome
    np.testing.assert_array_equal(np.sort(dome_times), np.arange(10, 20) * 0.025)
    # ... each at the first hand frame (pad frame) at or after the dome frame's time
    hand_time = np.arange(50) * 0.01
    first_after = np.searchsorted(hand_time, np.arange(10, 20) * 0.025, side="left")
    np.testing.assert_array_equal(np.sort(c["frame"][dome]), first_after)
    link3 = w["link"] == "link3"
    fz = w["force_z_n"][link3]
    changes = np.flatnonzero(np.diff(fz) != 0) + 1
    assert len(changes) > 3 and set(changes) <= set(first_after)  # held between its frames
    assert set(w) == set(WRENCH_COLUMNS)
    assert result.contacts_table().num_rows == len(c["frame"])


def test_hand_frame_grid_latest_frame_at_or_before():
    times, index, fresh = hand_frame_grid(
        {"a": np.array([0.0, 0.1, 0.2, 0.3]), "b": np.array([0.05, 0.25])}, ["a", "b"]
    )
    np.testing.assert_array_equal(times, [0.0, 0.1, 0.2, 0.3])
    np.testing.assert_array_equal(index[:, 1], [-1, 0, 0, 1])
    np.testing.assert_array_equal(fresh[:, 1], [False, True, False, True])


def test_bad_joint_names_and_values_give_clear_errors():
    skin = small_skin()
    locator = HandLocator(skin, rest_baselines(skin, np.random.default_rng(0)))
    frame = np.tile(locator._baseline, (1, 1))
    with pytest.raises(RobotSkinError, match="not a movable joint"):
        locator.locate(frame, {"elbow": 0.1})
    with pytest.raises(RobotSkinError, match="outside its limits"):
        locator.locate(frame, {"j3": 0.5})
    with pytest.raises(RobotSkinError, match="outside its limits"):
        locator.locate(frame, {"j1": float("nan")})


def test_update_takes_one_device_frame_and_holds_the_others():
    """Live: a frame of the pad alone gives the pad's contacts (as a whole hand frame
    would); a frame of the dome next leaves the pad's wrench on link2 as it was."""
    skin = small_skin()
    rng = np.random.default_rng(8)
    baselines = rest_baselines(skin, rng)
    locator = HandLocator(skin, baselines)
    pad = skin.patch("pad")
    counts = frames_from_contacts(pad.sensor, ContactBatch([[[12.0, 14.0]]], [[1.0]]), rng=rng)
    first = locator.update({"pad": counts.reshape(pad.sensor.shape)}, {"j1": 0.2})
    whole = HandLocator(skin, baselines).locate(
        locator.pack({"pad": counts, "dome": baselines["dome"]}), {"j1": 0.2}
    )
    np.testing.assert_array_equal(first.contacts["x_base_mm"], whole.contacts["x_base_mm"])
    np.testing.assert_array_equal(first.wrenches["force_z_n"], whole.wrenches["force_z_n"])
    second = locator.update({"dome": baselines["dome"]}, {"j1": 0.2})
    assert len(second.contacts["frame"]) == 0
    link2 = list(second.wrenches["link"]).index("link2")
    assert second.wrenches["contacts"][link2] == 1
    assert second.wrenches["force_z_n"][link2] == first.wrenches["force_z_n"][link2] != 0.0
    with pytest.raises(TactsenseInputError, match="no patch 'thumb'"):
        locator.update({"thumb": counts})
