"""A pad's response from a solution of the bonded layer that the simulator does not share
(issue 34 items 4 and 7): the truth that tests and the pad robustness study estimate
against.

The simulator (:mod:`tactsense.physics.layer`) samples a pressure map on a grid, takes
its FFT and multiplies it by the closed-form transfer functions of the Papkovich-Neuber
potentials. This module shares none of that:

* the **transfer function** is Love's axisymmetric strain function
  ``phi = J0(kr) f(z)``, ``f`` a combination of ``exp(-kz)``, ``z exp(-kz)``,
  ``exp(-k(h-z))``, ``(z-h) exp(-k(h-z))`` (Timoshenko & Goodier, *Theory of
  Elasticity*, 3rd ed., section 140), its four boundary conditions (``sigma_z(0) = -P``,
  ``tau_rz(0) = 0``, ``u_r(h) = w(h) = 0``: the layer bonded to a rigid base) solved as
  a 4x4 linear system per wavenumber (:func:`love_transfer`);
* the **load** is an exact Hankel transform of the pressure profile (Hertz, uniform
  disc or rigid flat punch: :func:`pressure_spectrum`), not a sampled grid;
* the **inverse transform** is a composite Gauss-Legendre rule in the wavenumber
  (:func:`radial_strain`), evaluated on radii joined by a cubic spline, and each
  taxel's reading is the mean over ``sub`` x ``sub`` points of its electrode
  (:func:`taxel_strain`).

:func:`fem_disc` is a third, again independent, evaluation: an axisymmetric
finite-element solution of the layer under a uniform disc (scikit-fem, quadratic quads;
needs ``scikit-fem``, which the ``test`` extra installs).

Conventions: z points into the layer (0 at the free surface, h at the base); a
pressure pushing into the layer is positive and gives a compressive (negative)
``eps_zz``. Lengths in metres inside the transforms, millimetres at the taxel
interface.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np
from scipy import special
from scipy.interpolate import CubicSpline

from tactsense._validation import TactsenseInputError

SHAPES = ("sphere", "disc", "punch")
"""Pressure profiles with an exact Hankel transform: Hertz's sphere (``p0 sqrt(1 -
r^2/a^2)``, ``a`` from the half space, as the simulator takes it), a uniform disc, and
Boussinesq's rigid flat punch (``F / (2 pi a sqrt(a^2 - r^2))``)."""


def love_transfer(k, z, h, nu) -> tuple[np.ndarray, np.ndarray]:
    """``2 mu w / P`` [m] and ``2 mu eps_zz / P`` [-] under the surface pressure
    ``P J0(kr)``, from Love's strain function, for every wavenumber ``k`` [1/m].

    Solved in units of ``1/k`` (``zeta = kz``, ``eta = kh``), so every entry of the
    4x4 system is a power of ``zeta`` times ``exp(-zeta)`` or ``exp(-(eta - zeta))``
    (nothing overflows at large ``kh``); ``w`` is scaled back by ``1/k``.

    Parameters
    ----------
    k : array_like
        Wavenumbers [1/m], > 0.
    z, h : float
        Depth and layer thickness [m], ``0 <= z <= h``; ``h = inf`` for the half space.
    nu : float
        Poisson's ratio [-], in [0, 0.5].
    """
    k = np.atleast_1d(np.asarray(k, dtype=float))
    if np.any(k <= 0):
        raise TactsenseInputError("love_transfer needs wavenumbers k > 0")
    zeta = k * z
    eta = k * h

    def derivs(s):
        """(n, K, 4): derivative order n = 0..3 of the four basis functions at zeta=s."""
        em = np.exp(-s)
        with np.errstate(invalid="ignore", over="ignore"):
            ep = np.where(np.isfinite(eta), np.exp(-(eta - s)), 0.0)
            shift = np.where(np.isfinite(eta), s - eta, 0.0)
        out = np.empty((4, len(k), 4))
        for n in range(4):
            sign = (-1.0) ** n
            out[n, :, 0] = sign * em
            out[n, :, 1] = sign * s * em + n * (-1.0) ** (n - 1) * em
            out[n, :, 2] = ep
            out[n, :, 3] = shift * ep + n * ep
        return out

    d0 = derivs(np.zeros_like(k))
    dh = derivs(np.where(np.isfinite(eta), eta, 0.0))
    if not np.isfinite(h):  # half space: the growing solutions are absent
        dh = np.zeros_like(dh)
        dh[0, :, 2] = dh[1, :, 3] = 1.0  # C = D = 0
    matrix = np.stack(
        [
            (2 - nu) * (d0[3] - d0[1]) - d0[3],  # sigma_z(0) per J0
            (1 - nu) * (d0[2] - d0[0]) - d0[2],  # tau_rz(0) per (-k J1)
            dh[1] if np.isfinite(h) else dh[0],  # u_r(h) per (k J1)
            2 * (1 - nu) * (dh[2] - dh[0]) - dh[2] if np.isfinite(h) else dh[1],  # w(h)
        ],
        axis=1,
    )
    rhs = np.zeros((len(k), 4, 1))
    rhs[:, 0, 0] = -1.0
    coef = np.linalg.solve(matrix, rhs)[..., 0]
    dz = derivs(zeta)
    w = np.einsum("kj,kj->k", 2 * (1 - nu) * (dz[2] - dz[0]) - dz[2], coef) / k
    eps = np.einsum("kj,kj->k", 2 * (1 - nu) * (dz[3] - dz[1]) - dz[3], coef)
    return w, eps


