"""A robot's skin described once: links, joints and the tactile sensors on them.

A :class:`RobotSkin` holds several sensors (:class:`Patch`) of any kind, each on a named
link at a pose, and the kinematic tree (:class:`Joint`) that places every link in the
base link's frame for a joint state. The frames:

* a **sensor's frame** is the one its description's taxel positions are written in
  (``spec.taxel_positions_mm()`` [mm], ``spec.taxel_normals()``): for a pad, x along its
  rows, y along its columns, z out of the surface;
* a patch's ``origin`` places the sensor's frame in its link's frame (URDF's
  ``<sensor><origin>``): ``p_link = R p_sensor + t`` [m];
* a joint's ``origin`` places the child link's frame in the parent's at zero joint
  position, then the joint moves it about (revolute) or along (prismatic) its ``axis``,
  written in the child's frame, as URDF defines it.

Positions in the robot are metres (a sensor's own description keeps millimetres);
angles are radians.
"""

from __future__ import annotations

import math
import re
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from tactsense._validation import TactsenseInputError
from tactsense.sensor.common import SpecBase

JOINT_TYPES = ("fixed", "revolute", "continuous", "prismatic")
"""The URDF joint types a skin's tree may hold (floating and planar joints are refused)."""


_NAME = re.compile(r"[A-Za-z0-9][A-Za-z0-9_.-]{0,63}")
_FRAME_NAME = re.compile(r"[A-Za-z0-9_][A-Za-z0-9_.:/+-]{0,127}")
"""A link's or joint's name: URDF/ROS frame names without spaces or XML's special signs."""


class RobotSkinError(TactsenseInputError):
    """A robot skin description that is invalid: says what was wrong and what was expected."""


def _triple(value: Any, what: str) -> tuple[float, float, float]:
    try:
        values = tuple(float(v) for v in value)
    except (TypeError, ValueError):
        values = ()
    if len(values) != 3 or not all(math.isfinite(v) for v in values):
        raise RobotSkinError(f"{what} = {value!r}: expected three finite numbers")
    return values  # type: ignore[return-value]


