"""Standard errors of a joint fit's contacts (issue 34 item 2): each contact's x, y
[mm] and force [N] with its error from the Fisher matrix at the fit, so that a contact
the frame does not determine (beyond the pad's edge, where a farther contact with more
force reads alike) is not reported as a confident number."""

from __future__ import annotations

import math

import numpy as np

from tactsense.estimate.contacts._joint import (
    MODEL_ERROR,
    NP,
    PRIOR_RADIUS_MM,
    PRIOR_WIDTH,
    data_noise_variance,
)
from tactsense.estimate.contacts._joint_lm import residual_jacobian, tables_of
from tactsense.estimate.reading import signal_noise_variance

SINGULAR = 1e-7
"""Smallest ratio of the least to the largest singular value of the column-scaled
Jacobian (a Fisher matrix's condition number of 1e14) at which
:func:`standard_errors` inverts it [-]."""


def _fisher_sd(model, frame, q, sigma):
    """Standard errors (k, 3) of each contact's x, y [mm] and force [N] from the Fisher
    matrix at the fit ``q`` (k, NP): ``J^T J / sigma^2`` of the residuals the fit
    minimised (the taxels that read, a resistive taxel in tension censored, and the
    size's prior), over the parameters not held at a bound (a contact radius at 0 or the
    table's top, a flat share at 0 or 1: fixed there). NaN where that matrix is
    singular. The box on x, y is a search limit, not knowledge: a contact at it keeps
    its position's error."""
    k = len(q)
    n = frame.size
    r, jac = np.empty(n + k), np.empty((n + k, NP * k))
    prior = np.array([sigma, PRIOR_WIDTH, PRIOR_RADIUS_MM, model.modulus_star_pa])
    residual_jacobian(
        np.ascontiguousarray(q, float).ravel(), np.ascontiguousarray(frame, float).ravel(),
        model.x_taxel, model.y_taxel, tables_of(model), not model.capacitive,
        float(model.scale), prior, r, jac,
    )  # fmt: skip
    edge = 1e-6
    free = np.ones((k, NP), bool)
    free[:, 3] = (q[:, 3] > edge) & (q[:, 3] < model.a_top_mm - edge)
    free[:, 4] = (q[:, 4] > edge) & (q[:, 4] < 1.0 - edge)
    free = free.ravel()
    out = np.full((k, 3), np.nan)
    j = jac[:, free] / sigma
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


def standard_errors(signal, frame_index, row, col, force, radius, flat, sensor, model):
    """Standard errors (n, 3) of each contact's x, y [mm] and force [N] of a joint fit
    (:func:`fit_sizes`' rows: frame ``frame_index``, ``row``, ``col`` [taxel], ``force``
    [N], ``radius`` [mm], ``flat`` [-]), from the Fisher matrix at the fit
    (:func:`_fisher_sd`), under the noise the order selection weighs (the described or
    the frames' own, whichever is larger, plus :data:`MODEL_ERROR`); NaN where it is
    singular or the contact has no fit. A contact the taxels barely reach (beyond the
    pad's edge, where a farther contact with more force reads alike) carries a large
    error instead of passing as a confident number."""
    n = len(row)
    out = np.full((n, 3), np.nan)
    px, py = model.pitch_mm
    frames = np.asarray(frame_index)
    q_all = np.column_stack([np.asarray(row) * px, np.asarray(col) * py, force, radius, flat])
    fitted = []
    for f in np.unique(frames):
        idx = np.flatnonzero((frames == f) & np.all(np.isfinite(q_all), axis=1))
        if len(idx):
            fitted.append((idx, np.asarray(signal[int(f)], float), q_all[idx]))
    if not fitted:
        return out
    noise_var = max(
        signal_noise_variance(sensor),
        data_noise_variance(model, [(frame, q) for _, frame, q in fitted]),
    )
    for idx, frame, q in fitted:
        sigma = math.sqrt(noise_var) + MODEL_ERROR * float(np.abs(frame).max())
        with np.errstate(all="ignore"):
            out[idx] = _fisher_sd(model, frame, q, sigma)
    return out
