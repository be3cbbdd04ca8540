"""Robot skins by name: a four-finger hand (``hand4``) and iCub's five fingertips
(``icub_hand``).

Sources
-------
``hand4``
    Kinematics: the Allegro Hand (right), as its maker publishes it in
    ``allegro_hand_description_right.urdf`` (simlabrobotics/allegro_hand_ros, commit
    67e31388ea04a8d3cbee4b3ef4e9b4819c252d4b): every joint's origin, axis and limits
    copied, the links renamed (:data:`ALLEGRO_JOINTS`). Patch outlines: that file's
    collision boxes (finger links 19.6 mm thick, 27.5 mm wide; proximal 54 mm, middle
    38.4 mm, distal 26.7 mm long; thumb 17.7, 51.4 and 42.3 mm; palm 40.8 x 113 x 95 mm)
    and fingertip spheres (12 mm radius): every pad fits the palmar face of its link, every
    fingertip covers its sphere's outer half. Taxel pitch 2 mm (the pitch of the
    ``pad12x32`` preset, about the human fingertip's two-point threshold): a design
    choice, not a product's figure. Pads: ``pad16``'s piezoresistive cells and 2 mm rubber;
    fingertips: ``dome12``'s capacitive taxels under 2 mm of rubber. 4,000 taxels in 20
    patches, read by four boards of five patches at 250 Hz (the speed goal of issue 36).
``icub_hand``
    Kinematics: iCub's right hand in robotology/icub-models,
    ``iCub_manual/robots/iCubGazeboV2_5_visuomanip/model.urdf`` (commit
    883a900fbf870580aeeb5563ce6886f89666b3b6): the 20 finger joints and 5 fixed tip
    joints under ``r_hand``, copied (:data:`ICUB_RIGHT_HAND_JOINTS`). Fingertips: the
    ``icub_fingertip`` preset (IIT's published 12-taxel layout), its frame's origin on
    the distal joint's axis (the layout's own root: "the centre of the rotation axis of
    the fingertip's support"), its x (towards the finger's base) along the distal link's
    -x, its y (the pressing side) along the link's +y (the side flexion turns toward).
    Simplified: the coupled joints (the distal two of each finger move together on the
    robot) are free here; the mirror between the published (left-hand) layout and the
    right hand is not applied.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Mapping
from types import MappingProxyType

import numpy as np

from tactsense.robot.description import (
    Joint,
    Patch,
    Pose,
    RobotSkin,
    RobotSkinError,
    rpy_from_matrix,
)
from tactsense.sensor import Grid, preset
from tactsense.sensor.points import Taxels

FINGERS4 = ("thumb", "index", "middle", "ring")
"""The four fingers of :func:`hand4`, in patch order."""

ICUB_FINGERS = ("thumb", "index", "middle", "ring", "little")
"""iCub's five fingertips, in the order of the iCub grasp dataset's taxel lines."""

HAND4_PITCH_MM = 2.0
"""Taxel pitch of every ``hand4`` pad [mm]."""

HAND4_RATE_HZ = 250.0
"""Scan rate of every ``hand4`` patch (four boards at 250 Hz) [Hz]."""

ALLEGRO_LINK_THICKNESS_M = 0.0196
"""Allegro finger links' collision boxes: thickness along the palmar normal (x) [m]."""

ALLEGRO_TIP_RADIUS_M = 0.012
"""Allegro fingertips' collision spheres [m]."""

