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

import dataclasses
import functools

import numpy as np

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


STICK, PARTIAL_SLIP, GROSS_SLIP = 0, 1, 2
"""A contact's slip state: all of it sticks, slip spreads in from its edge (Cattaneo-
Mindlin's annulus ``c < r < a``), or the whole contact slides."""


SLIP_TOLERANCE = 1e-9
"""Relative rounding allowed in ``Q / (mu P)`` at gross slip [-]: ``Q`` is the length of
its x and y parts, so ``Q = mu P`` set at an angle comes back a few ulp short (at -138 deg,
1 - 1e-16: "partial", ``c/a`` 5e-6, while sliding)."""


def slip_state(indenter) -> tuple[int, float]:
    """A contact's slip state (:data:`STICK`, :data:`PARTIAL_SLIP`, :data:`GROSS_SLIP`)
    and its stick ratio ``c / a`` [-] under its tangential force ``Q`` (``shear_n``).

    A sphere (Hertz pressure; Cattaneo 1938, Mindlin 1949; Johnson 1985, ch. 7): the central
    stick zone's radius ``c / a = (1 - Q / (mu P))^(1/3)``, partial slip for
    ``0 < Q < mu P``, gross slip at ``Q >= mu P`` (``c = 0``). Any other indenter: no
    partial-slip model (stick, ``c / a = 1``, below ``mu P``; gross slip, ``0``, at it).
    No tangential force: stick, ``c / a = 1``; a tangential force without a normal
    one: gross slip. (``c / a`` depends on ``Q / (mu P)`` alone: the same sphere and
    modulus set ``a`` and ``c``.)
    """
    q, p, mu = indenter.shear_n, indenter.force_n, indenter.friction
    if q == 0.0 or p <= 0.0:
        return (STICK, 1.0) if q == 0.0 else (GROSS_SLIP, 0.0)
    ratio = q / (mu * p)
    if ratio >= 1.0 - SLIP_TOLERANCE:  # Q = mu P rebuilt from its x, y parts: rounding
        return GROSS_SLIP, 0.0
    if getattr(indenter, "kind", "") != "sphere":
        return STICK, 1.0
    return PARTIAL_SLIP, float((1.0 - ratio) ** (1.0 / 3.0))


def transmitted_shear_n(indenter) -> tuple[float, float]:
    """The tangential force (x, y) [N] a contact passes to the skin: its own, limited in
    size to ``mu P`` (beyond it the contact slides and friction passes ``mu P``)."""
    q = indenter.shear_n
    if q == 0.0:
        return 0.0, 0.0
    scale = min(1.0, indenter.friction * indenter.force_n / q)
    return indenter.shear_x_n * scale, indenter.shear_y_n * scale


def tangential_traction_pa(indenter, x_mm, y_mm, *, modulus_star_pa: float) -> np.ndarray:
    """Magnitude of an indenter's tangential traction on the grid (x_mm, y_mm) [Pa],
    directed along its tangential force; shape (M, N), cell-averaged like the pressure.

    A sphere (Cattaneo-Mindlin; Johnson 1985, ch. 7): with Hertz's
    ``p0 = 3 P / (2 pi a^2)``, ``q = mu p0 sqrt(1 - r^2/a^2)`` over the contact minus
    ``mu p0 (c/a) sqrt(1 - r^2/c^2)`` inside the stick zone ``r < c``. The second term is
    the Hertz pressure of the same sphere under the load ``P (c/a)^3`` (whose contact
    radius is ``c``), so ``q = mu (p_P - p_{P (c/a)^3})``, each cell-averaged and summing
    to its load exactly: the traction sums to ``mu P (1 - (c/a)^3) = Q``. Gross slip
    (``Q >= mu P``): ``q = mu p``, summing to ``mu P`` (the contact slides; the
    tangential force it passes is limited to that).

    The traction depends on the present ``Q`` alone: a force ramped down retraces the
    loading solution (Mindlin-Deresiewicz's reverse slip on unloading is not modelled).
    With ``nu = 0.5`` the normal and tangential problems uncouple (Dundurs' beta = 0),
    as Cattaneo-Mindlin assume.

    Any other indenter: the traction is the pressure times ``min(Q, mu P) / P`` (the
    tangential traction of a rigid flat punch that sticks has the pressure's shape,
    Johnson 1985, ch. 7, with the coupling of normal and tangential loads left out;
    for the others an assumption: their partial slip is not modelled).
    """
    p = indenter.pressure_pa(x_mm, y_mm, modulus_star_pa=modulus_star_pa)
    q, force, mu = indenter.shear_n, indenter.force_n, indenter.friction
    if q == 0.0 or force <= 0.0:
        return np.zeros_like(p)
    state, stick = slip_state(indenter)
    if state == PARTIAL_SLIP:
        inner = dataclasses.replace(indenter, force_n=force * stick**3)
        return mu * (p - inner.pressure_pa(x_mm, y_mm, modulus_star_pa=modulus_star_pa))
    return p * (min(q, mu * force) / force)


