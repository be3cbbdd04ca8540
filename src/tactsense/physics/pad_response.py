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

GRID_STEP_MM = 0.5
"""Largest step of the grid on which a pad's pressure and strain are computed [mm]; at
least four points per pitch (a 1.6-mm probe of 50 g touches a disc of about 1.2 mm)."""


def oversample(spec: PadSpec) -> int:
    """Grid points per taxel pitch: at least 4, and steps of at most GRID_STEP_MM [-]."""
    pitch = max(spec.grid.row_pitch_mm, spec.grid.col_pitch_mm)
    return max(4, math.ceil(pitch / GRID_STEP_MM))


def modulus_star_pa(layer: Layer) -> float:
    """Plane-strain modulus E / (1 - nu^2) of a layer, for Hertz contact sizes [Pa]."""
    return layer.youngs_modulus_pa / (1.0 - layer.poisson_ratio**2)


@functools.lru_cache(maxsize=32)
def _pad_grid(spec: PadSpec) -> tuple[np.ndarray, np.ndarray, float, float, int]:
    """Fine grid over the pad and a margin of two layer thicknesses: x, y [mm], steps."""
    g = spec.grid
    n = oversample(spec)
    hx, hy = g.row_pitch_mm / n, g.col_pitch_mm / n
    margin = max(2.0 * spec.layer.thickness_mm, g.row_pitch_mm, g.col_pitch_mm)
    nx_margin, ny_margin = math.ceil(margin / hx), math.ceil(margin / hy)
    x = hx * np.arange(-nx_margin, (g.rows - 1) * n + nx_margin + 1)
    y = hy * np.arange(-ny_margin, (g.cols - 1) * n + ny_margin + 1)
    return x, y, hx, hy, nx_margin * 1000 + ny_margin


def strain_transfer(kx, ky, depth_mm: float, layer: Layer) -> np.ndarray:
    """Normal strain at ``depth_mm`` per unit surface pressure, in the wavenumber domain.

    The bonded layer's closed-form transfer function (:mod:`tactsense.physics.layer`):
    ``eps_hat_zz = p_hat dW_P(|k|, z) / (2 mu)``. A normal-load mode excites a field that
    does not vary along its crests, exactly the plane-strain strip of section 5 at
    ``|k|`` (:mod:`tactsense.physics.strip`); the tests check the two against each other.

    Parameters
    ----------
    kx, ky : array_like
        Wavenumbers [cycles/mm], broadcast together.
    depth_mm : float
        Depth below the free surface [mm].
    layer : Layer

    Returns
    -------
    ndarray
        ``eps_hat_zz / p_hat`` [1/Pa], negative (compression) for a push.
    """
    from tactsense.physics.layer import shear_modulus, transfer_functions

    k = 2.0 * np.pi * 1e3 * np.hypot(np.asarray(kx, dtype=float), np.asarray(ky, dtype=float))
    derivative = transfer_functions(
        k, depth_mm * 1e-3, layer.thickness_mm * 1e-3, layer.poisson_ratio
    )["dW_P"].real
    return derivative / (2.0 * shear_modulus(layer.youngs_modulus_pa, layer.poisson_ratio))


def strain_map(
    pressure_pa: np.ndarray,
    spacing_mm: tuple[float, float],
    layer: Layer,
    *,
    depth_mm: float | None = None,
    electrode_mm: tuple[float, float] | None = None,
) -> np.ndarray:
    """Normal strain ``eps_zz`` at a depth under a pressure map on a regular grid.

    :class:`tactsense.physics.layer.LayerResponse` (zero-padded FFT, the transfer
    function cached per grid, depth and layer), in millimetres.

    Parameters
    ----------
    pressure_pa : ndarray, shape (M, N)
        Surface pressure on the grid, compression positive [Pa].
    spacing_mm : (float, float)
        Grid steps along axis 0 and axis 1 [mm].
    layer : Layer
    depth_mm : float, optional
        Depth of the strain [mm] (default: the layer's sensing depth).
    electrode_mm : (float, float), optional
        Average over a rectangle of this size around each point (a taxel's electrode).

    Returns
    -------
    ndarray, shape (M, N)
        ``eps_zz`` [-], negative where compressed.
    """
    depth = layer.sensing_depth_mm if depth_mm is None else depth_mm
    pressure = np.asarray(pressure_pa, dtype=float)
    response = _response(
        pressure.shape[-2:],
        (float(spacing_mm[0]), float(spacing_mm[1])),
        float(depth),
        layer,
        None if electrode_mm is None else (float(electrode_mm[0]), float(electrode_mm[1])),
    )
    return response(pressure)["eps_zz"]