# (joint, Allegro's joint, parent link, child link, origin xyz [m], origin rpy [rad],
#  axis, lower, upper [rad]): allegro_hand_description_right.urdf, commit 67e31388.
ALLEGRO_JOINTS = (
    ("index_abduction", "joint_0.0", "palm", "index_base",
     (0.0, 0.0435, -0.001542), (-0.08726646255, 0.0, 0.0), (0, 0, 1), -0.47, 0.47),
    ("index_joint1", "joint_1.0", "index_base", "index_proximal",
     (0.0, 0.0, 0.0164), (0.0, 0.0, 0.0), (0, 1, 0), -0.196, 1.61),
    ("index_joint2", "joint_2.0", "index_proximal", "index_middle",
     (0.0, 0.0, 0.054), (0.0, 0.0, 0.0), (0, 1, 0), -0.174, 1.709),
    ("index_joint3", "joint_3.0", "index_middle", "index_distal",
     (0.0, 0.0, 0.0384), (0.0, 0.0, 0.0), (0, 1, 0), -0.227, 1.618),
    ("middle_abduction", "joint_4.0", "palm", "middle_base",
     (0.0, 0.0, 0.0007), (0.0, 0.0, 0.0), (0, 0, 1), -0.47, 0.47),
    ("middle_joint1", "joint_5.0", "middle_base", "middle_proximal",
     (0.0, 0.0, 0.0164), (0.0, 0.0, 0.0), (0, 1, 0), -0.196, 1.61),
    ("middle_joint2", "joint_6.0", "middle_proximal", "middle_middle",
     (0.0, 0.0, 0.054), (0.0, 0.0, 0.0), (0, 1, 0), -0.174, 1.709),
    ("middle_joint3", "joint_7.0", "middle_middle", "middle_distal",
     (0.0, 0.0, 0.0384), (0.0, 0.0, 0.0), (0, 1, 0), -0.227, 1.618),
    ("ring_abduction", "joint_8.0", "palm", "ring_base",
     (0.0, -0.0435, -0.001542), (0.08726646255, 0.0, 0.0), (0, 0, 1), -0.47, 0.47),
    ("ring_joint1", "joint_9.0", "ring_base", "ring_proximal",
     (0.0, 0.0, 0.0164), (0.0, 0.0, 0.0), (0, 1, 0), -0.196, 1.61),
    ("ring_joint2", "joint_10.0", "ring_proximal", "ring_middle",
     (0.0, 0.0, 0.054), (0.0, 0.0, 0.0), (0, 1, 0), -0.174, 1.709),
    ("ring_joint3", "joint_11.0", "ring_middle", "ring_distal",
     (0.0, 0.0, 0.0384), (0.0, 0.0, 0.0), (0, 1, 0), -0.227, 1.618),
    ("thumb_abduction", "joint_12.0", "palm", "thumb_base",
     (-0.0182, 0.019333, -0.045987), (0.0, -1.65806278845, -1.5707963259), (-1, 0, 0),
     0.263, 1.396),
    ("thumb_joint1", "joint_13.0", "thumb_base", "thumb_proximal",
     (-0.027, 0.005, 0.0399), (0.0, 0.0, 0.0), (0, 0, 1), -0.105, 1.163),
    ("thumb_joint2", "joint_14.0", "thumb_proximal", "thumb_middle",
     (0.0, 0.0, 0.0177), (0.0, 0.0, 0.0), (0, 1, 0), -0.189, 1.644),
    ("thumb_joint3", "joint_15.0", "thumb_middle", "thumb_distal",
     (0.0, 0.0, 0.0514), (0.0, 0.0, 0.0), (0, 1, 0), -0.162, 1.719),
)  # fmt: skip

# Per finger: (segment, link length along z [m], pad rows along the link); the distal
# length ends at the fingertip sphere's centre (Allegro's tip joint).
_SEGMENTS = {
    "long_fingers": (("proximal", 0.054, 24), ("middle", 0.0384, 16), ("distal", 0.0267, 8)),
    "thumb": (("proximal", 0.0177, 8), ("middle", 0.0514, 24), ("distal", 0.0423, 14)),
}
_PAD_COLS = 12  # 22 mm between the outer taxels' centres on a 27.5-mm-wide link
_PALM_PAD = 18  # 18 x 18 taxels, four on the palm
# palm pad k (read by the board of FINGERS4[k]): its centre on the palm's face (y, z) [m]
_PALM_CENTRES = ((0.019, -0.060), (0.019, -0.022), (-0.019, -0.022), (-0.019, -0.060))
_PALM_FACE_X_M = -0.0093 + 0.0408 / 2  # the palm box's palmar face (x) [m]

# A pad's frame on a palmar face: its rows (x) along the link's +z, its normal (z) along
# the link's +x (the side flexion turns toward), its columns (y) along the link's -y.
_PALMAR = np.array([[0.0, 0.0, 1.0], [0.0, -1.0, 0.0], [1.0, 0.0, 0.0]])


def _hand4_pad(rows: int, cols: int):
    pitch = HAND4_PITCH_MM
    spec = preset("pad16").replace(
        grid=Grid(
            rows=rows,
            cols=cols,
            row_pitch_mm=pitch,
            col_pitch_mm=pitch,
            electrode_x_mm=0.8 * pitch,
            electrode_y_mm=0.8 * pitch,
        ),
        electronics__scan_rate_hz=HAND4_RATE_HZ,
    )
    return dataclasses.replace(
        spec,
        name=f"hand4_pad{rows}x{cols}",
        description=f"{rows}x{cols} piezoresistive pad at {pitch:g} mm pitch (hand4's "
        "pads: pad16's cells and rubber), 250 Hz.",
    )


