"""Checks of the three-dimensional bonded layer (``tactsense.physics.layer``).

Independent evaluations: Love's axisymmetric strain function solved as a 4x4 system
per wavenumber (normal load), the Papkovich-Neuber potentials solved numerically
(tangential load: the code's own representation, so also Navier's equations in
displacements collocated on Chebyshev points, normal and tangential), Betti's
reciprocity, the closed-form Boussinesq/Love solution for a uniformly loaded disc on
the half space, and the Hankel-transform integral of the transfer functions (the
finite-element comparison is in ``test_layer_fem.py``).
"""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy import integrate, special

from tactsense._validation import TactsenseInputError
from tactsense.physics import layer

E = 2.5e5


def love_4x4(k, z, h, nu):
    """2 mu w / P and 2 mu eps_zz / P under the pressure P J0(kr), from Love's function.

    ``phi = J0(kr) f(z)``, ``f = (A + B z) e^{-kz} + (C + D z) e^{kz}``, with
    2 mu u_r = -d2phi/drdz, 2 mu w = 2(1-nu) lap phi - phi_zz,
    sigma_z = d/dz[(2-nu) lap phi - phi_zz], tau_rz = d/dr[(1-nu) lap phi - phi_zz]
    (Timoshenko & Goodier, section 140); the four conditions sigma_z(0) = -P,
    tau_rz(0) = 0, u_r(h) = w(h) = 0 are solved numerically.
    """

    def derivs(zz):  # rows: derivative order 0..3, columns: the four basis functions
        out = np.zeros((4, 4))
        em, ep = np.exp(-k * zz), np.exp(k * zz)
        for n in range(4):
            out[n] = [
                (-k) ** n * em,
                (-k) ** n * zz * em + n * (-k) ** (n - 1) * em,
                k**n * ep,
                k**n * zz * ep + n * k ** (n - 1) * ep,
            ]
        return out

    d0, dh = derivs(0.0), derivs(h)
    matrix = np.array(
        [
            (2 - nu) * (d0[3] - k * k * d0[1]) - d0[3],  # sigma_z(0) per J0
            (1 - nu) * (d0[2] - k * k * d0[0]) - d0[2],  # tau_rz(0) per (-k J1)
            dh[1],  # u_r(h) per (k J1)
            2 * (1 - nu) * (dh[2] - k * k * dh[0]) - dh[2],  # w(h)
        ]
    )
    coef = np.linalg.solve(matrix, [-1.0, 0.0, 0.0, 0.0])
    dz = derivs(z)
    w = (2 * (1 - nu) * (dz[2] - k * k * dz[0]) - dz[2]) @ coef
    eps = (2 * (1 - nu) * (dz[3] - k * k * dz[1]) - dz[3]) @ coef
    return w, eps


@pytest.mark.parametrize("nu", [0.0, 0.3, 0.45, 0.5])
@pytest.mark.parametrize("kh", [0.05, 0.7, 3.0, 12.0])
def test_normal_load_matches_love_4x4(nu, kh):
    h = 3e-3
    k = kh / h
    for z in (0.0, 0.3 * h, 0.8 * h, h):
        w, eps = love_4x4(k, z, h, nu)
        tf = layer.transfer_functions(k, z, h, nu)
        scale = max(abs(w), h * 1e-3)
        assert tf["W_P"].real == pytest.approx(w, abs=1e-9 * scale)
        assert tf["dW_P"].real == pytest.approx(eps, abs=1e-9)
        assert abs(tf["W_P"].imag) == 0 and abs(tf["dW_P"].imag) == 0


