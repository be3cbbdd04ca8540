"""The joint fit's compiled Levenberg-Marquardt (issue 34 item 1: the fit made fast).

The same problem as :func:`tactsense.estimate.contacts._joint._fit_frame`'s reference
(SciPy's ``least_squares`` with finite-difference Jacobians, one frame evaluation per
parameter per step): the frame's signal under k round contacts, each
``F s ((1 - w) G_sphere(a; x_i - x, y_j - y) + w G_disc(a; ...))`` from the pad's
separable tables (:mod:`tactsense.physics._hertz_table`, interpolated as
:func:`tactsense.physics._contact_kernel.superpose` does: linear in a, cubic in dx, dy),
with its Jacobian in closed form (the derivative of the interpolants), and the prior on
ln a as k extra residuals. Everything runs compiled (Numba): one call per frame.

The step is Marquardt's (``(J^T J + lambda diag(J^T J)) delta = -J^T r``) projected on the
bounds (each parameter clipped into its box after the step); lambda falls by 3 on a step
that lowers the cost and rises by 4 on one that does not. :func:`levenberg_marquardt`
descends twice from each start and keeps the lower cost: once with free steps (lambda from
1e-3) and once within a trust region in fixed units (:func:`step_units`, SciPy's
``x_scale`` of the reference) that starts at :data:`FIRST_REACH` units (half a pitch in
position, half a millimetre in a), doubles after a step it cut that lowered the cost and
halves after one that did not, lambda from :data:`FIRST_LAMBDA`.
Why: the free descent's first, nearly Gauss-Newton steps can leap several millimetres on
a pair's tables and clip a contact's force, radius or flat share onto a bound, where the
fit settles in a worse minimum than SciPy's reaches from the same start (lmcheck, round
10: on the ``pad4`` pair frame whose forces differed by 37 % none of the twenty re-seeds
reached the reference's minimum, best residual 3.9e-5 against 9.3e-8); the trust
region's descent alone, though, lost two noise-free placements of
``scripts/padfit_pairs.py`` on ``pad4`` that the free descent resolves (1.5 pitches at
67.5 deg, 2.5 at 0 deg): neither path is the better from every start.
"""

from __future__ import annotations

import functools
import math

import numpy as np

from tactsense._jit import jit

NP = 5
"""Parameters per contact: x, y [mm], force [N], contact radius a [mm], flat share [-]."""


@jit(inline="always")
def _weights(w):
    """Cubic Lagrange weights at -1, 0, 1, 2 for w in [0, 1), and their derivatives."""
    return (
        -w * (w - 1.0) * (w - 2.0) / 6.0,
        (w + 1.0) * (w - 1.0) * (w - 2.0) / 2.0,
        -(w + 1.0) * w * (w - 2.0) / 2.0,
        (w + 1.0) * w * (w - 1.0) / 6.0,
        -(3.0 * w * w - 6.0 * w + 2.0) / 6.0,
        (3.0 * w * w - 4.0 * w - 1.0) / 2.0,
        -(3.0 * w * w - 2.0 * w - 2.0) / 2.0,
        (3.0 * w * w - 1.0) / 6.0,
    )


