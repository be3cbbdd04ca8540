"""Simulated grasps (tactsense.simulate.grasp): the contacts an object makes on a robot's
skin, the forces, the frames at each patch's own rate, the truth, and the command.

The skin here is built in the test (small pads, a dome and a far pad on a two-joint
finger and a palm) so the tests do not depend on the presets' geometry."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from typer.testing import CliRunner

from tactsense.cli import app
from tactsense.io.robot_recording import read_robot_recording
from tactsense.robot import Joint, Patch, Pose, RobotSkin
from tactsense.sensor import Grid, preset
from tactsense.simulate import ContactBatch, frames_from_contacts
from tactsense.simulate._grasp_frames import frame_count
from tactsense.simulate._grasp_geometry import GraspObject, surface_sample
from tactsense.simulate.grasp import (
    PHASES,
    TRUTH_KEYS,
    Grasp,
    GraspError,
    Timing,
    fingers,
    grasp_contacts,
    grasp_from_toml,
    simulate_grasp,
    write_grasp,
)

RATES = {"palm_pad": 100.0, "finger_pad": 250.0, "tip": 50.0, "far_pad": 200.0}


def _pad(name: str, n: int, pitch_mm: float, rate_hz: float):
    spec = preset("pad16").replace(
        grid=Grid(
            rows=n,
            cols=n,
            row_pitch_mm=pitch_mm,
            col_pitch_mm=pitch_mm,
            electrode_x_mm=0.8 * pitch_mm,
            electrode_y_mm=0.8 * pitch_mm,
        ),
        electronics__scan_rate_hz=rate_hz,
    )
    return dataclasses.replace(spec, name=name)


def _skin() -> RobotSkin:
    """A palm (base) with a pad facing +z and a far pad, one finger of two links with a
    pad facing +z and a dome (point set) whose top is 0.5 mm above the finger pad."""
    tip = preset("dome12").replace(electronics__scan_rate_hz=RATES["tip"])
    return RobotSkin(
        name="test_hand",
        base_link="palm",
        links=("palm", "finger_base", "finger_tip"),
        joints=(
            Joint(
                "finger_yaw",
                "revolute",
                "palm",
                "finger_base",
                Pose((0.05, 0.0, 0.0)),
                (0.0, 0.0, 1.0),
                -1.0,
                1.0,
            ),
            Joint(
                "finger_pitch",
                "revolute",
                "finger_base",
                "finger_tip",
                Pose((0.03, 0.0, 0.0)),
                (0.0, 1.0, 0.0),
                -1.0,
                1.0,
            ),
        ),
        patches=(
            Patch("palm_pad", _pad("palm8", 8, 2.5, RATES["palm_pad"]), "palm"),
            Patch(
                "far_pad", _pad("far4", 4, 3.0, RATES["far_pad"]), "palm", Pose((-0.1, 0.0, 0.0))
            ),
            Patch(
                "finger_pad",
                _pad("finger6", 6, 2.0, RATES["finger_pad"]),
                "finger_base",
                Pose((0.01, 0.0, 0.0)),
            ),
            Patch("tip", tip, "finger_tip", Pose((0.005, 0.0, -0.007))),
        ),
    )


SKIN = _skin()
TIMING = Timing(0.1, 0.2, 0.3, 0.2)


def _sphere_on_palm(x_mm=7.3, y_mm=9.1, radius_mm=20.0, depth_mm=1.5) -> GraspObject:
    """A sphere pressed ``depth_mm`` into the palm pad's surface (z = 0) above (x, y)."""
    centre = (x_mm, y_mm, radius_mm - depth_mm)
    return GraspObject("sphere", (2 * radius_mm,), Pose(tuple(1e-3 * v for v in centre)))


def _box_on_finger_and_palm() -> GraspObject:
    """A flat box whose underside is 0.5 mm below z = 0: into the palm pad, the finger pad
    (0.5 mm) and the dome's top (1 mm); it stops short of the far pad."""
    return GraspObject("box", (110.0, 40.0, 10.0), Pose((0.04, 0.005, 0.0045)))


# ---- geometry --------------------------------------------------------------------------
def _brute_distance(grasped: GraspObject, points_mm: np.ndarray, step_mm: float) -> np.ndarray:
    """Unsigned distance to a dense sample of the box's surface (independent of the
    closed form): every face gridded at ``step_mm``."""
    half = 0.5 * np.asarray(grasped.size_mm)
    surface = []
    for axis in range(3):
        others = [a for a in range(3) if a != axis]
        u = np.arange(-half[others[0]], half[others[0]] + 1e-9, step_mm)
        v = np.arange(-half[others[1]], half[others[1]] + 1e-9, step_mm)
        uu, vv = (g.ravel() for g in np.meshgrid(u, v, indexing="ij"))
        for side in (-1.0, 1.0):
            face = np.zeros((len(uu), 3))
            face[:, axis] = side * half[axis]
            face[:, others[0]], face[:, others[1]] = uu, vv
            surface.append(face)
    surface = np.concatenate(surface)
    matrix = grasped.pose.matrix()
    surface = surface @ matrix[:3, :3].T + 1e3 * matrix[:3, 3]
    return np.array([np.min(np.linalg.norm(surface - p, axis=1)) for p in points_mm])