def hertz_radius_mm(force_n: float, radius_mm: float, youngs_modulus_pa: float, nu: float):
    """Hertz contact radius of a rigid sphere on the half space, at most the sphere's
    radius [mm] (Johnson 1985, eq. 4.22, ``E* = E / (1 - nu^2)``)."""
    e_star = youngs_modulus_pa / (1 - nu**2)
    a = (3 * force_n * 1e-3 * radius_mm / (4 * e_star)) ** (1 / 3) * 1e3
    return min(a, radius_mm)


def pressure_spectrum(q, force_n: float, shape: str) -> np.ndarray:
    """Hankel transform ``int p(r) J0(kr) 2 pi r dr`` of a profile of total force
    ``force_n`` [N] and contact radius ``a``, at ``q = k a`` [-].

    sphere: ``3 F (sin q - q cos q) / q^3``; disc: ``2 F J1(q) / q``; punch:
    ``F sin(q) / q`` (each 1 at q = 0 times F; Sneddon, *Fourier Transforms*, 1951).
    """
    q = np.asarray(q, dtype=float)
    if shape == "sphere":
        small = q < 1e-3
        qs = np.where(small, 1.0, q)
        return force_n * np.where(small, 1 - q**2 / 10, 3 * (np.sin(qs) - qs * np.cos(qs)) / qs**3)
    if shape == "disc":
        return force_n * 2 * special.j1(q) / np.where(q == 0, 1.0, q) + force_n * (q == 0)
    if shape == "punch":
        return force_n * np.sinc(q / np.pi)
    raise TactsenseInputError(f"shape {shape!r}: expected one of {', '.join(SHAPES)}")


@dataclass(frozen=True)
class TrueLayer:
    """The layer the truth is solved for (not a sensor description: the true pad's)."""

    thickness_mm: float
    sensing_depth_mm: float
    youngs_modulus_pa: float
    poisson_ratio: float

    @classmethod
    def of(cls, spec) -> TrueLayer:
        """The layer of a pad description."""
        lay = spec.layer
        return cls(
            float(lay.thickness_mm),
            float(lay.sensing_depth_mm),
            float(lay.youngs_modulus_pa),
            float(lay.poisson_ratio),
        )


@functools.lru_cache(maxsize=256)
def radial_strain(
    layer: TrueLayer, force_n: float, a_mm: float, shape: str, r_max_mm: float
) -> CubicSpline:
    """``eps_zz(r)`` [-] at the sensing depth under an axisymmetric load, as a cubic
    spline over ``r`` in [0, ``r_max_mm``] [mm] (1500 radii).

    ``eps_zz(r) = (1 / 2 pi) int S(k) E(k) J0(kr) k dk / (2 mu)`` with ``S`` the load's
    spectrum (:func:`pressure_spectrum`) and ``E`` Love's strain transfer
    (:func:`love_transfer`), by 16-point Gauss-Legendre panels (400 of them) up to
    ``k = 80 / max(z, a / 20)``, where ``exp(-kz)`` and the spectrum have decayed.
    """
    h, z = 1e-3 * layer.thickness_mm, 1e-3 * layer.sensing_depth_mm
    nu = layer.poisson_ratio
    mu = layer.youngs_modulus_pa / (2 * (1 + nu))
    a = 1e-3 * a_mm
    nodes, weights = np.polynomial.legendre.leggauss(16)
    edges = np.linspace(0.0, 80.0 / max(z, 0.05 * a), 401)
    half = np.diff(edges)[:, None] / 2
    k = ((edges[:-1, None] + edges[1:, None]) / 2 + half * nodes).ravel()
    _, eps_k = love_transfer(k, z, h, nu)
    weight = (half * weights).ravel() * pressure_spectrum(k * a, force_n, shape) * eps_k
    weight *= k / (2 * np.pi) / (2 * mu)
    radii = np.linspace(0.0, 1.0001 * r_max_mm, 1500)
    eps = np.concatenate(
        [special.j0(np.outer(1e-3 * part, k)) @ weight for part in np.array_split(radii, 10)]
    )
    return CubicSpline(radii, eps)


