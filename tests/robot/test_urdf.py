"""A whole skin in URDF: round trips, other URDF readers, a hand-written file, errors."""

import math

import numpy as np
import pytest

from tactsense.interop.robot_urdf import read_robot_urdf, robot_skin_to_urdf, write_robot_urdf
from tactsense.kinds.urdf import UrdfError
from tactsense.robot import skin_preset


@pytest.mark.parametrize("name, extends", [("hand4", None), ("icub_hand", "icub_fingertip")])
def test_round_trip_keeps_kinematics_sensors_and_boards(tmp_path, name, extends):
    """Kinematics come back exact (every number written with repr); taxel places within
    1e-12 m (a sensor's geometry is written to 15 significant digits)."""
    skin = skin_preset(name)
    path = write_robot_urdf(skin, tmp_path / f"{name}.urdf")
    back = read_robot_urdf(path, extends=extends)
    assert (back.name, back.base_link, back.links, back.joints) == (
        skin.name, skin.base_link, skin.links, skin.joints,
    )  # fmt: skip
    for ours, theirs in zip(skin.patches, back.patches, strict=True):
        assert (ours.name, ours.link, ours.origin, ours.device) == (
            theirs.name, theirs.link, theirs.origin, theirs.device,
        )  # fmt: skip
        assert ours.sensor.kind == theirs.sensor.kind and ours.n_taxels == theirs.n_taxels
        assert ours.sensor.electronics.scan_rate_hz == theirs.sensor.electronics.scan_rate_hz
    state = {j.name: (j.lower + j.upper) / 2 for j in skin.joints if j.type == "revolute"}
    placed, again = skin.taxels_in_base(state), back.taxels_in_base(state)
    for patch in skin.patches:
        np.testing.assert_allclose(again[patch.name][0], placed[patch.name][0], atol=1e-12)
        np.testing.assert_allclose(again[patch.name][1], placed[patch.name][1], atol=1e-12)
    if extends == "icub_fingertip":  # the preset gives back what URDF does not hold
        assert back.patches[0].sensor.transduction == skin.patches[0].sensor.transduction
    assert not list(tmp_path.glob(".*partial*"))


def test_ross_urdf_parser_reads_the_robot(tmp_path):
    """urdf_parser_py (ROS's Python URDF parser) reads links, joints and limits; it skips
    the <sensor> elements, which only the tactile toolbox's parser knows."""
    from urdf_parser_py.urdf import URDF

    skin = skin_preset("icub_hand")
    text = robot_skin_to_urdf(skin)
    robot = URDF.from_xml_string(text.split("\n", 1)[1])
    assert [link.name for link in robot.links] == list(skin.links)
    joints = {j.name: j for j in robot.joints}
    for joint in skin.joints:
        theirs = joints[joint.name]
        assert (theirs.type, theirs.parent, theirs.child) == (joint.type, joint.parent, joint.child)
        np.testing.assert_array_equal(theirs.origin.xyz, joint.origin.xyz_m)
        if joint.type == "revolute":
            assert (theirs.limit.lower, theirs.limit.upper) == (joint.lower, joint.upper)


TOOLBOX_HAND = """<?xml version="1.0"?>
<robot name="gripper">
  <link name="base"/>
  <link name="finger"/>
  <joint name="hinge" type="revolute">
    <parent link="base"/><child link="finger"/>
    <origin xyz="0.1 0 0" rpy="0 0 1.5707963267948966"/>
    <axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/>
  </joint>
  <sensor name="pad" update_rate="200">
    <parent link="finger"/>
    <origin xyz="0.02 0 0" rpy="0 0 0"/>
    <tactile channel="pad">
      <array rows="3" cols="4" size="0.002 0.002" spacing="0.003 0.003"/>
    </tactile>
  </sensor>
  <sensor name="bump" update_rate="50">
    <parent link="base"/>
    <origin xyz="0 0 0.01" rpy="3.141592653589793 0 0"/>
    <tactile channel="bump">
      <taxel idx="0" xyz="0 0 0" rpy="0 0 0"><geometry><box size="0.002 0.002 0"/></geometry></taxel>
      <taxel idx="1" xyz="0.004 0 0" rpy="0 0 0"><geometry><box size="0.002 0.002 0"/></geometry></taxel>
    </tactile>
  </sensor>
  <sensor name="camera"><parent link="base"/><camera/></sensor>
</robot>
"""  # noqa: E501


