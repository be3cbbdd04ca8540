"""Finite-element forms of the 3-D finger (``finger3d``, ``finger3d_tip``): elasticity
stiffness assembled from scalar gradient blocks, and the displacement-pressure (u-p)
systems of the nearly incompressible rubber, on its own or on a dielectric layer.

Forward model only: estimation code must never import this module.
"""

from __future__ import annotations

import numpy as np
from scipy import sparse
from skfem import BilinearForm, asm

YOUNGS_PA = 2.5e5
"""The skin's rubber (section 2.3) [Pa]."""


def _gradient_blocks(basis, weight=None):
    """The nine scalar blocks ``G_ij = int w d_i(phi_a) d_j(phi_b)`` (``w``: a function of
    the quadrature points' coordinates, or 1), six assembled: ``G_ji = G_ij^T``."""
    g = {}
    for i in range(3):
        for j in range(i, 3):
            if weight is None:
                form = BilinearForm(lambda u, v, w, i=i, j=j: v.grad[i] * u.grad[j])
            else:
                form = BilinearForm(lambda u, v, w, i=i, j=j: weight(w.x) * v.grad[i] * u.grad[j])
            g[i, j] = asm(form, basis)
            g[j, i] = g[i, j].T
    return g


def _elasticity(g_lam, g_mu):
    """Block (c, d) of the stiffness: ``G^lam_cd + G^mu_dc + delta_cd sum_i G^mu_ii``."""
    trace = g_mu[0, 0] + g_mu[1, 1] + g_mu[2, 2]
    blocks = [
        [g_lam[c, d] + g_mu[d, c] + (trace if c == d else 0 * trace) for d in range(3)]
        for c in range(3)
    ]
    return sparse.bmat(blocks, format="csr")


def _stiffness(basis, lam, mu):
    """Elasticity stiffness, component-major dofs [u_x; u_y; u_z].

    Assembled from the six scalar blocks ``G_ij = int d_i(phi_a) d_j(phi_b)``
    (much faster than the vector element's form): block (c, d) is
    ``lam G_cd + mu delta_cd sum_i G_ii + mu G_dc``.
    """
    g = _gradient_blocks(basis)
    return _elasticity({k: lam * v for k, v in g.items()}, {k: mu * v for k, v in g.items()})


def _stiffness_layered(basis, rubber, dielectric, top_m):
    """Elasticity stiffness with the material chosen per quadrature point by its radius:
    ``dielectric`` (lam, mu) below ``top_m`` (an element boundary), ``rubber`` above."""

    def material(k):
        return lambda x: np.where(np.hypot(x[1], x[2]) < top_m, dielectric[k], rubber[k])

    return _elasticity(_gradient_blocks(basis, material(0)), _gradient_blocks(basis, material(1)))


def _divergence_blocks(basis, pressure_basis, region=None):
    """``B = [B_x, B_y, B_z]`` with ``B_c[q, a] = int w psi_q d_c(phi_a)`` (``psi``: the
    pressure's basis, ``w`` the indicator ``region(x)`` of where the pressure lives, or 1):
    ``B u`` tests ``div u``; shape (pressure dofs, 3 N)."""
    w_of = (lambda x: 1.0) if region is None else region
    blocks = [
        asm(BilinearForm(lambda u, v, w, c=c: w_of(w.x) * v * u.grad[c]), basis, pressure_basis)
        for c in range(3)
    ]
    return sparse.hstack(blocks, format="csr")


def mixed_system(stiffness, basis, pressure_basis, inverse_lam, incompressible=None):
    """The displacement-pressure (u-p) system of nearly incompressible elasticity.

    ``sigma = 2 mu eps(u) - p I`` with ``p = -lam div u`` held weakly on the pressure's
    own (lower-order, continuous) basis where ``incompressible(x)`` is 1 (everywhere if
    None): Taylor-Hood, inf-sup stable, so the rubber (nu 0.49, or 0.5 exactly) does not
    lock as the pure displacement form does (``docs/model.md``, section 3a).

    Parameters
    ----------
    stiffness : sparse matrix (3 N, 3 N)
        The displacement block ``A``: ``2 mu eps(u) : eps(v)`` everywhere, plus
        ``lam (div u)(div v)`` only where the material is compressible (a dielectric).
    inverse_lam : callable
        ``1 / lam`` [1/Pa] at points (3, ...) [m] (0 for nu = 0.5).
    incompressible : callable, optional
        Indicator (0 or 1) of the region the pressure lives on, at points (3, ...).

    Returns
    -------
    matrix : sparse matrix
        The symmetric, indefinite ``[[A, -B^T], [-B, -M / lam]]`` over ``[u; p]``.
    support : ndarray
        The pressure dofs that carry anything (the others are dropped by the caller).
    """
    inside = (lambda x: np.ones(np.shape(x)[1:])) if incompressible is None else incompressible
    divergence = _divergence_blocks(basis, pressure_basis, inside)
    mass = asm(BilinearForm(lambda u, v, w: inside(w.x) * inverse_lam(w.x) * u * v), pressure_basis)
    support = asm(BilinearForm(lambda u, v, w: inside(w.x) * u * v), pressure_basis).diagonal()
    matrix = sparse.bmat([[stiffness, -divergence.T], [-divergence, -mass]], format="csr")
    return matrix, np.nonzero(support > 0)[0]


