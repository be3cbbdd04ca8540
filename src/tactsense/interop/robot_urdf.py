"""A whole robot's skin in URDF: links, joints and several tactile sensors, read and written.

The form is URDF's (``<link>``, ``<joint>`` with ``<origin>``, ``<axis>``, ``<limit>``)
with one ``<sensor>`` per patch in the ROS tactile toolbox's form (``urdf_tactile``)::

    <sensor name="index_tip" update_rate="250" tactsense:device="board_index">
      <parent link="index_distal"/>
      <origin xyz="0 0 0.0267" rpy="0 0 0"/>
      <tactile channel="index_tip"> <array .../> or <taxel .../>... </tactile>
    </sensor>

The sensor's ``<origin>`` is the patch's: its frame in the link's. The ``<tactile>``
element is :func:`tactsense.interop.urdf.sensor_to_urdf`'s (a pad as an ``<array>``,
anything else as a ``<taxel>`` list), its ``channel`` the patch's name (the
``TactileState`` channel that carries its data). The board that reads a patch has no
place in URDF: it is kept in a namespaced attribute ``tactsense:device``, which other
URDF readers ignore.

What URDF does not hold: a sensor's physics (elastic layer, transduction, electronics
beyond the scan rate, flaws). The file written here keeps each sensor's whole description
(its TOML) in a ``<tactsense:sensor format="toml">`` child of its ``<sensor>`` (other
readers skip it), so a round trip gives it back. A sensor without one takes them from a
preset (``extends``), as ``tactsense sensor import`` does for one sensor, with an
:class:`UrdfPhysicsWarning` saying which.
"""

from __future__ import annotations

import math
import os
import warnings
import xml.etree.ElementTree as ET
from collections.abc import Mapping
from pathlib import Path

import numpy as np

from tactsense._validation import TactsenseInputError
from tactsense.interop.urdf import read_tactile_arrays, read_tactile_taxels, sensor_to_urdf
from tactsense.kinds import kind_of
from tactsense.kinds.urdf import UrdfError
from tactsense.robot import (
    JOINT_TYPES,
    SKIN_PRESETS,
    Joint,
    Patch,
    Pose,
    RobotSkin,
    RobotSkinError,
    load_skin,
    rotation_matrix,
)
from tactsense.sensor import PRESETS, preset

__all__ = [
    "TACTSENSE_URDF_NS",
    "UrdfPhysicsWarning",
    "load_robot_skin",
    "read_robot_urdf",
    "robot_skin_to_urdf",
    "write_robot_urdf",
]

TACTSENSE_URDF_NS = "https://github.com/tactsense/urdf"
"""XML namespace of tactsense's own URDF attributes (``tactsense:device``)."""

ET.register_namespace("tactsense", TACTSENSE_URDF_NS)
_DEVICE = f"{{{TACTSENSE_URDF_NS}}}device"
_SENSOR = f"{{{TACTSENSE_URDF_NS}}}sensor"
_SAME_PLACE_MM = 1e-6
"""A sensor's own description must place its taxels where the URDF's geometry does,
within this [mm] (the geometry is written to 15 significant digits)."""


class UrdfPhysicsWarning(UserWarning):
    """A URDF's sensor without tactsense's own description: its physics (layer,
    transduction, electronics, flaws) come from a preset."""


DEFAULT_EXTENDS = {"array": "pad16", "taxels": "dome12"}
"""The preset a sensor's physics come from when ``extends`` does not name one."""


def _local(element) -> str:
    return element.tag.rsplit("}", 1)[-1]


def _child(element, tag: str):
    return next((c for c in element if _local(c) == tag), None)


def _numbers(element, attribute: str, count: int, default: str, where: str) -> tuple:
    text = default if element is None else element.get(attribute, default)
    try:
        values = tuple(float(v) for v in text.split())
    except ValueError:
        values = ()
    if len(values) != count or not all(math.isfinite(v) for v in values):
        raise UrdfError(f"{where}: {attribute}={text!r}; expected {count} finite numbers")
    return values


def _pose(element, where: str) -> Pose:
    origin = _child(element, "origin")
    return Pose(
        _numbers(origin, "xyz", 3, "0 0 0", f"{where} <origin>"),
        _numbers(origin, "rpy", 3, "0 0 0", f"{where} <origin>"),
    )


