"""The hand in 3-D for the browser view: where every taxel is, and where the contacts are.

Pure functions of a :class:`~tactsense.robot.RobotSkin` and a joint state: the layout the
page draws (every taxel of every patch in the base frame [mm], the links' origins and
the bones between them) and the contacts of a frame moved from a patch's own frame into
the link's and the base's (:func:`contacts_in_base`, the one function the view calls for
contacts: swap it for the robot estimator's output when that lands).

Conventions: positions are millimetres in the base link's frame; a normal points out of
the skin; a contact's force vector points into it (the object pushes on the skin).
"""

from __future__ import annotations

import math
from collections.abc import Mapping

import numpy as np
from matplotlib import colormaps

from tactsense.kinds import kind_of
from tactsense.robot import RobotSkin, RobotSkinError

COLORMAP = "viridis"
"""Colour map of the taxels' signal (as the single-array view's)."""

ARROW_MM_PER_N = 10.0
"""Length of a contact's force arrow on the page [mm per N] (the page caps it at 40 mm)."""


def parse_joint_state(text: str | None, skin: RobotSkin) -> dict[str, float]:
    """``"name=rad,name=rad"`` as joint positions [rad or m], checked against the skin.

    An empty or None text is every joint at 0. Unknown joints, repeated names,
    non-numbers and positions outside a joint's limits are one-line errors.
    """
    positions: dict[str, float] = {}
    if text is None or not text.strip():
        return positions
    for item in text.split(","):
        name, sep, value = item.partition("=")
        name = name.strip()
        if not sep or not name:
            raise RobotSkinError(
                f"--joints item {item.strip()!r}: expected NAME=POSITION (radians, or metres "
                "for a prismatic joint), items separated by commas"
            )
        if name in positions:
            raise RobotSkinError(f"--joints names joint {name!r} twice")
        try:
            positions[name] = float(value)
        except ValueError:
            raise RobotSkinError(
                f"--joints {name}={value.strip()!r}: not a number (radians, or metres for a "
                "prismatic joint)"
            ) from None
    try:
        skin.link_poses(positions)  # unknown names, NaN and limits: the skin's own checks
    except RobotSkinError as error:
        raise RobotSkinError(f"--joints: {error}") from None
    return positions


def _mm(array: np.ndarray) -> list:
    return np.round(np.asarray(array, dtype=float) * 1e3, 4).tolist()


def link_poses_message(poses: Mapping[str, np.ndarray]) -> dict[str, list]:
    """Every link's pose in the base frame for the page: the 3 x 4 ``[R | t]`` row by
    row, ``t`` in mm (12 numbers a link)."""
    out = {}
    for link, pose in poses.items():
        rows = np.asarray(pose, dtype=float)[:3].copy()
        rows[:, 3] *= 1e3
        out[link] = np.round(rows, 9).reshape(-1).tolist()
    return out


def scene_layout(skin: RobotSkin, joint_positions: Mapping[str, float] | None = None) -> dict:
    """What the page draws of the skin at a joint state (JSON-ready).

    Returns
    -------
    dict
        ``skin``, ``base_link``, ``joints`` (the state [rad or m]), ``patches`` (per patch:
        ``name``, ``link``, ``device``, ``kind``, ``n_taxels``, ``positions_mm`` (N, 3)
        and ``normals`` (N, 3) in the base frame, ``positions_link_mm`` and
        ``normals_link`` in the link's frame, taxels in the order of a frame's counts
        flattened row by row), ``links`` (name and origin [mm] in the base frame),
        ``bones`` (parent and child links and origins of each joint [mm]), ``link_poses``
        (:func:`link_poses_message`), ``colormap`` (name and its 256-entry RGB table),
        ``arrow_mm_per_n``.
    """
    joints = dict(joint_positions or {})
    poses = skin.link_poses(joints)
    taxels = skin.taxels_in_base(joints)
    patches = []
    for patch in skin.patches:
        positions, normals = taxels[patch.name]
        in_link, normals_in_link = patch.taxels_in_link()
        patches.append(
            {
                "name": patch.name,
                "link": patch.link,
                "device": patch.device,
                "kind": kind_of(patch.sensor).label,
                "n_taxels": int(patch.n_taxels),
                "positions_mm": _mm(positions),
                "normals": np.round(normals, 6).tolist(),
                "positions_link_mm": _mm(in_link),
                "normals_link": np.round(normals_in_link, 9).tolist(),
            }
        )
    links = [{"name": link, "origin_mm": _mm(poses[link][:3, 3])} for link in skin.links]
    bones = [
        {
            "joint": joint.name,
            "parent": joint.parent,
            "child": joint.child,
            "from_mm": _mm(poses[joint.parent][:3, 3]),
            "to_mm": _mm(poses[joint.child][:3, 3]),
        }
        for joint in skin.joints
    ]
    lut = (colormaps[COLORMAP](np.linspace(0.0, 1.0, 256))[:, :3] * 255).round().astype(int)
    return {
        "type": "robot_layout",
        "skin": skin.name,
        "base_link": skin.base_link,
        "joints": joints,
        "n_taxels": int(skin.n_taxels),
        "patches": patches,
        "links": links,
        "bones": bones,
        "link_poses": link_poses_message(poses),
        "colormap": {"name": COLORMAP, "lut": lut.tolist()},
        "arrow_mm_per_n": ARROW_MM_PER_N,
    }