def hand4_fingertip():
    """The ``hand4`` fingertip: 106 capacitive taxels over the outer half of a 12-mm sphere.

    Rings at polar angles of 0.25 rad steps (3 mm of arc) from the apex (+z) to 1.5 rad,
    each ring as many taxels as fit at 3 mm around it, each ring turned half a step from
    the last; the sphere's centre is the frame's origin, as in ``dome12``.
    """
    radius_mm = ALLEGRO_TIP_RADIUS_M * 1e3
    spacing_mm = 3.0
    normals = []
    for ring in range(7):
        polar = ring * spacing_mm / radius_mm
        count = max(1, round(2.0 * math.pi * radius_mm * math.sin(polar) / spacing_mm))
        for k in range(count):
            azimuth = 2.0 * math.pi * (k + 0.5 * (ring % 2)) / count
            normals.append(
                (
                    math.sin(polar) * math.cos(azimuth),
                    math.sin(polar) * math.sin(azimuth),
                    math.cos(polar),
                )
            )
    base = preset("dome12")
    return dataclasses.replace(
        base,
        name="hand4_fingertip",
        description=f"{len(normals)} capacitive taxels on the outer half of a 12-mm "
        "fingertip sphere (the Allegro Hand's), 3 mm apart, 2 mm rubber, 250 Hz.",
        taxels=Taxels(
            positions_mm=tuple(tuple(radius_mm * c for c in n) for n in normals),
            normals=tuple(normals),
            area_mm2=(4.0,) * len(normals),
        ),
        electronics=dataclasses.replace(base.electronics, scan_rate_hz=HAND4_RATE_HZ),
    )


def _palmar_pad_origin(rows: int, cols: int, centre_xyz_m: tuple[float, float, float]) -> Pose:
    """The pose that centres a pad of ``rows`` x ``cols`` on a palmar face at ``centre``."""
    pitch_m = HAND4_PITCH_MM * 1e-3
    centre_in_pad = np.array([(rows - 1) * pitch_m / 2, (cols - 1) * pitch_m / 2, 0.0])
    origin = np.asarray(centre_xyz_m) - _PALMAR @ centre_in_pad
    return Pose(tuple(float(v) for v in origin), rpy_from_matrix(_PALMAR))


def hand4() -> RobotSkin:
    """A four-finger hand with 20 patches and 4,000 taxels (the Allegro Hand's kinematics).

    Per finger: a pad on the palmar face of each phalanx and a fingertip; four palm pads.
    Board ``board_<finger>`` reads that finger's four patches and palm pad
    ``palm_<k>`` (k: the finger's place in :data:`FINGERS4`). Sources: this module's
    docstring.
    """
    joints = [
        Joint(
            name=name,
            type="revolute",
            parent=parent,
            child=child,
            origin=Pose(xyz, rpy),
            axis=axis,
            lower=lower,
            upper=upper,
        )
        for name, _, parent, child, xyz, rpy, axis, lower, upper in ALLEGRO_JOINTS
    ]
    layer_m = preset("pad16").layer.thickness_mm * 1e-3
    face_x = ALLEGRO_LINK_THICKNESS_M / 2 + layer_m  # the pads' free surface [m]
    tip = hand4_fingertip()
    pads: dict[int, object] = {}
    patches: list[Patch] = []
    for finger in FINGERS4:
        device = f"board_{finger}"
        segments = _SEGMENTS["thumb" if finger == "thumb" else "long_fingers"]
        for segment, length, rows in segments:
            sensor = pads.setdefault(rows, _hand4_pad(rows, _PAD_COLS))
            centre_z = (
                length / 2 if segment != "distal" else (length - ALLEGRO_TIP_RADIUS_M) / 2 + 0.002
            )
            patches.append(
                Patch(
                    name=f"{finger}_{segment}_pad",
                    sensor=sensor,
                    link=f"{finger}_{segment}",
                    origin=_palmar_pad_origin(rows, _PAD_COLS, (face_x, 0.0, centre_z)),
                    device=device,
                )
            )
        distal_length = segments[-1][1]
        patches.append(
            Patch(
                name=f"{finger}_tip",
                sensor=tip,
                link=f"{finger}_distal",
                origin=Pose((0.0, 0.0, distal_length)),
                device=device,
            )
        )
    palm = _hand4_pad(_PALM_PAD, _PALM_PAD)
    for k, (y, z) in enumerate(_PALM_CENTRES):
        patches.append(
            Patch(
                name=f"palm_{k}",
                sensor=palm,
                link="palm",
                origin=_palmar_pad_origin(_PALM_PAD, _PALM_PAD, (_PALM_FACE_X_M + layer_m, y, z)),
                device=f"board_{FINGERS4[k]}",
            )
        )
    links = ["palm"] + [joint.child for joint in joints]
    return RobotSkin(
        name="hand4",
        description=(
            "A four-finger hand (the Allegro Hand's published kinematics, right hand): a pad "
            "on every phalanx, a fingertip of 106 taxels on each finger, four palm pads; "
            "4,000 taxels in 20 patches, four boards of five patches at 250 Hz. Outlines "
            "from the Allegro URDF's collision boxes; 2 mm pitch is a design choice."
        ),
        base_link="palm",
        links=tuple(links),
        joints=tuple(joints),
        patches=tuple(patches),
    )


