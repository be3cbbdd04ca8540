"""The truth a simulated grasp writes in every stream (:data:`TRUTH_KEYS`)."""

from __future__ import annotations

from typing import Any

import numpy as np

from tactsense.simulate._grasp_timing import PHASES

TRUTH_KEYS = (
    "contact_position_mm",
    "contact_position_base_m",
    "contact_normal",
    "contact_normal_base",
    "contact_normal_force_n",
    "contact_tangential_force_n",
    "contact_tangential_force_base_n",
    "contact_radius_mm",
    "frame_step",
    "step_n_contacts",
)
"""The truth every stream of a simulated grasp carries, whether touched or not (one
contact per patch: ``k = 1``): ``contact_position_mm`` (T, 1, 3) [mm] in the patch's
sensor frame and ``contact_position_base_m`` (T, 1, 3) [m] in the base frame (NaN in a
frame without contact); ``contact_normal`` / ``contact_normal_base`` (T, 1, 3) the skin's
outward unit normal there (the force presses along its negative; NaN without contact);
``contact_normal_force_n`` (T, 1) [N]; ``contact_tangential_force_n`` /
``contact_tangential_force_base_n`` (T, 1, 3) [N] the tangential force the object
applies to the skin, in the sensor and base frames (0 without a load or contact);
``contact_radius_mm`` (T, 1) [mm] the indenter's
radius (NaN without contact); ``frame_step`` (T,) the phase of each frame (index into
:data:`PHASES`) and ``step_n_contacts`` (4,) the contacts the patch has in each phase."""


TIME_KEYS = frozenset(TRUTH_KEYS) - {"step_n_contacts"}
"""The truth keys that run along time (one row per frame)."""


def stream_truth(
    patch, contact, force, tangential, radius, phase, sensor_in_base
) -> dict[str, Any]:
    """A stream's truth: ``force`` (T,) [N] normal and ``tangential`` (T, 3) [N] in the
    sensor frame, each frame's, the contact (or None) and the sensor frame's pose."""
    n = len(force)
    touching = force > 0
    position = np.full((n, 1, 3), np.nan)
    base = np.full((n, 1, 3), np.nan)
    normal = np.full((n, 1, 3), np.nan)
    normal_base = np.full((n, 1, 3), np.nan)
    radii = np.full((n, 1), np.nan)
    if contact is not None:
        rotation = sensor_in_base[:3, :3]
        position[touching, 0] = contact.position_mm
        base[touching, 0] = 1e-3 * (rotation @ contact.position_mm) + sensor_in_base[:3, 3]
        normal[touching, 0] = contact.normal
        normal_base[touching, 0] = rotation @ contact.normal
        radii[touching, 0] = radius
    n_contacts = np.zeros(len(PHASES), dtype=np.int64)
    if contact is not None:
        n_contacts[1:] = 1
    return {
        "contact_position_mm": position,
        "contact_position_base_m": base,
        "contact_normal": normal,
        "contact_normal_base": normal_base,
        "contact_normal_force_n": force[:, None].copy(),
        "contact_tangential_force_n": tangential[:, None, :].copy(),
        "contact_tangential_force_base_n": (tangential @ sensor_in_base[:3, :3].T)[:, None, :],
        "contact_radius_mm": radii,
        "frame_step": np.asarray(phase, dtype=np.int64),
        "step_n_contacts": n_contacts,
        "patch": patch.name,
        "link": patch.link,
    }
