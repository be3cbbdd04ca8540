"""A pad frame's contacts fitted jointly, each with its own size (issue 34 item 1).

The layer is linear: a frame under k round contacts is the sum of their responses
(:meth:`~tactsense.kinds.Kind.contact_model`). Seeded by the watershed's contacts and the
fixed-shape fit, the positions [mm], forces [N] and contact radii [mm] of all contacts of
a frame are fitted together by least squares over every taxel of the frame (the taxels'
noise is independent and equal: the maximum-likelihood fit under Gaussian noise).
"""

from __future__ import annotations

import math
import warnings

import numpy as np
from scipy.optimize import least_squares

SEED_RADIUS_MM = 1.0
"""Contact radius the fit starts from [mm]."""


def _fit_frame(model, frame, x0, y0, f0, a0):
    """Least-squares (x, y [mm], force [N], a [mm]) of k contacts on one frame, and the
    residual sum of squares [-^2]."""
    k = len(x0)
    px, py = model.pitch_mm
    rows, cols = frame.shape
    p0 = np.column_stack([x0, y0, np.maximum(f0, 1e-6), np.clip(a0, 0.0, model.a_top_mm)])
    lo = np.tile([-2.0 * px, -2.0 * py, 0.0, 0.0], k)
    hi = np.tile([(rows + 1) * px, (cols + 1) * py, np.inf, model.a_top_mm], k)
    p0 = np.clip(p0.ravel(), lo + 1e-9, hi - 1e-9)
    target = frame.ravel()

    def residual(p):
        q = p.reshape(k, 4)
        return model.signal(q[:, :2], q[:, 2], q[:, 3]).ravel() - target

    scale = np.tile([0.1 * px, 0.1 * py, max(float(np.max(f0)), 1e-3) * 0.05, 0.1], k)
    with warnings.catch_warnings(), np.errstate(all="ignore"):
        warnings.simplefilter("ignore")
        out = least_squares(
            residual, p0, bounds=(lo, hi), x_scale=scale, method="trf",
            diff_step=1e-6, xtol=1e-10, ftol=1e-12, gtol=1e-12, max_nfev=200 * (k + 1),
        )  # fmt: skip
    q = out.x.reshape(k, 4)
    return q, float(np.sum(out.fun**2))


def joint_fit(signal, seg, row, col, force, sensor, model):
    """Each contact's row, column [taxel], force [N] and contact radius [mm], fitted
    jointly with the other contacts of its frame, starting from ``row``, ``col``
    [taxel] and ``force`` [N] (the fixed-shape fit). Contacts whose seed force is not
    finite keep their seed."""
    n = len(seg["frame"])
    row, col, force = (np.array(v, float, copy=True) for v in (row, col, force))
    radius = np.full(n, np.nan)
    if n == 0:
        return row, col, force, radius
    px, py = model.pitch_mm
    frames = np.asarray(seg["frame"])
    order = np.argsort(frames, kind="stable")
    bounds = np.flatnonzero(np.diff(frames[order])) + 1
    for group in np.split(order, bounds):
        good = group[np.isfinite(force[group]) & np.isfinite(row[group])]
        if len(good) == 0:
            continue
        f = int(frames[good[0]])
        q, _ = _fit_frame(
            model, np.asarray(signal[f], float), row[good] * px, col[good] * py,
            force[good], np.full(len(good), SEED_RADIUS_MM),
        )  # fmt: skip
        row[good], col[good] = q[:, 0] / px, q[:, 1] / py
        force[good], radius[good] = q[:, 2], q[:, 3]
    return row, col, force, radius


def information(rss, noise_var, n_taxels, n_params):
    """Bayesian information criterion of a fit [-]: ``rss / sigma^2 + p ln n``."""
    return rss / noise_var + n_params * math.log(n_taxels)
