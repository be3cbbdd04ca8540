"""Reading a MuJoCo model's contacts on a tactile sensor (:class:`MujocoSensor`), its
controls and its example; re-exported by :mod:`tactsense.interop.mujoco`, which
describes the sensor's frame and what a contact becomes."""

from __future__ import annotations

import csv
import math
from dataclasses import dataclass
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np

from tactsense._validation import TactsenseInputError
from tactsense.kinds import kind_of

SLIP_TOLERANCE = 1e-3
"""A contact slides when its friction force is within this fraction of the cone's limit
[-] (the solver's force sits on the cone to rounding while sliding)."""

DEFAULT_FLAT_RADIUS_MM = 1.6
"""Radius of the sphere each contact point of a flat body stands for [mm] (the scenarios'
probe)."""


class MujocoError(TactsenseInputError):
    """A MuJoCo model, its sensor mount or its controls cannot be used as asked."""


def _mujoco():
    try:
        import mujoco
    except ImportError:  # pragma: no cover - the extra is installed in the tests
        raise MujocoError(
            "the MuJoCo adapter needs the 'mujoco' package: pip install 'tactsense[mujoco]'"
        ) from None
    return mujoco


def example_model_path() -> Path:
    """The example model shipped with tactsense: a finger with a 40 x 40 mm pad (pad16)
    pressing on and sliding across a ball and a rod (``mujoco_finger.xml``)."""
    return Path(str(resources.files("tactsense.interop") / "data" / "mujoco_finger.xml"))


def example_pad_path() -> Path:
    """The gripper example's sampling pad (``mujoco_finger_pad.toml``): pad16's grid
    under a 6-mm layer read 4 mm deep, which spreads a contact over 9-11 taxels so that a
    frame determines its force and size (docs/mujoco.md); the preset pad16 (2-mm layer)
    reads 1-6."""
    return Path(str(resources.files("tactsense.interop") / "data" / "mujoco_finger_pad.toml"))


def example_controls_path() -> Path:
    """The example model's motion: ``time_s`` [s] and the three servos' targets [m]."""
    return Path(str(resources.files("tactsense.interop") / "data" / "mujoco_finger.csv"))


def fingertip_model_path() -> Path:
    """The second example: the paper's finger as a capsule slid along its axis over a
    ball (``mujoco_fingertip.xml``; its motion ``mujoco_fingertip.csv`` beside it)."""
    return Path(str(resources.files("tactsense.interop") / "data" / "mujoco_fingertip.xml"))


def load_model(path) -> Any:
    """A ``mujoco.MjModel`` from an MJCF (XML) file; a one-line error if it does not load."""
    mujoco = _mujoco()
    path = Path(path)
    if not path.is_file():
        raise MujocoError(f"{path}: no such model file")
    try:
        return mujoco.MjModel.from_xml_path(str(path))
    except (ValueError, mujoco.FatalError) as error:
        text = " ".join(str(error).split())
        raise MujocoError(f"{path}: MuJoCo cannot load it: {text}") from None


# ---- controls: a table of actuator targets over time --------------------------------


@dataclass(frozen=True)
class Controls:
    """Actuator controls over time, linearly interpolated between rows.

    Attributes
    ----------
    time_s : ndarray, shape (T,)
        Increasing times [s].
    values : ndarray, shape (T, nu)
        The control of every actuator of the model at those times (its own unit: a
        position servo's target [m] or [rad]); held at the last row after it.
    """

    time_s: np.ndarray
    values: np.ndarray

    def at(self, t_s: float) -> np.ndarray:
        """Every actuator's control at time ``t_s`` [s], shape (nu,): linear between the
        rows around it, the first row before the table and the last after it."""
        t = self.time_s
        if t_s <= t[0]:
            return self.values[0].copy()
        if t_s >= t[-1]:
            return self.values[-1].copy()
        i = int(np.searchsorted(t, t_s, side="right")) - 1
        weight = (t_s - t[i]) / (t[i + 1] - t[i])
        return self.values[i] + weight * (self.values[i + 1] - self.values[i])