def contact_radius_mm(layer: TrueLayer, force_n: float, radius_mm: float, shape: str) -> float:
    """The loaded radius [mm]: Hertz's for a sphere of ``radius_mm``, else ``radius_mm``."""
    if shape == "sphere":
        return hertz_radius_mm(force_n, radius_mm, layer.youngs_modulus_pa, layer.poisson_ratio)
    return float(radius_mm)


def taxel_strain(
    spec,
    x_mm,
    y_mm,
    force_n: float,
    radius_mm: float = 1.6,
    *,
    shape: str = "sphere",
    layer: TrueLayer | None = None,
    sub: int = 12,
) -> np.ndarray:
    """Compressive strain ``-eps_zz`` at every taxel of a pad [-], each the mean over
    ``sub`` x ``sub`` points of its electrode, under one or several round loads.

    Parameters
    ----------
    spec : PadSpec
        The pad (its grid and electrodes; its layer unless ``layer`` is given).
    x_mm, y_mm : float or array_like
        Centres of the loads [mm] (several: superposed, the layer is linear).
    force_n : float
        Each load's total force [N].
    radius_mm : float
        The sphere's radius (``shape="sphere"``: Hertz contact radius from the half
        space, at most this), or the disc's or punch's radius [mm].
    shape : {"sphere", "disc", "punch"}
    layer : TrueLayer, optional
        The true layer (default the description's).

    Returns
    -------
    ndarray, shape (rows, cols)
        ``-eps_zz`` [-], positive where compressed.
    """
    if shape not in SHAPES:
        raise TactsenseInputError(f"shape {shape!r}: expected one of {', '.join(SHAPES)}")
    layer = TrueLayer.of(spec) if layer is None else layer
    a_mm = contact_radius_mm(layer, force_n, radius_mm, shape)
    g = spec.grid
    offsets = (np.arange(sub) + 0.5) / sub - 0.5
    ex = np.arange(g.rows)[:, None] * g.row_pitch_mm + offsets * g.electrode_x_mm
    ey = np.arange(g.cols)[:, None] * g.col_pitch_mm + offsets * g.electrode_y_mm
    xs, ys = np.atleast_1d(x_mm), np.atleast_1d(y_mm)
    reach = np.hypot(
        max(ex.max() - xs.min(), xs.max() - ex.min()), max(ey.max() - ys.min(), ys.max() - ey.min())
    )
    # radii in 10-mm steps, so one profile serves every position on the pad (cached)
    r_max = 10.0 * np.ceil(reach / 10.0)
    profile = radial_strain(layer, float(force_n), float(a_mm), shape, float(r_max))
    out = np.zeros(spec.shape)
    for x, y in zip(xs, ys, strict=True):
        r = np.hypot(ex[:, None, :, None] - x, ey[None, :, None, :] - y)
        out -= profile(r).mean(axis=(2, 3))
    return out


def hankel_hertz_strain(spec, x_mm, y_mm, force_n, radius_mm=1.6, sub=12, shape="sphere"):
    """:func:`taxel_strain` under the name the tests have used (one load, the
    description's layer) [-]."""
    return taxel_strain(spec, x_mm, y_mm, force_n, radius_mm, shape=shape, sub=sub)


def disc_field(r_m, z_m, h_m, nu, a_m, p_pa, youngs_modulus_pa) -> tuple[float, float]:
    """``w`` [m] and ``eps_zz`` [-] at radius ``r_m`` and depth ``z_m`` under a uniform
    pressure ``p_pa`` on a disc of radius ``a_m`` (Hankel transform of Love's transfer,
    600 Gauss-Legendre panels); the reference of :func:`fem_disc`."""
    mu = youngs_modulus_pa / (2 * (1 + nu))
    nodes, weights = np.polynomial.legendre.leggauss(16)
    edges = np.linspace(0.0, 80.0 / max(z_m, 0.05 * a_m), 601)
    half = np.diff(edges)[:, None] / 2
    k = ((edges[:-1, None] + edges[1:, None]) / 2 + half * nodes).ravel()
    wk = (half * weights).ravel() * a_m * p_pa * special.j1(k * a_m) * special.j0(k * r_m)
    w, eps = love_transfer(k, z_m, h_m, nu)
    return float(np.sum(wk * w) / (2 * mu)), float(np.sum(wk * eps) / (2 * mu))