def test_box_signed_distance_agrees_with_a_dense_surface_sample():
    """|sdf| within the sample's half diagonal of the brute-force distance, for random
    points in and around a rotated box; the sign is inside/outside in the box's frame."""
    grasped = GraspObject("box", (20.0, 12.0, 8.0), Pose((0.01, -0.02, 0.005), (0.3, -0.5, 1.1)))
    rng = np.random.default_rng(1)
    centre = 1e3 * np.asarray(grasped.pose.xyz_m)
    points = centre + rng.uniform(-18, 18, size=(200, 3))
    step = 0.25
    sdf = grasped.signed_distance_mm(points)
    brute = _brute_distance(grasped, points, step)
    np.testing.assert_allclose(np.abs(sdf), brute, atol=step * math.sqrt(2) / 2)
    local = (points - centre) @ grasped.pose.matrix()[:3, :3]
    inside = np.all(np.abs(local) < 0.5 * np.asarray(grasped.size_mm), axis=1)
    assert np.array_equal(sdf < 0, inside)


def test_cylinder_and_sphere_signed_distance_closed_forms():
    cylinder = GraspObject("cylinder", (10.0, 40.0))  # radius 5, half length 20, axis z
    points = np.array([[0, 0, 0], [0, 0, 22], [8, 0, 24], [0, 7, 3], [3, 0, 19]], float)
    np.testing.assert_allclose(
        cylinder.signed_distance_mm(points), [-5.0, 2.0, 5.0, 2.0, -1.0], atol=1e-12
    )
    # the cylinder turned 90 degrees about x: its axis along y
    turned = GraspObject("cylinder", (10.0, 40.0), Pose(rpy_rad=(math.pi / 2, 0.0, 0.0)))
    np.testing.assert_allclose(turned.signed_distance_mm(np.array([[0, 22, 0.0]])), [2.0])
    sphere = GraspObject("sphere", (10.0,), Pose((0.001, 0.002, 0.003)))
    np.testing.assert_allclose(sphere.signed_distance_mm(np.array([[1.0, 2.0, 10.0]])), [2.0])


def test_surface_sample_covers_a_pad_to_half_a_pitch_beyond_its_taxels():
    spec = SKIN.patch("palm_pad").sensor
    sample = surface_sample(spec)
    np.testing.assert_allclose(sample.points_mm[:, 2], 0.0)
    assert sample.points_mm[:, :2].min() > -1.25 and sample.points_mm[:, :2].max() < 17.5 + 1.25
    np.testing.assert_allclose(sample.area_mm2.sum(), (8 * 2.5) ** 2)


def test_sphere_on_a_pad_touches_at_the_foot_of_its_centre():
    """The penetration-weighted centroid of a sphere's cap on a plane is the foot of the
    perpendicular from its centre (symmetry); the depth is R minus the centre's height."""
    grasp = Grasp(_sphere_on_palm(), force_n=1.0, timing=TIMING)
    contacts = grasp_contacts(SKIN, grasp)
    assert set(contacts) == {"palm_pad"}
    contact = contacts["palm_pad"]
    # the cap (radius sqrt(2 R d) = 7.7 mm) lies inside the pad: the sample is symmetric
    # about the foot to within one sample (2.5 / 7 mm) at the cap's rim
    np.testing.assert_allclose(contact.position_mm, [7.3, 9.1, 0.0], atol=0.05)
    np.testing.assert_allclose(contact.normal, [0.0, 0.0, 1.0], atol=1e-12)
    # the deepest sample is within half a sample diagonal (0.25 mm) of the foot: depth
    # error at most 0.25**2 / (2 R) = 0.0016 mm
    assert 1.5 - 0.002 <= contact.depth_mm <= 1.5


# ---- forces ------------------------------------------------------------------------
def _hold_force(recording, name: str) -> float:
    truth = recording.streams[name].truth
    hold = truth["frame_step"] == PHASES.index("hold")
    forces = truth["contact_normal_force_n"][hold, 0]
    assert np.ptp(forces) == 0.0
    return float(forces[0])


def test_total_normal_force_in_the_truth_is_the_commanded_force_per_finger():
    grasp = Grasp(_box_on_finger_and_palm(), force_n=1.5, timing=TIMING, flaws="none")
    recording = simulate_grasp(SKIN, grasp)
    assert fingers(SKIN) == {
        "palm_pad": "palm", "far_pad": "palm", "finger_pad": "finger_base", "tip": "finger_base"
    }  # fmt: skip
    touched = grasp_contacts(SKIN, grasp)
    assert set(touched) == {"palm_pad", "finger_pad", "tip"}
    finger = _hold_force(recording, "finger_pad") + _hold_force(recording, "tip")
    assert finger == pytest.approx(1.5, rel=1e-12)
    assert _hold_force(recording, "palm_pad") == pytest.approx(1.5, rel=1e-12)
    assert _hold_force(recording, "far_pad") == 0.0
    # shared by penetration volume: the dome (1 mm deep) and the pad (0.5 mm) both carry
    share = _hold_force(recording, "tip") / finger
    volumes = touched["tip"].volume_mm3, touched["finger_pad"].volume_mm3
    assert share == pytest.approx(volumes[0] / sum(volumes), rel=1e-12)


