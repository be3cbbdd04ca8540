"""The elastic strip on the rigid core (section 5): derived kernel, limits, print, FEM."""

import numpy as np
import pytest
from scipy import integrate

from tactsense.analysis import strip_capacitor_design
from tactsense.physics import halfplane, strip

E = 2.5e5
H = 3.8e-3


def boundary_value_solution(k, z, h, nu):
    """2 mu W(z) / p from the Papkovich-Neuber form, boundary conditions solved numerically.

    psi_3 = A e^{-kz} + B e^{kz}, phi = C e^{-kz} + D e^{kz} (times cos kx); plane strain.
    Rows: sigma_z(0) = -p, tau_xz(0) = 0, u(h) = 0, w(h) = 0.
    """
    kappa = 3 - 4 * nu
    lam_over_mu = 2 * nu / (1 - 2 * nu)

    def fields(zz):
        em, ep = np.exp(-k * zz), np.exp(k * zz)
        u = k * np.array([zz * em, zz * ep, em, ep])  # 2 mu U
        du = k * np.array([em - k * zz * em, ep + k * zz * ep, -k * em, k * ep])
        w = np.array([kappa * em + k * zz * em, kappa * ep - k * zz * ep, k * em, -k * ep])
        dw = np.array(
            [
                -kappa * k * em + k * em - k * k * zz * em,
                kappa * k * ep - k * ep - k * k * zz * ep,
                -k * k * em,
                -k * k * ep,
            ]
        )
        return u, du, w, dw

    u0, du0, w0, dw0 = fields(0.0)
    uh, _, wh, _ = fields(h)
    # sigma_z = [lam k (2 mu U) + (lam + 2 mu)(2 mu W')] / (2 mu), divided by mu here
    sigma = (lam_over_mu * k * u0 + (lam_over_mu + 2) * dw0) / 2
    tau = du0 - k * w0
    matrix = np.array([sigma, tau, uh, wh])
    coeffs = np.linalg.solve(matrix, [-1.0, 0.0, 0.0, 0.0])
    return fields(z)[2] @ coeffs


@pytest.mark.parametrize("nu", [0.0, 0.3, 0.45])
@pytest.mark.parametrize("kh", [0.05, 0.7, 3.0, 12.0])
def test_kernel_matches_direct_boundary_value_solution(nu, kh):
    for z_frac in (0.0, 0.3, 0.8, 1.0):
        k = kh / H
        want = boundary_value_solution(k, z_frac * H, H, nu)
        got = strip.strip_kernel(k / (2 * np.pi), z_frac * H, H, nu, "plane_strain")
        assert got == pytest.approx(want, rel=1e-9, abs=1e-12 * H)


def test_strain_kernel_is_the_depth_derivative():
    z = np.linspace(0.2e-3, 3.6e-3, 9)
    for s in (20.0, 150.0):
        dz = 1e-8
        numeric = (
            strip.strip_kernel(s, z + dz, H, 0.4) - strip.strip_kernel(s, z - dz, H, 0.4)
        ) / (2 * dz)
        np.testing.assert_allclose(strip.strip_strain_kernel(s, z, H, 0.4), numeric, rtol=1e-6)


def test_thick_strip_tends_to_half_plane():
    s = np.array([50.0, 200.0, 800.0])
    for z in (0.5e-3, 3.3e-3):
        thick = strip.strip_kernel(s, z, 2.0, 0.4)
        np.testing.assert_allclose(thick, strip.half_plane_kernel(s, z, 0.4), rtol=1e-9)
    # and the strain impulse response tends to the plane-stress half plane of section 4
    x = np.linspace(-0.015, 0.015, 13)
    got = strip.impulse_response(x, 3.3e-3, 1.0, youngs_modulus=E, poisson_ratio=0.5)
    want = halfplane.impulse_response(x, 3.3e-3, youngs_modulus=E, poisson_ratio=0.5)
    # a 1-m strip differs from the half plane by O(d / h) = 0.3 % of the peak
    np.testing.assert_allclose(got, want, atol=3e-3 * np.abs(want).max())


def test_small_and_large_kh_are_stable():
    # uniform pressure compresses a bonded layer as a constrained column
    nu = 0.3
    z = np.linspace(0, H, 7)
    np.testing.assert_allclose(
        strip.strip_kernel(0.0, z, H, nu, "plane_strain"),
        (H - z) * (1 - 2 * nu) / (1 - nu),
        rtol=1e-12,
    )
    # the series and the closed form meet at the switch without a jump
    k_switch = 1e-3 / H
    below = strip.strip_kernel(0.999 * k_switch / (2 * np.pi), 0.4 * H, H, nu)
    above = strip.strip_kernel(1.001 * k_switch / (2 * np.pi), 0.4 * H, H, nu)
    assert above == pytest.approx(below, rel=1e-6)
    with np.errstate(all="raise"):
        huge = strip.strip_kernel(1e7, np.array([0.0, 1e-4, H]), H, nu)
    assert np.all(np.isfinite(huge)) and huge[-1] == 0


