"""The finger's surface in 3-D: a cylinder closed by a hemispherical tip.

The math a finger's description needs to say where its taxels are
(:meth:`~tactsense.sensor.finger.SensorSpec.taxel_positions_mm`), kept in ``sensor/`` so
that the import goes one way: :mod:`tactsense.geometry` (coordinates on the finger)
builds on it and re-exports these names. Conventions: ``docs/nomenclature.md`` and
:mod:`tactsense.geometry`.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from tactsense._validation import TactsenseInputError, as_float_array

SensorSpec = Any
"""A :class:`~tactsense.sensor.finger.SensorSpec` (not imported: the finger imports this)."""


def wrap_angle_deg(angle_deg):
    """Wrap angles to (-180, 180] [deg]."""
    wrapped = np.mod(np.asarray(angle_deg, dtype=float) + 180.0, 360.0) - 180.0
    return np.where(wrapped == -180.0, 180.0, wrapped)


def surface_to_xyz(spec: SensorSpec, axial_mm, angle_deg, depth_mm=0.0):
    """3-D point of a surface position, optionally ``depth_mm`` below the skin.

    Returns
    -------
    ndarray, shape (..., 3)
        ``(x, y, z)`` [mm].
    """
    axial_mm, angle_deg, depth_mm = np.broadcast_arrays(
        as_float_array(axial_mm, "axial_mm"),
        as_float_array(angle_deg, "angle_deg"),
        as_float_array(depth_mm, "depth_mm"),
    )
    radius = spec.radius_mm
    if np.any(axial_mm < -np.pi * radius / 2 - 1e-9):
        raise TactsenseInputError(
            f"axial_mm below the apex of the tip (-{np.pi * radius / 2:.3f} mm)"
        )
    angle = np.deg2rad(angle_deg)
    latitude = np.clip(-axial_mm / radius, 0.0, None)
    on_cylinder = axial_mm >= 0
    r = radius - depth_mm
    x = np.where(on_cylinder, axial_mm, -r * np.sin(latitude))
    ring = np.where(on_cylinder, r, r * np.cos(latitude))
    return np.stack([x, ring * np.cos(angle), ring * np.sin(angle)], axis=-1)


def tactel_centers(spec: SensorSpec):
    """Surface positions of all wired tactels.

    Returns
    -------
    axial_mm, angle_deg : ndarray, shape (rows, cols)
    """
    axial = np.broadcast_to(spec.row_axial_mm[:, None], spec.shape)
    angle = np.broadcast_to(spec.col_angle_deg[None, :], spec.shape)
    return axial.copy(), angle.copy()
