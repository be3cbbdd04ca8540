"""Compiled forward model for single hemispherical-probe contacts (Numba).

The same separable model and the same 24-cell exact integration as
:mod:`tactsense.physics.array_response` (the tests check agreement to 1e-12),
as one loop per contact.
"""

from __future__ import annotations

import math

import numpy as np

from tactsense._jit import jit


@jit(inline="always", fastmath=True)
def _g_normal(x, d, E, nu):
    return -((1.0 + nu) * x * d / (x * x + d * d) + (1.0 - nu) * math.atan2(x, d)) / (math.pi * E)


@jit(inline="always", fastmath=True)
def _g_tangential(x, d, E, nu):
    r2 = x * x + d * d
    return ((1.0 + nu) * d * d / r2 + nu * math.log(r2 / (d * d))) / (math.pi * E)


@jit(inline="always", fastmath=True)
def _ring_cumulative(s, flex):
    u = abs(s) / flex
    value = 0.5 * (1.0 - math.exp(-u) * math.cos(u))
    return value if s >= 0 else -value


@jit(fastmath=True)
def probe_frames(
    row_x,
    row_depth,
    row_ring,
    col_angle,
    E,
    nu,
    flex,
    radius_mm,
    axial_mm,
    angle_deg,
    force_n,
    half_mm,
    beta,
    u,
    share,
):
    """Fractional deflection (N, rows, cols) of N parabolic-probe contacts.

    Parameters
    ----------
    row_x, row_depth : float64 (rows,)
        Axial position and effective depth of each row [m].
    row_ring : float64 (rows,)
        Ring radius of each row [mm].
    col_angle : float64 (cols,)
        Angle of each column [rad].
    E, nu, flex : float
        Plane-stress constants [Pa], [-]; ring flexural length [m].
    axial_mm, angle_deg, force_n, beta : float64 (N,)
        Contact centre, normal force [N] and tangential ratio.
    half_mm : float
        Half-width of the contact [mm] (> 0).
    u, share : float64 (cells + 1,), (cells,)
        Normalised cell edges and the load share of each cell.
    """
    n = axial_mm.size
    shares = np.empty((1, share.size))
    shares[0] = share
    return patch_frames(
        row_x, row_depth, row_ring, col_angle, E, nu, flex, radius_mm, axial_mm, angle_deg,
        force_n, np.full(n, half_mm), beta, np.zeros(n, np.int64), u, shares,
        np.arange(n), n,
    )  # fmt: skip


@jit(fastmath=True)
def patch_frames(
    row_x,
    row_depth,
    row_ring,
    col_angle,
    E,
    nu,
    flex,
    radius_mm,
    axial_mm,
    angle_deg,
    force_n,
    half_mm,
    beta,
    profile,
    u,
    shares,
    owner,
    n_frames,
):
    """Fractional deflection (n_frames, rows, cols) of square patches of any size and
    profile, each added to its frame (r9-fastpath: the finger's ``contact_forward``).

    Parameters as :func:`probe_frames`, and per patch: ``half_mm`` (P,) its half-width
    along and around [mm] (> 0), ``profile`` (P,) the row of ``shares`` (profiles,
    cells) holding its load share per cell, ``owner`` (P,) its frame (0 to
    ``n_frames`` - 1).
    """
    n = axial_mm.size
    rows = row_x.size
    cols = col_angle.size
    cells = shares.shape[1]
    out = np.zeros((n_frames, rows, cols))
    around = np.empty((rows, cols))
    axial_part = np.empty(rows)
    for p in range(n):
        share = shares[profile[p]]
        centre = axial_mm[p] * 1e-3
        half = half_mm[p] * 1e-3
        width = 2.0 * half / cells
        for i in range(rows):
            d = row_depth[i]
            acc = 0.0
            x_prev = row_x[i] - (centre + half * u[0])
            gn_prev = _g_normal(x_prev, d, E, nu)
            gt_prev = _g_tangential(x_prev, d, E, nu) if beta[p] != 0.0 else 0.0
            for k in range(cells):
                x_next = row_x[i] - (centre + half * u[k + 1])
                gn = _g_normal(x_next, d, E, nu)
                term = gn - gn_prev
                if beta[p] != 0.0:
                    gt = _g_tangential(x_next, d, E, nu)
                    term += beta[p] * (gt - gt_prev)
                    gt_prev = gt
                acc += share[k] / width * term
                gn_prev = gn
            axial_part[i] = acc
        latitude = min(max(-axial_mm[p] / radius_mm, 0.0), math.pi / 2 - 1e-6)
        half_angle = half_mm[p] / (radius_mm * math.cos(latitude))
        phi = angle_deg[p] * math.pi / 180.0
        for i in range(rows):
            r_ring = row_ring[i]
            if i > 0 and r_ring == row_ring[i - 1]:
                for j in range(cols):
                    around[i, j] = around[i - 1, j]
                continue
            arc_width = 2.0 * r_ring * half_angle * 1e-3 / cells
            for j in range(cols):
                delta = (col_angle[j] - phi + math.pi) % (2.0 * math.pi) - math.pi
                s = delta * r_ring
                acc = 0.0
                c_prev = _ring_cumulative((s - r_ring * half_angle * u[0]) * 1e-3, flex)
                for k in range(cells):
                    c_next = _ring_cumulative((s - r_ring * half_angle * u[k + 1]) * 1e-3, flex)
                    acc += share[k] * (c_prev - c_next) / arc_width
                    c_prev = c_next
                around[i, j] = acc
        frame = out[owner[p]]
        for i in range(rows):
            for j in range(cols):
                frame[i, j] += force_n[p] * axial_part[i] * around[i, j]
    return out


