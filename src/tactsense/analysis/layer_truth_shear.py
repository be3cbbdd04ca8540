"""Reference solutions for a tangential surface load, written apart from ``physics.layer``.

Two independent evaluations of the fields under a traction ``q_x = tau(r)`` (along +x,
axisymmetric in magnitude) on the free surface z = 0 of an elastic layer bonded to a
rigid base at z = h (z into the layer), used to check the layer model's tangential path
(issue 35 item 1; ``docs/model.md`` section 8):

* :func:`bonded_layer_shear_fields`: the bonded layer of finite thickness (or the half
  space) by Hankel transforms in cylindrical coordinates. Nothing is shared with
  ``physics.layer`` (which solves Cartesian Fourier modes split into plane strain and
  anti-plane shear with Papkovich-Neuber potentials): here Navier's equations are
  written in (r, theta, z) for the azimuthal order-1 fields
  ``u_r = U cos theta, u_theta = V sin theta, u_z = W cos theta``, transformed with
  Hankel transforms of orders 0 (``(U - V) / 2``), 2 (``(U + V) / 2``) and 1 (W), solved
  in z from their general solution (derived below) by a 4x4 linear solve per wavenumber
  (numerical, not a closed form), and inverted by Gauss-Legendre quadrature.
* :func:`cerruti_disc_fields`: the half space by Cerruti's closed-form point-force
  solution (Johnson, *Contact Mechanics*, 1985, eq. 2.19) integrated over the loaded
  disc numerically; strains by central differences.

Derivation of the layer solution. With ``a = (U - V)/2``, ``b = (U + V)/2``, the Hankel
transforms ``A = H_0[a]``, ``B = H_2[b]``, ``Wt = H_1[W]`` (``H_n[f](k) = int f J_n(kr) r
dr``) turn Navier's equations ``(lam + mu) grad div u + mu lap u = 0`` into

    (lam + mu) k Delta + 2 mu (A'' - k^2 A) = 0,    -(lam + mu) k Delta + 2 mu (B'' - k^2 B) = 0,
    (lam + mu) Delta' + mu (Wt'' - k^2 Wt) = 0,      Delta = H_1[div u / cos theta] = Wt' - k P

with ``P = A - B``, ``Q = A + B``. So ``Q'' = k^2 Q`` (anti-plane) and Delta is harmonic;
the general solution with ``E = exp(-kz)``, ``G = exp(-k(h - z))``, ``kappa = 3 - 4 nu`` is

    P  = (p0 + c kz) E + (p1 + c' k(z - h)) G
    Wt = (-p0 - kappa c - c kz) E + (p1 - kappa c' + c' k(z - h)) G
    lam Delta = 4 mu nu k (c E - c' G)            (regular at nu = 0.5)

The surface conditions (outward normal -z: ``sigma_rz = -tau cos theta``,
``sigma_thetaz = tau sin theta``, ``sigma_zz = 0``) become ``mu (P' + k Wt) = -T0``,
``mu Q' = -T0`` and ``lam Delta + 2 mu Wt' = 0`` at z = 0 with ``T0 = H_0[tau]``; the base
gives ``P = Q = Wt = 0`` at z = h. Back in space, ``u_x = a + b cos 2 theta``,
``u_y = b sin 2 theta``, ``u_z = W cos theta``, and the strains follow from the
cylindrical strain-displacement relations rotated to x, y.

References
----------
.. [1] R. Muki, "Asymmetric problems of the theory of elasticity for a semi-infinite
   solid and a thick plate", *Progress in Solid Mechanics* 1, 1960.
.. [2] K. L. Johnson, *Contact Mechanics*, Cambridge University Press, 1985, section 2.2.
"""

from __future__ import annotations

import numpy as np
from scipy import special

from tactsense._validation import TactsenseInputError

QUANTITIES = ("u_x", "u_y", "u_z", "eps_xx", "eps_yy", "eps_zz", "eps_xy", "eps_xz", "eps_yz")
"""The fields returned: displacements [m] and tensor strains [-] (as ``physics.layer``)."""

PROFILES = ("hertz", "uniform")
"""Traction profiles over the disc of radius a: ``hertz`` is ``q0 sqrt(1 - r^2/a^2)``
(the Cattaneo full-slip traction under a Hertz contact), ``uniform`` is constant."""