def test_forces_by_name_and_the_stiffness_rule():
    named = Grasp(
        _box_on_finger_and_palm(), force_n={"finger_base": 2.0, "palm_pad": 0.7}, timing=TIMING
    )
    recording = simulate_grasp(SKIN, named)
    assert _hold_force(recording, "palm_pad") == pytest.approx(0.7, rel=1e-12)
    finger = _hold_force(recording, "finger_pad") + _hold_force(recording, "tip")
    assert finger == pytest.approx(2.0, rel=1e-12)
    spring = Grasp(_sphere_on_palm(depth_mm=1.5), stiffness_n_per_mm=0.8, timing=TIMING)
    recording = simulate_grasp(SKIN, spring)
    depth = grasp_contacts(SKIN, spring)["palm_pad"].depth_mm
    assert _hold_force(recording, "palm_pad") == pytest.approx(0.8 * depth, rel=1e-12)
    assert depth == pytest.approx(1.5, abs=0.002)


def test_a_load_on_the_object_is_shared_as_tangential_forces():
    """Each touched patch carries the load in proportion to its normal force; on skins
    whose normals are all +z (zero joint state here) the tangential parts are the load's
    x and y, and they add up to them; the normal part is dropped."""
    load = (0.3, -0.2, -1.0)
    grasp = Grasp(_box_on_finger_and_palm(), force_n=1.5, load_n=load, timing=TIMING)
    recording = simulate_grasp(SKIN, grasp)
    total = np.zeros(3)
    normal_total = sum(_hold_force(recording, n) for n in ("palm_pad", "finger_pad", "tip"))
    for name in ("palm_pad", "finger_pad", "tip", "far_pad"):
        truth = recording.streams[name].truth
        hold = np.flatnonzero(truth["frame_step"] == PHASES.index("hold"))
        base = truth["contact_tangential_force_base_n"][hold[0], 0]
        share = _hold_force(recording, name) / normal_total
        normal = truth["contact_normal_base"][hold[0], 0]
        if name == "far_pad":
            np.testing.assert_array_equal(truth["contact_tangential_force_base_n"], 0.0)
            continue
        expected = share * (np.asarray(load) - (np.asarray(load) @ normal) * normal)
        np.testing.assert_allclose(base, expected, atol=1e-12)
        # the same force in the sensor frame, turned by the patch's pose
        pose = SKIN.patch_pose(name)
        sensor = truth["contact_tangential_force_n"][hold[0], 0]
        np.testing.assert_allclose(pose[:3, :3] @ sensor, base, atol=1e-12)
        # it follows the time course: none in the approach
        assert np.all(truth["contact_tangential_force_n"][truth["frame_step"] == 0] == 0)
        total += base
    # the tip's normal at its contact is not exactly +z: compare the sum loosely there
    np.testing.assert_allclose(total[:2], load[:2], atol=0.02 * np.hypot(*load[:2]))
    assert abs(total[2]) < 0.02


def test_the_force_follows_approach_squeeze_hold_release():
    grasp = Grasp(_sphere_on_palm(), force_n=2.0, timing=TIMING, flaws="none")
    truth = simulate_grasp(SKIN, grasp).streams["palm_pad"].truth
    t = np.arange(frame_count(TIMING.total_s, RATES["palm_pad"])) / RATES["palm_pad"]
    expected = np.select(
        [t < 0.1, t < 0.3, t < 0.6, t < 0.8],
        [0.0, (t - 0.1) / 0.2, 1.0, 1.0 - (t - 0.6) / 0.2],
        0.0,
    )
    np.testing.assert_allclose(truth["contact_normal_force_n"][:, 0], 2.0 * expected, atol=1e-12)
    np.testing.assert_array_equal(truth["frame_step"], np.searchsorted([0.1, 0.3, 0.6], t, "right"))
    np.testing.assert_array_equal(truth["step_n_contacts"], [0, 1, 1, 1])
    touching = truth["contact_normal_force_n"][:, 0] > 0
    assert np.all(np.isnan(truth["contact_position_mm"][~touching]))
    assert not np.any(np.isnan(truth["contact_position_mm"][touching]))


# ---- frames ------------------------------------------------------------------------
def test_each_patch_keeps_its_own_rate():
    grasp = Grasp(_sphere_on_palm(), force_n=1.0, timing=TIMING)
    recording = simulate_grasp(SKIN, grasp)
    for name, rate in RATES.items():
        stream = recording.streams[name]
        assert len(stream) == round(0.8 * rate)  # duration x rate
        np.testing.assert_allclose(np.diff(stream.time_s), 1.0 / rate)
        assert stream.sensor.electronics.scan_rate_hz == rate
    assert len({len(s) for s in recording.streams.values()}) == len(RATES)