def test_a_toolbox_style_file_places_its_taxels(tmp_path):
    path = tmp_path / "gripper.urdf"
    path.write_text(TOOLBOX_HAND)
    skin = read_robot_urdf(path)
    assert [p.name for p in skin.patches] == ["pad", "bump"]  # the camera is no tactile sensor
    pad, bump = skin.patches
    assert (pad.sensor.kind, pad.sensor.shape, pad.sensor.electronics.scan_rate_hz) == (
        "pad", (3, 4), 200.0,
    )  # fmt: skip
    assert (bump.sensor.kind, bump.n_taxels, bump.device) == ("points", 2, "bump")
    placed = skin.taxels_in_base({"hinge": 0.5})
    # by hand: the finger frame at (0.1, 0, 0) turned pi/2 + 0.5 about z; taxel (row 2,
    # col 1) of the pad at (0.02 + 2 * 0.003, 1 * 0.003, 0) in the finger's frame
    angle = math.pi / 2 + 0.5
    local = np.array([0.02 + 0.006, 0.003])
    expected = [
        0.1 + math.cos(angle) * local[0] - math.sin(angle) * local[1],
        math.sin(angle) * local[0] + math.cos(angle) * local[1],
        0.0,
    ]
    np.testing.assert_allclose(placed["pad"][0][2 * 4 + 1], expected, atol=1e-15)
    # the bump is turned over (roll pi): its second taxel at (0.004, 0, 0.01), facing -z
    np.testing.assert_allclose(placed["bump"][0][1], [0.004, 0.0, 0.01], atol=1e-15)
    np.testing.assert_allclose(placed["bump"][1][1], [0.0, 0.0, -1.0], atol=1e-15)


def _without(text: str, old: str, new: str = "") -> str:
    assert old in text
    return text.replace(old, new)


ERRORS = [
    ("<robot", "not XML"),
    ("<root/>", "the root element is <root>"),
    (_without(TOOLBOX_HAND, 'type="revolute"', 'type="floating"'), "type 'floating'"),
    (
        _without(TOOLBOX_HAND, '<limit lower="-1" upper="1" effort="1" velocity="1"/>'),
        "a revolute joint needs a <limit>",
    ),
    (_without(TOOLBOX_HAND, 'lower="-1"', 'lower="low"'), "<limit lower='low'> is not a number"),
    (_without(TOOLBOX_HAND, 'lower="-1"', 'lower="2"'), "lower limit 2.0 is above upper"),
    (_without(TOOLBOX_HAND, '<axis xyz="0 0 1"/>', '<axis xyz="0 0"/>'), "expected 3 finite"),
    (_without(TOOLBOX_HAND, '<child link="finger"/>'), "joint 'hinge': no <child link=...>"),
    (_without(TOOLBOX_HAND, '<link name="finger"/>', '<link name="finger"/><link name="x"/>'),
     "2 links are no joint's child (base, x)"),
    (_without(TOOLBOX_HAND, '<parent link="finger"/>\n    <origin xyz="0.02 0 0"',
              '<parent link="hand"/>\n    <origin xyz="0.02 0 0"'),
     "patch 'pad': link 'hand' is not one of the links"),
    (_without(TOOLBOX_HAND, '<parent link="finger"/>\n    <origin xyz="0.02 0 0"',
              '<origin xyz="0.02 0 0"'), "sensor 'pad': no <parent link=...>"),
    (_without(TOOLBOX_HAND, '<sensor name="bump"', '<sensor name="pad"'), "described twice"),
    (_without(TOOLBOX_HAND, 'origin xyz="0.02 0 0"', 'origin xyz="0.02 nan 0"'),
     "expected 3 finite numbers"),
    (_without(TOOLBOX_HAND, '<sensor name="pad"', '<sensor name="my pad"'), "patch name 'my pad'"),
]  # fmt: skip


@pytest.mark.parametrize("text, message", ERRORS, ids=[m for _, m in ERRORS])
def test_bad_urdf_files_say_what_and_where(tmp_path, text, message):
    path = tmp_path / "bad.urdf"
    path.write_text(text)
    with pytest.raises(UrdfError) as caught:
        read_robot_urdf(path)
    assert message in str(caught.value) and "bad.urdf" in str(caught.value)