def _name(element, what: str, where: str) -> str:
    name = element.get("name")
    if not name:
        raise UrdfError(f"{where}: a <{what}> has no name")
    return name


def _link_of(element, tag: str, where: str) -> str:
    found = _child(element, tag)
    if found is None or not found.get("link"):
        raise UrdfError(f"{where}: no <{tag} link=...>")
    return found.get("link")


def _limit(limit, attribute: str, where: str) -> float:
    text = limit.get(attribute, "0")  # URDF: lower and upper default to 0
    try:
        value = float(text)
    except ValueError:
        raise UrdfError(f"{where}: <limit {attribute}={text!r}> is not a number") from None
    if math.isnan(value):
        raise UrdfError(f"{where}: <limit {attribute}={text!r}> is not a number")
    return value


def _joint(element, source: str) -> Joint:
    name = _name(element, "joint", source)
    where = f"{source}: joint {name!r}"
    kind = element.get("type")
    if kind not in JOINT_TYPES:
        raise UrdfError(
            f"{where}: type {kind!r}; a skin's tree holds {', '.join(JOINT_TYPES)} joints "
            "(floating and planar ones are not supported)"
        )
    lower, upper = -math.inf, math.inf
    if kind in ("revolute", "prismatic"):
        limit = _child(element, "limit")
        if limit is None:
            raise UrdfError(f"{where}: a {kind} joint needs a <limit> (URDF requires it)")
        lower, upper = _limit(limit, "lower", where), _limit(limit, "upper", where)
    axis = _numbers(_child(element, "axis"), "xyz", 3, "1 0 0", f"{where} <axis>")
    try:
        return Joint(
            name=name,
            type=kind,
            parent=_link_of(element, "parent", where),
            child=_link_of(element, "child", where),
            origin=_pose(element, where),
            axis=axis,
            lower=lower,
            upper=upper,
        )
    except RobotSkinError as error:
        raise UrdfError(f"{source}: {error}") from None


def _shifted(origin: Pose, offset_m: tuple[float, float]) -> Pose:
    """The sensor frame of an ``<array>`` with an ``offset``: the toolbox puts taxel (row,
    col) at (row * spacing.x - offset.x, col * spacing.y - offset.y, 0) in the sensor's
    frame (``TaxelInfoIterator``), a sensor description at (row * pitch, col * pitch), so
    the frame moves by -offset."""
    if not any(offset_m):
        return origin
    shift = rotation_matrix(origin.rpy_rad) @ np.array([-offset_m[0], -offset_m[1], 0.0])
    return Pose(tuple(float(v) for v in np.asarray(origin.xyz_m) + shift), origin.rpy_rad)


def _preset_for(extends, name: str, form: str) -> str:
    if isinstance(extends, Mapping):
        chosen = extends.get(name)
    else:
        chosen = extends
    chosen = chosen or DEFAULT_EXTENDS[form]
    if chosen not in PRESETS:
        raise UrdfError(
            f"sensor {name!r}: extends {chosen!r} is not a sensor preset ({', '.join(PRESETS)})"
        )
    return chosen


def _names_preset(extends, name: str) -> bool:
    """Whether ``extends`` names this sensor's preset (one for all, or by name)."""
    if isinstance(extends, Mapping):
        return bool(extends.get(name))
    return bool(extends)


def _own_description(element, geometric, where: str):
    """The sensor's whole description kept in a ``<tactsense:sensor format="toml">``
    child, checked to place its taxels where the URDF's geometry does."""
    from tactsense.sensor import SpecBase

    if element.get("format", "toml") != "toml":
        raise UrdfError(
            f"{where}: <tactsense:sensor format={element.get('format')!r}>: only 'toml' is read"
        )
    try:
        spec = SpecBase.from_toml_string(element.text or "")
    except TactsenseInputError as error:
        raise UrdfError(f"{where}: its <tactsense:sensor> description: {error}") from None
    mine = np.asarray(spec.taxel_positions_mm(), float)
    theirs = np.asarray(geometric.taxel_positions_mm(), float)
    if mine.shape != theirs.shape or not np.allclose(mine, theirs, rtol=0, atol=_SAME_PLACE_MM):
        raise UrdfError(
            f"{where}: its <tactsense:sensor> description places {len(mine)} taxels, not where "
            f"the URDF's geometry places its {len(theirs)} (was one edited?); fix the "
            "description or remove it (the physics then come from a preset)"
        )
    return spec