def read_controls(path, model) -> Controls:
    """Read a CSV of controls: a ``time_s`` column [s, increasing] and one column per
    actuator of ``model`` named as in the model (actuators not named keep control 0)."""
    mujoco = _mujoco()
    path = Path(path)
    names = [
        mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_ACTUATOR, a) or "" for a in range(model.nu)
    ]
    try:
        with path.open(newline="") as handle:
            rows = list(csv.reader(handle))
    except UnicodeDecodeError:
        raise MujocoError(f"--controls {path}: not a text CSV file") from None
    except OSError as error:
        raise MujocoError(f"--controls {path}: cannot read it ({error.strerror})") from None
    if not rows or "time_s" not in [h.strip() for h in rows[0]]:
        raise MujocoError(
            f"--controls {path}: expected a CSV with a header naming 'time_s' [s] and "
            "the model's actuators"
        )
    header = [h.strip() for h in rows[0]]
    unknown = [h for h in header if h != "time_s" and h not in names]
    if unknown:
        raise MujocoError(
            f"--controls {path}: no actuator named {', '.join(unknown)} in the model "
            f"(its actuators: {', '.join(n for n in names if n) or 'none'})"
        )
    body = [r for r in rows[1:] if any(cell.strip() for cell in r)]
    if not body:
        raise MujocoError(f"--controls {path}: no rows under the header")
    try:
        table = np.array([[float(cell) for cell in r] for r in body])
    except ValueError as error:
        raise MujocoError(f"--controls {path}: not a number ({error})") from None
    if table.shape[1] != len(header) or not np.all(np.isfinite(table)):
        raise MujocoError(f"--controls {path}: every row needs {len(header)} finite numbers")
    times = table[:, header.index("time_s")]
    if np.any(np.diff(times) <= 0) or times[0] < 0:
        raise MujocoError(f"--controls {path}: time_s must increase from 0 or later [s]")
    values = np.zeros((len(times), model.nu))
    for column, name in enumerate(header):
        if name != "time_s":
            values[:, names.index(name)] = table[:, column]
    return Controls(times, values)


# ---- the mount: a sensor on a geom or a site ----------------------------------------


@dataclass(frozen=True)
class SurfaceContacts:
    """The contacts on a sensor at one instant, in its surface coordinates.

    Attributes
    ----------
    position_mm : ndarray, shape (k, 2)
        Contact points in the sensor's surface coordinates [mm].
    normal_force_n : ndarray, shape (k,)
        Force pressing on the sensor, along its inward normal [N] (>= 0).
    tangential_force_n : ndarray, shape (k, 2)
        Friction force on the sensor along its surface axes [N].
    radius_mm : ndarray, shape (k,)
        Radius of the sphere each contact stands for [mm].
    slipping : ndarray of bool, shape (k,)
        Whether the friction force is at the friction cone's limit (the contact slides).
    geom : ndarray of int, shape (k,)
        The MuJoCo geom pressing on the sensor.
    friction : ndarray, shape (k,)
        The contact's friction coefficient (MuJoCo's first tangential one, mu) [-]; 0
        where the contact has none.
    """

    position_mm: np.ndarray
    normal_force_n: np.ndarray
    tangential_force_n: np.ndarray
    radius_mm: np.ndarray
    slipping: np.ndarray
    geom: np.ndarray
    friction: np.ndarray | None = None

    def __len__(self) -> int:
        return len(self.normal_force_n)


