"""Pads and point sets: from indenters on the surface to each taxel's deflection.

The chain for a pad (``kind = "pad"``):

indenters -> pressure on a fine grid over the pad (:mod:`tactsense.physics.indenters`)
-> normal strain ``eps_zz`` at the sensing depth in the elastic layer bonded to its rigid
substrate (:mod:`tactsense.physics.layer`, the three-dimensional layer solved in the
wavenumber domain) -> averaged over each taxel's electrode -> the taxel's fractional
deflection: ``strain_gain * (-eps_zz)`` for a capacitive pad (eq. 3 of the paper when 1),
``-eps_zz`` (compression positive) for a resistive one, whose transducer turns it into
counts (:func:`deflection_to_counts`).

For a point set each taxel is loaded through the same flat layer in its own tangent
plane (locally flat): an indenter centred at a surface point acts on a taxel as it would
on a flat layer at the taxel's in-plane offset from it.
"""

from __future__ import annotations

import functools
import math

import numpy as np

from tactsense._validation import TactsenseInputError
from tactsense.physics.indenters import Indenter, pressure_map
from tactsense.sensor import Layer, PadSpec, PointsSpec

OVERSAMPLE = 4
"""Grid points per taxel pitch on which pressure and strain are computed [-]."""


def modulus_star_pa(layer: Layer) -> float:
    """Plane-strain modulus E / (1 - nu^2) of a layer, for Hertz contact sizes [Pa]."""
    return layer.youngs_modulus_pa / (1.0 - layer.poisson_ratio**2)


@functools.lru_cache(maxsize=32)
def _pad_grid(spec: PadSpec) -> tuple[np.ndarray, np.ndarray, float, float, int]:
    """Fine grid over the pad and a margin of two layer thicknesses: x, y [mm], steps."""
    g = spec.grid
    hx, hy = g.row_pitch_mm / OVERSAMPLE, g.col_pitch_mm / OVERSAMPLE
    margin = max(2.0 * spec.layer.thickness_mm, g.row_pitch_mm, g.col_pitch_mm)
    nx_margin, ny_margin = math.ceil(margin / hx), math.ceil(margin / hy)
    x = hx * np.arange(-nx_margin, (g.rows - 1) * OVERSAMPLE + nx_margin + 1)
    y = hy * np.arange(-ny_margin, (g.cols - 1) * OVERSAMPLE + ny_margin + 1)
    return x, y, hx, hy, nx_margin * 1000 + ny_margin


def pad_strain(spec: PadSpec, indenters) -> np.ndarray:
    """Compressive strain ``-eps_zz`` at each taxel, averaged over its electrode.

    Parameters
    ----------
    spec : PadSpec
    indenters : sequence of Indenter
        What presses on the pad (superposed: the layer is linear).

    Returns
    -------
    ndarray, shape (rows, cols)
        Compressive strain at the sensing depth [-], positive when compressed.
    """
    from tactsense.physics.layer import taxel_strain

    x, y, hx, hy, _ = _pad_grid(spec)
    pressure = pressure_map(indenters, x, y, modulus_star_pa=modulus_star_pa(spec.layer))
    g = spec.grid
    return taxel_strain(
        pressure,
        spacing_mm=(hx, hy),
        layer=spec.layer,
        first_taxel_index=(round(-x[0] / hx), round(-y[0] / hy)),
        taxel_step=(OVERSAMPLE, OVERSAMPLE),
        taxel_shape=spec.shape,
        electrode_mm=(g.electrode_x_mm, g.electrode_y_mm),
    )