def read_robot_urdf(
    path: str | Path, *, extends: str | Mapping[str, str] | None = None
) -> RobotSkin:
    """A robot skin from a URDF file: every link, joint and tactile ``<sensor>``.

    Parameters
    ----------
    path : path
        The URDF file.
    extends : str or mapping, optional
        The sensor preset that gives each sensor what a URDF does not hold (its layer,
        transduction, electronics, flaws): one preset for every sensor, or a mapping
        ``{sensor name: preset}``. Sensors not named take ``pad16`` for an ``<array>`` and
        ``dome12`` for a ``<taxel>`` list. The preset's kind must fit the form (a pad or a
        finger for an ``<array>``; a point set or a finger for a ``<taxel>`` list).

    Returns
    -------
    RobotSkin
        Base link: the one link that is no joint's child. Every problem of the
        description (unknown links, two parents, loops, names) is a
        :class:`~tactsense.kinds.urdf.UrdfError` naming the file.
    """
    path = Path(path)
    source = str(path)
    try:
        root = ET.parse(path).getroot()
    except ET.ParseError as error:
        raise UrdfError(f"{path}: not XML ({error})") from None
    except OSError as error:
        raise UrdfError(f"cannot read {path}: {error.strerror or error}") from None
    if _local(root) != "robot":
        raise UrdfError(f"{path}: the root element is <{_local(root)}>; a URDF's is <robot>")
    robot_name = root.get("name") or path.stem
    links = [_name(e, "link", source) for e in root if _local(e) == "link"]
    joints = [_joint(e, source) for e in root if _local(e) == "joint"]
    children = {j.child for j in joints}
    roots = [link for link in links if link not in children]
    if len(roots) != 1:
        raise UrdfError(
            f"{path}: {len(roots)} links are no joint's child ({', '.join(roots) or 'none'}); "
            "a robot's tree has exactly one root"
        )
    arrays = {a.name: a for a in read_tactile_arrays(path)}
    lists = {t.name: t for t in read_tactile_taxels(path)}
    patches, seen = [], set()
    from_presets: dict[str, list[str]] = {}
    for element in root.iter():
        if _local(element) != "sensor" or _child(element, "tactile") is None:
            continue
        name = _name(element, "sensor", source)
        where = f"{source}: sensor {name!r}"
        if name in seen:
            raise UrdfError(f"{where} is described twice")
        seen.add(name)
        form = "array" if name in arrays else "taxels" if name in lists else None
        if form is None:
            raise UrdfError(f"{where}: its <tactile> holds neither an <array> nor <taxel>s")
        chosen = _preset_for(extends, name, form)
        base = preset(chosen)
        if form == "array":
            spec = kind_of(base).from_urdf_array(arrays[name], base, path=path, preset=chosen)
        else:
            spec = kind_of(base).from_urdf_taxels(lists[name], base, path=path)
        if spec is None:
            raise UrdfError(
                f"{where}: a {'<taxel> list' if form == 'taxels' else '<array>'} cannot "
                f"extend preset {chosen!r} (a {base.kind}); name a preset of a kind that fits"
            )
        own = element.find(_SENSOR)
        if own is not None and not _names_preset(extends, name):
            spec = _own_description(own, spec, where)
        elif not _names_preset(extends, name):
            from_presets.setdefault(chosen, []).append(name)
        try:
            origin = _pose(element, where)
            if form == "array":
                origin = _shifted(origin, arrays[name].offset_m)
            patches.append(
                Patch(
                    name=name,
                    sensor=spec,
                    link=_link_of(element, "parent", where),
                    origin=origin,
                    device=element.get(_DEVICE, ""),
                )
            )
        except RobotSkinError as error:
            raise UrdfError(f"{source}: {error}") from None
    if from_presets:
        listed = "; ".join(f"{', '.join(names)} from {p!r}" for p, names in from_presets.items())
        warnings.warn(
            UrdfPhysicsWarning(
                f"{path}: the URDF gives these sensors' geometry and rate but not their "
                f"physics (layer, transduction, electronics, flaws), taken from presets: "
                f"{listed} (name the right ones with extends; a URDF written by tactsense "
                "keeps each sensor's whole description)"
            ),
            stacklevel=2,
        )
    try:
        return RobotSkin(
            name=robot_name,
            base_link=roots[0],
            links=tuple(links),
            joints=tuple(joints),
            patches=tuple(patches),
            description=f"read from {path.name}",
        )
    except RobotSkinError as error:
        raise UrdfError(f"{path}: {error}") from None