def _zero_frames(spec, n, flaws, seed):
    batch = ContactBatch(np.zeros((n, 1, 2)), np.zeros((n, 1)))
    return frames_from_contacts(spec, batch, flaws=flaws, rng=seed).reshape(n, *spec.shape)


def test_an_untouched_patch_reads_rest_frames():
    """Without flaws, exactly the frames of no contact; with every per-frame flaw, the
    same rest level to within the read noise (each taxel's mean over 160 frames)."""
    clean = simulate_grasp(SKIN, Grasp(_sphere_on_palm(), force_n=1.0, timing=TIMING, flaws="none"))
    spec = SKIN.patch("far_pad").sensor
    far = clean.streams["far_pad"].frames
    np.testing.assert_array_equal(far, _zero_frames(spec, len(far), "none", 0))
    noisy = simulate_grasp(SKIN, Grasp(_sphere_on_palm(), force_n=1.0, timing=TIMING, seed=3))
    far = noisy.streams["far_pad"].frames
    rest = _zero_frames(spec, len(far), "all", 99)
    spread = np.sqrt(far.var(axis=0) + rest.var(axis=0) + 1 / 6) / math.sqrt(len(far))
    assert np.all(np.abs(far.mean(axis=0) - rest.mean(axis=0)) <= 5 * spread + 1e-9)
    # the approach frames of the touched pad are rest frames too
    palm = clean.streams["palm_pad"]
    approach = palm.truth["frame_step"] == 0
    np.testing.assert_array_equal(
        palm.frames[approach], _zero_frames(palm.sensor, int(approach.sum()), "none", 0)
    )


def _locate_error_mm(stream) -> np.ndarray:
    """The single-array estimator (``find_contacts``, as ``tactsense locate``) on every
    hold frame of a stream, baseline from its approach frames: distance of the located
    position from the truth in the patch's frame [mm], one per hold frame."""
    from tactsense.estimate.contacts.find import find_contacts

    step = stream.truth["frame_step"]
    baseline = np.median(stream.frames[step == 0], axis=0)
    hold = np.flatnonzero(step == PHASES.index("hold"))
    table = find_contacts(stream.frames[hold], stream.sensor, baseline=baseline, max_contacts=1)
    assert np.array_equal(table.frame, np.arange(len(hold)))  # one contact in every frame
    truth = stream.truth["contact_position_mm"][hold, 0]
    return np.hypot(table.x_mm - truth[:, 0], table.y_mm - truth[:, 1])


@pytest.mark.parametrize(
    "flaws, tolerance", [("noise,quantization", 0.2), ("all", 0.4)], ids=["noise", "all"]
)
@pytest.mark.parametrize("name", ["palm_pad", "finger_pad", "far_pad"])
@pytest.mark.parametrize("where", [(0.35, 0.4), (0.6, 0.3)])
def test_locating_each_pad_gives_back_the_contact(name, where, flaws, tolerance):
    """Simulate, then estimate: a sphere (10-mm radius, 0.8 mm deep) on each pad of the
    skin in turn, at a point inside it (fractions ``where`` of its extent) at a bent
    joint state, located by the single-array estimator on every hold frame.

    Tolerance, in pitches of the pad (2 to 3 mm): with read noise and quantization, 0.2
    (the interpolated peak's bias between taxels, up to 0.13 measured here; the noise
    moves it by under 0.001); with every per-frame flaw, 0.4 (an uncalibrated gain spread
    and dead taxels pull the peak: up to 0.29 measured here)."""
    joints = {"finger_yaw": 0.4, "finger_pitch": 0.3}
    patch = SKIN.patch(name)
    extent = np.asarray(patch.sensor.extent_mm) - patch.sensor.grid.row_pitch_mm
    point = np.array([where[0] * extent[0], where[1] * extent[1], 10.0 - 0.8])
    centre = SKIN.patch_pose(name, joints) @ np.r_[1e-3 * point, 1.0]
    grasped = GraspObject("sphere", (20.0,), Pose(tuple(centre[:3])))
    recording = simulate_grasp(
        SKIN, Grasp(grasped, joints=joints, force_n=1.0, timing=TIMING, seed=5, flaws=flaws)
    )
    stream = recording.streams[name]
    truth = stream.truth["contact_position_mm"][stream.truth["frame_step"] == 2, 0]
    np.testing.assert_allclose(truth[0], [point[0], point[1], 0.0], atol=0.05)
    error = _locate_error_mm(stream)
    assert error.max() < tolerance * patch.sensor.grid.row_pitch_mm, error.max()