def papkovich_numeric(k, z, h, nu, P, Q):
    """(2 mu w, 2 mu u_L) from the potentials solved as a numerical 4x4 system.

    psi_z = A e^{-kz} + B e^{kz}, phi = C e^{-kz} + D e^{kz} (mode e^{ikx});
    2 mu u = -ik (z psi + phi), 2 mu w = (3 - 4 nu) psi - z psi' - phi',
    sigma_zz = 2 nu psi' + 2 mu w', sigma_xz = mu (u' + ik w).
    """
    kappa = 3 - 4 * nu

    def fields(zz):
        # per unknown: psi, psi', psi''; phi, phi', phi''
        e_m, e_p = np.exp(-k * zz), np.exp(k * zz)
        basis_psi = np.array(
            [[e_m, e_p, 0, 0], [-k * e_m, k * e_p, 0, 0], [k * k * e_m, k * k * e_p, 0, 0]]
        )
        basis_phi = np.array(
            [[0, 0, e_m, e_p], [0, 0, -k * e_m, k * e_p], [0, 0, k * k * e_m, k * k * e_p]]
        )
        psi, dpsi, ddpsi = basis_psi
        phi, dphi, ddphi = basis_phi
        w2 = kappa * psi - zz * dpsi - dphi
        dw2 = (kappa - 1) * dpsi - zz * ddpsi - ddphi
        u2 = -1j * k * (zz * psi + phi)
        du2 = -1j * k * (psi + zz * dpsi + dphi)
        return w2, dw2, u2, du2, dpsi

    w0, dw0, _u0, du0, dpsi0 = fields(0.0)
    wh, _, uh, _, _ = fields(h)
    matrix = np.array([2 * nu * dpsi0 + dw0, 0.5 * (du0 + 1j * k * w0), uh, wh], dtype=complex)
    coef = np.linalg.solve(matrix, np.array([-P, -Q, 0, 0], dtype=complex))
    wz, dwz, uz, duz, _ = fields(z)
    return wz @ coef, uz @ coef, dwz @ coef, duz @ coef


@pytest.mark.parametrize("nu", [0.2, 0.5])
@pytest.mark.parametrize("kh", [0.1, 1.0, 6.0])
def test_tangential_load_matches_numeric_potentials(nu, kh):
    h = 2e-3
    k = kh / h
    for z in (0.0, 0.5 * h, 0.9 * h):
        tf = layer.transfer_functions(k, z, h, nu)
        for P, Q, suffix in ((1.0, 0.0, "P"), (0.0, 1.0, "Q")):
            w, u, dw, du = papkovich_numeric(k, z, h, nu, P, Q)
            for name, ref in (("W_", w), ("U_", u), ("dW_", dw), ("dU_", du)):
                got = tf[name + suffix]
                assert abs(got - ref) <= 1e-9 * max(
                    abs(ref), h if "W" in name or "U_" == name else 1.0
                )


def chebyshev(n):
    """Chebyshev points x_j = cos(pi j / n) and the differentiation matrix on them
    (Trefethen, *Spectral Methods in MATLAB*, 2000, cheb.m)."""
    x = np.cos(np.pi * np.arange(n + 1) / n)
    c = np.r_[2.0, np.ones(n - 1), 2.0] * (-1.0) ** np.arange(n + 1)
    dx = x[:, None] - x[None, :]
    d = np.outer(c, 1 / c) / (dx + np.eye(n + 1))
    return d - np.diag(d.sum(axis=1)), x


def navier_collocation(k, h, nu, P, Q, n=60):
    """(2 mu u, 2 mu w) and their z-derivatives under the surface load
    ``(P, Q) exp(ikx)``, by Chebyshev collocation of Navier's equations in displacements
    (no potentials): with ``u = U(z) exp(ikx)``, ``w = W(z) exp(ikx)``,

        mu U'' - (lam + 2 mu) k^2 U + (lam + mu) i k W' = 0
        (lam + 2 mu) W'' - mu k^2 W + (lam + mu) i k U' = 0

    and ``sigma_zz(0) = lam (ikU + W') + 2 mu W' = -P``, ``sigma_xz(0) = mu (U' + ikW)
    = -Q``, ``U(h) = W(h) = 0`` replacing the equations' rows at the two ends. mu = 1/2,
    so the displacements are 2 mu u, 2 mu w. Not for nu = 0.5 (lam infinite)."""
    mu = 0.5
    lam = 2 * mu * nu / (1 - 2 * nu)
    d, x = chebyshev(n)
    z = h * (1 - x) / 2  # z = 0 at index 0, z = h at index n
    dz = -2 / h * d
    d2, eye, m = dz @ dz, np.eye(n + 1), n + 1
    a = np.zeros((2 * m, 2 * m), complex)
    a[:m, :m] = mu * d2 - (lam + 2 * mu) * k**2 * eye
    a[:m, m:] = (lam + mu) * 1j * k * dz
    a[m:, m:] = (lam + 2 * mu) * d2 - mu * k**2 * eye
    a[m:, :m] = (lam + mu) * 1j * k * dz
    b = np.zeros(2 * m, complex)
    a[0], a[m] = 0, 0
    a[0, 0], a[0, m:], b[0] = lam * 1j * k, (lam + 2 * mu) * dz[0], -P  # sigma_zz(0)
    a[m, :m], a[m, m], b[m] = mu * dz[0], mu * 1j * k, -Q  # sigma_xz(0)
    a[n], a[m + n] = 0, 0
    a[n, n], a[m + n, m + n] = 1, 1  # bonded at z = h
    solution = np.linalg.solve(a, b)
    u, w = solution[:m], solution[m:]
    return z, {"U_": u, "W_": w, "dU_": dz @ u, "dW_": dz @ w}