@functools.lru_cache(maxsize=64)
def _response(shape, spacing_mm, depth_mm, layer, electrode_mm):
    from tactsense.physics.layer import LayerResponse

    return LayerResponse(
        shape,
        (spacing_mm[0] * 1e-3, spacing_mm[1] * 1e-3),
        depth_mm * 1e-3,
        thickness=layer.thickness_mm * 1e-3,
        youngs_modulus=layer.youngs_modulus_pa,
        poisson_ratio=layer.poisson_ratio,
        electrode=None
        if electrode_mm is None
        else (electrode_mm[0] * 1e-3, electrode_mm[1] * 1e-3),
    )


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
    x, y, hx, hy, _ = _pad_grid(spec)
    pressure = pressure_map(indenters, x, y, modulus_star_pa=modulus_star_pa(spec.layer))
    g = spec.grid
    compressive = -strain_map(
        pressure, (hx, hy), spec.layer, electrode_mm=(g.electrode_x_mm, g.electrode_y_mm)
    )
    first_x, first_y = round(-x[0] / hx), round(-y[0] / hy)
    n = oversample(spec)
    return compressive[first_x : first_x + g.rows * n : n, first_y : first_y + g.cols * n : n]


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
    positions, normals = spec.taxel_positions_mm(), spec.taxel_normals()
    strain = np.zeros(len(positions))
    for indenter in indenters:
        centre, normal = surface_point(spec, indenter)
        t1, t2 = _local_frame(normal)
        offsets = positions - centre
        # the taxel's offset in the contact's tangent plane, and only taxels facing it
        u, v = offsets @ t1, offsets @ t2
        facing = normals @ normal > 0.0
        strain[facing] += _local_strain(
            indenter.moved(-indenter.x_mm, -indenter.y_mm),
            u[facing],
            v[facing],
            spec.layer,
            np.sqrt(spec.areas_mm2[facing]),
        )
    return strain[np.newaxis, :]


def _local_strain(indenter, u, v, layer: Layer, electrode_mm: np.ndarray) -> np.ndarray:
    """Compressive strain of a flat layer under ``indenter`` (centred at the origin) at the
    points (u, v) [mm], averaged over a square electrode of side ``electrode_mm`` each."""
    from scipy.interpolate import RegularGridInterpolator

    step = min(0.25, float(electrode_mm.min()) / 4.0, layer.thickness_mm / 4.0)
    reach = max(float(np.abs(u).max(initial=0.0)), float(np.abs(v).max(initial=0.0)))
    half = reach + 2.0 * layer.thickness_mm + float(electrode_mm.max())
    axis = step * np.arange(-math.ceil(half / step), math.ceil(half / step) + 1)
    pressure = indenter.pressure_pa(axis, axis, modulus_star_pa=modulus_star_pa(layer))
    out = np.empty(len(u))
    for side in np.unique(electrode_mm):
        chosen = electrode_mm == side
        compressive = -strain_map(pressure, (step, step), layer, electrode_mm=(side, side))
        interpolate = RegularGridInterpolator((axis, axis), compressive, bounds_error=False,
                                              fill_value=0.0)  # fmt: skip
        out[chosen] = interpolate(np.column_stack([u[chosen], v[chosen]]))
    return out


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


def strain_batch(spec: PadSpec | PointsSpec, applied, response) -> np.ndarray:
    """Compressive strain of every taxel for each step's indenters, (S, rows, cols) [-].

    ``response(spec, indenters)`` is the sensor's strain under one step's indenters, the
    kind's (:func:`pad_strain`, :func:`points_strain`; ``Kind.layer_strain``). Steps with
    the same indenters are computed once.
    """
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


def deflection_batch_flat(spec: PadSpec | PointsSpec, applied, response) -> np.ndarray:
    """Fractional deflection of every taxel per step, (S, rows, cols) [-], from the
    kind's strain ``response`` (:func:`strain_batch`).

    Capacitive: ``strain_gain`` times the compressive strain (eq. 3 when 1); resistive: the
    compressive strain itself (the transducer's gain is applied by
    :func:`deflection_to_counts`).
    """
    strain = strain_batch(spec, applied, response)
    if spec.transduction.kind == "capacitive":
        return spec.transduction.strain_gain * strain
    return strain


def resistive_counts(spec: PadSpec | PointsSpec, strain: np.ndarray) -> np.ndarray:
    """Reading of a resistive taxel: ``nominal_counts + counts_per_strain * max(strain, 0)``
    (``-`` for a falling sensor, ``[transduction] polarity``), unquantized and unclipped
    [counts].

    A piezoresistive element responds to compression; the tension beside a contact (an
    incompressible layer bulges there) leaves its reading at rest.
    """
    compression = np.maximum(strain, 0.0)
    change = spec.transduction.counts_per_strain * compression
    if spec.transduction.polarity == "falling":
        return spec.electronics.nominal_counts - change
    return spec.electronics.nominal_counts + change