def test_a_point_set_is_pressed_on_the_taxel_the_object_touches():
    """On a curved point set (iCub's fingertip) pressed from the side, the taxel under the
    contact reads the largest change: the contact is placed in that taxel's tangent
    plane, not at its (x, y) seen from +z (taxels 3 and 4 share one)."""
    tip = preset("icub_fingertip")
    skin = RobotSkin("one_tip", "hand", ("hand",), (), (Patch("tip", tip, "hand"),))
    positions, normals = tip.taxel_positions_mm(), tip.taxel_normals()
    for taxel in (1, 4, 3):
        centre = positions[taxel] + (6.0 - 0.6) * normals[taxel]  # 0.6 mm deep
        grasp = Grasp(
            GraspObject("sphere", (12.0,), Pose(tuple(1e-3 * centre))),
            force_n=0.5, timing=TIMING, flaws="none",
        )  # fmt: skip
        stream = simulate_grasp(skin, grasp).streams["tip"]
        change = np.abs(stream.frames[-1 - int(0.2 * 50) - 5] - stream.frames[0]).ravel()
        assert int(np.argmax(change)) == taxel
        contact = stream.truth["contact_position_mm"][-16, 0]
        assert np.linalg.norm(contact - positions[taxel]) < 0.3


def test_truth_in_the_base_frame_follows_the_joint_state():
    joints = {"finger_yaw": 0.3, "finger_pitch": -0.2}
    pad_pose = SKIN.patch_pose("finger_pad", joints)
    centre = pad_pose @ np.array([0.005, 0.004, 0.009 - 0.0007, 1.0])  # 0.7 mm into the pad
    grasped = GraspObject("sphere", (18.0,), Pose(tuple(centre[:3])))
    grasp = Grasp(grasped, joints=joints, force_n=1.0, timing=TIMING)
    stream = simulate_grasp(SKIN, grasp).streams["finger_pad"]
    hold = stream.truth["frame_step"] == 2
    local = stream.truth["contact_position_mm"][hold, 0][0]
    np.testing.assert_allclose(local, [5.0, 4.0, 0.0], atol=0.05)
    base = stream.truth["contact_position_base_m"][hold, 0][0]
    np.testing.assert_allclose(base, (pad_pose @ np.r_[1e-3 * local, 1.0])[:3], atol=1e-12)
    np.testing.assert_allclose(
        stream.truth["contact_normal_base"][hold, 0][0], pad_pose[:3, 2], atol=1e-9
    )
    # the contact lies in the object, no deeper than the penetration
    assert -0.7 - 1e-6 <= grasped.signed_distance_mm(1e3 * base[None])[0] <= 0.0


# ---- the recording and the file ----------------------------------------------------
def test_a_grasp_is_written_as_a_robot_recording_with_the_same_truth_keys(tmp_path):
    grasp = Grasp(_box_on_finger_and_palm(), force_n=1.0, load_n=(0, 0.1, -1), timing=TIMING)
    write_grasp(tmp_path / "run", SKIN, grasp)
    in_memory = simulate_grasp(SKIN, grasp)
    back = read_robot_recording(tmp_path / "run")
    assert set(back.streams) == set(RATES) and back.closed_cleanly
    for name, stream in back.streams.items():
        assert set(TRUTH_KEYS) <= set(stream.truth)
        assert stream.truth["patch"] == name
        same = in_memory.streams[name]
        # one block per patch here (200 frames at most): the same noise draws
        np.testing.assert_array_equal(stream.frames, same.frames)
        np.testing.assert_array_equal(stream.time_s, same.time_s)
        np.testing.assert_array_equal(stream.gains, same.gains)
        for key in TRUTH_KEYS:
            np.testing.assert_array_equal(stream.truth[key], same.truth[key])
        assert stream.scenario == same.scenario and stream.scenario["kind"] == "grasp"
    with pytest.raises(FileExistsError):
        write_grasp(tmp_path / "run", SKIN, grasp)
    assert not list(tmp_path.glob("*.partial"))


def test_the_folder_is_written_block_by_block(tmp_path, monkeypatch):
    """Blocks of 7 frames give the frames and truth of one block (without noise: the
    noise is drawn block by block), so memory holds one block whatever the length."""
    import importlib

    module = importlib.import_module("tactsense.simulate.grasp")

    grasp = Grasp(_sphere_on_palm(), force_n=1.0, timing=TIMING, flaws="gain_spread,dead")
    whole = simulate_grasp(SKIN, grasp)
    monkeypatch.setattr(module, "BLOCK_FRAMES", 7)
    seen = []
    write_grasp(tmp_path / "run", SKIN, grasp, progress=lambda done, total: seen.append(done))
    back = read_robot_recording(tmp_path / "run")
    for name, stream in back.streams.items():
        np.testing.assert_array_equal(stream.frames, whole.streams[name].frames)
        for key in TRUTH_KEYS:
            np.testing.assert_array_equal(stream.truth[key], whole.streams[name].truth[key])
    total = sum(len(s) for s in whole.streams.values())
    assert seen[-1] == total and len(seen) == sum(
        math.ceil(len(s) / 7) for s in back.streams.values()
    )


def test_an_interrupted_write_leaves_nothing(tmp_path):
    grasp = Grasp(_sphere_on_palm(), force_n=1.0, timing=TIMING)

    def stop(done, total):
        if done > total // 2:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        write_grasp(tmp_path / "run", SKIN, grasp, progress=stop)
    assert list(tmp_path.iterdir()) == []