def _g(value: float) -> str:
    return repr(float(value)) if math.isfinite(value) else ("inf" if value > 0 else "-inf")


def _xyz(values) -> str:
    return " ".join(_g(v) for v in values)


def robot_skin_to_urdf(skin: RobotSkin) -> str:
    """The skin as a URDF document: every link, joint and sensor.

    Numbers are written in full (``repr``), so reading the file back gives the same
    kinematics to the last bit; the sensors' geometry is written as
    :func:`~tactsense.interop.urdf.sensor_to_urdf` writes one sensor (15 significant
    digits). A revolute or prismatic joint without limits gets ``lower="-inf"``
    ``upper="inf"`` (URDF requires a ``<limit>``; effort and velocity are written 0,
    unknown).
    """
    root = ET.Element("robot", name=skin.name)
    root.append(
        ET.Comment(
            f" tactsense robot skin {skin.name!r}: {skin.n_taxels} taxels in "
            f"{len(skin.patches)} sensors. {skin.description} "
        )
    )
    for link in skin.links:
        ET.SubElement(root, "link", name=link)
    for joint in skin.joints:
        element = ET.SubElement(root, "joint", name=joint.name, type=joint.type)
        ET.SubElement(element, "parent", link=joint.parent)
        ET.SubElement(element, "child", link=joint.child)
        ET.SubElement(
            element, "origin", xyz=_xyz(joint.origin.xyz_m), rpy=_xyz(joint.origin.rpy_rad)
        )
        ET.SubElement(element, "axis", xyz=_xyz(joint.axis))  # a fixed joint ignores it
        if joint.type in ("revolute", "prismatic"):
            ET.SubElement(
                element,
                "limit",
                lower=_g(joint.lower),
                upper=_g(joint.upper),
                effort="0",
                velocity="0",
            )
    for patch in skin.patches:
        single = ET.fromstring(sensor_to_urdf(patch.sensor, link=patch.link))
        sensor = _child(single, "sensor")
        sensor.set("name", patch.name)
        sensor.set(_DEVICE, patch.device)
        origin = _child(sensor, "origin")
        origin.set("xyz", _xyz(patch.origin.xyz_m))
        origin.set("rpy", _xyz(patch.origin.rpy_rad))
        _child(sensor, "tactile").set("channel", patch.name)
        own = ET.SubElement(sensor, _SENSOR, format="toml")  # other readers skip it
        own.text = "\n" + patch.sensor.to_toml_string()
        root.append(sensor)
    ET.indent(root)
    return '<?xml version="1.0" encoding="utf-8"?>\n' + ET.tostring(root, encoding="unicode") + "\n"


def write_robot_urdf(skin: RobotSkin, path: str | Path) -> Path:
    """Write :func:`robot_skin_to_urdf` to ``path`` (a temporary name, then moved)."""
    path = Path(path)
    text = robot_skin_to_urdf(skin)
    temporary = path.with_name(f".{path.stem}.{os.getpid()}.partial{path.suffix}")
    try:
        temporary.write_text(text, encoding="utf-8")
        os.replace(temporary, path)
    except BaseException:
        temporary.unlink(missing_ok=True)
        raise
    return path


def load_robot_skin(
    source: str | Path | RobotSkin, *, extends: str | Mapping[str, str] | None = None
) -> RobotSkin:
    """A skin from a preset's name, a skin TOML or a URDF file (``*.urdf``), or one built.

    :func:`tactsense.robot.load_skin` reads presets and TOML; this adds URDF (``extends``:
    as :func:`read_robot_urdf`'s). Commands that take a ``SKIN`` argument read it here.
    """
    if isinstance(source, RobotSkin):
        return source
    text = str(source)
    if text not in SKIN_PRESETS and Path(text).suffix.lower() == ".urdf":
        if not Path(text).is_file():
            raise UrdfError(f"robot skin file {text} does not exist")
        return read_robot_urdf(text, extends=extends)
    return load_skin(text)