def printed_kernel(k, z, h, nu, *, corrected_eq32=False):
    """Eqs. 28-33 as printed (s taken as the angular wavenumber k)."""
    kappa, om = 3 - 4 * nu, k * h
    alpha = (-kappa * np.exp(2 * om) + 2 * om - 1) / (kappa * np.exp(-2 * om) + 2 * om + 1)
    b = (np.exp(-om) + np.exp(om)) / (
        np.exp(-om) * (alpha * (kappa - 2 * om) - 1) + np.exp(om) * (alpha - kappa - 2 * om)
    )
    a = alpha * b
    if corrected_eq32:
        minus_d = (
            a * (om - (1 - 2 * nu)) * np.exp(-om)
            + b * (om * np.exp(om) - (1 - 2 * nu) * np.exp(-om))
        ) / (np.exp(-om) + np.exp(om))
    else:
        minus_d = (
            a * (om - (1 - 2 * nu)) * np.exp(-om)
            + b * (om * np.exp(om) - (1 - 2 * nu)) * np.exp(-om)
        ) / (np.exp(-om) + np.exp(om))
    d = -minus_d
    c = d - (1 - 2 * nu) * (a + b)
    return (
        (kappa * a + k * z * a + c) * np.exp(-k * z) + (kappa * b - k * z * b - d) * np.exp(k * z)
    ) / k


@pytest.mark.parametrize("kh", [0.3, 1.0, 4.0])
def test_printed_eq32_is_misprinted(kh):
    nu, k = 0.3, kh / H
    z = np.array([0.0, 0.5 * H, H])
    ours = strip.strip_kernel(k / (2 * np.pi), z, H, nu, "plane_strain")
    literal = printed_kernel(k, z, H, nu)
    fixed = printed_kernel(k, z, H, nu, corrected_eq32=True)
    # the printed kernel is right at the surface, wrong inside, and does not vanish at the core
    assert literal[0] == pytest.approx(ours[0], rel=1e-9)
    assert abs(literal[2]) > 1e-3 * ours[0]
    # with the bracket of eq. 32 moved, it is our kernel everywhere
    np.testing.assert_allclose(fixed, ours, rtol=1e-8, atol=1e-14)


def test_parabolic_pressure_transform():
    width, load = 3e-3, 200.0
    a = width / 2
    p = lambda x: 1.5 * load / width * (1 - (x / a) ** 2)  # noqa: E731
    for s in (0.0, 100.0, 700.0):
        numeric = 2 * integrate.quad(lambda x, s=s: p(x) * np.cos(2 * np.pi * s * x), 0, a)[0]
        assert strip.parabolic_pressure_transform(s, load, width) == pytest.approx(
            numeric, rel=1e-9
        )


@pytest.mark.parametrize("model", ["plane_stress", "plane_strain"])
def test_displacement_matches_adaptive_quadrature(model):
    nu = 0.45
    mu = E / (2 * (1 + nu))
    for x, z in ((0.0, 0.0), (0.0, 3.3e-3), (2e-3, 1e-3), (6e-3, 2.5e-3)):
        integrand = lambda s, x=x, z=z: (  # noqa: E731
            strip.parabolic_pressure_transform(s, 200.0, 3e-3)
            * strip.strip_kernel(s, z, H, nu, model)
            * np.cos(2 * np.pi * s * x)
        )
        want = 2 * integrate.quad(integrand, 0, np.inf, limit=2000)[0] / (2 * mu)
        got = strip.displacement(
            x, z, H, 200.0, 3e-3, youngs_modulus=E, poisson_ratio=nu, model=model
        )
        assert got == pytest.approx(want, rel=2e-6)


def test_fig17_shapes():
    kw = {"youngs_modulus": E, "poisson_ratio": 0.5}
    # first case: gain falls as the top plate goes deeper but stays finite near the core
    top = np.linspace(0.5e-3, 3.7e-3, 17)
    gain = strip.capacitor_gain(top, H, H, 200.0, 3e-3, **kw)
    assert np.all(np.diff(gain) < 0) and gain[-1] > 0.5 * gain[0]
    # second case: a thicker backing changes the gain by less than 10 %
    design = strip_capacitor_design(H, 0.5e-3, 200.0, 3e-3, backing=np.linspace(0, 0.1, 30), **kw)
    spread = design["gain"].max() / design["gain"].min()
    assert 1.0 < spread < 1.1


def test_design_broadcasts_over_many_designs():
    thickness = np.linspace(2e-3, 6e-3, 1000)
    result = strip_capacitor_design(thickness, 0.5e-3, 200.0, 3e-3)
    assert result["gain"].shape == (1000,)
    one = strip_capacitor_design(thickness[123], 0.5e-3, 200.0, 3e-3)
    assert one["gain"] == pytest.approx(result["gain"][123], rel=1e-12)
    assert result["closing"][123] == pytest.approx(0.5e-3 * result["gain"][123], rel=1e-12)


def test_bad_designs_are_reported():
    with pytest.raises(ValueError, match="separation"):
        strip_capacitor_design(3.8e-3, 4e-3, 200.0, 3e-3)
    with pytest.raises(ValueError, match="within the strip"):
        strip.strip_kernel(10.0, 5e-3, H, 0.4)
    with pytest.raises(ValueError, match="thickness"):
        strip.strip_kernel(10.0, 0.0, -1.0, 0.4)
    with pytest.raises(ValueError, match="backing"):
        strip_capacitor_design(3.8e-3, 0.5e-3, 200.0, 3e-3, backing=-1e-3)


def test_strain_integral_of_the_strip():
    # docs/estimation.md: the integral of eps_z at depth is P(0) dH/dz(0) / (2 mu), with
    # dH/dz(0) = -(1 - 2 nu)/(1 - nu): zero for an incompressible layer in plane strain
    for z in (0.5e-3, 3.3e-3):
        assert strip.strip_strain_kernel(0.0, z, H, 0.5, "plane_strain") == 0.0
        assert strip.strip_strain_kernel(0.0, z, H, 0.5, "plane_stress") == pytest.approx(-0.5)
        assert strip.strip_strain_kernel(0.0, z, H, 0.3, "plane_strain") == pytest.approx(
            -0.4 / 0.7
        )