class MujocoSensor:
    """A tactile sensor mounted on a MuJoCo geom (or site) of a model.

    Parameters
    ----------
    model : mujoco.MjModel
    spec : sensor description
        The tactile array (a flat kind: its surface coordinates in mm).
    geom, site : str
        The geom the sensor covers, or a site (the sensor covers every geom of the
        site's body; the site's frame is the sensor's). Exactly one.
    flat_radius_mm : float
        Radius of the sphere each contact point of a flat body stands for [mm].
    """

    def __init__(
        self,
        model,
        spec,
        *,
        geom: str | None = None,
        site: str | None = None,
        flat_radius_mm: float = DEFAULT_FLAT_RADIUS_MM,
    ):
        mujoco = _mujoco()
        kind = kind_of(spec)
        units = tuple(kind.position_units)
        if units not in (("mm", "mm"), ("mm", "deg")):
            raise kind.unsupported(spec, f"MuJoCo contacts (surface coordinates in {units})")
        self.curved = units == ("mm", "deg")  # along an axis [mm] and around it [deg]
        if geom is None and self.curved:
            raise MujocoError(f"{spec.name!r} is a skin around an axis: mount it on a geom")
        if (geom is None) == (site is None):
            raise MujocoError("give the sensor's geom or its site (one of them)")
        if not (isinstance(flat_radius_mm, float | int) and 0 < flat_radius_mm < 1e3):
            raise MujocoError(f"flat radius {flat_radius_mm!r} mm: expected 0 < r < 1000 [mm]")
        self.model, self.spec, self.flat_radius_mm = model, spec, float(flat_radius_mm)
        if geom is not None:
            self.geom_id = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, geom)
            if self.geom_id < 0:
                raise MujocoError(f"--geom {geom}: the model has no geom of that name")
            self.site_id = -1
            self.members = frozenset([self.geom_id])
        else:
            self.site_id = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, site)
            if self.site_id < 0:
                raise MujocoError(f"--site {site}: the model has no site of that name")
            self.geom_id = -1
            body = model.site_bodyid[self.site_id]
            self.members = frozenset(np.flatnonzero(model.geom_bodyid == body).tolist())
        self.name = geom if geom is not None else site
        self.half_length_mm = 0.0
        grid = kind.surface_grid(spec)
        if self.curved:
            types = mujoco.mjtGeom
            if int(model.geom_type[self.geom_id]) not in (
                int(types.mjGEOM_CAPSULE), int(types.mjGEOM_CYLINDER)
            ):  # fmt: skip
                raise MujocoError(
                    f"--geom {geom}: {spec.name!r} is a skin around an axis; mount it on a "
                    "capsule or a cylinder (its local z the axis, the tip at +z)"
                )
            self.half_length_mm = float(model.geom_size[self.geom_id][1]) * 1e3
            self.radius_mm = float(spec.radius_mm)
            self.origin_mm = np.zeros(2)
        elif grid is not None:
            (x_pitch, rows), (y_pitch, cols) = grid
            self.origin_mm = np.array([(rows - 1) * x_pitch / 2, (cols - 1) * y_pitch / 2])
        else:  # taxels around their centroid
            self.origin_mm = np.asarray(spec.taxel_positions_mm(), float)[:, :2].mean(axis=0)
        self._force = np.zeros(6)

    def size_note(self) -> str | None:
        """A sentence when the geom's face (a box's x and y) and the sensor's taxel grid
        differ by more than a pitch [mm]; None when they agree or cannot be compared."""
        mujoco = _mujoco()
        grid = kind_of(self.spec).surface_grid(self.spec)
        if self.geom_id < 0 or grid is None or self.curved:
            return None
        if int(self.model.geom_type[self.geom_id]) != int(mujoco.mjtGeom.mjGEOM_BOX):
            return None
        (x_pitch, rows), (y_pitch, cols) = grid
        face = 2e3 * self.model.geom_size[self.geom_id][:2]
        grid_mm = np.array([rows * x_pitch, cols * y_pitch])
        if np.all(np.abs(face - grid_mm) <= np.array([x_pitch, y_pitch])):
            return None
        return (
            f"the geom's face is {face[0]:.4g} x {face[1]:.4g} mm and the taxels of "
            f"{self.spec.name!r} span {grid_mm[0]:.4g} x {grid_mm[1]:.4g} mm (centred on it): "
            "contacts beyond the taxels read little or nothing"
        )

    def _pose(self, data) -> tuple[np.ndarray, np.ndarray]:
        if self.geom_id >= 0:
            return data.geom_xpos[self.geom_id], data.geom_xmat[self.geom_id].reshape(3, 3)
        return data.site_xpos[self.site_id], data.site_xmat[self.site_id].reshape(3, 3)

    def _radius_mm(self, other: int) -> float:
        mujoco = _mujoco()
        kind, size = self.model.geom_type[other], self.model.geom_size[other]
        types = mujoco.mjtGeom
        round_ones = (types.mjGEOM_SPHERE, types.mjGEOM_CAPSULE, types.mjGEOM_CYLINDER)
        if int(kind) in {int(t) for t in round_ones}:
            return float(size[0]) * 1e3
        if int(kind) == int(types.mjGEOM_ELLIPSOID):
            return float(np.min(size)) * 1e3
        return self.flat_radius_mm

    def _around(self, point_mm, force_n):
        """A contact on a skin around the geom's z axis (the tip at +z): its position
        (axial [mm] from where the tip meets the cylinder, toward the base; arc around
        [mm] at the sensor's radius from the local x axis), the normal force pressing
        in [N], and the tangential force along the axial and the arc direction [N]."""
        angle = math.atan2(point_mm[1], point_mm[0])
        outward = np.array([math.cos(angle), math.sin(angle), 0.0])
        around = np.array([-math.sin(angle), math.cos(angle), 0.0])
        axial = self.half_length_mm - point_mm[2]
        position = (axial, angle * self.radius_mm)
        return position, -float(force_n @ outward), (-float(force_n[2]), float(force_n @ around))

    def read(self, data) -> SurfaceContacts:
        """The contacts on the sensor now (after ``mj_step`` or ``mj_forward``)."""
        mujoco = _mujoco()
        origin, rotation = self._pose(data)
        rows = []
        for i in range(data.ncon):
            contact = data.contact[i]
            g1, g2 = int(contact.geom1), int(contact.geom2)
            if g1 in self.members and g2 not in self.members:
                sign, other = -1.0, g2  # the force computed acts on geom2: ours is opposite
            elif g2 in self.members and g1 not in self.members:
                sign, other = 1.0, g1
            else:
                continue
            mujoco.mj_contactForce(self.model, data, i, self._force)
            frame = contact.frame.reshape(3, 3)  # rows: normal (geom1 -> geom2), tangents
            on_sensor = sign * (frame.T @ self._force[:3])  # world [N]
            local_force = rotation.T @ on_sensor
            local_point = rotation.T @ (contact.pos - origin) * 1e3  # [mm]
            if self.curved:
                position, normal, tangential = self._around(local_point, local_force)
            else:
                position = local_point[:2] + self.origin_mm
                normal = -local_force[2]  # pressing into the +z face
                tangential = local_force[:2]
            if normal <= 0:
                continue
            mu = contact.friction[:2]
            f1, f2 = self._force[1], self._force[2]
            cone = math.hypot(f1 / mu[0], f2 / mu[1]) if mu[0] > 0 and mu[1] > 0 else 0.0
            slipping = mu[0] > 0 and cone >= (1.0 - SLIP_TOLERANCE) * self._force[0] > 0
            rows.append(
                (
                    position[0],
                    position[1],
                    normal,
                    tangential[0],
                    tangential[1],
                    self._radius_mm(other),
                    slipping,
                    other,
                    mu[0],
                )
            )
        table = np.array(rows, float).reshape(-1, 9)
        return SurfaceContacts(
            position_mm=table[:, 0:2],
            normal_force_n=table[:, 2],
            tangential_force_n=table[:, 3:5],
            radius_mm=table[:, 5],
            slipping=table[:, 6].astype(bool),
            geom=table[:, 7].astype(np.int64),
            friction=table[:, 8],
        )


