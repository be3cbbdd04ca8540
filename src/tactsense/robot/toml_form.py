"""A robot skin in TOML: read and written.

The form::

    name = "hand4"
    description = "..."
    base_link = "palm"
    links = ["palm", "index_proximal", ...]

    [[joints]]
    name = "index_mcp"
    type = "revolute"            # fixed, revolute, continuous, prismatic
    parent = "palm"
    child = "index_proximal"
    xyz_m = [0.03, 0.02, 0.0]    # the child's frame in the parent's at zero position [m]
    rpy_rad = [0.0, 0.0, 0.0]    # URDF roll-pitch-yaw [rad]
    axis = [0.0, 1.0, 0.0]
    lower = 0.0                  # limits [rad or m], optional
    upper = 1.57

    [[sensors]]
    name = "index_tip"
    link = "index_distal"
    xyz_m = [0.0, 0.0, 0.01]     # the sensor's frame in the link's [m]
    rpy_rad = [0.0, 0.0, 0.0]
    device = "board1"            # optional: the board that reads it (default: its name)
    sensor = "pad16"             # a preset, a TOML file (relative to this one) or a table

Every unknown key is an error, named with where it stands.
"""

from __future__ import annotations

import math
import tomllib
from pathlib import Path
from typing import Any

import tomli_w

from tactsense.robot.description import Joint, Patch, Pose, RobotSkin, RobotSkinError
from tactsense.sensor import PRESETS, SensorSpecError, load_sensor, sensor_from_dict

_TOP = {"name", "description", "base_link", "links", "joints", "sensors"}
_JOINT = {"name", "type", "parent", "child", "xyz_m", "rpy_rad", "axis", "lower", "upper"}
_SENSOR = {"name", "link", "xyz_m", "rpy_rad", "device", "sensor"}


def _unknown(table: dict, allowed: set[str], where: str) -> None:
    extra = sorted(set(table) - allowed)
    if extra:
        raise RobotSkinError(
            f"{where}: unknown key(s) {', '.join(extra)}; "
            f"expected some of {', '.join(sorted(allowed))}"
        )


def _required(table: dict, key: str, where: str) -> Any:
    if key not in table:
        raise RobotSkinError(f"{where}: missing {key!r}")
    return table[key]


def _number(table: dict, key: str, default: float, where: str) -> float:
    value = table.get(key, default)
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise RobotSkinError(f"{where}: {key} = {value!r}; expected a number")
    return float(value)


def _pose(table: dict, where: str) -> Pose:
    try:
        return Pose(table.get("xyz_m", (0, 0, 0)), table.get("rpy_rad", (0, 0, 0)))
    except RobotSkinError as error:
        raise RobotSkinError(f"{where}: {error}") from None


def _text(table: dict, key: str, where: str, default: str | None = None) -> str:
    value = _required(table, key, where) if default is None else table.get(key, default)
    if not isinstance(value, str):
        raise RobotSkinError(f"{where}: {key} = {value!r}; expected a string")
    return value


def _tables(data: dict, key: str, source: str) -> list:
    value = data.get(key, [])
    if not isinstance(value, list):
        raise RobotSkinError(
            f"{source}: {key} is a {type(value).__name__}; expected an array of tables ([[{key}]])"
        )
    return value


def _sensor(value: Any, where: str, folder: Path | None):
    try:
        if isinstance(value, dict):
            return sensor_from_dict(dict(value), source=where)
        if isinstance(value, str):
            if value in PRESETS:
                return load_sensor(value)
            path = Path(value)
            if folder is not None and not path.is_absolute():
                path = folder / path
            if path.suffix.lower() == ".toml" or path.exists():
                if not path.exists():
                    raise RobotSkinError(f"{where}: sensor file {path} does not exist")
                return load_sensor(path)
            raise RobotSkinError(
                f"{where}: sensor {value!r} is neither a preset ({', '.join(PRESETS)}) nor a "
                "TOML file"
            )
    except SensorSpecError as error:
        raise RobotSkinError(f"{where}: {error}") from None
    raise RobotSkinError(
        f"{where}: sensor = {value!r}; expected a preset's name, a TOML path or a table"
    )


