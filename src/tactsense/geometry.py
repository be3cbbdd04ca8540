"""Coordinates on the finger: tactel, surface, unwrapped plane and 3-D.

Conventions (written once, in ``docs/nomenclature.md``):

* **Tactel** ``(row, col)``, fractional allowed: row 0 is the row under the
  hemispherical tip, rows 1.. run along the cylinder toward the base; col
  runs around the circumference in the direction of increasing angle. Frames
  are arrays ``(..., rows, cols)`` in this order.
* **Surface** ``(axial_mm, angle_deg)``: ``axial_mm`` is the arc length along
  a meridian from the junction of hemisphere and cylinder, positive toward
  the base on the cylinder, negative on the hemisphere (the apex is at
  ``-pi R / 2``); ``angle_deg`` is the angle around the finger axis in
  (-180, 180].
* **Unwrapped plane** ``(u_mm, v_mm) = (axial_mm, R * angle_rad)``: the
  surface cut open along angle 180 deg and laid flat, as in Fig. 21 of the
  paper. On the hemisphere this is a map, not an isometry.
* **3-D** ``(x, y, z)`` in mm: x along the finger axis from the junction
  toward the base, angle 0 on +y, angle 90 deg on +z.
"""

from __future__ import annotations

import numpy as np

from tactsense._validation import TactsenseInputError, as_float_array
from tactsense.sensor import SensorSpec
from tactsense.sensor.cylinder import surface_to_xyz, tactel_centers, wrap_angle_deg

__all__ = [
    "surface_to_tactel",
    "surface_to_unwrapped",
    "surface_to_xyz",
    "tactel_centers",
    "tactel_to_surface",
    "unwrapped_to_surface",
    "wrap_angle_deg",
    "xyz_to_surface",
]


def _row_knots(spec: SensorSpec) -> tuple[np.ndarray, np.ndarray]:
    """Row indices and axial positions used for piecewise-linear row mapping."""
    rows = np.arange(spec.array.wired_rows, dtype=float)
    return rows, spec.row_axial_mm


def tactel_to_surface(spec: SensorSpec, row, col):
    """Surface position of fractional tactel coordinates.

    Between rows the axial position is interpolated linearly (the step from
    the tip row to the first cylinder row is larger than the ring spacing);
    outside the array it is extrapolated with the nearest step.

    Parameters
    ----------
    spec : SensorSpec
    row, col : array_like
        Fractional tactel coordinates [tactel].

    Returns
    -------
    axial_mm, angle_deg : ndarray
        Surface position [mm], [deg].
    """
    row = as_float_array(row, "row")
    col = as_float_array(col, "col")
    knots, axial = _row_knots(spec)
    axial_mm = _piecewise_linear(row, knots, axial)
    angle_deg = wrap_angle_deg(spec.col_angle_deg[0] + spec.array.spacing_angle_deg * col)
    return axial_mm, angle_deg


def surface_to_tactel(spec: SensorSpec, axial_mm, angle_deg):
    """Fractional tactel coordinates of surface positions.

    For a layout that closes on itself the column is wrapped into
    ``[-0.5, cols - 0.5)``; otherwise the angle is measured from the first
    wired column the short way round.

    Returns
    -------
    row, col : ndarray
        Fractional tactel coordinates [tactel].
    """
    axial_mm = as_float_array(axial_mm, "axial_mm")
    angle_deg = as_float_array(angle_deg, "angle_deg")
    knots, axial = _row_knots(spec)
    if axial.size > 1 and np.any(np.diff(axial) <= 0):
        raise TactsenseInputError("row positions must increase along the finger")
    row = _piecewise_linear(axial_mm, axial, knots)
    offset = wrap_angle_deg(angle_deg - spec.col_angle_deg[0])
    col = offset / spec.array.spacing_angle_deg
    if spec.closes_circumference:
        cols = spec.array.wired_cols
        col = np.mod(col + 0.5, cols) - 0.5
    return row, col


def surface_to_unwrapped(spec: SensorSpec, axial_mm, angle_deg):
    """Unwrapped-plane coordinates ``(u, v)`` of surface positions [mm]."""
    axial_mm = as_float_array(axial_mm, "axial_mm")
    angle = np.deg2rad(wrap_angle_deg(as_float_array(angle_deg, "angle_deg")))
    return axial_mm + 0.0 * angle, spec.radius_mm * angle + 0.0 * axial_mm


def unwrapped_to_surface(spec: SensorSpec, u_mm, v_mm):
    """Surface positions of unwrapped-plane coordinates [mm] -> ([mm], [deg])."""
    u_mm = as_float_array(u_mm, "u_mm")
    v_mm = as_float_array(v_mm, "v_mm")
    return u_mm + 0.0 * v_mm, wrap_angle_deg(np.rad2deg(v_mm / spec.radius_mm)) + 0.0 * u_mm


def xyz_to_surface(spec: SensorSpec, points):
    """Surface position of the skin point radially above 3-D points.

    Parameters
    ----------
    points : array_like, shape (..., 3)
        ``(x, y, z)`` [mm].

    Returns
    -------
    axial_mm, angle_deg, depth_mm : ndarray
        Surface position [mm], [deg] and depth below the skin [mm]
        (negative outside the finger).
    """
    points = as_float_array(points, "points")
    if points.shape[-1:] != (3,):
        raise TactsenseInputError(f"points has shape {points.shape}; expected (..., 3)")
    x, y, z = points[..., 0], points[..., 1], points[..., 2]
    radius = spec.radius_mm
    rho = np.hypot(y, z)
    angle_deg = wrap_angle_deg(np.rad2deg(np.arctan2(z, y)))
    latitude = np.arctan2(-x, rho)
    on_cylinder = x >= 0
    axial_mm = np.where(on_cylinder, x, -radius * latitude)
    depth_mm = np.where(on_cylinder, radius - rho, radius - np.hypot(x, rho))
    return axial_mm, angle_deg, depth_mm


def _piecewise_linear(value: np.ndarray, knots: np.ndarray, targets: np.ndarray) -> np.ndarray:
    """Linear interpolation that extrapolates with the end segments."""
    if knots.size == 1:
        return targets[0] + 0.0 * value
    result = np.interp(value, knots, targets)
    low_slope = (targets[1] - targets[0]) / (knots[1] - knots[0])
    high_slope = (targets[-1] - targets[-2]) / (knots[-1] - knots[-2])
    result = np.where(value < knots[0], targets[0] + (value - knots[0]) * low_slope, result)
    return np.where(value > knots[-1], targets[-1] + (value - knots[-1]) * high_slope, result)