@pytest.mark.parametrize("nu", [0.2, 0.45, 0.499])
@pytest.mark.parametrize("kh", [0.1, 1.0, 6.0, 12.0])
def test_plane_strain_mode_matches_a_direct_navier_solve(nu, kh):
    """The transfer functions (normal and tangential load) against a solution that
    shares no representation with the code (which uses the Papkovich-Neuber potentials,
    as does ``papkovich_numeric`` above): Navier's equations collocated on 61 Chebyshev
    points, interpolated barycentrically to depths off the nodes. Agreement within 1e-6
    (of h for displacements; measured at most 2.2e-7, at kh = 0.1, nu = 0.2)."""
    from scipy.interpolate import BarycentricInterpolator

    h = 2e-3
    k = kh / h
    for P, Q, suffix in ((1.0, 0.0, "P"), (0.0, 1.0, "Q")):
        z, fields = navier_collocation(k, h, nu, P, Q)
        for depth in (0.0, 0.37 * h, 0.9 * h):
            tf = layer.transfer_functions(k, depth, h, nu)
            for name, values in fields.items():
                ref = BarycentricInterpolator(z, values.real)(depth) + 1j * (
                    BarycentricInterpolator(z, values.imag)(depth)
                )
                scale = h if name in ("U_", "W_") else 1.0
                assert abs(complex(tf[name + suffix]) - complex(ref)) <= 1e-6 * scale, (
                    name + suffix,
                    depth,
                )


@pytest.mark.parametrize("nu", [0.25, 0.5])
def test_reciprocity_at_the_surface(nu):
    # Betti: the tangential surface displacement under a pressure mode exp(ikx) equals the
    # normal surface displacement under the traction mode exp(-ikx); U_P is odd in k
    k = np.array([30.0, 300.0, 3000.0])
    tf = layer.transfer_functions(k, 0.0, 3e-3, nu)
    np.testing.assert_allclose(tf["W_Q"], -tf["U_P"], rtol=1e-10, atol=1e-13 * 3e-3)


def test_antiplane_kernel_closed_form():
    k, h, z = 400.0, 2e-3, 0.7e-3
    tf = layer.transfer_functions(k, z, h, 0.3)
    assert tf["T"].real == pytest.approx(2 * np.sinh(k * (h - z)) / (k * np.cosh(k * h)), rel=1e-12)
    assert tf["dT"].real == pytest.approx(-2 * np.cosh(k * (h - z)) / np.cosh(k * h), rel=1e-12)


def test_no_overflow_at_large_kh_and_half_space_limit():
    z = 1e-3
    k = np.array([10.0, 1e3, 1e5, 1e8])
    with np.errstate(all="raise"):
        deep = layer.transfer_functions(k, z, 1.0, 0.5)  # kh up to 1e8
        half = layer.transfer_functions(k, z, np.inf, 0.5)
    for name in ("W_P", "dW_P", "U_P", "dU_P", "W_Q", "U_Q", "T"):
        assert np.all(np.isfinite(deep[name]))
    # Boussinesq: 2 mu w = P (kz + 2(1-nu)) e^{-kz} / k, exactly the half-space closed form
    np.testing.assert_allclose(half["W_P"].real, (k * z + 1.0) * np.exp(-k * z) / k, rtol=1e-14)
    np.testing.assert_allclose(deep["W_P"][1:], half["W_P"][1:], rtol=1e-12)