def rotation_matrix(rpy_rad: tuple[float, float, float]) -> np.ndarray:
    """URDF's fixed-axis roll-pitch-yaw as a rotation: R = Rz(yaw) Ry(pitch) Rx(roll)."""
    roll, pitch, yaw = rpy_rad
    cr, sr, cp, sp = math.cos(roll), math.sin(roll), math.cos(pitch), math.sin(pitch)
    cy, sy = math.cos(yaw), math.sin(yaw)
    return np.array(
        [
            [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
            [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
            [-sp, cp * sr, cp * cr],
        ]
    )


def rpy_from_matrix(rotation: np.ndarray) -> tuple[float, float, float]:
    """URDF roll-pitch-yaw [rad] of a rotation matrix (the inverse of :func:`rotation_matrix`).

    At pitch = +-pi/2 (gimbal lock) roll is taken as 0 and yaw carries the whole turn.
    """
    r = np.asarray(rotation, dtype=float)
    pitch = -math.asin(max(-1.0, min(1.0, float(r[2, 0]))))
    if abs(math.cos(pitch)) < 1e-9:
        return 0.0, pitch, math.atan2(-float(r[0, 1]), float(r[1, 1]))
    roll = math.atan2(float(r[2, 1]), float(r[2, 2]))
    yaw = math.atan2(float(r[1, 0]), float(r[0, 0]))
    return roll, pitch, yaw


def axis_rotation(axis: np.ndarray, angle_rad: float) -> np.ndarray:
    """Rotation by ``angle_rad`` about the unit vector ``axis`` (Rodrigues)."""
    x, y, z = axis
    k = np.array([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]])
    return np.eye(3) + math.sin(angle_rad) * k + (1.0 - math.cos(angle_rad)) * (k @ k)


def _frame_name(name: object) -> bool:
    return isinstance(name, str) and _FRAME_NAME.fullmatch(name) is not None


@dataclass(frozen=True)
class Pose:
    """A rigid placement: translation [m] and URDF roll-pitch-yaw [rad]."""

    xyz_m: tuple[float, float, float] = (0.0, 0.0, 0.0)
    rpy_rad: tuple[float, float, float] = (0.0, 0.0, 0.0)

    def __post_init__(self) -> None:
        object.__setattr__(self, "xyz_m", _triple(self.xyz_m, "xyz_m"))
        object.__setattr__(self, "rpy_rad", _triple(self.rpy_rad, "rpy_rad"))

    def matrix(self) -> np.ndarray:
        """The 4 x 4 homogeneous transform (rotation, then translation [m])."""
        out = np.eye(4)
        out[:3, :3] = rotation_matrix(self.rpy_rad)
        out[:3, 3] = self.xyz_m
        return out


@dataclass(frozen=True)
class Joint:
    """One joint of the kinematic tree, as URDF defines it.

    Attributes
    ----------
    name, parent, child : str
        The joint's name and the links it joins.
    type : {"fixed", "revolute", "continuous", "prismatic"}
    origin : Pose
        The child link's frame in the parent's at zero joint position.
    axis : (3,) tuple
        Axis of rotation or translation in the child's (= joint's) frame, unit length.
    lower, upper : float
        Limits [rad or m]; ``-inf``/``inf`` when none (continuous, fixed).
    """

    name: str
    type: str
    parent: str
    child: str
    origin: Pose = field(default_factory=Pose)
    axis: tuple[float, float, float] = (1.0, 0.0, 0.0)
    lower: float = -math.inf
    upper: float = math.inf

    def __post_init__(self) -> None:
        if self.type not in JOINT_TYPES:
            raise RobotSkinError(
                f"joint {self.name!r}: type {self.type!r}; expected one of {', '.join(JOINT_TYPES)}"
            )
        axis = np.asarray(_triple(self.axis, f"joint {self.name!r} axis"))
        norm = float(np.linalg.norm(axis))
        if self.type != "fixed" and norm == 0.0:
            raise RobotSkinError(f"joint {self.name!r}: axis is zero; expected a direction")
        if norm > 0:
            object.__setattr__(self, "axis", tuple(float(v) for v in axis / norm))
        for which in ("lower", "upper"):
            value = getattr(self, which)
            try:
                value = float(value)
            except (TypeError, ValueError):
                value = math.nan
            if math.isnan(value):
                raise RobotSkinError(
                    f"joint {self.name!r}: {which} limit {getattr(self, which)!r} is not a "
                    "number [rad or m]"
                )
            object.__setattr__(self, which, value)
        if not self.lower <= self.upper:
            raise RobotSkinError(
                f"joint {self.name!r}: lower limit {self.lower} is above upper limit {self.upper}"
            )

    def motion(self, position: float) -> np.ndarray:
        """The 4 x 4 transform of the joint's own motion at ``position`` [rad or m]."""
        out = np.eye(4)
        if self.type in ("revolute", "continuous"):
            out[:3, :3] = axis_rotation(np.asarray(self.axis), position)
        elif self.type == "prismatic":
            out[:3, 3] = np.asarray(self.axis) * position
        return out


@dataclass(frozen=True)
class Patch:
    """One tactile sensor on a link.

    Attributes
    ----------
    name : str
        The patch's name in the skin (unique); its stream's name in a recording.
    sensor : SpecBase
        The sensor's description (any kind).
    link : str
        The link it is mounted on.
    origin : Pose
        The sensor's frame in the link's frame.
    device : str
        The board that reads it (patches with the same device come over one stream);
        defaults to the patch's own name: one device per patch.
    """

    name: str
    sensor: SpecBase
    link: str
    origin: Pose = field(default_factory=Pose)
    device: str = ""

    def __post_init__(self) -> None:
        if not isinstance(self.name, str) or not _NAME.fullmatch(self.name):
            raise RobotSkinError(
                f"patch name {self.name!r}: expected letters, digits, '_', '-' or '.', starting "
                "with a letter or digit (it names the patch's stream and file)"
            )
        if not isinstance(self.sensor, SpecBase):
            raise RobotSkinError(
                f"patch {self.name!r}: sensor is a {type(self.sensor).__name__}; expected a "
                "sensor description (tactsense.sensor)"
            )
        if not self.device:
            object.__setattr__(self, "device", self.name)
        if not isinstance(self.device, str) or not _NAME.fullmatch(self.device):
            raise RobotSkinError(
                f"patch {self.name!r}: device name {self.device!r}: expected letters, digits, "
                "'_', '-' or '.', starting with a letter or digit"
            )

    @property
    def n_taxels(self) -> int:
        return self.sensor.n_taxels

    def taxels_in_link(self) -> tuple[np.ndarray, np.ndarray]:
        """Taxel positions [m] and outward unit normals in the link's frame, (N, 3) each."""
        rotation = rotation_matrix(self.origin.rpy_rad)
        positions = np.asarray(self.sensor.taxel_positions_mm(), float) * 1e-3
        normals = np.asarray(self.sensor.taxel_normals(), float)
        return positions @ rotation.T + np.asarray(self.origin.xyz_m), normals @ rotation.T


@dataclass(frozen=True)
class RobotSkin:
    """Several tactile sensors on the links of one robot, and its kinematic tree.

    Attributes
    ----------
    name, description : str
    base_link : str
        The root of the tree: the frame "base" positions are written in.
    links : tuple of str
        Every link (the base and each joint's child).
    joints : tuple of Joint
    patches : tuple of Patch
    """

    name: str
    base_link: str
    links: tuple[str, ...]
    joints: tuple[Joint, ...] = ()
    patches: tuple[Patch, ...] = ()
    description: str = ""

    def __post_init__(self) -> None:
        object.__setattr__(self, "links", tuple(self.links))
        object.__setattr__(self, "joints", tuple(self.joints))
        object.__setattr__(self, "patches", tuple(self.patches))
        problems = self.problems()
        if problems:
            raise RobotSkinError(
                f"invalid robot skin {self.name!r}:\n  - " + "\n  - ".join(problems)
            )

    def problems(self) -> list[str]:
        """Everything wrong with the description, one line each (empty: it is valid)."""
        problems: list[str] = []
        links = set(self.links)
        if len(links) != len(self.links):
            twice = sorted({name for name in self.links if self.links.count(name) > 1})
            problems.append(f"link(s) named twice: {', '.join(map(repr, twice))}")
        bad = [name for name in self.links if not _frame_name(name)]
        bad += [j.name for j in self.joints if not _frame_name(j.name)]
        for name in bad:
            problems.append(
                f"name {name!r}: a link or joint name is letters, digits and _ . : / + -, "
                "without spaces (at most 128)"
            )
        if self.base_link not in links:
            problems.append(f"base_link {self.base_link!r} is not one of the links")
        children: dict[str, str] = {}
        names: set[str] = set()
        for joint in self.joints:
            if joint.name in names:
                problems.append(f"joint {joint.name!r} is named twice")
            names.add(joint.name)
            for end in (joint.parent, joint.child):
                if end not in links:
                    problems.append(f"joint {joint.name!r}: link {end!r} is not one of the links")
            if joint.child in children:
                problems.append(
                    f"link {joint.child!r} is the child of two joints "
                    f"({children[joint.child]!r} and {joint.name!r}); a tree has one parent"
                )
            children[joint.child] = joint.name
        if self.base_link in children:
            problems.append(f"base_link {self.base_link!r} is a joint's child")
        cycle = self._cycle()
        if cycle:
            problems.append("the joints close a loop: " + " -> ".join(cycle) + "; a tree has none")
        if not problems:
            unreached = links - set(self._order())
            if unreached:
                problems.append("links not joined to the base: " + ", ".join(sorted(unreached)))
        patch_names: set[str] = set()
        for patch in self.patches:
            if patch.name in patch_names:
                problems.append(f"patch {patch.name!r} is named twice")
            patch_names.add(patch.name)
            if patch.link not in links:
                problems.append(
                    f"patch {patch.name!r}: link {patch.link!r} is not one of the links"
                )
        if not self.patches:
            problems.append("no sensors: a skin holds at least one")
        return problems

    # ---- the tree --------------------------------------------------------------
    def _cycle(self) -> list[str]:
        """Links on a loop of joints (parent -> child), the first found; [] when none."""
        children: dict[str, list[str]] = {}
        for joint in self.joints:
            children.setdefault(joint.parent, []).append(joint.child)
        state: dict[str, int] = {}  # 1: on the current path, 2: done
        for start in children:
            if state.get(start):
                continue
            path, stack = [start], [iter(children.get(start, []))]
            state[start] = 1
            while stack:
                child = next(stack[-1], None)
                if child is None:
                    state[path.pop()] = 2
                    stack.pop()
                elif state.get(child) == 1:
                    return [*path[path.index(child) :], child]
                elif not state.get(child):
                    state[child] = 1
                    path.append(child)
                    stack.append(iter(children.get(child, [])))
        return []

    def _order(self) -> list[str]:
        """Links from the base outwards (each after its parent)."""
        by_parent: dict[str, list[Joint]] = {}
        for joint in self.joints:
            by_parent.setdefault(joint.parent, []).append(joint)
        order, todo = [], [self.base_link]
        while todo:
            link = todo.pop(0)
            if link in order:
                continue
            order.append(link)
            todo.extend(j.child for j in by_parent.get(link, []))
        return order

    @property
    def movable_joints(self) -> tuple[str, ...]:
        """Names of the joints that move (not fixed), in description order."""
        return tuple(j.name for j in self.joints if j.type != "fixed")

    def rest_joint_positions(self) -> dict[str, float]:
        """Each movable joint at 0, or at its nearer limit when 0 is outside its limits
        (Allegro's thumb rotation, for one) [rad or m]: a valid state to start from."""
        return {
            j.name: float(min(max(0.0, j.lower), j.upper)) for j in self.joints if j.type != "fixed"
        }

    def link_poses(
        self, joint_positions: Mapping[str, float] | None = None
    ) -> dict[str, np.ndarray]:
        """Every link's frame in the base frame, 4 x 4, for a joint state.

        Parameters
        ----------
        joint_positions : mapping, optional
            Position of each movable joint [rad or m]; joints left out are at 0. A name
            that is not a movable joint, a non-finite value or one outside the joint's
            limits is an error.
        """
        positions = dict(joint_positions or {})
        movable = {j.name: j for j in self.joints if j.type != "fixed"}
        for name, value in positions.items():
            if name not in movable:
                raise RobotSkinError(
                    f"joint position for {name!r}: not a movable joint of {self.name!r}; "
                    f"expected one of {', '.join(movable) or '(none)'}"
                )
            value = float(value)
            joint = movable[name]
            if not math.isfinite(value) or not joint.lower - 1e-9 <= value <= joint.upper + 1e-9:
                raise RobotSkinError(
                    f"joint {name!r} at {value}: outside its limits "
                    f"[{joint.lower}, {joint.upper}] [rad or m]"
                )
            positions[name] = value
        by_child = {j.child: j for j in self.joints}
        poses: dict[str, np.ndarray] = {}
        for link in self._order():
            joint = by_child.get(link)
            if joint is None:
                poses[link] = np.eye(4)
                continue
            poses[link] = (
                poses[joint.parent]
                @ joint.origin.matrix()
                @ joint.motion(positions.get(joint.name, 0.0))
            )
        return poses

    # ---- the sensors -----------------------------------------------------------
    @property
    def n_taxels(self) -> int:
        """Taxels of every patch together [-]."""
        return sum(p.n_taxels for p in self.patches)

    def patch(self, name: str) -> Patch:
        """The patch called ``name``, or an error listing the patches."""
        for patch in self.patches:
            if patch.name == name:
                return patch
        raise RobotSkinError(
            f"{self.name!r} has no patch {name!r}; its patches: "
            + ", ".join(p.name for p in self.patches)
        )

    @property
    def devices(self) -> dict[str, tuple[str, ...]]:
        """Each device (board) and the patches it reads, in description order."""
        out: dict[str, list[str]] = {}
        for patch in self.patches:
            out.setdefault(patch.device, []).append(patch.name)
        return {device: tuple(names) for device, names in out.items()}

    def patch_pose(
        self, name: str, joint_positions: Mapping[str, float] | None = None
    ) -> np.ndarray:
        """A patch's sensor frame in the base frame, 4 x 4, for a joint state."""
        patch = self.patch(name)
        return self.link_poses(joint_positions)[patch.link] @ patch.origin.matrix()

    def taxels_in_base(
        self, joint_positions: Mapping[str, float] | None = None
    ) -> dict[str, tuple[np.ndarray, np.ndarray]]:
        """Every patch's taxel positions [m] and unit normals in the base frame, (N, 3)."""
        poses = self.link_poses(joint_positions)
        out = {}
        for patch in self.patches:
            positions, normals = patch.taxels_in_link()
            pose = poses[patch.link]
            out[patch.name] = (
                positions @ pose[:3, :3].T + pose[:3, 3],
                normals @ pose[:3, :3].T,
            )
        return out