def contact_batch(readings: list[SurfaceContacts], *, shear: bool = True):
    """The readings of N frames as one :class:`~tactsense.simulate.ContactBatch` (N frames
    x the most contacts any of them has; a missing contact has force 0); without their
    tangential forces unless ``shear`` (for a kind that does not take them)."""
    from tactsense.simulate import ContactBatch

    n = len(readings)
    k = max([1, *(len(r) for r in readings)])
    position = np.zeros((n, k, 2))
    normal = np.zeros((n, k))
    tangential = np.zeros((n, k, 2))
    radius = np.full((n, k), DEFAULT_FLAT_RADIUS_MM)
    friction = np.zeros((n, k))
    for j, r in enumerate(readings):
        m = len(r)
        position[j, :m], normal[j, :m] = r.position_mm, r.normal_force_n
        tangential[j, :m], radius[j, :m] = r.tangential_force_n, r.radius_mm
        if r.friction is not None:  # a sliding contact: at the cone's limit (gross slip)
            ratio = np.hypot(*r.tangential_force_n.T) / np.maximum(r.normal_force_n, 1e-300)
            friction[j, :m] = np.where(r.slipping, np.maximum(ratio, 1e-12), r.friction)
    return ContactBatch(
        position_mm=position,
        normal_force_n=normal,
        tangential_force_n=tangential if shear else None,
        radius_mm=radius,
        shape="sphere",
        friction=friction if shear else None,
    )


def contact_labels(readings: list[SurfaceContacts]) -> dict[str, np.ndarray]:
    """Per-frame truth from MuJoCo's contacts: total normal force [N], friction force
    (x, y) [N], force-weighted centroid (x, y) [mm] (NaN without contact), number of
    contacts, and whether any contact slides."""
    n = len(readings)
    force, count = np.zeros(n), np.zeros(n, np.int64)
    tangential, centroid = np.zeros((n, 2)), np.full((n, 2), np.nan)
    slip = np.zeros(n, bool)
    for j, r in enumerate(readings):
        count[j] = len(r)
        if len(r):
            force[j] = r.normal_force_n.sum()
            tangential[j] = r.tangential_force_n.sum(axis=0)
            centroid[j] = (r.normal_force_n @ r.position_mm) / force[j]
            slip[j] = bool(r.slipping.any())
    return {
        "force_n": force,
        "tangential_force_n": tangential,
        "centroid_mm": centroid,
        "n_contacts": count,
        "slip": slip,
    }