def _lame(youngs_pa, poisson_ratio):
    """(lam, mu) [Pa]; lam infinite at nu 0.5 (only the mixed form takes it)."""
    mu = youngs_pa / (2 * (1 + poisson_ratio))
    if poisson_ratio >= 0.5:
        return np.inf, mu
    return youngs_pa * poisson_ratio / ((1 + poisson_ratio) * (1 - 2 * poisson_ratio)), mu


LAYER_PRESSURE_NU = 0.4
"""A dielectric of Poisson's ratio above this gets a pressure field of its own in the u-p
form (:func:`mixed_layered`): a solid rubber layer (nu 0.49) in displacement form locks
as the skin did; a foam (nu 0.3, the shipped ``finger3d-foam`` tables) keeps the
displacement form, which does not."""


def mixed_layered(basis, pressure_basis, poisson_ratio, dielectric=None, rubber=None):
    """The u-p matrix of the skin's rubber (nu ``poisson_ratio``), and of a
    ``dielectric`` where the indicator ``rubber(x)`` is 0, restricted to the pressure dofs
    that carry anything: (matrix, their count). Shared by the cylinder and the tip.

    The dielectric is in displacement form when it is compressible (nu up to
    :data:`LAYER_PRESSURE_NU`); above, it gets a pressure field of its own on the same
    basis restricted to the layer (so the pressure may jump at the interface, as the
    true one does between two materials)."""
    lam, mu = _lame(YOUNGS_PA, poisson_ratio)
    if dielectric is None:
        g = _gradient_blocks(basis)
        stiffness = _elasticity({k: 0 * v for k, v in g.items()}, {k: mu * v for k, v in g.items()})
        matrix, keep = mixed_system(stiffness, basis, pressure_basis, lambda x: 0 * x[0] + 1 / lam)
    elif dielectric.poisson_ratio <= LAYER_PRESSURE_NU:
        soft_lam, soft_mu = _lame(dielectric.youngs_pa, dielectric.poisson_ratio)
        stiffness = _elasticity(
            _gradient_blocks(basis, lambda x: soft_lam * (1 - rubber(x))),
            _gradient_blocks(basis, lambda x: np.where(rubber(x) > 0, mu, soft_mu)),
        )
        matrix, keep = mixed_system(
            stiffness, basis, pressure_basis, lambda x: rubber(x) / lam, rubber
        )
    else:
        return _two_pressures(basis, pressure_basis, (lam, mu), dielectric, rubber)
    n_u = 3 * basis.N
    rows = np.concatenate([np.arange(n_u), n_u + keep])
    return matrix[rows][:, rows], len(keep)


def _two_pressures(basis, pressure_basis, rubber_lame, dielectric, rubber):
    """u-p matrix with one pressure field in the rubber and another in a nearly
    incompressible dielectric: ``[[A, -B_r^T, -B_d^T], [-B_r, -M_r / lam_r, 0],
    [-B_d, 0, -M_d / lam_d]]``, ``A`` the deviatoric part ``2 mu eps : eps`` of each
    material; (matrix, pressure count)."""
    lam, mu = rubber_lame
    soft_lam, soft_mu = _lame(dielectric.youngs_pa, dielectric.poisson_ratio)

    def layer(x):
        return 1.0 - rubber(x)

    g_mu = _gradient_blocks(basis, lambda x: np.where(rubber(x) > 0, mu, soft_mu))
    stiffness = _elasticity({k: 0 * v for k, v in g_mu.items()}, g_mu)
    parts = []
    for region, inverse_lam in ((rubber, 1 / lam), (layer, 1 / soft_lam)):
        divergence = _divergence_blocks(basis, pressure_basis, region)
        mass = asm(
            BilinearForm(lambda u, v, w, r=region, k=inverse_lam: r(w.x) * k * u * v),
            pressure_basis,
        )
        support = asm(BilinearForm(lambda u, v, w, r=region: r(w.x) * u * v), pressure_basis)
        keep = np.nonzero(support.diagonal() > 0)[0]
        parts.append((divergence[keep], mass[keep][:, keep]))
    (b_r, m_r), (b_d, m_d) = parts
    matrix = sparse.bmat(
        [[stiffness, -b_r.T, -b_d.T], [-b_r, -m_r, None], [-b_d, None, -m_d]], format="csr"
    )
    return matrix, b_r.shape[0] + b_d.shape[0]
