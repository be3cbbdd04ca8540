"""ROS 2 message layouts of the ROS tactile toolbox (``tactile_msgs``), as tactsense fills them.

No ROS 2 tactile message is standard; the toolbox's are the de-facto layouts:

``tactile_msgs/msg/TactileState`` (modelled on ``sensor_msgs/JointState``)::

    std_msgs/Header header
    sensor_msgs/ChannelFloat32[] sensors      # one per sensor: name, float32[] values

``tactile_msgs/msg/TactileContact``::

    std_msgs/Header header
    string name
    geometry_msgs/Point position
    geometry_msgs/Vector3 normal
    geometry_msgs/Wrench wrench

tactsense fills one ``TactileState`` per frame (one sensor: the finger's name and its
counts, rows x cols row-major, as float32) and one ``TactileContact`` per frame with a
contact: the point on the skin [m] in the finger's frame (x along the finger from the
junction of tip and cylinder toward the base, angle 0 along +y, as
:func:`tactsense.geometry.surface_to_xyz`), the outward normal there, and the force
the object applies (-force x normal [N]) with its torque about the frame's origin,
``position x force`` [N m]: upstream's message says the wrench "should be represented in
reference frame, not in contact point frame", and its contact merger writes the torque
so. Upstream's ``name`` is the "unique name of the contact", and RViz's tactile contact
display keeps one contact per ``(frame_id, name)``: a finger's one contact is named as
the sensor, and each contact of a pad or a point set ``<sensor>/<id>`` with its tracked
id (stable while the contact lasts). Each frame's contacts also go together in one
``tactile_msgs/msg/TactileContacts`` (an empty list for a frame without one), as
upstream's contact merger publishes them. The header's ``frame_id`` is the link the
sensor is mounted on (``--frame-id``, default ``finger``, the link ``sensor export
--urdf`` writes) and its stamp the frame's
arrival on the host's clock for a recorded stream, else the recording's time plus
``--start-time``.
"""

from __future__ import annotations

import numpy as np

from tactsense.geometry import surface_to_xyz
from tactsense.sensor import SensorSpec

SEPARATOR = "=" * 80

_DEPENDENCIES = {
    "std_msgs/Header": "builtin_interfaces/Time stamp\nstring frame_id",
    "builtin_interfaces/Time": "int32 sec\nuint32 nanosec",
    "sensor_msgs/ChannelFloat32": "string name\nfloat32[] values",
    "geometry_msgs/Point": "float64 x\nfloat64 y\nfloat64 z",
    "geometry_msgs/Vector3": "float64 x\nfloat64 y\nfloat64 z",
    "geometry_msgs/Wrench": "geometry_msgs/Vector3 force\ngeometry_msgs/Vector3 torque",
}

TACTILE_STATE = "tactile_msgs/msg/TactileState"
TACTILE_CONTACT = "tactile_msgs/msg/TactileContact"
TACTILE_CONTACTS = "tactile_msgs/msg/TactileContacts"


def _msgdef(body: str, dependencies: list[str]) -> str:
    parts = [body]
    for name in dependencies:
        parts.append(f"{SEPARATOR}\nMSG: {name}\n{_DEPENDENCIES[name]}")
    return "\n".join(parts) + "\n"


TACTILE_STATE_MSGDEF = _msgdef(
    "std_msgs/Header header\nsensor_msgs/ChannelFloat32[] sensors",
    ["std_msgs/Header", "builtin_interfaces/Time", "sensor_msgs/ChannelFloat32"],
)
"""ROS 2 message definition of ``TactileState`` with its dependencies (the ``ros2msg``
schema encoding of MCAP)."""

TACTILE_CONTACT_MSGDEF = _msgdef(
    "std_msgs/Header header\nstring name\ngeometry_msgs/Point position\n"
    "geometry_msgs/Vector3 normal\ngeometry_msgs/Wrench wrench",
    [
        "std_msgs/Header",
        "builtin_interfaces/Time",
        "geometry_msgs/Point",
        "geometry_msgs/Vector3",
        "geometry_msgs/Wrench",
    ],
)
"""ROS 2 message definition of ``TactileContact`` with its dependencies."""

