"""Where a grasped object touches a robot's skin: objects, their signed distance, and
the contact each patch feels.

An object (:class:`GraspObject`: a sphere, a cylinder or a box, its size [mm] and its
pose in the robot's base frame) is tested against a dense sample of every patch's
surface: each taxel carries a small square of points in its tangent plane (``SAMPLES``
by ``SAMPLES`` points over the square of side the distance to its nearest neighbour), so
a pad's sample covers the pad (to half a pitch beyond its outer taxels) and a curved
point set's is a set of tangent facets. A sample point inside the object is pressed in
by its penetration depth (the object's signed distance, negated [mm]).

A patch's contact is the penetration-weighted centroid of its points inside the object
(its centre of pressure for a pressure that grows with the depth), with the weighted
mean of their outward normals as its normal; the penetration volume (sum of depth times
the area a point stands for [mm^3]) shares a finger's force among its patches.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from tactsense._validation import TactsenseInputError
from tactsense.robot import Pose

OBJECTS = ("sphere", "cylinder", "box")
"""The shapes of a grasped object."""

SIZES = {
    "sphere": ("diameter",),
    "cylinder": ("diameter", "length"),
    "box": ("x", "y", "z"),
}
"""What an object's ``size_mm`` lists [mm], per shape: a sphere's diameter; a cylinder's
diameter and length (its axis along the object's own z); a box's edges along its own x,
y and z."""

SAMPLES = 7
"""Sample points per taxel along each tangent direction [-]."""

FLAT_BOX_SHAPE = "disc"
"""The indenter a box's face presses with: uniform pressure on a disc of the contact's
area (a flat face has no curvature; see :func:`PatchContact.radius_mm`)."""


class GraspError(TactsenseInputError):
    """A grasp that cannot be simulated: a bad object, pose, force or joint state."""


@dataclass(frozen=True)
class GraspObject:
    """A rigid object held in the hand.

    Attributes
    ----------
    shape : {"sphere", "cylinder", "box"}
    size_mm : tuple of float
        :data:`SIZES`: a sphere's diameter, a cylinder's diameter and length, a box's
        three edges [mm], each > 0.
    pose : Pose
        The object's frame in the robot's base frame (translation [m], URDF roll-pitch-
        yaw [rad]); its centre at the origin, a cylinder's axis along its z.
    """

    shape: str
    size_mm: tuple[float, ...]
    pose: Pose = field(default_factory=Pose)

    def __post_init__(self) -> None:
        if self.shape not in OBJECTS:
            raise GraspError(f"object {self.shape!r}: expected one of {', '.join(OBJECTS)}")
        names = SIZES[self.shape]
        try:
            size = tuple(float(v) for v in self.size_mm)
        except (TypeError, ValueError):
            size = ()
        if len(size) != len(names) or not all(math.isfinite(v) and v > 0 for v in size):
            raise GraspError(
                f"{self.shape} size {self.size_mm!r}: expected {len(names)} number(s) > 0 "
                f"[mm] ({', '.join(names)})"
            )
        if max(size) > 10_000.0:
            raise GraspError(f"{self.shape} size {size}: at most 10,000 mm (10 m) each")
        if not isinstance(self.pose, Pose):
            raise GraspError(f"object pose must be a tactsense.robot.Pose; got {self.pose!r}")
        object.__setattr__(self, "size_mm", size)

    @property
    def curvature_radius_mm(self) -> float | None:
        """The radius of the indenter it presses with [mm]: a sphere's radius, a
        cylinder's across its axis; None for a box (a flat face)."""
        if self.shape == "box":
            return None
        return 0.5 * self.size_mm[0]

    def signed_distance_mm(self, points_mm: np.ndarray) -> np.ndarray:
        """Signed distance of points in the base frame [mm] to the object's surface [mm],
        (M,): negative inside (exact for every shape, corners and rims included)."""
        matrix = self.pose.matrix()
        centre = 1e3 * matrix[:3, 3]
        local = (np.asarray(points_mm, float) - centre) @ matrix[:3, :3]
        if self.shape == "sphere":
            return np.linalg.norm(local, axis=1) - 0.5 * self.size_mm[0]
        if self.shape == "cylinder":
            radius, half = 0.5 * self.size_mm[0], 0.5 * self.size_mm[1]
            d = np.column_stack(
                [np.hypot(local[:, 0], local[:, 1]) - radius, np.abs(local[:, 2]) - half]
            )
        else:
            d = np.abs(local) - 0.5 * np.asarray(self.size_mm)
        outside = np.linalg.norm(np.maximum(d, 0.0), axis=1)
        return outside + np.minimum(d.max(axis=1), 0.0)


def tangents(normals: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Two unit tangents (t1, t2) of each outward unit normal, (N, 3) each: t1 the part of
    +x tangent to the surface (+y where x is normal), t2 = n x t1 (the convention of the
    point sets' layer model, ``physics.pad_response._local_frame``)."""
    normals = np.asarray(normals, float)
    t1 = np.tile([1.0, 0.0, 0.0], (len(normals), 1))
    t1 -= normals[:, :1] * normals
    small = np.linalg.norm(t1, axis=1) <= 1e-9
    if np.any(small):
        y = np.array([0.0, 1.0, 0.0])
        t1[small] = y - normals[small, 1:2] * normals[small]
    t1 /= np.linalg.norm(t1, axis=1, keepdims=True)
    return t1, np.cross(normals, t1)


def taxel_spacing_mm(positions_mm: np.ndarray) -> np.ndarray:
    """Distance from each taxel to its nearest neighbour [mm], (N,); 1 mm for a lone one."""
    positions = np.asarray(positions_mm, float)
    if len(positions) < 2:
        return np.ones(len(positions))
    out = np.empty(len(positions))
    for first in range(0, len(positions), 512):  # bounded memory on large patches
        block = positions[first : first + 512]
        gaps = np.linalg.norm(block[:, None] - positions[None], axis=-1)
        gaps[np.arange(len(block)), first + np.arange(len(block))] = np.inf
        out[first : first + len(block)] = gaps.min(axis=1)
    return np.maximum(out, 1e-3)


@dataclass(frozen=True)
class SurfaceSample:
    """A patch's surface as points in its sensor frame: positions [mm] (M, 3), outward
    normals (M, 3), the area each stands for [mm^2] (M,), its taxel (M,), and the
    taxels' own positions [mm] (N, 3)."""

    points_mm: np.ndarray
    normals: np.ndarray
    area_mm2: np.ndarray
    taxel: np.ndarray
    taxels_mm: np.ndarray


def surface_sample(spec) -> SurfaceSample:
    """The dense sample of a sensor's surface in its own frame (module docstring)."""
    positions = np.asarray(spec.taxel_positions_mm(), float)
    normals = np.asarray(spec.taxel_normals(), float)
    spacing = taxel_spacing_mm(positions)
    t1, t2 = tangents(normals)
    steps = (np.arange(SAMPLES) + 0.5) / SAMPLES - 0.5  # cell centres over [-1/2, 1/2]
    a, b = (g.ravel() for g in np.meshgrid(steps, steps, indexing="ij"))
    offsets = spacing[:, None, None] * (
        a[None, :, None] * t1[:, None, :] + b[None, :, None] * t2[:, None, :]
    )
    points = (positions[:, None, :] + offsets).reshape(-1, 3)
    n = len(a)
    return SurfaceSample(
        points_mm=points,
        normals=np.repeat(normals, n, axis=0),
        area_mm2=np.repeat((spacing / SAMPLES) ** 2, n),
        taxel=np.repeat(np.arange(len(positions)), n),
        taxels_mm=positions,
    )


@dataclass(frozen=True)
class PatchContact:
    """Where the object touches one patch, in the patch's sensor frame.

    Attributes
    ----------
    position_mm : (3,) ndarray
        Centre of the contact (penetration-weighted centroid) [mm].
    normal : (3,) ndarray
        Outward unit normal of the skin there (the force presses along ``-normal``).
    depth_mm : float
        Deepest penetration of the object into the skin's surface [mm].
    volume_mm3 : float
        Penetration volume (sum of depth x area) [mm^3].
    area_mm2 : float
        Area of the skin's surface inside the object [mm^2].
    taxel : int
        The pressed taxel nearest the centre (index in frame order).
    """

    position_mm: np.ndarray
    normal: np.ndarray
    depth_mm: float
    volume_mm3: float
    area_mm2: float
    taxel: int

    def radius_mm(self, grasped: GraspObject) -> float:
        """The indenter's radius [mm]: the object's curvature radius (a sphere's; a
        cylinder's across its axis), or for a box's flat face the radius of a disc of the
        contact's area (at least a quarter of a millimetre)."""
        radius = grasped.curvature_radius_mm
        if radius is not None:
            return radius
        return max(math.sqrt(self.area_mm2 / math.pi), 0.25)


def patch_contact(
    grasped: GraspObject, sample: SurfaceSample, sensor_in_base: np.ndarray
) -> PatchContact | None:
    """The contact of ``grasped`` on a patch whose surface is ``sample`` (sensor frame)
    and whose sensor frame is ``sensor_in_base`` (4 x 4, metres) in the base frame;
    None when no point of its surface is inside the object."""
    rotation, origin_mm = sensor_in_base[:3, :3], 1e3 * sensor_in_base[:3, 3]
    in_base = sample.points_mm @ rotation.T + origin_mm
    depth = -grasped.signed_distance_mm(in_base)
    inside = depth > 0
    if not np.any(inside):
        return None
    weight = depth[inside] * sample.area_mm2[inside]
    centre = weight @ sample.points_mm[inside] / weight.sum()
    normal = weight @ sample.normals[inside]
    normal /= np.linalg.norm(normal)
    pressed = np.unique(sample.taxel[inside])
    nearest = pressed[np.argmin(np.linalg.norm(sample.taxels_mm[pressed] - centre, axis=1))]
    return PatchContact(
        position_mm=centre,
        normal=normal,
        depth_mm=float(depth[inside].max()),
        volume_mm3=float(weight.sum()),
        area_mm2=float(sample.area_mm2[inside].sum()),
        taxel=int(nearest),
    )
