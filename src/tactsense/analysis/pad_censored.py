"""Bounds for one-sided pads: a censored-likelihood Cramer-Rao bound, an honest rank test,
and a Bayesian (hybrid Van Trees) bound averaged over the position within a taxel.

A resistive or piezoresistive taxel does not report tension: its reading rests at the
untouched value when the layer above it is stretched (``max(strain, 0)`` in
:func:`tactsense.analysis.pad_bound.counts_from_strain`). The classic bound of
:mod:`tactsense.analysis.pad_bound` puts Gaussian noise *after* that clip, so a taxel in
tension carries no information, and a probe centred on a ``pad16`` taxel (every
neighbour in tension) gives a singular Fisher matrix. Here the noise sits *before* the
clip (the element's own output noise, then a transducer or converter that cannot read
below rest: the Tobit model), ``y = max(mu + n, c)`` with ``mu`` the latent reading
(the response continued linearly into tension with its slope at rest), ``c`` the rest
reading and ``n ~ N(0, sigma^2)``. A taxel's Fisher information on ``mu`` is then
``w(alpha) / sigma^2`` with ``alpha = (c - mu) / sigma`` and

    w(alpha) = Q(alpha) + alpha phi(alpha) + phi(alpha)^2 / Phi(alpha)

(``phi``, ``Phi`` the standard normal density and distribution, ``Q = 1 - Phi``): 1 far
above rest (the unclipped Gaussian's), 0.82 at rest, falling as ``alpha phi(alpha)``
below it -- not zero and not 1. ``J = sum_i w_i g_i g_i^T / sigma^2`` with ``g_i`` the
latent reading's derivatives (central differences, as the classic bound's).

Singular Fisher matrices are reported by a rank test
(:func:`tactsense.analysis.pad_bound.rank_test`): the singular values of the whitened
Jacobian in units of a pitch and of the load, the matrix singular when the smallest is
below ``RANK_TOLERANCE`` (1e-6) times the largest (eigenvalue ratio 1e-12): a move of a
pitch changes the readings by less than a millionth of what doubling the load does.

The Bayesian bound is the hybrid Cramer-Rao bound (Van Trees for the random part, Rockah
and Schultz 1987): the position uniform-ish within one taxel cell, a ``cos^2`` prior
per axis over the pitch (``(2/L) cos^2(pi u / L)``, Fisher information ``(2 pi / L)^2``,
zero at the cell's edges as Van Trees needs), the force a fixed unknown:
``B = (E_prior[J(x, y, F)] + diag(J_p, J_p, 0))^-1``, the prior mean by Gauss-Legendre
quadrature (``BAYES_NODES`` per axis). It bounds the mean square error over the cell of
any estimator unbiased in the force, and stays finite where the point bound is infinite.

:func:`ziv_zakai_bound` bounds the same cell's mean square error of one coordinate
without averaging the information (Van Trees sits far under the best estimator's error
where the information varies across the cell by orders of magnitude).
"""

from __future__ import annotations

import math

import numpy as np
from scipy import special

from tactsense._validation import TactsenseInputError, check_positive
from tactsense.analysis.pad_bound import (
    PROBE_RADIUS_MM,
    _check_pad,
    bound_stds,
    counts_from_strain,
    rank_test,
)
from tactsense.analysis.pad_bound import (
    RANK_TOLERANCE as RANK_TOLERANCE,  # re-exported
)
from tactsense.physics.indenters import SphereProbe
from tactsense.physics.pad_response import pad_strain

BAYES_NODES = 8
"""Gauss-Legendre nodes per axis of the Bayesian bound's average over a taxel cell."""
REALISTIC_NOISE_FS_PCT = 1.0
"""Realistic read noise of a piezoresistive array [% of full scale]: the lower end of
1-2 %; Interlink's FSR 400 Series Data Sheet gives a single part's force repeatability
as +-2 % (one standard deviation over the mean, at 1 kg)."""
MODELS = ("classic", "censored", "unclipped")