def test_a_grasp_file_gives_the_grasp_of_the_options(tmp_path):
    path = tmp_path / "grasp.toml"
    path.write_text(
        "force_n = { finger_base = 2.0, palm_pad = 0.5 }\nflaws = 'noise'\nseed = 4\n"
        "[object]\nshape = 'cylinder'\nsize_mm = [20, 60]\nxyz_mm = [10, 0, 9.5]\n"
        "rpy_deg = [90, 0, 0]\n[joints]\nfinger_yaw = 0.1\n"
        "[timing]\napproach_s = 0.05\nsqueeze_s = 0.1\nhold_s = 0.2\nrelease_s = 0.1\n"
    )
    grasp = grasp_from_toml(path)
    assert grasp == Grasp(
        GraspObject("cylinder", (20.0, 60.0), Pose((0.01, 0.0, 0.0095), (math.pi / 2, 0, 0))),
        joints={"finger_yaw": 0.1},
        force_n={"finger_base": 2.0, "palm_pad": 0.5},
        timing=Timing(0.05, 0.1, 0.2, 0.1),
        flaws="noise",
        seed=4,
    )
    path.write_text("[object]\nshape = 'sphere'\nsize_mm = 10\ncolour = 'red'\n")
    with pytest.raises(GraspError, match="unknown key"):
        grasp_from_toml(path)


@pytest.mark.parametrize(
    "grasp, message",
    [
        (lambda: Grasp(_sphere_on_palm(x_mm=-60.0), force_n=1.0), "touches no patch"),
        (lambda: Grasp(_sphere_on_palm(), force_n={"thumb": 1.0}), "not a finger"),
        (lambda: Grasp(_sphere_on_palm(), force_n={"finger_base": 1.0}), "touches none"),
        (lambda: Grasp(_sphere_on_palm(), force_n={"tip": 1.0}), "does not touch it"),
        (lambda: Grasp(_box_on_finger_and_palm(), force_n={"palm": 1.0}), "no force is given"),
        (lambda: Grasp(_sphere_on_palm(), joints={"wrist": 0.1}), "not a movable joint"),
        (lambda: Grasp(_sphere_on_palm(), joints={"finger_yaw": 2.0}), "outside its limits"),
        (lambda: Grasp(_sphere_on_palm(), flaws="viscoelastic"), "need a frame sequence"),
        (lambda: Grasp(_sphere_on_palm(), force_n=-1.0), "more than 0"),
        (lambda: Grasp(_sphere_on_palm(), load_n=(1.0, 2.0)), "load_n"),
        (lambda: Grasp(_sphere_on_palm(), load_n=(1.0, 2.0, math.nan)), "load_n"),
        (lambda: Grasp(_sphere_on_palm(), timing=Timing(0, 0, 0, 0)), "0 s in all"),
        (lambda: Grasp(_sphere_on_palm(), timing=Timing(-1, 1, 1, 1)), "approach duration"),
        (lambda: Grasp(GraspObject("cone", (1.0,))), "expected one of sphere"),
        (lambda: Grasp(GraspObject("box", (1.0, 2.0))), "expected 3 number"),
    ],
)
def test_bad_grasps_say_what_is_wrong(grasp, message):
    with pytest.raises(GraspError, match=message):
        simulate_grasp(SKIN, grasp())


def test_a_kind_without_a_surface_is_refused_in_one_line():
    skin = RobotSkin("finger", "hand", ("hand",), (), (Patch("f", preset("initial"), "hand"),))
    with pytest.raises(Exception, match="does not apply") as error:
        simulate_grasp(skin, Grasp(GraspObject("sphere", (10.0,)), force_n=1.0))
    assert "\n" not in str(error.value)


# ---- the command -------------------------------------------------------------------
def test_the_command_writes_a_robot_recording(tmp_path):
    from tactsense.robot import skin_to_toml_string

    (tmp_path / "skin.toml").write_text(skin_to_toml_string(SKIN))
    out = tmp_path / "run"
    args = ["grasp", str(tmp_path / "skin.toml"), "--object", "box", "--size-mm", "110,40,10",
            "--pose", "40,5,4.5", "--force-n", "finger_base=1,palm=0.5", "--duration-s",
            "0.05,0.1,0.1,0.05", "--out", str(out), "--quiet"]  # fmt: skip
    result = CliRunner().invoke(app, args, terminal_width=200)
    assert result.exit_code == 0, result.output
    assert "3 patches touched" in result.output
    back = read_robot_recording(out)
    assert len(back.streams["finger_pad"]) == round(0.3 * 250)
    again = CliRunner().invoke(app, args)
    assert again.exit_code == 2 and "exists" in again.output
    inside = CliRunner().invoke(app, [*args[:-3], "--out", str(tmp_path), "--force"])
    assert inside.exit_code == 2 and "holds the input" in inside.output