@jit()
def unit_response(x_taxel, y_taxel, xc, yc, a, xf, yf, step, a_step, g, gx, gy, ga):
    """One contact's response per newton ``g`` (rows, cols) [1/N] at (xc, yc) [mm] with
    pressure radius ``a`` [mm], and its derivatives along xc, yc [1/(N mm)] and a
    [1/(N mm)], written into ``g``, ``gx``, ``gy``, ``ga``; ``xf``, ``yf`` the table's
    padded factors (``SeparableResponse.padded_x``/``padded_y``)."""
    n_a, n_x, terms = xf.shape
    n_y = yf.shape[0]
    rows, cols = x_taxel.size, y_taxel.size
    u = np.zeros((rows, terms))
    ux = np.zeros((rows, terms))
    ua = np.zeros((rows, terms))
    v = np.zeros((terms, cols))
    vy = np.zeros((terms, cols))
    t = a / a_step
    ia = min(int(t), n_a - 2)
    wa = t - ia
    slope = 1.0 / a_step
    if wa > 1.0:
        wa = 1.0
        slope = 0.0
    below, above = xf[ia], xf[ia + 1]
    for i in range(rows):
        s = x_taxel[i] - xc
        d = abs(s) / step
        ix = int(d)
        if ix >= n_x - 3:
            continue
        w0, w1, w2, w3, d0, d1, d2, d3 = _weights(d - ix)
        sign = -1.0 if s > 0.0 else 1.0  # d(d)/d(xc) times step
        for r in range(terms):
            lo = w0 * below[ix, r] + w1 * below[ix + 1, r] + w2 * below[ix + 2, r]
            lo += w3 * below[ix + 3, r]
            hi = w0 * above[ix, r] + w1 * above[ix + 1, r] + w2 * above[ix + 2, r]
            hi += w3 * above[ix + 3, r]
            dlo = d0 * below[ix, r] + d1 * below[ix + 1, r] + d2 * below[ix + 2, r]
            dlo += d3 * below[ix + 3, r]
            dhi = d0 * above[ix, r] + d1 * above[ix + 1, r] + d2 * above[ix + 2, r]
            dhi += d3 * above[ix + 3, r]
            u[i, r] = (1.0 - wa) * lo + wa * hi
            ua[i, r] = (hi - lo) * slope
            ux[i, r] = ((1.0 - wa) * dlo + wa * dhi) * sign / step
    for j in range(cols):
        s = y_taxel[j] - yc
        d = abs(s) / step
        iy = int(d)
        if iy >= n_y - 3:
            continue
        w0, w1, w2, w3, d0, d1, d2, d3 = _weights(d - iy)
        sign = -1.0 if s > 0.0 else 1.0
        for r in range(terms):
            v[r, j] = w0 * yf[iy, r] + w1 * yf[iy + 1, r] + w2 * yf[iy + 2, r] + w3 * yf[iy + 3, r]
            dv = d0 * yf[iy, r] + d1 * yf[iy + 1, r] + d2 * yf[iy + 2, r] + d3 * yf[iy + 3, r]
            vy[r, j] = dv * sign / step
    for i in range(rows):
        for j in range(cols):
            s0 = 0.0
            sx = 0.0
            sy = 0.0
            sa = 0.0
            for r in range(terms):
                s0 += u[i, r] * v[r, j]
                sx += ux[i, r] * v[r, j]
                sy += u[i, r] * vy[r, j]
                sa += ua[i, r] * v[r, j]
            g[i, j] = s0
            gx[i, j] = sx
            gy[i, j] = sy
            ga[i, j] = sa


@jit()
def residual_jacobian(p, target, x_taxel, y_taxel, tabs, clip, scale, prior, out_r, out_j):
    """Residual (n + k) [-] and Jacobian (n + k, 5 k) of k contacts' parameters ``p``
    (5 k: x, y [mm], F [N], a [mm], w [-] per contact) against ``target`` (rows * cols)
    [-]; the prior's k residuals last when ``prior[0]`` (sigma [-]) > 0.

    ``tabs``: (sphere x factors, y factors, step, disc x factors, y factors, step,
    a step); ``clip``: a resistive taxel reads no tension (its residual and Jacobian row
    where the model is below zero: zero signal, zero slope); ``scale`` the force's
    factor (a capacitive pad's strain gain); ``prior``: (sigma, width, sphere radius
    [mm], plane-strain modulus [Pa])."""
    xs, ys, step_s, xd, yd, step_d, a_step = tabs
    rows, cols = x_taxel.size, y_taxel.size
    n = rows * cols
    k = p.size // 5
    out_r[:] = 0.0
    out_j[:, :] = 0.0
    gs = np.empty((4, rows, cols))
    gd = np.empty((4, rows, cols))
    model = np.zeros(n)
    for c in range(k):
        x, y, f, a, w = p[5 * c], p[5 * c + 1], p[5 * c + 2], p[5 * c + 3], p[5 * c + 4]
        unit_response(x_taxel, y_taxel, x, y, a, xs, ys, step_s, a_step, gs[0], gs[1], gs[2], gs[3])
        unit_response(x_taxel, y_taxel, x, y, a, xd, yd, step_d, a_step, gd[0], gd[1], gd[2], gd[3])
        fs = f * scale
        for i in range(rows):
            for j in range(cols):
                m = i * cols + j
                s0 = (1.0 - w) * gs[0, i, j] + w * gd[0, i, j]
                model[m] += fs * s0
                out_j[m, 5 * c] = fs * ((1.0 - w) * gs[1, i, j] + w * gd[1, i, j])
                out_j[m, 5 * c + 1] = fs * ((1.0 - w) * gs[2, i, j] + w * gd[2, i, j])
                out_j[m, 5 * c + 2] = scale * s0
                out_j[m, 5 * c + 3] = fs * ((1.0 - w) * gs[3, i, j] + w * gd[3, i, j])
                out_j[m, 5 * c + 4] = fs * (gd[0, i, j] - gs[0, i, j])
    for m in range(n):
        if clip and model[m] <= 0.0:
            out_r[m] = -target[m]
            out_j[m, :] = 0.0
        else:
            out_r[m] = model[m] - target[m]
    sigma, width, radius, e_star = prior
    if sigma > 0.0:
        for c in range(k):
            f, a = p[5 * c + 2], p[5 * c + 3]
            ff = max(f, 1e-4)
            hertz = (3.0 * ff * 1e-3 * radius / (4.0 * e_star)) ** (1.0 / 3.0) * 1e3
            capped = hertz >= radius
            ref = radius if capped else hertz
            aa = max(a, 1e-3)
            out_r[n + c] = sigma * math.log(aa / ref) / width
            if a > 1e-3:
                out_j[n + c, 5 * c + 3] = sigma / (width * a)
            if f > 1e-4 and not capped:
                out_j[n + c, 5 * c + 2] = -sigma / (3.0 * width * f)