def test_extends_must_fit_the_form(tmp_path):
    path = tmp_path / "gripper.urdf"
    path.write_text(TOOLBOX_HAND)
    with pytest.raises(UrdfError, match="cannot extend preset 'dome12'"):
        read_robot_urdf(path, extends={"pad": "dome12"})
    with pytest.raises(UrdfError, match="'pad99' is not a sensor preset"):
        read_robot_urdf(path, extends="pad99")
    skin = read_robot_urdf(path, extends={"pad": "fsr16"})
    assert skin.patch("pad").sensor.transduction.kind == "piezoresistive"


def test_load_robot_skin_reads_every_form(tmp_path):
    from tactsense.interop.robot_urdf import load_robot_skin
    from tactsense.robot import skin_to_toml_string

    skin = skin_preset("icub_hand")
    (tmp_path / "s.toml").write_text(skin_to_toml_string(skin))
    write_robot_urdf(skin, tmp_path / "s.urdf")
    assert load_robot_skin("icub_hand") == skin == load_robot_skin(tmp_path / "s.toml")
    from_urdf = load_robot_skin(tmp_path / "s.urdf", extends="icub_fingertip")
    assert from_urdf.joints == skin.joints
    with pytest.raises(UrdfError, match="does not exist"):
        load_robot_skin(tmp_path / "none.urdf")


def _toolbox_taxels_in_link(sensor) -> tuple[np.ndarray, np.ndarray]:
    """Each taxel's position [m] and normal in its link's frame by the tactile toolbox's
    rule (urdf_tactile's TaxelInfoIterator, ubi-agni/tactile_toolbox commit b46718d9),
    written out from the XML alone: an <array>'s taxel (row, col) at origin + R (row *
    spacing.x - offset.x, col * spacing.y - offset.y, 0), normal R z; a <taxel>'s at
    origin + R xyz, normal R R_taxel z. (Upstream's compose() for <taxel> lists adds the
    origin's x to all three coordinates; the rule here is the one its README states, the
    URDF convention.)"""
    from scipy.spatial.transform import Rotation

    def numbers(element, attribute, default):
        return np.array([float(v) for v in element.get(attribute, default).split()])

    origin = sensor.find("origin")
    t = numbers(origin, "xyz", "0 0 0")
    r = Rotation.from_euler("xyz", numbers(origin, "rpy", "0 0 0")).as_matrix()
    array = sensor.find("tactile/array")
    if array is not None:
        rows, cols = int(array.get("rows")), int(array.get("cols"))
        spacing, offset = numbers(array, "spacing", ""), numbers(array, "offset", "0 0")
        assert array.get("order", "row-major") == "row-major"
        local = np.array(
            [
                (row * spacing[0] - offset[0], col * spacing[1] - offset[1], 0.0)
                for row in range(rows)
                for col in range(cols)
            ]
        )
        return local @ r.T + t, np.tile(r[:, 2], (len(local), 1))
    positions, normals = [], []
    for taxel in sensor.findall("tactile/taxel"):
        own = Rotation.from_euler("xyz", numbers(taxel, "rpy", "0 0 0")).as_matrix()
        positions.append(r @ numbers(taxel, "xyz", "0 0 0") + t)
        normals.append((r @ own)[:, 2])
    return np.array(positions), np.array(normals)


@pytest.mark.parametrize("name", ["hand4", "icub_hand"])
def test_every_taxel_is_where_the_toolbox_and_yourdfpy_put_it(tmp_path, name):
    """An independent evaluation of the whole placement: the written URDF read with the
    toolbox's taxel rule (from the XML) and yourdfpy's forward kinematics, against
    ``skin.taxels_in_base`` at a random joint state; within 1e-12 m (15-digit file)."""
    import xml.etree.ElementTree as ET

    import yourdfpy

    skin = skin_preset(name)
    path = write_robot_urdf(skin, tmp_path / "skin.urdf")
    robot = yourdfpy.URDF.load(str(path), load_meshes=False, build_collision_scene_graph=False)
    rng = np.random.default_rng(11)
    state = {j.name: float(rng.uniform(j.lower, j.upper)) for j in skin.joints if j.type != "fixed"}
    robot.update_cfg(state)
    placed = skin.taxels_in_base(state)
    sensors = ET.parse(path).getroot().findall("sensor")
    assert [s.get("name") for s in sensors] == [p.name for p in skin.patches]
    for sensor in sensors:
        link = robot.get_transform(frame_to=sensor.find("parent").get("link"))
        positions, normals = _toolbox_taxels_in_link(sensor)
        ours_p, ours_n = placed[sensor.get("name")]
        np.testing.assert_allclose(positions @ link[:3, :3].T + link[:3, 3], ours_p, atol=1e-12)
        np.testing.assert_allclose(normals @ link[:3, :3].T, ours_n, atol=1e-12)