def skin_from_dict(
    data: dict[str, Any], *, source: str = "robot skin", folder: Path | None = None
) -> RobotSkin:
    """A skin from the TOML form's tables (``folder``: where relative sensor paths start).

    Every error is a :class:`RobotSkinError` that starts with ``source``."""
    try:
        return _skin_from_dict(data, source, folder)
    except RobotSkinError as error:
        if str(error).startswith(source):
            raise
        raise RobotSkinError(f"{source}: {error}") from None


def _skin_from_dict(data: dict[str, Any], source: str, folder: Path | None) -> RobotSkin:
    if not isinstance(data, dict):
        raise RobotSkinError(f"{source}: expected a table, got {type(data).__name__}")
    _unknown(data, _TOP, source)
    joints = []
    for i, table in enumerate(_tables(data, "joints", source)):
        where = f"{source}: joints[{i}]"
        if not isinstance(table, dict):
            raise RobotSkinError(f"{where}: expected a table")
        _unknown(table, _JOINT, where)
        joints.append(
            Joint(
                name=_text(table, "name", where),
                type=_text(table, "type", where),
                parent=_text(table, "parent", where),
                child=_text(table, "child", where),
                origin=_pose(table, where),
                axis=table.get("axis", (1.0, 0.0, 0.0)),
                lower=_number(table, "lower", -math.inf, where),
                upper=_number(table, "upper", math.inf, where),
            )
        )
    patches = []
    for i, table in enumerate(_tables(data, "sensors", source)):
        where = f"{source}: sensors[{i}]"
        if not isinstance(table, dict):
            raise RobotSkinError(f"{where}: expected a table")
        _unknown(table, _SENSOR, where)
        name = _text(table, "name", where)
        patches.append(
            Patch(
                name=name,
                sensor=_sensor(_required(table, "sensor", where), f"{where} ({name})", folder),
                link=_text(table, "link", where),
                origin=_pose(table, where),
                device=_text(table, "device", where, default=""),
            )
        )
    base_link = _text(data, "base_link", source)
    links = data.get("links")
    if links is None:  # the base and every joint's child
        links = [base_link]
        links += [j.child for j in joints if j.child not in links]
    if not isinstance(links, list) or not all(isinstance(v, str) for v in links):
        raise RobotSkinError(f"{source}: links = {links!r}; expected an array of names")
    return RobotSkin(
        name=_text(data, "name", source),
        description=_text(data, "description", source, default=""),
        base_link=base_link,
        links=tuple(links),
        joints=tuple(joints),
        patches=tuple(patches),
    )


def skin_to_dict(skin: RobotSkin) -> dict[str, Any]:
    """The TOML form's tables; each sensor written whole (the file stands alone)."""

    def limits(joint: Joint) -> dict[str, float]:
        out = {}
        if math.isfinite(joint.lower):
            out["lower"] = joint.lower
        if math.isfinite(joint.upper):
            out["upper"] = joint.upper
        return out

    return {
        "name": skin.name,
        "description": skin.description,
        "base_link": skin.base_link,
        "links": list(skin.links),
        "joints": [
            {
                "name": j.name,
                "type": j.type,
                "parent": j.parent,
                "child": j.child,
                "xyz_m": list(j.origin.xyz_m),
                "rpy_rad": list(j.origin.rpy_rad),
                "axis": list(j.axis),
                **limits(j),
            }
            for j in skin.joints
        ],
        "sensors": [
            {
                "name": p.name,
                "link": p.link,
                "xyz_m": list(p.origin.xyz_m),
                "rpy_rad": list(p.origin.rpy_rad),
                "device": p.device,
                "sensor": p.sensor.to_dict(),
            }
            for p in skin.patches
        ],
    }


def skin_to_toml_string(skin: RobotSkin) -> str:
    """The skin as TOML text."""
    return tomli_w.dumps(skin_to_dict(skin))


def skin_from_toml(path: str | Path) -> RobotSkin:
    """A skin from a TOML file, or an error naming the file and what is wrong."""
    path = Path(path)
    try:
        data = tomllib.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise RobotSkinError(f"robot skin file {path} does not exist") from None
    except (OSError, UnicodeDecodeError) as error:
        raise RobotSkinError(f"cannot read {path}: {error}") from None
    except tomllib.TOMLDecodeError as error:
        raise RobotSkinError(f"{path}: not TOML ({error})") from None
    return skin_from_dict(data, source=str(path), folder=path.parent)
