"""The Fisher matrix of a joint fit's contacts at the fit (issue 34 item 2): each
contact's standard errors of x, y [mm] and force [N], NaN where the frame does not
determine them."""

from __future__ import annotations

import numpy as np

from tactsense.estimate.contacts._joint_lm import NP, residual_jacobian, tables_of

SINGULAR = 1e-7
"""Smallest ratio of the least to the largest singular value of the column-scaled
Jacobian (a Fisher matrix's condition number of 1e14) at which
:func:`fisher_sd` inverts it [-]."""


def fisher_sd(model, frame, q, prior):
    """Standard errors (k, 3) of each contact's x, y [mm] and force [N] from the Fisher
    matrix at the fit ``q`` (k, NP), ``prior`` the fit's (sigma [-], width [-], sphere
    radius [mm], plane-strain modulus [Pa]: :func:`._joint._fit_frame`'s):
    ``J^T J / sigma^2`` of the residuals the fit
    minimised (the taxels that read, a resistive taxel in tension censored, and the
    size's prior), over the parameters not held at a bound (a contact radius at 0 or the
    table's top, a flat share at 0 or 1: fixed there). NaN where that matrix is
    singular. The box on x, y is a search limit, not knowledge: a contact at it keeps
    its position's error."""
    k = len(q)
    n = frame.size
    r, jac = np.empty(n + k), np.empty((n + k, NP * k))
    residual_jacobian(
        np.ascontiguousarray(q, float).ravel(), np.ascontiguousarray(frame, float).ravel(),
        model.x_taxel, model.y_taxel, tables_of(model), not model.capacitive,
        float(model.scale), np.asarray(prior, float), r, jac,
    )  # fmt: skip
    edge = 1e-6
    free = np.ones((k, NP), bool)
    free[:, 3] = (q[:, 3] > edge) & (q[:, 3] < model.a_top_mm - edge)
    free[:, 4] = (q[:, 4] > edge) & (q[:, 4] < 1.0 - edge)
    free = free.ravel()
    out = np.full((k, 3), np.nan)
    j = jac[:, free] / prior[0]
    # fewer readings (the taxels whose rows carry the fit's slope, and the size's prior)
    # than free parameters: singular, however the rounding leaves the smallest singular
    # value (round 10's trial: one taxel read gave errors of 11 m instead of NaN)
    rows = np.linalg.norm(j, axis=1)
    if np.sum(rows > 1e-6 * max(float(rows.max(initial=0.0)), 1e-300)) < j.shape[1]:
        return out
    norms = np.linalg.norm(j, axis=0)
    if not np.all(np.isfinite(j)) or norms.min() <= 0.0:
        return out
    unit = j / norms
    s = np.linalg.svd(unit, compute_uv=False)
    if s[-1] < SINGULAR * s[0]:
        return out
    cov = np.linalg.inv(unit.T @ unit) / np.outer(norms, norms)
    where = np.flatnonzero(free)
    sd = np.sqrt(np.maximum(np.diag(cov), 0.0))
    for c in range(k):
        for m in range(3):
            out[c, m] = sd[np.searchsorted(where, NP * c + m)]
    return out
