"""The three-axis magnetic pad's forward model: tractions -> magnet displacement -> field.

A contact's normal pressure and tangential traction load the free surface; the bonded
layer's three-dimensional response (:class:`tactsense.physics.layer.LayerResponse`, its
tangential part checked against Cerruti and an independent Hankel solution in
``tests/physics/test_layer_shear*.py``) gives the displacement of each magnet's centre,
averaged over the magnet's footprint; every Hall sensor reads the point-dipole field of
the displaced magnets (:func:`dipole_field_t`), converted to counts
(:func:`field_counts`).

Coordinates are the pad's: x along rows, y along columns, z outward (``sensor.pad``).
"""

from __future__ import annotations

import functools

import numpy as np

from tactsense.physics.indenters import pressure_map
from tactsense.physics.pad_response import _pad_grid, modulus_star_pa, oversample
from tactsense.sensor.triaxial import TriaxialSpec

MU0_OVER_4PI = 1e-7
"""mu0 / (4 pi) [T m / A]."""


@functools.lru_cache(maxsize=16)
def _response(spec: TriaxialSpec, shape: tuple[int, int], hx: float, hy: float):
    from tactsense.physics.layer import LayerResponse

    g, layer = spec.grid, spec.layer
    # LayerResponse's axis 0 is its "y": the pad's x (rows) runs along it
    return LayerResponse(
        shape,
        (hx * 1e-3, hy * 1e-3),
        layer.sensing_depth_mm * 1e-3,
        thickness=layer.thickness_mm * 1e-3,
        youngs_modulus=layer.youngs_modulus_pa,
        poisson_ratio=layer.poisson_ratio,
        quantities=("u_x", "u_y", "u_z"),
        tangential=True,
        electrode=(g.electrode_x_mm * 1e-3, g.electrode_y_mm * 1e-3),
    )


def traction_maps(spec: TriaxialSpec, indenters, x_mm, y_mm):
    """Pressure and tangential tractions (p, q_x, q_y) [Pa] on the grid (x_mm, y_mm).

    Each indenter's tangential traction is its pressure times its tangential force over its
    normal force (the traction of full slip, limited to ``friction`` times the pressure).
    """
    modulus = modulus_star_pa(spec.layer)
    p = np.zeros((np.size(x_mm), np.size(y_mm)))
    qx, qy = np.zeros_like(p), np.zeros_like(p)
    for indenter in indenters:
        own = pressure_map([indenter], x_mm, y_mm, modulus_star_pa=modulus)
        p += own
        if indenter.force_n > 0 and (indenter.shear_x_n or indenter.shear_y_n):
            ratio = min(1.0, indenter.friction * indenter.force_n / max(indenter.shear_n, 1e-300))
            qx += own * (indenter.shear_x_n * ratio / indenter.force_n)
            qy += own * (indenter.shear_y_n * ratio / indenter.force_n)
    return p, qx, qy


def magnet_displacement(spec: TriaxialSpec, indenters) -> np.ndarray:
    """Displacement of every magnet's centre (x, y, z outward) [mm], shape (rows, cols, 3)."""
    x, y, hx, hy, _ = _pad_grid(spec)
    p, qx, qy = traction_maps(spec, indenters, x, y)
    response = _response(spec, p.shape, hx, hy)
    fields = response(p, traction_x=qy, traction_y=qx)
    g = spec.grid
    first_x, first_y = round(-x[0] / hx), round(-y[0] / hy)
    n = oversample(spec)
    pick = (slice(first_x, first_x + g.rows * n, n), slice(first_y, first_y + g.cols * n, n))
    out = np.empty((g.rows, g.cols, 3))
    out[..., 0] = fields["u_y"][pick] * 1e3
    out[..., 1] = fields["u_x"][pick] * 1e3
    out[..., 2] = -fields["u_z"][pick] * 1e3  # the layer's z points inward
    return out


def dipole_field_t(spec: TriaxialSpec, displacement_mm: np.ndarray) -> np.ndarray:
    """Field (x, y, z) [T] each Hall sensor reads, shape (..., rows, cols, 3).

    Magnet ``j`` sits at its taxel's centre, ``layer.sensing_depth_mm`` deep, moved by
    ``displacement_mm[..., j, :]``; sensor ``i`` at its taxel's centre,
    ``transduction.hall_depth_mm`` deep. ``B_i = sum_j mu0/(4 pi |r|^3) (3 (m . r^) r^ - m)``
    with ``r = sensor_i - magnet_j`` and ``m`` along +z; the sum runs over every magnet
    when ``transduction.neighbours``, else over the sensor's own.
    """
    d = np.asarray(displacement_mm, dtype=float)
    rows, cols = spec.shape
    lead = d.shape[:-3]
    t = spec.transduction
    centres = spec.taxel_positions_mm()[:, :2] * 1e-3  # (N, 2) [m]
    magnets = np.empty((*lead, rows * cols, 3))
    magnets[..., :2] = centres + d.reshape(*lead, rows * cols, 3)[..., :2] * 1e-3
    magnets[..., 2] = -spec.layer.sensing_depth_mm * 1e-3 + d.reshape(*lead, -1, 3)[..., 2] * 1e-3
    sensors = np.column_stack([centres, np.full(len(centres), -t.hall_depth_mm * 1e-3)])
    if t.neighbours:
        r = sensors[:, None, :] - magnets[..., None, :, :]  # (..., N sensors, N magnets, 3)
    else:
        r = (sensors - magnets)[..., None, :]
    dist = np.linalg.norm(r, axis=-1)
    m_dot_r = t.moment_a_m2 * r[..., 2]
    b = 3.0 * m_dot_r[..., None] * r / dist[..., None] ** 5
    b[..., 2] -= t.moment_a_m2 / dist**3
    total = MU0_OVER_4PI * b.sum(axis=-2)
    return total.reshape(*lead, rows, cols, 3)


def field_counts(spec: TriaxialSpec, field_t: np.ndarray) -> np.ndarray:
    """Counts (before noise, quantization and clipping) of a field [T]: the converter's
    zero field ``electronics.nominal_counts`` plus the field over each axis' LSB."""
    return spec.electronics.nominal_counts + np.asarray(field_t) / spec.lsb_t


def rest_field_t(spec: TriaxialSpec) -> np.ndarray:
    """The field every sensor reads untouched [T], shape (rows, cols, 3)."""
    return dipole_field_t(spec, np.zeros((*spec.shape, 3)))