FIRST_LAMBDA = 1.0
"""Marquardt's lambda at the first step [-] (1: the damping equal to the curvature along
each parameter, a step between Gauss-Newton's and a scaled gradient's)."""

FIRST_REACH = 5.0
"""The trust region's first radius, the largest step of any parameter in
:func:`step_units` [-]."""


@jit()
def step_units(p0, x_taxel, y_taxel):
    """Units (5 k) of the parameters' steps: a tenth of the taxel pitch in x and y [mm],
    a twentieth of the largest starting force [N], 0.1 mm in a, 0.1 in the flat share
    (the ``x_scale`` of the reference fit,
    :func:`~tactsense.estimate.contacts._joint._fit_frame_reference`); the pitch is
    the taxels' mean spacing along each axis (the other axis's on a single row)."""
    k = p0.size // 5
    px = (x_taxel[-1] - x_taxel[0]) / (x_taxel.size - 1) if x_taxel.size > 1 else 0.0
    py = (y_taxel[-1] - y_taxel[0]) / (y_taxel.size - 1) if y_taxel.size > 1 else 0.0
    if px <= 0.0:
        px = py
    if py <= 0.0:
        py = px
    if px <= 0.0:
        px = py = 1.0
    f = 1e-3
    for c in range(k):
        f = max(f, p0[5 * c + 2])
    units = np.empty(5 * k)
    for c in range(k):
        units[5 * c] = 0.1 * px
        units[5 * c + 1] = 0.1 * py
        units[5 * c + 2] = 0.05 * f
        units[5 * c + 3] = 0.1
        units[5 * c + 4] = 0.1
    return units


@jit()
def levenberg_marquardt(p0, lo, hi, target, x_taxel, y_taxel, tabs, clip, scale, prior, max_iter):
    """Least squares of :func:`residual_jacobian` from ``p0`` within [lo, hi]: returns
    the parameters, the data's residual sum of squares [-^2] (without the prior) and the
    number of Jacobians evaluated (both descents').

    Two descents from ``p0``, the lower cost (the data's and the prior's) kept: Marquardt's
    steps free (lambda from 1e-3) and within the trust region (lambda from
    :data:`FIRST_LAMBDA`, reach :data:`FIRST_REACH`). Each settles in a worse minimum
    than the other from some starts (:mod:`._joint_lm`'s notes); the pair of them ends
    worse than SciPy's reference less often than either."""
    p1, cost1, rss1, e1 = _descend(
        p0, lo, hi, target, x_taxel, y_taxel, tabs, clip, scale, prior, max_iter, 1e-3, np.inf
    )
    p2, cost2, rss2, e2 = _descend(
        p0, lo, hi, target, x_taxel, y_taxel, tabs, clip, scale, prior, max_iter,
        FIRST_LAMBDA, FIRST_REACH,
    )  # fmt: skip
    if cost2 < cost1:
        return p2, rss2, e1 + e2
    return p1, rss1, e1 + e2