def noise_variance(spec, noise_counts: float | None = None) -> float:
    """Variance of one reading: read noise (the preset's, or ``noise_counts`` RMS) plus
    uniform quantization [counts^2]."""
    read = spec.flaws.read_noise_counts if noise_counts is None else float(noise_counts)
    if not (math.isfinite(read) and read >= 0):
        raise TactsenseInputError(f"noise_counts must be a number >= 0; got {noise_counts!r}")
    return read**2 + 1.0 / 12.0


def noise_from_full_scale(spec, percent: float) -> float:
    """Read noise of ``percent`` of the pad's converter's full scale [counts RMS]."""
    if not (math.isfinite(percent) and 0 < percent <= 50):
        raise TactsenseInputError(f"noise must be 0 to 50 % of full scale; got {percent!r}")
    return percent / 100.0 * (2**spec.electronics.adc_bits - 1)


def rest_and_slope(spec) -> tuple[float, float, bool]:
    """The untouched reading ``c`` [counts], the response's slope at rest [counts per
    unit strain] and whether the transducer is one-sided (tension reads as rest)."""
    rest = float(counts_from_strain(spec, 0.0))
    h = 1e-6
    slope = float(counts_from_strain(spec, h) - rest) / h
    one_sided = float(counts_from_strain(spec, -h)) == rest
    return rest, slope, one_sided


def latent_counts(spec, strain) -> np.ndarray:
    """The reading before the clip: the response in compression, continued linearly
    (its slope at rest) into tension [counts]."""
    strain = np.asarray(strain, dtype=float)
    rest, slope, _ = rest_and_slope(spec)
    return np.where(strain >= 0, counts_from_strain(spec, strain), rest + slope * strain)


def censored_weight(alpha) -> np.ndarray:
    """Fisher information of a Gaussian mean censored from below, in units of the
    uncensored ``1 / sigma^2``; ``alpha = (c - mu) / sigma`` [-]."""
    alpha = np.asarray(alpha, dtype=float)
    log_ratio = 2.0 * _log_phi(alpha) - special.log_ndtr(alpha)  # phi^2 / Phi, no underflow
    return special.ndtr(-alpha) + alpha * np.exp(_log_phi(alpha)) + np.exp(log_ratio)


def _log_phi(alpha):
    return -0.5 * alpha**2 - 0.5 * math.log(2.0 * math.pi)


def _latent(spec, theta, radius_mm):
    x, y, f = theta
    probe = SphereProbe(float(x), float(y), float(f), radius_mm=float(radius_mm))
    return latent_counts(spec, pad_strain(spec, [probe])).ravel()


def whitened_jacobian(
    spec,
    x_mm: float,
    y_mm: float,
    force_n: float,
    *,
    model: str = "censored",
    noise_counts: float | None = None,
    radius_mm: float = PROBE_RADIUS_MM,
) -> np.ndarray:
    """``A`` with ``J = A^T A`` the Fisher information of ``(x [mm], y [mm], F [N])``
    from one frame, (taxels, 3): rows ``sqrt(w_i) g_i / sigma``.

    ``model``: ``"classic"`` (noise after the clip: ``w = 1`` where the latent reading
    is above rest, 0 where at or below), ``"censored"`` (noise before it: ``w`` of
    :func:`censored_weight`) or ``"unclipped"`` (a two-sided transducer: ``w = 1``).
    A two-sided pad (capacitive) gives the same for all three.
    """
    if model not in MODELS:
        raise TactsenseInputError(f"model must be one of {', '.join(MODELS)}; got {model!r}")
    check_positive(force_n, "force_n")
    check_positive(radius_mm, "radius_mm")
    _check_pad(spec, x_mm, y_mm)
    sigma = math.sqrt(noise_variance(spec, noise_counts))
    theta = np.array([x_mm, y_mm, force_n], dtype=float)
    h = 0.01 * min(spec.grid.row_pitch_mm, spec.grid.col_pitch_mm)
    columns = []
    for k, step in enumerate((h, h, 1e-4 * force_n)):
        up, down = theta.copy(), theta.copy()
        up[k] += step
        down[k] -= step
        columns.append((_latent(spec, up, radius_mm) - _latent(spec, down, radius_mm)) / (2 * step))
    g = np.column_stack(columns)
    rest, _, one_sided = rest_and_slope(spec)
    mu = _latent(spec, theta, radius_mm)
    if not one_sided or model == "unclipped":
        w = np.ones_like(mu)
    elif model == "classic":
        w = (mu > rest).astype(float)
    else:
        w = censored_weight((rest - mu) / sigma)
    return g * np.sqrt(w)[:, None] / sigma