def _window(indenter, x_mm, y_mm, modulus: float) -> tuple[slice, slice]:
    """The cells of the grid (x_mm, y_mm) an indenter's load can reach, and one more on
    each side (its pressure is zero beyond ``reach_mm``); clipped to the grid."""
    reach = indenter.reach_mm(modulus)
    hx = float(x_mm[1] - x_mm[0]) if np.size(x_mm) > 1 else 1.0
    hy = float(y_mm[1] - y_mm[0]) if np.size(y_mm) > 1 else 1.0
    span = []
    for centre, axis, h in ((indenter.x_mm, x_mm, hx), (indenter.y_mm, y_mm, hy)):
        lo = int(np.searchsorted(axis, centre - reach - 1.5 * h))
        hi = int(np.searchsorted(axis, centre + reach + 1.5 * h, side="right"))
        lo, hi = max(0, lo - 1), min(np.size(axis), hi + 1)
        span.append(slice(lo, hi) if hi - lo >= 2 else slice(0, np.size(axis)))
    return span[0], span[1]


def traction_maps(spec: TriaxialSpec, indenters, x_mm, y_mm, *, window: bool = True):
    """Pressure and tangential tractions (p, q_x, q_y) [Pa] on the grid (x_mm, y_mm).

    Each indenter's tangential traction is :func:`tangential_traction_pa` (Cattaneo-
    Mindlin on a sphere), directed along its tangential force (``shear_x_n``,
    ``shear_y_n``). ``window``: each indenter's load is evaluated on the cells it can
    reach alone (the same cell averages and the same scaling to its force as on the
    whole grid: ``tests/physics/test_triaxial.py`` checks the two agree to 1e-12); False:
    on the whole grid (the straightforward way, for the benchmark).
    """
    modulus = modulus_star_pa(spec.layer)
    x_mm, y_mm = np.asarray(x_mm, dtype=float), np.asarray(y_mm, dtype=float)
    p = np.zeros((x_mm.size, y_mm.size))
    qx, qy = np.zeros_like(p), np.zeros_like(p)
    for indenter in indenters:
        if indenter.force_n <= 0:
            continue
        cells = _window(indenter, x_mm, y_mm, modulus) if window else (slice(None),) * 2
        xs, ys = x_mm[cells[0]], y_mm[cells[1]]
        p[cells] += indenter.pressure_pa(xs, ys, modulus_star_pa=modulus)
        shear = indenter.shear_n
        if shear > 0:
            q = tangential_traction_pa(indenter, xs, ys, modulus_star_pa=modulus)
            qx[cells] += q * (indenter.shear_x_n / shear)
            qy[cells] += q * (indenter.shear_y_n / shear)
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


def background_field_t(spec: TriaxialSpec) -> np.ndarray:
    """The uniform background field (the Earth's) every sensor reads [T], shape (3,)."""
    t = spec.transduction
    return 1e-6 * np.array([t.earth_field_x_ut, t.earth_field_y_ut, t.earth_field_z_ut])


def sensor_offsets_t(spec: TriaxialSpec, rng=None) -> np.ndarray:
    """Each sensor's offset per axis [T], shape (rows, cols, 3): normal with standard
    deviation ``transduction.offset_sd_ut``, drawn from ``flaws.gain_seed`` (the skin's
    own, the same in every run) unless ``rng`` is given."""
    rng = np.random.default_rng(spec.flaws.gain_seed + 1 if rng is None else rng)
    return 1e-6 * spec.transduction.offset_sd_ut * rng.standard_normal((*spec.shape, 3))


def rest_field_t(spec: TriaxialSpec) -> np.ndarray:
    """The field every sensor reads untouched [T], shape (rows, cols, 3): the magnets'
    (its own and, with ``neighbours``, the others') and the background field (before
    gains and offsets)."""
    return dipole_field_t(spec, np.zeros((*spec.shape, 3))) + background_field_t(spec)


def magnet_moment_a_m2(remanence_t: float, diameter_mm: float, height_mm: float) -> float:
    """Dipole moment of a uniformly magnetised cylinder [A m^2]: ``Br V / mu0`` with its
    remanence ``Br`` [T] and volume ``pi d^2 h / 4`` (d, h [mm])."""
    volume_m3 = np.pi * (diameter_mm * 1e-3) ** 2 * (height_mm * 1e-3) / 4.0
    return float(remanence_t * volume_m3 / (4e-7 * np.pi))


def rest_saturation(spec: TriaxialSpec) -> list[dict]:
    """Where the untouched skin's reading is at or beyond the converter's range: one entry
    per axis and side that any taxel reaches, ``{"axis": "z", "taxels": n, "of": rows x
    cols, "counts": the most extreme rest count (before clipping), "rail": 0 or full
    scale}``. The rest field (:func:`rest_field_t`, offsets and gains left out: they
    move it by tens of uT) through :func:`field_counts`: a taxel there reads its rail
    and no press or shear can move that axis."""
    counts = field_counts(spec, rest_field_t(spec))
    full = 2 ** int(spec.electronics.adc_bits) - 1
    found = []
    for axis, name in enumerate(spec.component_names):
        values = counts[..., axis]
        for rail, hit in ((0, values <= 0), (full, values >= full)):
            if hit.any():
                extreme = values.min() if rail == 0 else values.max()
                found.append({"axis": name, "taxels": int(hit.sum()), "of": int(hit.size),
                              "counts": float(extreme), "rail": rail})  # fmt: skip
    return found