def traction_profile(r, radius, force, profile="hertz"):
    """Magnitude of the tangential traction tau(r) [Pa] carrying ``force`` [N] along +x.

    Parameters
    ----------
    r : array_like
        Distance from the centre of the disc [m].
    radius : float
        a [m].
    force : float
        Total tangential force F [N].
    profile : {"hertz", "uniform"}
        See :data:`PROFILES`.
    """
    r = np.asarray(r, dtype=float)
    inside = r < radius
    if profile == "uniform":
        return np.where(inside, force / (np.pi * radius**2), 0.0)
    if profile == "hertz":
        q0 = 3 * force / (2 * np.pi * radius**2)
        return np.where(inside, q0 * np.sqrt(np.clip(1 - (r / radius) ** 2, 0, None)), 0.0)
    raise TactsenseInputError(f"profile must be one of {', '.join(PROFILES)}; got {profile!r}")


def sampled_disc_traction(n, spacing, radius, force, profile="hertz", sub=16):
    """tau(r) [Pa] on an ``n x n`` grid of ``spacing`` [m] centred on sample (n//2, n//2).

    Each sample is the mean of :func:`traction_profile` over its cell (``sub x sub``
    points), so the sampled load carries the disc's force to within the cell average
    (what a :class:`tactsense.physics.layer.LayerResponse` takes as ``traction_x``).
    """
    x = (np.arange(n) - n // 2) * spacing
    gx, gy = np.meshgrid(x, x)
    offsets = (np.arange(sub) + 0.5) / sub - 0.5
    total = np.zeros_like(gx)
    for sx in offsets:
        for sy in offsets:
            r = np.hypot(gx + sx * spacing, gy + sy * spacing)
            total += traction_profile(r, radius, force, profile)
    return total / sub**2


def _load_transform(k, radius, force, profile):
    """T0(k) = H_0[tau] [Pa m^2] of the disc's traction."""
    x = k * radius
    if profile == "uniform":
        return force * special.j1(x) / (np.pi * radius * k)
    small = x < 1e-3  # (sin x - x cos x) / x^3 -> 1/3 - x^2/30
    xs = np.where(small, 1.0, x)
    shape = np.where(small, 1 / 3 - x * x / 30, (np.sin(xs) - xs * np.cos(xs)) / xs**3)
    return 3 * force * shape / (2 * np.pi)


def _bessel_over_x(n, x):
    """J_n(x) / x, with its limit at x = 0 (1/2 for n = 1, 0 for n = 2)."""
    small = x < 1e-12
    xs = np.where(small, 1.0, x)
    return np.where(small, 0.5 if n == 1 else 0.0, special.jv(n, xs) / xs)


def _depth_functions(k, z, h, nu, t0_over_mu):
    """P, Wt, Q and their z-derivatives at depth z for each wavenumber k (1-D)."""
    kappa = 3 - 4 * nu
    finite = np.isfinite(h)
    n = k.size
    with np.errstate(under="ignore"):
        e_h = np.exp(-k * h) if finite else np.zeros(n)  # E at z = h and G at z = 0
    # unknowns (p0, c, p1, c'); rows: shear and normal stress at z = 0 (divided by k),
    # P(h) = 0, Wt(h) = 0
    m = np.zeros((n, 4, 4))
    kh = k * h if finite else np.zeros(n)
    # at z = 0: P'/k = (-p0 + c) + (p1 + c' - c' kh) e_h and
    # Wt = (-p0 - kappa c) + (p1 - kappa c' - c' kh) e_h; the row is P'/k + Wt
    m[:, 0] = np.stack(
        [
            -2 * np.ones(n),
            (1 - kappa) * np.ones(n),
            2 * e_h,
            (1 - kappa - 2 * kh) * e_h,
        ],
        axis=1,
    )
    # at z = 0: lam Delta / (mu k) = 4 nu (c - c' e_h) and
    # Wt'/k = (p0 + (kappa - 1) c) + (p1 + (1 - kappa) c' - c' kh) e_h; the row is
    # lam Delta / (mu k) + 2 Wt'/k
    m[:, 1] = np.stack(
        [
            2 * np.ones(n),
            (4 * nu + 2 * (kappa - 1)) * np.ones(n),
            2 * e_h,
            (-4 * nu + 2 * (1 - kappa) - 2 * kh) * e_h,
        ],
        axis=1,
    )
    if finite:
        m[:, 2] = np.stack([e_h, kh * e_h, np.ones(n), np.zeros(n)], axis=1)  # P(h)
        m[:, 3] = np.stack(
            [-e_h, (-kappa - kh) * e_h, np.ones(n), -kappa * np.ones(n)], axis=1
        )  # Wt(h)
    else:
        m[:, 2, 2] = m[:, 3, 3] = 1.0  # no growing solution in the half space
    rhs = np.zeros((n, 4))
    rhs[:, 0] = -1.0
    p0, c, p1, c1 = (np.linalg.solve(m, rhs[..., None])[..., 0] * (t0_over_mu / k)[:, None]).T
    with np.errstate(under="ignore"):
        big_e = np.exp(-k * z)
        big_g = np.exp(-k * (h - z)) if finite else np.zeros(n)
    t, s = k * z, (k * (z - h) if finite else np.zeros(n))
    p = (p0 + c * t) * big_e + (p1 + c1 * s) * big_g
    dp = k * ((-p0 + c - c * t) * big_e + (p1 + c1 + c1 * s) * big_g)
    wt = (-p0 - kappa * c - c * t) * big_e + (p1 - kappa * c1 + c1 * s) * big_g
    dwt = k * ((p0 + (kappa - 1) * c + c * t) * big_e + (p1 + (1 - kappa) * c1 + c1 * s) * big_g)
    # anti-plane: Q = q0 (E - e_h G), mu Q'(0) = -T0
    q0 = t0_over_mu / (k * (1 + e_h * e_h))
    q = q0 * (big_e - e_h * big_g)
    dq = -k * q0 * (big_e + e_h * big_g)
    return p, dp, wt, dwt, q, dq


def _wavenumbers(z, radius, panels):
    """Gauss-Legendre nodes and weights on [0, k_max] [rad/m]."""
    top = 80.0 / max(z, 0.02 * radius)
    nodes, weights = np.polynomial.legendre.leggauss(16)
    edges = np.linspace(0.0, top, panels + 1)
    half = np.diff(edges)[:, None] / 2
    k = ((edges[:-1, None] + edges[1:, None]) / 2 + half * nodes).ravel()
    return k, (half * weights).ravel()


def bonded_layer_shear_fields(
    x,
    y,
    depth,
    *,
    thickness,
    youngs_modulus,
    poisson_ratio,
    radius,
    force,
    profile="hertz",
    direction_deg=0.0,
    panels=800,
):
    """Fields at ``(x, y, depth)`` under a tangential disc traction.

    The traction points along ``(cos phi, sin phi)``, phi = ``direction_deg``; the
    solution is found for phi = 0 at the rotated positions and rotated back (the
    displacement as a vector, the strain as a tensor).

    Parameters
    ----------
    x, y : array_like
        Positions relative to the centre of the disc [m] (broadcast together).
    depth : float
        z, 0 <= z <= thickness [m].
    thickness : float
        h [m]; ``np.inf`` for the half space.
    youngs_modulus : float
        E [Pa].
    poisson_ratio : float
        nu, in (-1, 0.5] [-].
    radius : float
        a, the loaded disc's radius [m].
    force : float
        Total tangential force along +x [N].
    profile : {"hertz", "uniform"}
        The traction's radial profile (:data:`PROFILES`).
    direction_deg : float
        Direction of the traction, counter-clockwise from +x [deg].
    panels : int
        16-point Gauss-Legendre panels over [0, 80 / max(z, a / 50)] in k.

    Returns
    -------
    dict of ndarray
        Each of :data:`QUANTITIES`, shaped like ``x`` and ``y`` broadcast.
    """
    h, z, nu = float(thickness), float(depth), float(poisson_ratio)
    if not (h > 0) or not (0 <= z <= h) or not (-1 < nu <= 0.5):
        raise TactsenseInputError("need thickness > 0, 0 <= depth <= thickness, -1 < nu <= 0.5")
    if profile not in PROFILES:
        raise TactsenseInputError(f"profile must be one of {', '.join(PROFILES)}; got {profile!r}")
    mu = youngs_modulus / (2 * (1 + nu))
    x, y = np.broadcast_arrays(np.asarray(x, float), np.asarray(y, float))
    shape = x.shape
    phi = np.deg2rad(direction_deg)
    cphi, sphi = np.cos(phi), np.sin(phi)
    x, y = cphi * x.ravel() + sphi * y.ravel(), -sphi * x.ravel() + cphi * y.ravel()
    r = np.hypot(x, y)
    cos, sin = (
        np.where(r > 0, x / np.where(r > 0, r, 1), 1.0),
        np.where(r > 0, y / np.where(r > 0, r, 1), 0.0),
    )

    k, wk = _wavenumbers(z, radius, panels)
    t0 = _load_transform(k, radius, force, profile)
    p, dp, wt, dwt, q, dq = _depth_functions(k, z, h, nu, t0 / mu)
    big_a, big_b = (q + p) / 2, (q - p) / 2
    da, db = (dq + dp) / 2, (dq - dp) / 2
    kr = np.outer(r, k)
    j0, j1, j2 = special.j0(kr), special.j1(kr), special.jv(2, kr)
    j1x, j2x = _bessel_over_x(1, kr), _bessel_over_x(2, kr)
    dj1 = j0 - j1x  # J1'
    dj2 = j1 - 2 * j2x  # J2'
    kw = k * wk  # the Hankel measure k dk

    def inv(kernel, values):
        return kernel @ (values * kw)

    a, a_r, a_z = inv(j0, big_a), -inv(j1, big_a * k), inv(j0, da)
    b, b_r, b_z, b_over_r = inv(j2, big_b), inv(dj2, big_b * k), inv(j2, db), inv(j2x, big_b * k)
    w, w_r, w_z, w_over_r = inv(j1, wt), inv(dj1, wt * k), inv(j1, dwt), inv(j1x, wt * k)

    dU_dr, dV_dr = a_r + b_r, b_r - a_r  # U, V as in the derivation
    dU_dz, dV_dz = a_z + b_z, b_z - a_z
    e_rr = dU_dr * cos
    e_tt = 2 * b_over_r * cos
    e_rt = 0.5 * (dV_dr - 2 * b_over_r) * sin
    e_rz = 0.5 * (dU_dz + w_r) * cos
    e_tz = 0.5 * (dV_dz - w_over_r) * sin
    c2, s2, cs = cos * cos, sin * sin, cos * sin
    out = {
        "u_x": a + b * (c2 - s2),
        "u_y": b * 2 * cs,
        "u_z": w * cos,
        "eps_xx": e_rr * c2 + e_tt * s2 - 2 * e_rt * cs,
        "eps_yy": e_rr * s2 + e_tt * c2 + 2 * e_rt * cs,
        "eps_zz": w_z * cos,
        "eps_xy": (e_rr - e_tt) * cs + e_rt * (c2 - s2),
        "eps_xz": e_rz * cos - e_tz * sin,
        "eps_yz": e_rz * sin + e_tz * cos,
    }
    return {name: value.reshape(shape) for name, value in _rotated(out, cphi, sphi).items()}


def _rotated(local, c, s):
    """Fields of the local frame (x' along the traction) expressed in x, y."""
    rot = np.array([[c, -s], [s, c]])
    u = np.stack([local["u_x"], local["u_y"]])
    eps = np.array([[local["eps_xx"], local["eps_xy"]], [local["eps_xy"], local["eps_yy"]]])
    ez = np.stack([local["eps_xz"], local["eps_yz"]])
    u = np.einsum("ij,j...->i...", rot, u)
    eps = np.einsum("ij,jk...,lk->il...", rot, eps, rot)
    ez = np.einsum("ij,j...->i...", rot, ez)
    return {
        "u_x": u[0],
        "u_y": u[1],
        "u_z": local["u_z"],
        "eps_xx": eps[0, 0],
        "eps_yy": eps[1, 1],
        "eps_zz": local["eps_zz"],
        "eps_xy": eps[0, 1],
        "eps_xz": ez[0],
        "eps_yz": ez[1],
    }


def cerruti_point_displacement(x, y, z, *, force, youngs_modulus, poisson_ratio):
    """Cerruti: displacement [m] of the half space under a surface point force along +x.

    Johnson 1985, eq. 2.19 (z into the solid, rho = |(x, y, z)|)::

        u_x = F/(4 pi G) [1/rho + x^2/rho^3 + (1 - 2 nu)(1/(rho + z) - x^2/(rho (rho + z)^2))]
        u_y = F/(4 pi G) [x y/rho^3 - (1 - 2 nu) x y/(rho (rho + z)^2)]
        u_z = F/(4 pi G) [x z/rho^3 + (1 - 2 nu) x/(rho (rho + z))]

    Returns
    -------
    (u_x, u_y, u_z) : tuple of ndarray
    """
    nu = poisson_ratio
    g = youngs_modulus / (2 * (1 + nu))
    x, y, z = np.broadcast_arrays(*(np.asarray(v, float) for v in (x, y, z)))
    rho = np.sqrt(x * x + y * y + z * z)
    f = force / (4 * np.pi * g)
    m = 1 - 2 * nu
    u_x = f * (1 / rho + x * x / rho**3 + m * (1 / (rho + z) - x * x / (rho * (rho + z) ** 2)))
    u_y = f * (x * y / rho**3 - m * x * y / (rho * (rho + z) ** 2))
    u_z = f * (x * z / rho**3 + m * x / (rho * (rho + z)))
    return u_x, u_y, u_z


def cerruti_disc_fields(
    x, y, depth, *, youngs_modulus, poisson_ratio, radius, force, profile="hertz", order=96
):
    """Half-space fields [m, -] under a tangential disc traction, from Cerruti's point force.

    The point solution is integrated over the disc by Gauss-Legendre quadrature in r'
    (``order`` nodes, with the substitution ``r' = a (1 - s^2)`` that makes the Hertz
    profile's square-root edge smooth) and the trapezoid rule in theta' (``2 order``
    nodes, exact for the periodic integrand); strains by central differences of step
    ``1e-4 a`` (truncation ~1e-8 relative). Needs depth > 0 (the kernel is singular on
    the surface).
    """
    z = float(depth)
    if not z > 0:
        raise TactsenseInputError("cerruti_disc_fields needs depth > 0 [m]")
    nodes, weights = np.polynomial.legendre.leggauss(order)
    s = (nodes + 1) / 2  # s in (0, 1), r' = a (1 - s^2), dr' = 2 a s ds
    rr = radius * (1 - s * s)
    wr = weights / 2 * 2 * radius * s * rr * traction_profile(rr, radius, 1.0, profile)
    th = 2 * np.pi * np.arange(2 * order) / (2 * order)
    wt = 2 * np.pi / (2 * order)
    sx = (rr[:, None] * np.cos(th)).ravel()
    sy = (rr[:, None] * np.sin(th)).ravel()
    sw = np.repeat(wr, th.size) * wt * force

    x, y = np.broadcast_arrays(np.asarray(x, float), np.asarray(y, float))

    def displacement(px, py, pz):
        out = np.zeros((3, *px.shape))
        for idx in np.ndindex(px.shape):
            u = cerruti_point_displacement(
                px[idx] - sx,
                py[idx] - sy,
                pz,
                force=1.0,
                youngs_modulus=youngs_modulus,
                poisson_ratio=poisson_ratio,
            )
            for j in range(3):
                out[(j, *idx)] = np.dot(u[j], sw)
        return out

    step = 1e-4 * radius
    u0 = displacement(x, y, z)
    grads = []  # d u_i / d(x, y, z)
    for dx, dy, dz in ((step, 0, 0), (0, step, 0), (0, 0, step)):
        plus = displacement(x + dx, y + dy, z + dz)
        minus = displacement(x - dx, y - dy, z - dz)
        grads.append((plus - minus) / (2 * step))
    gx, gy, gz = grads
    return {
        "u_x": u0[0],
        "u_y": u0[1],
        "u_z": u0[2],
        "eps_xx": gx[0],
        "eps_yy": gy[1],
        "eps_zz": gz[2],
        "eps_xy": 0.5 * (gy[0] + gx[1]),
        "eps_xz": 0.5 * (gz[0] + gx[2]),
        "eps_yz": 0.5 * (gz[1] + gy[2]),
    }