def point_bound(
    spec,
    x_mm: float,
    y_mm: float,
    force_n: float,
    *,
    model: str = "censored",
    noise_counts: float | None = None,
    radius_mm: float = PROBE_RADIUS_MM,
) -> dict:
    """Cramer-Rao bound at one point under ``model`` (see :func:`whitened_jacobian`):
    the rank test's ``rank``, ``smallest_ratio``, ``singular``; and where not singular
    the standard deviations as :func:`tactsense.analysis.pad_bound.cramer_rao_bound`
    (where singular those are ``inf``)."""
    a = whitened_jacobian(
        spec, x_mm, y_mm, force_n, model=model, noise_counts=noise_counts, radius_mm=radius_mm
    )
    g = spec.grid
    test = rank_test(a, (g.row_pitch_mm, g.col_pitch_mm, force_n))
    if test["singular"]:
        keys = ("x_mm", "y_mm", "position_mm", "force_n", "force_relative", "x_pitch", "y_pitch")
        return {**test, **dict.fromkeys(keys, math.inf)}
    return {**test, **bound_stds(a.T @ a, spec, force_n)}


def cell_prior_information(pitch_mm: float) -> float:
    """Fisher information of the ``cos^2`` prior over one pitch, ``(2 pi / L)^2``
    [1/mm^2]."""
    return (2.0 * math.pi / pitch_mm) ** 2