def test_an_array_offset_moves_the_taxels_as_the_toolbox_does(tmp_path):
    import xml.etree.ElementTree as ET

    text = TOOLBOX_HAND.replace(
        'spacing="0.003 0.003"/>', 'spacing="0.003 0.003" offset="0.004 -0.001"/>'
    )
    path = tmp_path / "offset.urdf"
    path.write_text(text)
    skin = read_robot_urdf(path)
    sensor = next(s for s in ET.parse(path).getroot().findall("sensor") if s.get("name") == "pad")
    expected, _ = _toolbox_taxels_in_link(sensor)
    np.testing.assert_allclose(skin.patch("pad").taxels_in_link()[0], expected, atol=1e-15)
    # taxel (0, 0) at (0.02 - 0.004, 0 + 0.001, 0) in the finger's frame
    np.testing.assert_allclose(expected[0], [0.016, 0.001, 0.0], atol=1e-15)


# ---- r7-fixb: a written URDF keeps each sensor's whole description ----


def _arm2():
    """Two pads of different physics (pad4: capacitive, 4 mm; pad16: resistive) on two
    links: the trial's arm, where a round trip gave pad4's patch pad16's physics."""
    import dataclasses

    from tactsense.robot import Joint, Patch, Pose, RobotSkin
    from tactsense.sensor import preset

    return RobotSkin(
        name="arm2",
        base_link="base",
        links=("base", "fore"),
        joints=(Joint("elbow", "revolute", "base", "fore", Pose((0.1, 0, 0)), (0, 0, 1), -1, 1),),
        patches=(
            Patch("base_pad", dataclasses.replace(preset("pad16")), "base", Pose(), "board_a"),
            Patch("fore_pad", preset("pad4"), "fore", Pose((0.02, 0, 0.01)), "board_b"),
        ),
    )


def test_a_round_trip_gives_back_every_sensors_whole_description(tmp_path):
    import warnings

    import yourdfpy
    from urdf_parser_py.urdf import URDF

    skin = _arm2()
    path = write_robot_urdf(skin, tmp_path / "arm2.urdf")
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no physics-from-a-preset warning: all is kept
        back = read_robot_urdf(path)
    for ours, theirs in zip(skin.patches, back.patches, strict=True):
        assert theirs.sensor.to_dict() == ours.sensor.to_dict(), ours.name
    # still a URDF other readers load (they skip tactsense's element)
    assert len(yourdfpy.URDF.load(str(path)).robot.links) == 2
    assert len(URDF.from_xml_string(path.read_text()).links) == 2


def test_a_urdf_without_tactsense_descriptions_warns_where_physics_come_from(tmp_path):
    import re
    import warnings

    from tactsense.interop.robot_urdf import UrdfPhysicsWarning

    path = tmp_path / "plain.urdf"
    text = robot_skin_to_urdf(_arm2())
    path.write_text(re.sub(r"<tactsense:sensor .*?</tactsense:sensor>", "", text, flags=re.S))
    with pytest.warns(UrdfPhysicsWarning, match=r"base_pad, fore_pad from 'pad16'"):
        read_robot_urdf(path)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a preset named for every sensor: no warning
        read_robot_urdf(path, extends="pad16")


def test_an_edited_urdf_geometry_disagreeing_with_the_description_is_refused(tmp_path):
    path = tmp_path / "edited.urdf"
    text = robot_skin_to_urdf(_arm2())
    assert text.count('rows="4"') == 1
    path.write_text(text.replace('rows="4"', 'rows="3"'))
    with pytest.raises(UrdfError, match=r"fore_pad.*tactsense:sensor.*not where"):
        read_robot_urdf(path)