@pytest.mark.parametrize("z_frac", [0.0, 0.4, 1.0])
def test_incompressible_is_the_limit(z_frac):
    h = 3e-3
    k = np.array([0.0, 1e-2, 50.0, 500.0, 5000.0])
    exact = layer.transfer_functions(k, z_frac * h, h, 0.5)
    near = [layer.transfer_functions(k, z_frac * h, h, 0.5 - d) for d in (1e-4, 1e-5)]
    for name in exact:
        scale = h if name in ("W_P", "W_Q", "U_P", "U_Q", "T") else 1.0
        err = [np.max(np.abs(n[name] - exact[name])) / scale for n in near]
        assert err[1] <= 1e-4, name
        assert err[1] <= err[0] * 0.2 + 1e-10, name  # converges, linearly in 0.5 - nu


def test_zero_wavenumber_limits():
    h, z = 3e-3, 1e-3
    at0 = layer.transfer_functions(0.0, z, h, 0.3)
    tiny = layer.transfer_functions(1e-5 / h, z, h, 0.3)  # kh = 1e-5: the closed form
    for name in at0:
        assert abs(at0[name] - tiny[name]) <= 1e-4 * (h if name[0] != "d" else 1.0), name


# --- the FFT solver against closed forms ---------------------------------------------


def disc_load(n, dx, a, p, m=16):
    """Uniform pressure p on a disc of radius a centred on sample (n//2, n//2); each
    sample carries the fraction of its cell inside the disc (m x m sub-points)."""
    x = (np.arange(n) - n // 2) * dx
    X, Y = np.meshgrid(x, x)
    sub = (np.arange(m) + 0.5) / m - 0.5
    cover = np.zeros_like(X)
    for sx in sub:
        for sy in sub:
            cover += (X + sx * dx) ** 2 + (Y + sy * dx) ** 2 <= a * a
    return p * cover / m**2


@pytest.mark.parametrize("nu", [0.3, 0.5])
def test_half_space_disc_matches_boussinesq_love(nu):
    a, p, n = 1e-3, 2e3, 128
    dx = a / 16
    load = disc_load(n, dx, a, p)
    c = n // 2
    for z in (0.25 * a, a, 2 * a):
        R = np.hypot(a, z)
        s_zz = -p * (1 - z**3 / R**3)
        s_rr = -p / 2 * ((1 + 2 * nu) - 2 * (1 + nu) * z / R + z**3 / R**3)
        eps_zz = (s_zz - 2 * nu * s_rr) / E
        eps_rr = (s_rr - nu * (s_rr + s_zz)) / E
        response = layer.LayerResponse(
            load.shape,
            dx,
            z,
            thickness=np.inf,
            youngs_modulus=E,
            poisson_ratio=nu,
            quantities=("eps_zz", "eps_xx", "eps_yy"),
            padding=(5 * n, 5 * n),
        )
        out = response(load)
        assert out["eps_zz"][c, c] == pytest.approx(eps_zz, rel=0.01)
        assert out["eps_xx"][c, c] == pytest.approx(eps_rr, rel=0.01, abs=0.01 * abs(eps_zz))
        assert out["eps_yy"][c, c] == pytest.approx(eps_rr, rel=0.01, abs=0.01 * abs(eps_zz))
    surface = layer.LayerResponse(
        load.shape,
        dx,
        0.0,
        thickness=np.inf,
        youngs_modulus=E,
        poisson_ratio=nu,
        quantities=("u_z",),
        padding=(5 * n, 5 * n),
    )
    w = surface(load)["u_z"][c, c]
    assert w == pytest.approx(2 * (1 - nu**2) * p * a / E, rel=0.01)


def hankel_disc(r, z, h, nu, a, p, name="W_P"):
    """(1 / 2 mu) (1 / 2 pi) int P(k) X(k, z) J0(kr) k dk for a disc of pressure p.

    ``P(k) = 2 pi a p J1(ka) / k``; composite 16-point Gauss-Legendre rule on 600 panels
    up to k = 80 / max(z, a / 20), where exp(-kz) and the disc's spectrum have decayed
    (checked against scipy.integrate.quad in ``test_hankel_rule_matches_quad``).
    """
    mu = E / (2 * (1 + nu))
    top = 80.0 / max(z, 0.05 * a)
    nodes, weights = np.polynomial.legendre.leggauss(16)
    edges = np.linspace(0.0, top, 601)
    half = np.diff(edges)[:, None] / 2
    k = ((edges[:-1, None] + edges[1:, None]) / 2 + half * nodes).ravel()
    wk = (half * weights).ravel()
    tf = layer.transfer_functions(k, z, h, nu)[name].real
    return np.sum(wk * a * p * special.j1(k * a) * tf * special.j0(k * r)) / (2 * mu)


def test_hankel_rule_matches_quad():
    h, nu, a, p, z, r = 3e-3, 0.3, 1.5e-3, 1e3, 1e-3, 1e-3
    mu = E / (2 * (1 + nu))

    def f(k):
        return (
            a
            * p
            * special.j1(k * a)
            * layer.transfer_functions(k, z, h, nu)["W_P"].real
            * special.j0(k * r)
        )

    ref = integrate.quad(f, 0, 80 / z, limit=2000)[0] / (2 * mu)
    assert hankel_disc(r, z, h, nu, a, p) == pytest.approx(ref, rel=1e-7)


@pytest.mark.parametrize("nu", [0.3, 0.5])
def test_finite_layer_fft_matches_hankel_integral(nu):
    # the FFT pipeline (grid, padding, k = 0 bin) against the transfer functions integrated
    # exactly; the transfer functions themselves are checked by the 4x4 solves and by FEM
    h, a, p, n = 3e-3, 1.5e-3, 1e3, 128
    dx = a / 12
    load = disc_load(n, dx, a, p)
    c = n // 2
    for z in (0.5e-3, 1.5e-3, 2.5e-3):
        out = layer.layer_response(
            load,
            dx,
            z,
            thickness=h,
            youngs_modulus=E,
            poisson_ratio=nu,
            quantities=("u_z", "eps_zz"),
        )
        for j in (0, 12, 24):  # r = 0, a, 2a
            w_ref = hankel_disc(j * dx, z, h, nu, a, p, "W_P")
            e_ref = hankel_disc(j * dx, z, h, nu, a, p, "dW_P")
            assert out["u_z"][c, c + j] == pytest.approx(
                w_ref, rel=0.005, abs=0.005 * abs(w_ref) + 1e-12
            )
            assert out["eps_zz"][c, c + j] == pytest.approx(e_ref, rel=0.005, abs=1e-3 * p / E)


# --- properties --------------------------------------------------------------------

_SHAPE = (12, 10)
_RESPONSE = layer.LayerResponse(
    _SHAPE,
    0.5e-3,
    1e-3,
    thickness=2e-3,
    youngs_modulus=E,
    poisson_ratio=0.45,
    quantities=("u_z", "eps_zz", "eps_xz", "eps_xy", "u_x"),
    tangential=True,
)
# deep enough (4 pi samples) that the sampled kernel has decayed at the Nyquist wavenumber;
# otherwise its band-limited tail (about exp(-pi z / dx) of the peak) wraps differently
# once the load is rotated within the zero-padded period
_SQUARE = layer.LayerResponse(
    (11, 11),
    0.5e-3,
    2e-3,
    thickness=3e-3,
    youngs_modulus=E,
    poisson_ratio=0.45,
    quantities=("u_z", "eps_zz", "eps_xx", "eps_yy", "u_x", "u_y"),
)
_loads = st.lists(st.floats(-1e4, 1e4), min_size=120, max_size=120).map(
    lambda v: np.reshape(v, _SHAPE)
)
_square_loads = st.lists(st.floats(0, 1e4), min_size=121, max_size=121).map(
    lambda v: np.reshape(v, (11, 11))
)


@settings(max_examples=30, deadline=None)
@given(_loads, _loads, _loads, st.floats(-3, 3))
def test_linearity(p1, p2, q, scale):
    one = _RESPONSE(p1, q, None)
    two = _RESPONSE(p2, None, q)
    both = _RESPONSE(p1 + scale * p2, q, scale * q)
    for name in both:
        expected = one[name] + scale * two[name]
        bound = 1e-12 * (np.max(np.abs(one[name])) + abs(scale) * np.max(np.abs(two[name])) + 1e-30)
        assert np.max(np.abs(both[name] - expected)) <= bound


@settings(max_examples=30, deadline=None)
@given(_square_loads)
def test_rotation_and_mirror_symmetry(p):
    out = _SQUARE(p)
    # a load rotated by 90 degrees (x -> y) gives the rotated response
    rot = _SQUARE(np.rot90(p))
    # exact up to the wrap-around left by the 10-h padding (~exp(-14) of the peak)
    tol = 1e-5 * (np.max(np.abs(out["u_z"])) + 1e-30)
    np.testing.assert_allclose(rot["u_z"], np.rot90(out["u_z"]), atol=tol)
    etol = 1e-5 * (np.max(np.abs(out["eps_zz"])) + 1e-30)
    np.testing.assert_allclose(rot["eps_zz"], np.rot90(out["eps_zz"]), atol=etol)
    # np.rot90 maps (row, col) = (y, x) -> (n-1-x, y): the new eps_xx is the old eps_yy
    np.testing.assert_allclose(rot["eps_xx"], np.rot90(out["eps_yy"]), atol=etol)
    # mirror x -> -x: w even, u_x odd
    mir = _SQUARE(p[:, ::-1])
    np.testing.assert_allclose(mir["u_z"], out["u_z"][:, ::-1], atol=tol)
    np.testing.assert_allclose(mir["u_x"], -out["u_x"][:, ::-1], atol=tol)
    np.testing.assert_allclose(mir["u_y"], out["u_y"][:, ::-1], atol=tol)


def test_padding_removes_wraparound():
    # a load at one edge must not reach the opposite edge through the period
    load = np.zeros((40, 40))
    load[20, 0] = 1e4
    # (deep enough that the band-limited tail of the sampled kernel, ~exp(-pi z / dx), is small)
    kwargs = dict(thickness=3e-3, youngs_modulus=E, poisson_ratio=0.5)
    padded = layer.LayerResponse(load.shape, 0.5e-3, 2e-3, **kwargs)(load)["eps_zz"]
    wider = layer.LayerResponse(load.shape, 0.5e-3, 2e-3, padding=(400, 400), **kwargs)(load)[
        "eps_zz"
    ]
    bare = layer.LayerResponse(load.shape, 0.5e-3, 2e-3, padding=(0, 0), **kwargs)(load)["eps_zz"]
    peak = np.max(np.abs(wider))
    assert np.max(np.abs(padded - wider)) < 1e-5 * peak
    assert np.max(np.abs(bare - wider)) > 1e-3 * peak  # without padding it wraps


# --- taxels ----------------------------------------------------------------------


@pytest.mark.parametrize("n", [3, 4])
def test_taxel_reading_is_the_electrode_average(n):
    rows, cols, pitch, electrode, depth = 4, 5, 2e-3, (1.2e-3, 1.6e-3), 1e-3
    kwargs = dict(thickness=3e-3, youngs_modulus=E, poisson_ratio=0.5)
    pad = layer.TaxelPad(rows, cols, pitch, electrode, depth, subsamples=n, **kwargs)

    # a smooth load (two Gaussian bumps), sampled on the pad's grid and on an 8x finer one
    def load(y, x):
        Y, X = np.meshgrid(y, x, indexing="ij")
        bump = np.exp(-((Y - 3e-3) ** 2 + (X - 4e-3) ** 2) / (2 * 1.2e-3**2))
        return 2e3 * bump + 1e3 * np.exp(-((Y - 6e-3) ** 2 + (X - 8e-3) ** 2) / (2 * 1.5e-3**2))

    pressure = load(*pad.sample_positions())
    readings = pad(pressure)
    assert readings.shape == (rows, cols)
    # reference: the point strain on an 8x finer grid, averaged over each electrode by the
    # midpoint rule on that grid (one fine sample = 1/8 of a coarse one: O(1e-3) error)
    f = 8
    spacing = pitch / (n * f)
    y = (np.arange(rows * n * f) + 0.5) * spacing
    x = (np.arange(cols * n * f) + 0.5) * spacing
    fine = load(y, x)
    field = layer.LayerResponse(fine.shape, spacing, depth, **kwargs)(fine)["eps_zz"]
    cy, cx = pad.taxel_centres()
    ref = np.empty((rows, cols))
    for i, yc in enumerate(cy):
        for j, xc in enumerate(cx):
            inside_y = np.abs(y - yc) < electrode[0] / 2
            inside_x = np.abs(x - xc) < electrode[1] / 2
            ref[i, j] = field[np.ix_(inside_y, inside_x)].mean()
    # the pad's grid (3-4 samples per pitch) resolves the bumps to about 1 % of the peak
    np.testing.assert_allclose(readings, ref, rtol=0, atol=0.01 * np.max(np.abs(ref)))


def test_bad_inputs_name_what_is_wrong():
    with pytest.raises(TactsenseInputError, match="thickness"):
        layer.LayerResponse((4, 4), 1e-3, 0.0, thickness=-1, youngs_modulus=E, poisson_ratio=0.3)
    with pytest.raises(TactsenseInputError, match="depth"):
        layer.LayerResponse((4, 4), 1e-3, 5e-3, thickness=2e-3, youngs_modulus=E, poisson_ratio=0.3)
    with pytest.raises(TactsenseInputError, match="poisson_ratio"):
        layer.LayerResponse((4, 4), 1e-3, 0.0, thickness=2e-3, youngs_modulus=E, poisson_ratio=0.6)
    with pytest.raises(TactsenseInputError, match="quantity"):
        layer.LayerResponse(
            (4, 4),
            1e-3,
            0.0,
            thickness=2e-3,
            youngs_modulus=E,
            poisson_ratio=0.3,
            quantities=("sigma",),
        )
    r = layer.LayerResponse((4, 4), 1e-3, 0.0, thickness=2e-3, youngs_modulus=E, poisson_ratio=0.3)
    with pytest.raises(TactsenseInputError, match="pressure has shape"):
        r(np.zeros((5, 4)))
    with pytest.raises(TactsenseInputError, match="NaN"):
        r(np.full((4, 4), np.nan))
    with pytest.raises(TactsenseInputError, match="tangential"):
        r(np.zeros((4, 4)), np.zeros((4, 4)))
    with pytest.raises(TactsenseInputError, match="pressure has shape"):
        layer.layer_response(
            np.zeros(5), 1e-3, 0.0, thickness=2e-3, youngs_modulus=E, poisson_ratio=0.3
        )
    with pytest.raises(TactsenseInputError, match="precision"):
        layer.LayerResponse(
            (4, 4), 1e-3, 0.0, thickness=2e-3, youngs_modulus=E, poisson_ratio=0.3, precision="half"
        )
    with pytest.raises(TactsenseInputError, match="electrode"):
        layer.TaxelPad(
            2, 2, 1e-3, 2e-3, 0.5e-3, thickness=2e-3, youngs_modulus=E, poisson_ratio=0.3
        )


@pytest.mark.parametrize(("n", "shape"), [(3, (12, 15)), (4, (16, 20)), (2, (7, 9))])
def test_decimated_equals_the_full_field_sampled(n, shape):
    rng = np.random.default_rng(2)
    load = rng.uniform(0, 1e3, (2, *shape))
    response = layer.LayerResponse(
        shape,
        0.4e-3,
        0.8e-3,
        thickness=2e-3,
        youngs_modulus=E,
        poisson_ratio=0.5,
        quantities=("eps_zz", "u_x"),
        shift=(0.2e-3, 0.1e-3),
        electrode=(0.8e-3, 0.6e-3),
        multiple_of=n,
    )
    full = response(load)
    part = response.decimated(n, load)
    for name in full:
        expected = full[name][..., ::n, ::n]
        assert part[name].shape == expected.shape
        np.testing.assert_allclose(part[name], expected, atol=1e-12 * np.max(np.abs(expected)))


def test_single_precision_keeps_six_digits():
    kwargs = dict(thickness=3e-3, youngs_modulus=E, poisson_ratio=0.5)
    double = layer.TaxelPad(8, 8, 2e-3, 1.5e-3, 2e-3, **kwargs)
    single = layer.TaxelPad(8, 8, 2e-3, 1.5e-3, 2e-3, precision="single", **kwargs)
    load = np.random.default_rng(3).uniform(0, 1e4, double.grid_shape)
    ref, got = double(load), single(load)
    assert got.dtype == np.float32
    assert np.max(np.abs(got - ref)) < 1e-5 * np.max(np.abs(ref))