# ---- the finger's fast forward (r9-fastpath) ----
class FingerContactForward:
    """The finger's fast forward (``Kind.contact_forward``): every contact of a batch as
    the paper's probe (a parabolic pressure across its Hertz diameter, a sphere) or a
    uniform square (a disc), on the 2-D twin compiled (:func:`patch_frames`): the same
    model and cells as ``elastic_batch``'s (tests/simulate/test_contact_frames_wide.py
    checks the two to 1e-9), without contact objects."""

    def __init__(self, spec):
        from tactsense.physics.array_response import _CELLS, _plane_stress_constants
        from tactsense.physics.contact import profile_cdf

        self.spec = spec
        e = spec.elastic
        self.E, self.nu = _plane_stress_constants(
            e.youngs_modulus_pa, e.effective_poisson_ratio, e.model
        )
        self.modulus_star_pa = e.youngs_modulus_pa / (1.0 - e.poisson_ratio**2)
        self.u = np.linspace(-1.0, 1.0, _CELLS + 1)
        self.shares = np.stack([np.diff(profile_cdf(self.u, p)) for p in ("parabolic", "uniform")])
        latitude = np.clip(-spec.row_axial_mm / spec.radius_mm, 0.0, np.pi / 2)
        self.rows = (
            np.ascontiguousarray(spec.row_axial_mm * 1e-3),
            np.ascontiguousarray(spec.row_depth_mm * 1e-3),
            np.ascontiguousarray(spec.ring_radius_mm * np.cos(latitude)),
            np.ascontiguousarray(np.deg2rad(spec.col_angle_deg)),
        )

    def prepare(self, contacts):
        """A function ``(first, last) -> (last - first, rows * cols)``: the fractional
        deflection [-] of every taxel for those frames of ``contacts``."""
        spec = self.spec
        force = contacts.normal_force_n
        shear = (
            np.zeros_like(force)
            if contacts.tangential_force_n is None
            else contacts.tangential_force_n[..., 0]
        )
        radius = contacts.radius_mm
        sphere = (
            np.full(force.shape, contacts.shape == "sphere")
            if isinstance(contacts.shape, str)
            else contacts.shape == "sphere"
        )
        hertz = 1e3 * np.cbrt(3.0 * force * radius * 1e-3 / (4.0 * self.modulus_star_pa))
        half = np.where(sphere, np.minimum(hertz, radius), radius)
        with np.errstate(divide="ignore", invalid="ignore"):
            beta = np.where(force > 0, shear / force, 0.0)
        rows, cols = spec.shape

        def block(first: int, last: int) -> np.ndarray:
            frame, slot = np.nonzero(force[first:last] > 0)
            at = (frame + first, slot)
            out = patch_frames(
                *self.rows, self.E, self.nu, spec.ring_flexural_length_mm * 1e-3,
                spec.radius_mm,
                np.ascontiguousarray(contacts.position_mm[at][:, 0]),
                np.ascontiguousarray(np.degrees(contacts.position_mm[at][:, 1] / spec.radius_mm)),
                np.ascontiguousarray(force[at]), np.ascontiguousarray(half[at]),
                np.ascontiguousarray(beta[at]),
                np.ascontiguousarray(np.where(sphere[at], 0, 1).astype(np.int64)),
                self.u, self.shares, np.ascontiguousarray(frame.astype(np.int64)), last - first,
            )  # fmt: skip
            return out.reshape(last - first, rows * cols)

        return block


# ---- /r9-fastpath ----