def fem_disc(
    thickness_m: float,
    radius_m: float,
    pressure_pa: float,
    youngs_modulus_pa: float,
    nu: float,
    depths_m,
    radii_m,
    *,
    nr: int = 40,
    nz: int = 16,
) -> dict[float, tuple[np.ndarray, np.ndarray]]:
    """Axisymmetric finite-element solution of the bonded layer under a uniform disc.

    A disc of radius a under the pressure p on a layer of thickness h bonded to a rigid
    base (u_r = u_z = 0 at z = h), free elsewhere on top, meshed on r in [0, 15 h]
    (clamped there: the bonded layer's response has died out), u_r = 0 on the axis;
    quadratic quads (scikit-fem), the axisymmetric weak form (strains u_r,r, u_r / r,
    u_z,z, u_r,z + u_z,r, weight r). ``nr`` x ``nz`` elements, graded beyond 3a.

    Returns
    -------
    dict
        depth [m] -> (w [m], eps_zz [-]) at ``radii_m``; the strain by a central
        difference inside one quadratic element (exact there).
    """
    try:
        from skfem import (
            Basis,
            BilinearForm,
            ElementQuad2,
            ElementVector,
            FacetBasis,
            LinearForm,
            MeshQuad,
            asm,
            condense,
            solve,
        )
    except ImportError as error:  # pragma: no cover - the test extra installs it
        raise TactsenseInputError(
            "fem_disc needs scikit-fem (pip install 'tactsense[test]')"
        ) from error
    H, A, P = thickness_m, radius_m, pressure_pa
    mu = youngs_modulus_pa / (2 * (1 + nu))
    lam = 2 * mu * nu / (1 - 2 * nu)
    side = 15 * H
    rs = np.unique(
        np.concatenate(
            [
                np.linspace(0, A, nr // 4 + 1),
                np.linspace(A, 3 * A, nr // 4 + 1),
                3 * A + (side - 3 * A) * np.linspace(0, 1, nr // 2 + 1) ** 2,
            ]
        )
    )
    mesh = MeshQuad.init_tensor(rs, np.linspace(0, H, nz + 1))  # y = h - z
    element = ElementVector(ElementQuad2())
    basis = Basis(mesh, element, intorder=5)

    @BilinearForm
    def stiffness(u, v, w):
        r = w.x[0]

        def strains(f):
            return f.grad[0, 0], f[0] / r, f.grad[1, 1], f.grad[0, 1] + f.grad[1, 0]

        err, ett, ezz, erz = strains(u)
        vrr, vtt, vzz, vrz = strains(v)
        tr = err + ett + ezz
        return (
            (2 * mu * err + lam * tr) * vrr
            + (2 * mu * ett + lam * tr) * vtt
            + (2 * mu * ezz + lam * tr) * vzz
            + mu * erz * vrz
        ) * r

    top = FacetBasis(
        mesh, element, facets=mesh.facets_satisfying(lambda x: np.isclose(x[1], H)), intorder=8
    )

    @LinearForm
    def pressure(v, w):
        r = w.x[0]
        return -np.where(r < A, P, 0.0) * v[1] * r

    K = asm(stiffness, basis)
    f = asm(pressure, top)
    fixed = np.concatenate(
        [
            basis.get_dofs(lambda x: np.isclose(x[1], 0.0)).all(),
            basis.get_dofs(lambda x: np.isclose(x[0], side)).all(),
            basis.get_dofs(lambda x: np.isclose(x[0], 0.0)).all("u^1"),
        ]
    )
    u = solve(*condense(K, f, D=fixed))
    radii = np.asarray(radii_m, dtype=float)
    n = len(radii)
    (_, _), (uy, vertical) = basis.split(u)
    step = H / nz / 4
    results = {}
    for z in depths_m:
        y = H - z
        pts = np.array(
            [np.tile(radii, 3), np.concatenate([np.full(n, y), np.full(n, y + step),
                                                np.full(n, y - step)])]
        )  # fmt: skip
        vals = vertical.probes(pts) @ uy
        results[z] = (-vals[:n], (vals[n : 2 * n] - vals[2 * n :]) / (2 * step))
    return results