def test_the_docs_grasp_file_reads():
    """The grasp file shown in docs/robot.md is one `--grasp` reads."""
    import re
    import tomllib
    from pathlib import Path

    from tactsense.simulate.grasp import grasp_from_dict

    doc = (Path(__file__).resolve().parents[2] / "docs" / "robot.md").read_text()
    section = doc[doc.index("<!-- r7-grasp -->") : doc.index("<!-- /r7-grasp -->")]
    (block,) = re.findall(r"```toml\n(.*?)```", section, flags=re.S)
    grasp = grasp_from_dict(tomllib.loads(block))
    assert grasp.object.shape == "cylinder" and grasp.timing.total_s == pytest.approx(1.3)


def test_joints_left_out_rest_at_zero_clipped_into_their_limits():
    from tactsense.simulate.grasp import joint_state

    skin = dataclasses.replace(
        SKIN,
        joints=(
            dataclasses.replace(SKIN.joints[0], lower=0.2, upper=1.0),
            dataclasses.replace(SKIN.joints[1], lower=-1.0, upper=-0.1),
        ),
    )
    assert joint_state(skin, {}) == {"finger_yaw": 0.2, "finger_pitch": -0.1}
    assert joint_state(skin, {"finger_yaw": 0.5}) == {"finger_yaw": 0.5, "finger_pitch": -0.1}
    grasp = Grasp(_sphere_on_palm(), force_n=1.0, timing=TIMING, flaws="none")
    assert simulate_grasp(skin, grasp).streams["tip"].scenario["joints"] == {
        "finger_yaw": 0.2,
        "finger_pitch": -0.1,
    }


@pytest.mark.parametrize("name", ["hand4", "icub_hand"])
def test_every_preset_takes_a_grasp_on_its_largest_patch(name):
    """Whatever a preset's geometry: a sphere pressed 1 mm into its largest patch (at its
    taxels' centroid, along their mean normal, at rest) touches it, and every patch keeps
    its own rate."""
    from tactsense.robot import load_skin
    from tactsense.simulate.grasp import joint_state

    skin = load_skin(name)
    largest = max(skin.patches, key=lambda p: p.n_taxels)
    positions, normals = skin.taxels_in_base(joint_state(skin, {}))[largest.name]
    normal = normals.mean(axis=0) / np.linalg.norm(normals.mean(axis=0))
    centre = positions.mean(axis=0) + 1e-3 * (10.0 - 1.0) * normal
    grasp = Grasp(GraspObject("sphere", (20.0,), Pose(tuple(centre))), force_n=1.0, timing=TIMING)
    assert largest.name in grasp_contacts(skin, grasp)
    recording = simulate_grasp(skin, grasp)
    for patch in skin.patches:
        stream = recording.streams[patch.name]
        assert len(stream) == frame_count(0.8, patch.sensor.electronics.scan_rate_hz)
    assert np.max(recording.streams[largest.name].truth["contact_normal_force_n"]) > 0


def test_the_docs_figures_are_the_codes():
    """The numbers docs/robot.md's grasp section states are the constants the code uses."""
    from pathlib import Path

    from tactsense.cli._grasp import DEFAULT_DURATIONS
    from tactsense.simulate._grasp_geometry import SAMPLES
    from tactsense.simulate.grasp import BLOCK_FRAMES, MAX_PHASE_S

    doc = (Path(__file__).resolve().parents[2] / "docs" / "robot.md").read_text()
    section = " ".join(
        doc[doc.index("<!-- r7-grasp -->") : doc.index("<!-- /r7-grasp -->")].split()
    )
    assert f"a {SAMPLES} x {SAMPLES} square of points" in section
    assert f"{BLOCK_FRAMES:,} frames at a time" in section
    assert f"a phase is at most {MAX_PHASE_S:g} s" in section
    assert f"default `{DEFAULT_DURATIONS}`" in section
    assert Timing() == Timing(*(float(v) for v in DEFAULT_DURATIONS.split(",")))
    stiffness = Grasp(GraspObject("sphere", (1.0,))).stiffness_n_per_mm
    assert f"`--stiffness-n-per-mm` [N/mm] (default {stiffness:g})" in section


def test_the_command_takes_a_grasp_file_and_the_stiffness_rule(tmp_path):
    from tactsense.robot import skin_to_toml_string

    (tmp_path / "skin.toml").write_text(skin_to_toml_string(SKIN))
    (tmp_path / "grasp.toml").write_text(
        "stiffness_n_per_mm = 0.5\nflaws = 'none'\n"
        "[object]\nshape = 'sphere'\nsize_mm = 40\nxyz_mm = [7.3, 9.1, 18.5]\n"
        "[timing]\napproach_s = 0.05\nsqueeze_s = 0.05\nhold_s = 0.1\nrelease_s = 0.0\n"
    )
    out = tmp_path / "run"
    args = ["grasp", str(tmp_path / "skin.toml"), "--grasp", str(tmp_path / "grasp.toml"),
            "--out", str(out), "--quiet"]  # fmt: skip
    result = CliRunner().invoke(app, args, terminal_width=200)
    assert result.exit_code == 0, result.output
    stream = read_robot_recording(out).streams["palm_pad"]
    assert stream.scenario["force_rule"] == "penetration stiffness"
    # 0.5 N/mm times the sphere's 1.5-mm penetration (to the sample's 0.002 mm)
    assert stream.truth["contact_normal_force_n"].max() == pytest.approx(0.75, abs=0.001)
    assert len(stream) == round(0.2 * RATES["palm_pad"])