def _local_frame(normal: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Two unit tangents (t1, t2) of a surface with outward ``normal``: t1 along the part of
    +x tangent to it (+y where x is normal), t2 = n x t1."""
    for axis in (np.array([1.0, 0.0, 0.0]), np.array([0.0, 1.0, 0.0])):
        t1 = axis - axis.dot(normal) * normal
        if np.linalg.norm(t1) > 1e-9:
            break
    t1 = t1 / np.linalg.norm(t1)
    return t1, np.cross(normal, t1)


def points_strain(spec: PointsSpec, indenters) -> np.ndarray:
    """Compressive strain at each taxel of a point set, shape (1, N) [-].

    An indenter's ``(x_mm, y_mm)`` are taken in the tangent plane of the taxel nearest to
    it, with the 3-D point ``position_mm`` of :class:`SurfaceIndenter` when given: each
    taxel reads the flat layer's response at its in-plane offset from the indenter's
    centre, averaged over a square of its electrode area.
    """
    from tactsense.physics.layer import point_strain

    positions, normals = spec.taxel_positions_mm(), spec.taxel_normals()
    strain = np.zeros(len(positions))
    for indenter in indenters:
        centre, normal = surface_point(spec, indenter)
        t1, t2 = _local_frame(normal)
        offsets = positions - centre
        # the taxel's offset in the contact's tangent plane, and only taxels facing it
        u, v = offsets @ t1, offsets @ t2
        facing = normals @ normal > 0.0
        strain[facing] += point_strain(
            indenter.moved(-indenter.x_mm, -indenter.y_mm),
            u[facing],
            v[facing],
            layer=spec.layer,
            electrode_mm=np.sqrt(spec.areas_mm2[facing]),
        )
    return strain[np.newaxis, :]


def surface_point(spec: PointsSpec, indenter: Indenter) -> tuple[np.ndarray, np.ndarray]:
    """The 3-D centre and outward normal of an indenter on a point set's surface.

    ``(x_mm, y_mm)`` place it in the tangent plane of taxel ``at_taxel`` (an attribute of
    the indenter when present, else the taxel nearest the point (x, y) seen from +z).
    """
    positions, normals = spec.taxel_positions_mm(), spec.taxel_normals()
    index = getattr(indenter, "at_taxel", None)
    if index is None:
        index = int(np.argmin(np.hypot(positions[:, 0] - indenter.x_mm,
                                       positions[:, 1] - indenter.y_mm)))  # fmt: skip
        return (
            positions[index]
            + (indenter.x_mm - positions[index, 0]) * np.array([1.0, 0.0, 0.0])
            + (indenter.y_mm - positions[index, 1]) * np.array([0.0, 1.0, 0.0]),
            normals[index],
        )
    if not 0 <= index < len(positions):
        raise TactsenseInputError(f"at_taxel = {index} is not a taxel of {spec.name!r}")
    t1, t2 = _local_frame(normals[index])
    return positions[index] + indenter.x_mm * t1 + indenter.y_mm * t2, normals[index]


def strain_batch(spec: PadSpec | PointsSpec, applied) -> np.ndarray:
    """Compressive strain of every taxel for each step's indenters, (S, rows, cols) [-].

    Steps with the same indenters are computed once.
    """
    response = pad_strain if spec.kind == "pad" else points_strain
    out = np.zeros((len(applied), *spec.shape))
    seen: dict[tuple, np.ndarray] = {}
    for k, indenters in enumerate(applied):
        key = tuple(indenters)
        if not key:
            continue
        for indenter in key:
            if not isinstance(indenter, Indenter):
                raise TactsenseInputError(
                    f"a {spec.kind} is pressed by indenters (sphere, disc, punch, knife); "
                    f"got {type(indenter).__name__}, a contact for the finger"
                )
        if key not in seen:
            seen[key] = response(spec, key)
        out[k] = seen[key]
    return out


def deflection_batch_flat(spec: PadSpec | PointsSpec, applied) -> np.ndarray:
    """Fractional deflection of every taxel per step, (S, rows, cols) [-].

    Capacitive: ``strain_gain`` times the compressive strain (eq. 3 when 1); resistive: the
    compressive strain itself (the transducer's gain is applied by
    :func:`deflection_to_counts`).
    """
    strain = strain_batch(spec, applied)
    if spec.transduction.kind == "capacitive":
        return spec.transduction.strain_gain * strain
    return strain


def resistive_counts(spec: PadSpec | PointsSpec, strain: np.ndarray) -> np.ndarray:
    """Reading of a resistive taxel: ``nominal_counts + counts_per_strain * strain``,
    unquantized and unclipped [counts]."""
    return spec.electronics.nominal_counts + spec.transduction.counts_per_strain * strain