@jit()
def _descend(p0, lo, hi, target, x_taxel, y_taxel, tabs, clip, scale, prior, max_iter, lam, reach):
    """One Levenberg-Marquardt descent from ``p0`` with Marquardt's ``lam`` [-] and the
    trust region's radius ``reach`` [step units] at the first step (inf: no trust
    region): the parameters, the cost with the prior, the data's residual sum of squares
    [-^2] and the Jacobians evaluated."""
    n = target.size
    k = p0.size // 5
    m = n + (k if prior[0] > 0.0 else 0)
    r = np.empty(n + k)
    jac = np.empty((n + k, 5 * k))
    r2 = np.empty(n + k)
    j2 = np.empty((n + k, 5 * k))
    p = np.minimum(np.maximum(p0.copy(), lo), hi)
    units = step_units(p, x_taxel, y_taxel)
    residual_jacobian(p, target, x_taxel, y_taxel, tabs, clip, scale, prior, r, jac)
    cost = np.sum(r[:m] ** 2)
    evaluations = 1
    for _ in range(max_iter):
        jm = jac[:m]
        a = jm.T @ jm
        g = jm.T @ r[:m]
        diag = np.diag(a).copy()
        floor = 1e-12 * max(diag.max(), 1e-300)
        for q in range(diag.size):
            diag[q] = max(diag[q], floor)
        # a parameter on its bound that the gradient pushes outward stays there (active
        # set): the others move, so a fit is not stalled by one bound
        held = np.zeros(diag.size, dtype=np.bool_)
        for q in range(diag.size):
            held[q] = (p[q] <= lo[q] and g[q] > 0.0) or (p[q] >= hi[q] and g[q] < 0.0)
        accepted = False
        trial = p
        new_cost = cost
        while lam < 1e16:
            system = a.copy()
            rhs = -g
            for q in range(diag.size):
                system[q, q] += lam * diag[q]
                if held[q]:
                    system[q, :] = 0.0
                    system[:, q] = 0.0
                    system[q, q] = 1.0
                    rhs[q] = 0.0
            delta = np.linalg.solve(system, rhs)
            size = np.max(np.abs(delta) / units)
            cut = size > reach
            if cut:
                delta *= reach / size
            trial = np.minimum(np.maximum(p + delta, lo), hi)
            residual_jacobian(trial, target, x_taxel, y_taxel, tabs, clip, scale, prior, r2, j2)
            evaluations += 1
            new_cost = np.sum(r2[:m] ** 2)
            if new_cost < cost:
                accepted = True
                lam = max(lam / 3.0, 1e-12)
                if cut:
                    reach *= 2.0
                break
            lam *= 4.0
            reach = max(0.5 * reach, 1e-12)
        if not accepted:
            break
        moved = np.max(np.abs(trial - p) / (np.abs(p) + 1e-3))
        drop = cost - new_cost
        p = trial
        cost = new_cost
        r[:] = r2
        jac[:, :] = j2
        if drop <= 1e-12 * cost or moved < 1e-10:
            break
    return p, cost, float(np.sum(r[:n] ** 2)), evaluations


@functools.lru_cache(maxsize=8)
def tables_of(model):
    """The argument ``tabs`` of :func:`residual_jacobian` for a
    :class:`~tactsense.physics._pad_model.PadContactModel` (once per model)."""
    s, d = model.tables["sphere"], model.tables["disc"]
    assert s.a_step_mm == d.a_step_mm  # one grid of a for both shapes (PadContactModel)
    return (
        np.ascontiguousarray(s.padded_x, dtype=np.float64),
        np.ascontiguousarray(s.padded_y, dtype=np.float64),
        float(s.step_mm),
        np.ascontiguousarray(d.padded_x, dtype=np.float64),
        np.ascontiguousarray(d.padded_y, dtype=np.float64),
        float(d.step_mm),
        float(s.a_step_mm),
    )
