"""A robot's skin: many tactile sensors of any kind on the links of one robot.

:class:`RobotSkin` describes them once (sensors, links, poses, the kinematic tree);
:func:`load_skin` reads one from a preset's name or a TOML file;
:func:`tactsense.interop.robot_urdf.load_robot_skin` also from a URDF file. Presets:
``hand4`` (the Allegro Hand's kinematics, 20 patches, 4,000 taxels) and ``icub_hand``
(iCub's right hand and its five fingertips); sources in :mod:`tactsense.robot.presets`.
"""

from __future__ import annotations

from pathlib import Path

from tactsense.robot.description import (
    JOINT_TYPES,
    Joint,
    Patch,
    Pose,
    RobotSkin,
    RobotSkinError,
    rotation_matrix,
    rpy_from_matrix,
)
from tactsense.robot.presets import SKIN_PRESETS, skin_preset
from tactsense.robot.toml_form import (
    skin_from_dict,
    skin_from_toml,
    skin_to_dict,
    skin_to_toml_string,
)


def load_skin(source: str | Path | RobotSkin) -> RobotSkin:
    """A robot skin from a preset's name, a TOML file, or one already built."""
    if isinstance(source, RobotSkin):
        return source
    text = str(source)
    if text in SKIN_PRESETS:
        return skin_preset(text)
    path = Path(text)
    if path.suffix.lower() == ".toml" or path.exists():
        return skin_from_toml(path)
    raise RobotSkinError(
        f"robot skin {text!r} is neither a preset ({', '.join(SKIN_PRESETS)}) nor a TOML file"
    )


__all__ = [
    "JOINT_TYPES",
    "SKIN_PRESETS",
    "Joint",
    "Patch",
    "Pose",
    "RobotSkin",
    "RobotSkinError",
    "load_skin",
    "rotation_matrix",
    "rpy_from_matrix",
    "skin_from_dict",
    "skin_from_toml",
    "skin_preset",
    "skin_to_dict",
    "skin_to_toml_string",
]