# (joint, parent, child, origin xyz [m], origin rpy [rad], axis, lower, upper [rad] or
# None for a fixed joint): iCubGazeboV2_5_visuomanip/model.urdf, commit 883a900f.
ICUB_RIGHT_HAND_JOINTS = (
    ("r_hand_thumb_0_joint", "r_hand", "r_hand_thumb_0",
     (-0.0318492127582281, -0.00405679999993591, 0.0192026964178796),
     (0.0880846384483103, -1.32396952212432, 2.97584384270403), (0, 0, 1), 0.0, math.pi / 2),
    ("r_hand_thumb_1_joint", "r_hand_thumb_0", "r_hand_thumb_1", (0.0211, 0.0049, 0.0),
     (-1.5707963267949, 0.0, 0.0), (0, 0, 1), 0.0, math.pi / 2),
    ("r_hand_thumb_2_joint", "r_hand_thumb_1", "r_hand_thumb_2", (0.026, 0.0, 0.0),
     (0.0, 0.0, 0.0), (0, 0, 1), 0.0, math.pi / 2),
    ("r_hand_thumb_3_joint", "r_hand_thumb_2", "r_hand_thumb_3", (0.022, 0.0, 0.0),
     (0.0, 0.0, 0.0), (0, 0, 1), 0.0, math.pi / 2),
    ("r_hand_thumb_tip_joint", "r_hand_thumb_3", "r_hand_thumb_tip", (0.0168, 0.0, 0.0),
     (-math.pi / 2, 0.0, 0.0), (0, 0, 1), None, None),
    ("r_hand_index_0_joint", "r_hand", "r_hand_index_0",
     (-0.0525584344285222, 0.00514320000012944, 0.039473341148855),
     (1.48159614751736, -2.80851293007006, 0.00659385709493776), (0, 0, 1),
     -0.3490658503988659, 0.0),
    ("r_hand_index_1_joint", "r_hand_index_0", "r_hand_index_1", (0.0148, 0.00175, 0.0),
     (1.5707963267949, 0.0, 0.0), (0, 0, 1), 0.0, math.pi / 2),
    ("r_hand_index_2_joint", "r_hand_index_1", "r_hand_index_2", (0.0259, 0.0, 0.0),
     (0.0, 0.0, 0.0), (0, 0, 1), 0.0, math.pi / 2),
    ("r_hand_index_3_joint", "r_hand_index_2", "r_hand_index_3", (0.022, 0.0, 0.0),
     (0.0, 0.0, 0.0), (0, 0, 1), 0.0, math.pi / 2),
    ("r_hand_index_tip_joint", "r_hand_index_3", "r_hand_index_tip", (0.0168, 0.0, 0.0),
     (-math.pi / 2, 0.0, 0.0), (0, 0, 1), None, None),
    ("r_hand_middle_0_joint", "r_hand", "r_hand_middle_0",
     (-0.057540451023329, 0.00604320000004786, 0.0237779752515841),
     (1.57079632679979, -2.87979333376279, 2.06501482580279e-13), (0, 0, 1), 0.0, 0.0),
    ("r_hand_middle_1_joint", "r_hand_middle_0", "r_hand_middle_1", (0.0153, 0.0022, 0.0),
     (1.5707963267949, 0.0, 0.0), (0, 0, 1), 0.0, math.pi / 2),
    ("r_hand_middle_2_joint", "r_hand_middle_1", "r_hand_middle_2", (0.0258, 0.0, 0.0),
     (0.0, 0.0, 0.0), (0, 0, 1), 0.0, math.pi / 2),
    ("r_hand_middle_3_joint", "r_hand_middle_2", "r_hand_middle_3", (0.024, 0.0, 0.0),
     (0.0, 0.0, 0.0), (0, 0, 1), 0.0, math.pi / 2),
    ("r_hand_middle_tip_joint", "r_hand_middle_3", "r_hand_middle_tip", (0.0168, 0.0, 0.0),
     (-math.pi / 2, 0.0, 0.0), (0, 0, 1), None, None),
    ("r_hand_ring_0_joint", "r_hand", "r_hand_ring_0",
     (-0.0606910842022157, 0.00544319999997171, 0.00865822622681494),
     (-1.54796540941373, -0.154343069643928, 3.05377499029501), (0, 0, 1),
     0.0, 0.3490658503988659),
    ("r_hand_ring_1_joint", "r_hand_ring_0", "r_hand_ring_1", (0.0148, 0.00175, 0.0),
     (1.5707963267949, 0.0, 0.0), (0, 0, 1), 0.0, math.pi / 2),
    ("r_hand_ring_2_joint", "r_hand_ring_1", "r_hand_ring_2", (0.0259, 0.0, 0.0),
     (0.0, 0.0, 0.0), (0, 0, 1), 0.0, math.pi / 2),
    ("r_hand_ring_3_joint", "r_hand_ring_2", "r_hand_ring_3", (0.022, 0.0, 0.0),
     (0.0, 0.0, 0.0), (0, 0, 1), 0.0, math.pi / 2),
    ("r_hand_ring_tip_joint", "r_hand_ring_3", "r_hand_ring_tip", (0.0168, 0.0, 0.0),
     (-math.pi / 2, 0.0, 0.0), (0, 0, 1), None, None),
    ("r_hand_little_0_joint", "r_hand", "r_hand_little_0",
     (-0.0636290045193172, 0.00444319999987861, -0.0101109273025847),
     (-1.54796540941373, -0.154343069643928, 3.05377499029501), (0, 0, 1),
     0.0, 0.3490658503988659),
    ("r_hand_little_1_joint", "r_hand_little_0", "r_hand_little_1", (0.0148, -0.00175, 0.0),
     (1.5707963267949, 0.0, 0.0), (0, 0, 1), 0.0, math.pi / 2),
    ("r_hand_little_2_joint", "r_hand_little_1", "r_hand_little_2", (0.0219, 0.0, 0.0),
     (0.0, 0.0, 0.0), (0, 0, 1), 0.0, math.pi / 2),
    ("r_hand_little_3_joint", "r_hand_little_2", "r_hand_little_3", (0.019, 0.0, 0.0),
     (0.0, 0.0, 0.0), (0, 0, 1), 0.0, math.pi / 2),
    ("r_hand_little_tip_joint", "r_hand_little_3", "r_hand_little_tip", (0.0168, 0.0, 0.0),
     (-math.pi / 2, 0.0, 0.0), (0, 0, 1), None, None),
)  # fmt: skip