_DEPENDENCIES["tactile_msgs/TactileContact"] = TACTILE_CONTACT_MSGDEF.split(f"\n{SEPARATOR}")[0]
TACTILE_CONTACTS_MSGDEF = _msgdef(
    "tactile_msgs/TactileContact[] contacts",
    [
        "tactile_msgs/TactileContact",
        "std_msgs/Header",
        "builtin_interfaces/Time",
        "geometry_msgs/Point",
        "geometry_msgs/Vector3",
        "geometry_msgs/Wrench",
    ],
)
"""ROS 2 message definition of ``TactileContacts`` (upstream's list of the contacts of
one moment, which its contact merger publishes on ``contact_states`` and RViz's
tactile contact display reads) with its dependencies."""


def stamp(time_s: float) -> dict:
    """``builtin_interfaces/Time`` of a time in seconds."""
    ns = round(float(time_s) * 1e9)
    return {"sec": ns // 1_000_000_000, "nanosec": ns % 1_000_000_000}


def tactile_state(sensor: SensorSpec, counts, time_s: float, frame_id: str = "finger") -> dict:
    """One ``TactileState`` of one frame: the sensor's counts, row-major; a sensor of
    several components (three-axis taxels) has a channel per component, named
    ``<sensor>/<component>`` (:mod:`tactsense.interop.components`)."""
    if sensor.components > 1:  # ---- a channel per component (r8-triinterop) ----
        from tactsense.interop._state_bytes import state_message

        when = stamp(time_s)
        return state_message(sensor, when["sec"], when["nanosec"], np.ravel(counts), frame_id)
    return {
        "header": {"stamp": stamp(time_s), "frame_id": frame_id},
        "sensors": [
            {"name": sensor.name, "values": np.asarray(counts, dtype=np.float32).ravel().tolist()}
        ],
    }


def contact_geometry(sensor: SensorSpec, axial_mm, angle_deg) -> tuple[np.ndarray, np.ndarray]:
    """Points on the skin [m] and outward unit normals there, shape (..., 3) each."""
    outside = surface_to_xyz(sensor, axial_mm, angle_deg)
    inside = surface_to_xyz(sensor, axial_mm, angle_deg, depth_mm=1.0)
    normal = outside - inside
    normal /= np.linalg.norm(normal, axis=-1, keepdims=True)
    return outside * 1e-3, normal


def tactile_contact(
    sensor: SensorSpec,
    time_s: float,
    point_m,
    normal,
    force_n: float,
    frame_id: str = "finger",
    name: str | None = None,
    shear_n=None,
) -> dict:
    """One ``TactileContact``: where, the normal, and the wrench the object applies.

    The wrench is in the reference frame (``frame_id``), as upstream's message says
    ("represented in reference frame, not in contact point frame"): the force, and the
    torque of that force about the frame's origin, ``position x force`` [N m], as the
    toolbox's contact merger writes it. ``name``: the contact's unique name (default the
    sensor's, for a finger's one contact). ``shear_n``: the tangential force the object
    applies [N], (3,) in the reference frame, added to the force (three-axis taxels).
    """
    force = -float(force_n) * np.asarray(normal, dtype=float)
    if shear_n is not None:  # the tangential force [N] of a sensor that senses shear
        force = force + np.asarray(shear_n, dtype=float)
    torque = np.cross(np.asarray(point_m, dtype=float), force)
    return {
        "header": {"stamp": stamp(time_s), "frame_id": frame_id},
        "name": sensor.name if name is None else name,
        "position": dict(zip("xyz", map(float, point_m), strict=True)),
        "normal": dict(zip("xyz", map(float, normal), strict=True)),
        "wrench": {
            "force": dict(zip("xyz", map(float, force), strict=True)),
            "torque": dict(zip("xyz", map(float, torque), strict=True)),
        },
    }