def test_ctrl_c_in_the_command_leaves_nothing(tmp_path):
    """SIGINT while the streams are being written: exit status 1, "interrupted", and
    neither the recording nor its temporary folder is left (waits on the temporary
    folder's first stream, not on a timer)."""
    import os
    import signal
    import subprocess
    import sys
    import time

    from tactsense.robot import skin_to_toml_string

    (tmp_path / "skin.toml").write_text(skin_to_toml_string(SKIN))
    out = tmp_path / "run"
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)}
    process = subprocess.Popen(
        [sys.executable, "-m", "tactsense", "grasp", str(tmp_path / "skin.toml"), "--object",
         "sphere", "--size-mm", "40", "--pose", "7.3,9.1,18.5", "--force-n", "1",
         "--duration-s", "0,1,120,1", "--out", str(out)],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env,
    )  # fmt: skip
    try:
        deadline = time.monotonic() + 120
        streams = out.with_name("run.partial") / "streams"
        while not (streams.is_dir() and any(streams.iterdir())):
            assert process.poll() is None, process.communicate()
            assert time.monotonic() < deadline, "the command wrote no stream in 120 s"
            time.sleep(0.05)
        process.send_signal(signal.SIGINT)
        _, err = process.communicate(timeout=120)
    finally:
        if process.poll() is None:
            process.kill()
    assert process.returncode == 1 and "interrupted" in err, err
    assert "Traceback" not in err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["skin.toml"]


# ---- r7-fixb: every example of docs/robot.md's grasp block runs ----


def _doc_block(marker: str) -> str:
    from pathlib import Path

    doc = (Path(__file__).resolve().parents[2] / "docs" / "robot.md").read_text()
    return doc[doc.index(f"<!-- {marker} -->") : doc.index(f"<!-- /{marker} -->")]


def doc_commands(marker: str, command: str) -> list[list[str]]:
    """The ``tactsense COMMAND ...`` console lines of a docs/robot.md block, as argument
    lists (comments dropped, the shell prompt ``$`` too), leaving out synopsis lines that
    hold placeholders (SKIN, RUN, ...)."""
    import re
    import shlex

    found = []
    for line in _doc_block(marker).splitlines():
        line = line.strip().removeprefix("$ ").split(" #")[0].strip()
        if not line.startswith(f"tactsense {command}") or re.search(r"\b[A-Z]{2,}\b", line):
            continue
        found.append(shlex.split(line)[1:])
    return found


def test_every_grasp_example_in_the_docs_runs(tmp_path, monkeypatch):
    """Issue 36 trial defect 3: the docs' grasp command and grasp file touched no patch.
    Each is run here on hand4 (shorter phases: where the object touches does not depend on
    the time course) and must touch the patches it names."""
    import re

    monkeypatch.chdir(tmp_path)
    short = ["--duration-s", "0.02,0.02,0.02,0.02", "--quiet", "--flaws", "none"]
    commands = doc_commands("r7-grasp", "grasp")
    assert commands, "no runnable `tactsense grasp` line in the docs"
    for i, args in enumerate(commands):
        args = [*args[: args.index("--out")], *short, "--out", f"run{i}"]
        result = CliRunner().invoke(app, args, terminal_width=200)
        assert result.exit_code == 0, f"{args}: {result.output}"
        assert "palm_0" in result.output
    (block,) = re.findall(r"```toml\n(.*?)```", _doc_block("r7-grasp"), flags=re.S)
    (tmp_path / "grasp.toml").write_text(re.sub(r"(_s = )[0-9.]+", r"\g<1>0.02", block))
    args = ["grasp", "hand4", "--grasp", "grasp.toml", "--out", "run_file", "--quiet"]
    result = CliRunner().invoke(app, args, terminal_width=200)
    assert result.exit_code == 0, result.output
    back = read_robot_recording(tmp_path / "run_file")
    forces = back.streams["palm_0"].scenario["patch_force_n"]
    # the file commands 2 N on the index finger and 1 N on the palm: both are touched
    assert sum(v for k, v in forces.items() if k.startswith("index_")) == pytest.approx(2.0)
    assert sum(v for k, v in forces.items() if k.startswith("palm_")) == pytest.approx(1.0)


def test_an_object_touching_nothing_names_the_nearest_patch():
    from tactsense.robot import skin_preset
    from tactsense.simulate.grasp import plan_grasp

    grasp = Grasp(object=GraspObject("sphere", (40.0,), Pose(xyz_m=(0.0365, -0.0565, -0.0285))))
    with pytest.raises(GraspError, match=r"nearest patch is 'palm_2', [0-9.]+ mm.*sensor show"):
        plan_grasp(skin_preset("hand4"), grasp)