def bayesian_information(
    spec,
    force_n: float,
    *,
    taxel: tuple[int, int] | None = None,
    model: str = "censored",
    noise_counts: float | None = None,
    radius_mm: float = PROBE_RADIUS_MM,
    nodes: int = BAYES_NODES,
) -> np.ndarray:
    """The prior mean of the Fisher information over the cell of ``taxel`` (row, col;
    default the middle one), ``cos^2`` prior per axis, by ``nodes`` x ``nodes``
    Gauss-Legendre quadrature, (3, 3) (without the prior's own information)."""
    g = spec.grid
    r, c = (g.rows // 2, g.cols // 2) if taxel is None else taxel
    u, weights = np.polynomial.legendre.leggauss(int(nodes))
    # the prior (2/L) cos^2(pi s / L) ds at s = u L / 2 is cos^2(pi u / 2) du on [-1, 1]
    w1 = weights * np.cos(0.5 * np.pi * u) ** 2
    w1 = w1 / w1.sum()
    information = np.zeros((3, 3))
    for i, ui in enumerate(u):
        for j, uj in enumerate(u):
            a = whitened_jacobian(
                spec,
                (r + 0.5 * ui) * g.row_pitch_mm,
                (c + 0.5 * uj) * g.col_pitch_mm,
                force_n,
                model=model,
                noise_counts=noise_counts,
                radius_mm=radius_mm,
            )
            information += w1[i] * w1[j] * (a.T @ a)
    return information


def bayesian_bound(
    spec,
    force_n: float,
    *,
    taxel: tuple[int, int] | None = None,
    model: str = "censored",
    noise_counts: float | None = None,
    radius_mm: float = PROBE_RADIUS_MM,
    nodes: int = BAYES_NODES,
) -> dict:
    """Hybrid Van Trees bound on ``(x, y, F)`` with the position random over the cell of
    ``taxel`` (row, col; default the middle one) under a ``cos^2`` prior per axis and
    the force fixed: root mean square errors as :func:`point_bound`'s keys (the prior
    alone keeps the position's finite; the force's is ``inf`` where no position in the
    cell informs it), plus ``nodes``. It is at most the cell's mean of the point bound
    (Jensen): a bound on the average error, not on the typical one."""
    g = spec.grid
    information = bayesian_information(
        spec, force_n, taxel=taxel, model=model, noise_counts=noise_counts,
        radius_mm=radius_mm, nodes=nodes,
    )  # fmt: skip
    information[0, 0] += cell_prior_information(g.row_pitch_mm)
    information[1, 1] += cell_prior_information(g.col_pitch_mm)
    if information[2, 2] <= 0:
        std = np.sqrt(np.diag(np.linalg.inv(information[:2, :2])))
        return {"x_mm": float(std[0]), "y_mm": float(std[1]),
                "position_mm": float(np.sqrt(0.5 * (std @ std))), "force_n": math.inf,
                "force_relative": math.inf, "x_pitch": float(std[0] / g.row_pitch_mm),
                "y_pitch": float(std[1] / g.col_pitch_mm), "nodes": int(nodes)}  # fmt: skip
    return {**bound_stds(information, spec, force_n), "nodes": int(nodes)}


# ---- Ziv-Zakai bound over the cell (r9-padbounds) ----
ZZ_POINTS = 161
"""Grid points across the cell for the Ziv-Zakai bound's integrals [-]."""


def _log_bhattacharyya(mu0, mu1, rest, sigma, one_sided):
    """Log of the Bhattacharyya coefficient of two frames' distributions, taxels
    independent: Gaussian ``N(mu, sigma^2)``, or ``max(mu + n, rest)`` when
    ``one_sided`` (a point mass at rest plus the Gaussian's tail above it)."""
    d2 = ((mu1 - mu0) / sigma) ** 2
    if not one_sided:
        return float(-np.sum(d2) / 8.0)
    a0, a1 = (rest - mu0) / sigma, (rest - mu1) / sigma
    mass = 0.5 * (special.log_ndtr(a0) + special.log_ndtr(a1))
    tail = -d2 / 8.0 + special.log_ndtr(-(rest - 0.5 * (mu0 + mu1)) / sigma)
    return float(np.sum(np.logaddexp(mass, tail)))


def ziv_zakai_bound(
    spec,
    force_n: float,
    *,
    taxel: tuple[int, int] | None = None,
    axis: int = 0,
    model: str = "censored",
    noise_counts: float | None = None,
    radius_mm: float = PROBE_RADIUS_MM,
    points: int = ZZ_POINTS,
) -> dict:
    """Ziv-Zakai bound (Bell, Steinberg, Ephraim and Van Trees 1997, with valley filling)
    on the mean square error of the position along ``axis`` (0: x, 1: y) of a sphere
    random over the cell of ``taxel`` (``cos^2`` prior over one pitch, as
    :func:`bayesian_bound`), the other coordinate and the force known.

    ``MSE >= 1/2 int_0^L h V{ int (p(t) + p(t + h)) P_min(t, t + h) dt } dh`` with
    ``P_min`` the least error probability of telling ``t`` from ``t + h`` from one frame
    (priors in proportion to ``p``). Frames ``model="classic"`` (noise after the clip)
    or ``"unclipped"`` are Gaussian and ``P_min`` is exact; ``"censored"`` frames (noise
    before the clip) take the Bhattacharyya lower bound
    ``P_min >= (1 - sqrt(1 - 4 q0 q1 rho^2)) / 2``, so the bound stays a bound. Unlike
    Van Trees it does not average the information: a cell with a nearly blind middle
    keeps its error. Integrals on ``points`` grid points across the cell.

    Returns
    -------
    dict
        ``rms_mm`` (the bound's square root) [mm], ``mse_mm2`` [mm^2],
        ``prior_rms_mm`` (the prior's own spread) [mm], ``grid_points``.
    """
    if model not in MODELS:
        raise TactsenseInputError(f"model must be one of {', '.join(MODELS)}; got {model!r}")
    if axis not in (0, 1):
        raise TactsenseInputError(f"axis must be 0 (x) or 1 (y); got {axis!r}")
    check_positive(force_n, "force_n")
    if not (isinstance(points, int) and points >= 11):
        raise TactsenseInputError(f"points must be an integer >= 11; got {points!r}")
    g = spec.grid
    r, c = (g.rows // 2, g.cols // 2) if taxel is None else taxel
    pitch = g.row_pitch_mm if axis == 0 else g.col_pitch_mm
    centre = np.array([r * g.row_pitch_mm, c * g.col_pitch_mm])
    _check_pad(spec, *centre)
    sigma = math.sqrt(noise_variance(spec, noise_counts))
    rest, _, one_sided = rest_and_slope(spec)
    u = np.linspace(-0.5, 0.5, points) * pitch
    step = u[1] - u[0]
    mus = []
    for offset in u:
        at = centre.copy()
        at[axis] += offset
        mus.append(_latent(spec, (at[0], at[1], force_n), radius_mm))
    mus = np.array(mus)
    clip = one_sided and model != "unclipped"
    if clip and model == "classic":
        mus = np.maximum(mus, rest)  # noise after the clip: Gaussian about the clipped mean
    density = (2.0 / pitch) * np.cos(np.pi * u / pitch) ** 2
    inner = np.zeros(points)  # inner[k]: int (p(t) + p(t + h)) P_min dt at h = k step
    for k in range(1, points):
        p0, p1 = density[:-k], density[k:]
        total = p0 + p1
        q0 = np.divide(p0, total, out=np.full_like(total, 0.5), where=total > 0)
        pmin = np.empty(points - k)
        for i in range(points - k):
            if model == "censored" and one_sided:
                rho2 = math.exp(2.0 * _log_bhattacharyya(mus[i], mus[i + k], rest, sigma, True))
                pmin[i] = 0.5 * (1.0 - math.sqrt(max(0.0, 1.0 - 4.0 * q0[i] * (1 - q0[i]) * rho2)))
            else:
                d = float(np.linalg.norm(mus[i + k] - mus[i]) / sigma)
                pmin[i] = _gaussian_pmin(q0[i], d)
        inner[k] = np.sum(total * pmin) * step
    valley = np.maximum.accumulate(inner[::-1])[::-1]  # V{f}(h) = max over h' >= h
    h = np.arange(points) * step
    mse = 0.5 * float(np.sum(h * valley) * step)
    prior_var = pitch**2 * (1.0 / 12.0 - 1.0 / (2.0 * math.pi**2))
    return {"rms_mm": math.sqrt(mse), "mse_mm2": mse, "prior_rms_mm": math.sqrt(prior_var),
            "grid_points": int(points)}  # fmt: skip


def _gaussian_pmin(q0: float, d: float) -> float:
    """Least error probability between two Gaussian means ``d`` noise units apart, with
    prior ``q0`` on the first [-]."""
    q1 = 1.0 - q0
    if q0 <= 0.0 or q1 <= 0.0:
        return 0.0
    if d == 0.0:
        return min(q0, q1)
    t = math.log(q0 / q1) / d
    return float(q0 * special.ndtr(-(0.5 * d + t)) + q1 * special.ndtr(-(0.5 * d - t)))


# ---- /Ziv-Zakai bound over the cell (r9-padbounds) ----
