"""Robot skins by name: a four-finger hand and iCub's five fingertips.

SKELETON (round 7): the geometry here is a first cut for the other parts to build on;
the ``skin`` part replaces it with sizes from stated sources.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Mapping
from types import MappingProxyType

from tactsense.robot.description import Joint, Patch, Pose, RobotSkin, RobotSkinError
from tactsense.sensor import Grid, preset

FINGERS4 = ("thumb", "index", "middle", "ring")
"""The four fingers of :func:`hand4`."""

ICUB_FINGERS = ("thumb", "index", "middle", "ring", "little")
"""iCub's five fingertips, in the order of the iCub grasp dataset's taxel lines."""


def _pad(name: str, rows: int, cols: int, pitch_mm: float, rate_hz: float):
    spec = preset("pad16").replace(
        grid=Grid(
            rows=rows,
            cols=cols,
            row_pitch_mm=pitch_mm,
            col_pitch_mm=pitch_mm,
            electrode_x_mm=0.8 * pitch_mm,
            electrode_y_mm=0.8 * pitch_mm,
        ),
        electronics__scan_rate_hz=rate_hz,
    )
    return dataclasses.replace(spec, name=name)


def hand4() -> RobotSkin:
    """A four-finger hand (thumb and three fingers, four joints each) with 20 patches:
    a fingertip (point set) and three phalanx pads per finger, and four palm pads."""
    links = ["palm"]
    joints: list[Joint] = []
    patches: list[Patch] = []
    lengths_m = (0.054, 0.0384, 0.0267)  # proximal, middle, distal phalanx
    phalanx = _pad("phalanx_pad", 4, 8, 3.0, 250.0)
    tip = dataclasses.replace(preset("dome12"), name="fingertip")
    for i, finger in enumerate(FINGERS4):
        device = f"board_{finger}"
        base = f"{finger}_base"
        links.append(base)
        joints.append(
            Joint(
                name=f"{finger}_abduction",
                type="revolute",
                parent="palm",
                child=base,
                origin=Pose((0.095, -0.045 + 0.03 * i, 0.0)),
                axis=(0.0, 0.0, 1.0),
                lower=-0.5,
                upper=0.5,
            )
        )
        parent = base
        offset = 0.0
        segments = zip(("proximal", "middle", "distal"), lengths_m, strict=True)
        for j, (segment, length) in enumerate(segments):
            link = f"{finger}_{segment}"
            links.append(link)
            joints.append(
                Joint(
                    name=f"{finger}_joint{j + 1}",
                    type="revolute",
                    parent=parent,
                    child=link,
                    origin=Pose((offset, 0.0, 0.0)),
                    axis=(0.0, 1.0, 0.0),
                    lower=-0.2,
                    upper=1.6,
                )
            )
            patches.append(
                Patch(
                    name=f"{finger}_{segment}_pad",
                    sensor=phalanx,
                    link=link,
                    origin=Pose((0.5 * length - 0.0105, -0.0105, -0.008), (math.pi, 0.0, 0.0)),
                    device=device,
                )
            )
            parent, offset = link, length
        patches.append(
            Patch(
                name=f"{finger}_tip",
                sensor=tip,
                link=f"{finger}_distal",
                origin=Pose((lengths_m[-1], 0.0, 0.0), (0.0, math.pi / 2, 0.0)),
                device=device,
            )
        )
    palm = _pad("palm_pad", 12, 12, 3.0, 100.0)
    for k in range(4):
        patches.append(
            Patch(
                name=f"palm_{k}",
                sensor=palm,
                link="palm",
                origin=Pose(
                    (0.02 + 0.037 * (k // 2), -0.04 + 0.037 * (k % 2) * 2, -0.01),
                    (math.pi, 0.0, 0.0),
                ),
                device="board_palm",
            )
        )
    return RobotSkin(
        name="hand4",
        description="A four-finger hand: fingertips, three phalanx pads per finger, a palm "
        "of four pads (SKELETON geometry).",
        base_link="palm",
        links=tuple(links),
        joints=tuple(joints),
        patches=tuple(patches),
    )


def icub_hand() -> RobotSkin:
    """iCub's five fingertips (12 taxels each), each on its finger's distal link."""
    tip = preset("icub_fingertip")
    links = ["hand"]
    joints, patches = [], []
    for i, finger in enumerate(ICUB_FINGERS):
        link = f"{finger}_distal"
        links.append(link)
        joints.append(
            Joint(
                name=f"{finger}_distal_joint",
                type="revolute",
                parent="hand",
                child=link,
                origin=Pose((0.06, -0.03 + 0.015 * i, 0.0)),
                axis=(0.0, 0.0, 1.0),
                lower=0.0,
                upper=1.6,
            )
        )
        patches.append(Patch(name=f"{finger}_tip", sensor=tip, link=link, device="skin"))
    return RobotSkin(
        name="icub_hand",
        description="iCub's five fingertips, 12 taxels each (SKELETON kinematics).",
        base_link="hand",
        links=tuple(links),
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
        return SKIN_PRESETS[name]()
    except KeyError:
        raise RobotSkinError(
            f"no robot skin preset {name!r}; presets: {', '.join(SKIN_PRESETS)}"
        ) from None