def icub_hand() -> RobotSkin:
    """iCub's right hand with its five fingertips (12 taxels each), read by one board.

    Every finger joint of icub-models' hand (20 revolute, 5 fixed tip links); each
    fingertip on its finger's distal link ``r_hand_<finger>_3``. Sources and what is
    simplified: this module's docstring.
    """
    joints = []
    for name, parent, child, xyz, rpy, axis, lower, upper in ICUB_RIGHT_HAND_JOINTS:
        fixed = lower is None
        joints.append(
            Joint(
                name=name,
                type="fixed" if fixed else "revolute",
                parent=parent,
                child=child,
                origin=Pose(xyz, rpy),
                axis=axis,
                lower=-math.inf if fixed else lower,
                upper=math.inf if fixed else upper,
            )
        )
    tip = preset("icub_fingertip")
    patches = [
        Patch(
            name=f"{finger}_tip",
            sensor=tip,
            link=f"r_hand_{finger}_3",
            origin=Pose((0.0, 0.0, 0.0), (0.0, math.pi, 0.0)),
            device="skin",
        )
        for finger in ICUB_FINGERS
    ]
    return RobotSkin(
        name="icub_hand",
        description=(
            "iCub's right hand (robotology/icub-models iCubGazeboV2_5_visuomanip) with its "
            "five fingertips of 12 taxels (IIT's published layout), read by one board at "
            "50 Hz. The distal joints' coupling is not modelled."
        ),
        base_link="r_hand",
        links=("r_hand", *(joint.child for joint in joints)),
        joints=tuple(joints),
        patches=tuple(patches),
    )


SKIN_PRESETS: Mapping[str, Callable[[], RobotSkin]] = MappingProxyType(
    {"hand4": hand4, "icub_hand": icub_hand}
)
"""Robot skins by name."""


def skin_preset(name: str) -> RobotSkin:
    """The preset skin called ``name``, or an error listing them."""
    try:
        factory = SKIN_PRESETS[name]
    except KeyError:
        raise RobotSkinError(
            f"no robot skin preset {name!r}; presets: {', '.join(SKIN_PRESETS)}"
        ) from None
    return factory()
