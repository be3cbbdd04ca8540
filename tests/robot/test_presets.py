"""The skin presets: names other parts rely on, sizes against their stated sources."""

import math

import numpy as np

from tactsense.robot import skin_preset
from tactsense.robot.presets import ALLEGRO_JOINTS, FINGERS4, ICUB_FINGERS

HAND4_PATCHES = [
    *(f"{f}_{s}" for f in FINGERS4 for s in ("proximal_pad", "middle_pad", "distal_pad", "tip")),
    "palm_0",
    "palm_1",
    "palm_2",
    "palm_3",
]


def test_hand4_names_counts_boards_and_rates():
    skin = skin_preset("hand4")
    assert [p.name for p in skin.patches] == HAND4_PATCHES  # other parts use these names
    assert FINGERS4 == ("thumb", "index", "middle", "ring")
    assert skin.n_taxels == 4000
    assert {d: len(n) for d, n in skin.devices.items()} == {f"board_{f}": 5 for f in FINGERS4}
    assert {p.sensor.electronics.scan_rate_hz for p in skin.patches} == {250.0}
    assert skin.base_link == "palm" and len(skin.movable_joints) == 16


def test_hand4_joints_are_the_allegro_urdfs():
    skin = skin_preset("hand4")
    joints = {j.name: j for j in skin.joints}
    for name, _, parent, child, xyz, rpy, axis, lower, upper in ALLEGRO_JOINTS:
        joint = joints[name]
        assert (joint.parent, joint.child, joint.origin.xyz_m, joint.origin.rpy_rad) == (
            parent, child, xyz, rpy,
        )  # fmt: skip
        assert joint.axis == tuple(float(a) for a in axis) and (joint.lower, joint.upper) == (
            lower,
            upper,
        )
    # spot values read from allegro_hand_description_right.urdf (commit 67e31388)
    assert joints["index_abduction"].origin.xyz_m == (0.0, 0.0435, -0.001542)
    assert joints["thumb_joint3"].origin.xyz_m == (0.0, 0.0, 0.0514)
    assert (joints["middle_joint2"].lower, joints["middle_joint2"].upper) == (-0.174, 1.709)


def test_hand4_pads_lie_on_the_palmar_face_of_their_links():
    """Every phalanx pad inside its link's collision box outline (27.5 mm wide, from the
    joint to the link's end or the fingertip sphere), on the palmar face (+x), facing +x."""
    skin = skin_preset("hand4")
    for patch in skin.patches:
        positions, normals = patch.taxels_in_link()
        if patch.name.endswith("_pad"):
            np.testing.assert_allclose(
                normals, np.tile([1.0, 0, 0], (patch.n_taxels, 1)), atol=1e-12
            )
            np.testing.assert_allclose(positions[:, 0], 0.0098 + 0.002, atol=1e-12)
            assert np.abs(positions[:, 1]).max() <= 0.0275 / 2
            assert positions[:, 2].min() > 0.0 and positions[:, 2].max() < 0.054
        elif patch.name.endswith("_tip"):  # the 12-mm fingertip sphere's outer half
            centre = np.array(patch.origin.xyz_m)
            np.testing.assert_allclose(np.linalg.norm(positions - centre, axis=1), 0.012)
            assert ((positions - centre)[:, 2] >= -1e-12).all()
        else:  # palm pads: on the palm box's face, inside its 113 x 95 mm outline
            np.testing.assert_allclose(positions[:, 0], -0.0093 + 0.0204 + 0.002, atol=1e-12)
            assert np.abs(positions[:, 1]).max() < 0.113 / 2
            assert positions[:, 2].max() < 0 and positions[:, 2].min() > -0.095


def test_hand4_patches_do_not_overlap():
    from tactsense.cli._robot_sensor import skin_warnings

    assert skin_warnings(skin_preset("hand4")) == []


def test_icub_hand_fingertips_sit_on_the_distal_links_as_published():
    skin = skin_preset("icub_hand")
    assert [p.name for p in skin.patches] == [f"{f}_tip" for f in ICUB_FINGERS]
    assert skin.n_taxels == 60 and skin.devices == {"skin": tuple(p.name for p in skin.patches)}
    assert len(skin.movable_joints) == 20 and skin.base_link == "r_hand"
    for patch in skin.patches:
        assert patch.link == f"r_hand_{patch.name.removesuffix('_tip')}_3"
        positions, normals = patch.taxels_in_link()
        # the layout's taxel 11 is the tip end, 20.9 mm from the support's axis: along
        # the distal link's +x, beyond the model's tip frame at 16.8 mm
        np.testing.assert_allclose(positions[11], [0.0209, 0.0, 0.0], atol=1e-12)
        np.testing.assert_allclose(normals[11], [1.0, 0.0, 0.0], atol=1e-12)
        # the pressing side (taxel 1's normal) is the side flexion turns toward (+y)
        np.testing.assert_allclose(normals[1], [0.0, 1.0, 0.0], atol=1e-12)
    # flexing a finger's proximal joint by 90 deg turns its fingertip toward the palm side
    flexed = skin.taxels_in_base({"r_hand_index_1_joint": math.pi / 2})["index_tip"][0]
    straight = skin.taxels_in_base()["index_tip"][0]
    assert np.linalg.norm(flexed.mean(0) - straight.mean(0)) > 0.02


def test_rest_state_is_within_every_limit():
    skin = skin_preset("hand4")
    rest = skin.rest_joint_positions()
    assert rest["thumb_abduction"] == 0.263  # Allegro's lower limit: 0 is outside
    assert rest["index_joint1"] == 0.0
    assert set(rest) == set(skin.movable_joints)
    skin.link_poses(rest)  # every value within its limits, or this raises


def test_the_docs_preset_tables_are_current():
    """docs/robot.md's tables are scripts/robot_skin_numbers.py's: each row is found."""
    import importlib.util
    from pathlib import Path

    root = Path(__file__).resolve().parents[2]
    spec = importlib.util.spec_from_file_location(
        "robot_skin_numbers", root / "scripts" / "robot_skin_numbers.py"
    )
    script = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(script)
    doc = (root / "docs" / "robot.md").read_text()
    for name in ("hand4", "icub_hand"):
        skin = skin_preset(name)
        for row in script._patch_rows(skin):
            assert row in doc, row
        assert f"**`{name}`**: {len(skin.patches)} patches, {skin.n_taxels} taxels" in doc