def _finite(value) -> float | None:
    if value is None:
        return None
    value = float(value)
    return value if math.isfinite(value) else None


def contacts_in_base(
    skin: RobotSkin, link_poses: Mapping[str, np.ndarray], patch_name: str, estimate: dict | None
) -> list[dict]:
    """The contacts of one patch's frame in the link's and the base's frame.

    Parameters
    ----------
    skin : RobotSkin
    link_poses : mapping
        Every link's 4 x 4 pose in the base frame (:meth:`RobotSkin.link_poses`).
    patch_name : str
    estimate : dict or None
        The single-array estimator's estimate of the patch's frame
        (:class:`~tactsense.stream.live.LiveContacts`): ``contacts`` with ``x_mm``,
        ``y_mm``, ``z_mm`` in the sensor's frame [mm] and ``force_n`` [N]. An estimate
        without a ``contacts`` list (the finger's one contact, on its unwrapped surface)
        gives no contacts here.

    Returns
    -------
    list of dict
        Per contact: ``patch``, ``link``, ``id``, ``position_mm`` (base frame),
        ``position_link_mm`` (link frame), ``normal`` (base frame, unit, out of the skin:
        the normal of the taxel nearest the contact), ``force_n`` [N] and ``force_vector_n``
        (base frame [N], ``-force_n * normal``: pushing into the skin).
    """
    if not estimate or not isinstance(estimate.get("contacts"), list):
        return []
    patch = skin.patch(patch_name)
    sensor_in_link = patch.origin.matrix()
    sensor_in_base = np.asarray(link_poses[patch.link]) @ sensor_in_link
    taxels_mm = np.asarray(patch.sensor.taxel_positions_mm(), dtype=float)
    normals = np.asarray(patch.sensor.taxel_normals(), dtype=float)
    out = []
    for contact in estimate["contacts"]:
        x, y = _finite(contact.get("x_mm")), _finite(contact.get("y_mm"))
        if x is None or y is None:
            continue
        nearest = int(np.argmin(((taxels_mm[:, :2] - (x, y)) ** 2).sum(axis=1)))
        z = _finite(contact.get("z_mm"))
        p_sensor = np.array([x, y, taxels_mm[nearest, 2] if z is None else z, 1e3]) * 1e-3
        p_link = sensor_in_link @ p_sensor
        p_base = sensor_in_base @ p_sensor
        normal = sensor_in_base[:3, :3] @ normals[nearest]
        force = _finite(contact.get("force_n"))
        out.append(
            {
                "patch": patch.name,
                "link": patch.link,
                "id": contact.get("id"),
                "position_mm": _mm(p_base[:3]),
                "position_link_mm": _mm(p_link[:3]),
                "normal": np.round(normal, 6).tolist(),
                "force_n": None if force is None else round(force, 6),
                "force_vector_n": None if force is None else np.round(-force * normal, 6).tolist(),
            }
        )
    return out


def contacts_by_link(skin: RobotSkin, contacts: list[dict]) -> list[dict]:
    """The contacts summed per link, in the skin's link order (links with contacts only).

    Returns
    -------
    list of dict
        ``link``, ``n_contacts``, ``patches`` (names), ``force_n`` (sum of the contacts'
        normal forces [N]) and ``force_vector_n`` (their vector sum in the base frame [N]).
    """
    rows: dict[str, dict] = {}
    for contact in contacts:
        row = rows.setdefault(
            contact["link"],
            {"link": contact["link"], "n_contacts": 0, "patches": [], "force_n": 0.0,
             "force_vector_n": [0.0, 0.0, 0.0]},
        )  # fmt: skip
        row["n_contacts"] += 1
        if contact["patch"] not in row["patches"]:
            row["patches"].append(contact["patch"])
        if contact["force_n"] is not None:
            row["force_n"] += contact["force_n"]
            row["force_vector_n"] = [
                a + b for a, b in zip(row["force_vector_n"], contact["force_vector_n"], strict=True)
            ]
    order = {link: i for i, link in enumerate(skin.links)}
    out = sorted(rows.values(), key=lambda row: order.get(row["link"], len(order)))
    for row in out:
        row["force_n"] = round(row["force_n"], 6)
        row["force_vector_n"] = [round(v, 6) for v in row["force_vector_n"]]
    return out
