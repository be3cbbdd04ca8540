"""Compiled forward model of the paper's finger for round contacts (Numba).

The same separable model and the same 24-cell exact integration as
:mod:`tactsense.physics.array_response` (the tests check agreement to 1e-12): single
probes of one diameter (:func:`probe_frames`, the simulator's fast path) and patches of
any size and profile summed per frame (:func:`patch_frames`, the finger's
``contact_forward`` for ``frames_from_contacts``).
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
