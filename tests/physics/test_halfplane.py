"""The elastic half plane: Flamant's closed forms and the printed eqs. 5-10, 38, 41.

Every formula is checked against an evaluation that does not share its code:
polar Flamant stresses rotated to Cartesian, force equilibrium by quadrature,
Fourier transforms by numerical integration, convolutions by scipy.quad.
"""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy import integrate

from tactsense.physics import halfplane as hp

E = 2.5e5
D = 3.8e-3


def polar_flamant(x, z, force, alpha):
    """Radial stress -2F cos(theta - alpha) / (pi r) rotated to Cartesian (Johnson 2.15)."""
    r = np.hypot(x, z)
    theta = np.arctan2(x, z)  # from the z axis toward +x
    sigma_r = -2.0 * force * np.cos(theta - alpha) / (np.pi * r)
    # radial unit vector (sin theta, cos theta) in (x, z)
    return (
        sigma_r * np.sin(theta) ** 2,
        sigma_r * np.cos(theta) ** 2,
        sigma_r * np.sin(theta) * np.cos(theta),
    )


@pytest.mark.parametrize("alpha", [0.0, 0.3, -0.7])
def test_flamant_matches_polar_form(alpha):
    x = np.linspace(-8e-3, 8e-3, 41)
    z = 2.5e-3
    got = hp.flamant_stresses(x, z, 200.0 * np.cos(alpha), 200.0 * np.sin(alpha))
    want = polar_flamant(x, z, 200.0, alpha)
    for g, w in zip(got, want, strict=True):
        np.testing.assert_allclose(g, w, rtol=1e-12, atol=1e-9)


def test_flamant_equilibrium_at_depth():
    # the stresses across any horizontal line carry the applied line load
    normal, tangential, z = 150.0, 40.0, 2e-3
    sz = integrate.quad(
        lambda x: hp.flamant_stresses(x, z, normal, tangential)[1], -np.inf, np.inf
    )[0]
    txz = integrate.quad(
        lambda x: hp.flamant_stresses(x, z, normal, tangential)[2], -np.inf, np.inf
    )[0]
    assert sz == pytest.approx(-normal, rel=1e-8)
    assert txz == pytest.approx(-tangential, rel=1e-8)


def test_centre_strain_closed_form():
    # under the load sigma_x = 0, sigma_z = -2P/(pi z): eps_z = -2P/(pi E z) in plane stress
    got = hp.line_load_strain(0.0, D, 200.0, youngs_modulus=E, poisson_ratio=0.4)
    assert got == pytest.approx(-2 * 200.0 / (np.pi * E * D), rel=1e-12)


@pytest.mark.parametrize("model", ["plane_stress", "plane_strain"])
def test_eq7_eq9_match_stress_strain_law(model):
    # eq. 7 / eq. 9 in closed form against eq. 5 applied to Flamant's stresses
    x = np.linspace(-10e-3, 10e-3, 51)
    alpha, nu, load = 0.4, 0.35, 120.0
    sx, sz, _ = hp.flamant_stresses(x, D, load * np.cos(alpha), load * np.sin(alpha))
    if model == "plane_stress":
        want = (sz - nu * sx) / E
    else:
        sy = nu * (sx + sz)  # eq. 8
        want = (sz - nu * (sx + sy)) / E
    got = hp.line_load_strain(x, D, load, alpha, youngs_modulus=E, poisson_ratio=nu, model=model)
    np.testing.assert_allclose(got, want, rtol=1e-10, atol=1e-14)
    assert np.allclose(hp.strain_from_stress(sx, sz, E, nu, model), want, rtol=1e-12)


def test_eq9_printed_form():
    # eq. 9 as printed: -2Pz(1+nu)/(pi r^4 E) [z^2 (1-nu) - nu x^2]
    x, nu, load = np.linspace(-9e-3, 9e-3, 37), 0.3, 80.0
    r4 = (x**2 + D**2) ** 2
    printed = -2 * load * D * (1 + nu) / (np.pi * r4 * E) * (D**2 * (1 - nu) - nu * x**2)
    got = hp.line_load_strain(x, D, load, youngs_modulus=E, poisson_ratio=nu, model="plane_strain")
    np.testing.assert_allclose(got, printed, rtol=1e-12)


@given(
    nu=st.floats(0.0, 0.5),
    x=st.floats(-0.02, 0.02),
    z=st.floats(5e-4, 0.02),
    alpha=st.floats(-1.2, 1.2),
)
@settings(max_examples=60, deadline=None)
def test_eq10_plane_stress_is_plane_strain_with_equivalent_constants(nu, x, z, alpha):
    e_star, nu_star = hp.plane_strain_equivalent(E, nu)
    stress = hp.line_load_strain(x, z, 1.0, alpha, youngs_modulus=E, poisson_ratio=nu)
    strain = hp.line_load_strain(
        x, z, 1.0, alpha, youngs_modulus=e_star, poisson_ratio=nu_star, model="plane_strain"
    )
    assert strain == pytest.approx(stress, rel=1e-9, abs=1e-18)
    # eq. 10 as printed: nu = nu* / (1 - nu*)
    assert nu_star / (1 - nu_star) == pytest.approx(nu, abs=1e-12)


def test_eq10_paper_example():
    # "plane stress with nu = 0.5 corresponds to plane strain with nu = 0.3333"
    assert hp.plane_strain_equivalent(E, 0.5)[1] == pytest.approx(0.3333, abs=1e-4)


@pytest.mark.parametrize("nu", [0.5, 0.4, 0.2])
@pytest.mark.parametrize("s", [0.0, 10.0, 41.9, 120.0, 300.0])
def test_eq41_is_fourier_transform_of_eq38(nu, s):
    h = lambda x: hp.impulse_response(x, D, youngs_modulus=E, poisson_ratio=nu)  # noqa: E731
    if s == 0:
        numeric = integrate.quad(h, -np.inf, np.inf)[0]
    else:
        numeric = 2 * integrate.quad(h, 0, np.inf, weight="cos", wvar=2 * np.pi * s, limit=500)[0]
    got = hp.frequency_response(s, D, youngs_modulus=E, poisson_ratio=nu)
    assert got == pytest.approx(numeric, rel=1e-6, abs=1e-12 / E)


@pytest.mark.parametrize("s", [-150.0, -20.0, 20.0, 80.0])
def test_tangential_transform(s):
    # odd function: transform = -2i * sine transform. The 2 nu / (pi E x) tail is
    # removed with a term whose sine transform is known, (pi/2) exp(-w d); the
    # remainder decays as 1/x^3 and is integrated by the trapezoid rule.
    nu, omega = 0.4, 2 * np.pi * abs(s)
    tail = 2 * nu / (np.pi * E)
    x = np.linspace(0.0, 0.5, 2_000_001)
    ht = hp.impulse_response_tangential(x, D, youngs_modulus=E, poisson_ratio=nu)
    remainder = ht - tail * x / (x * x + D * D)
    sine = np.trapezoid(remainder * np.sin(omega * x), x) + tail * np.pi / 2 * np.exp(-omega * D)
    numeric = -2.0 * np.sign(s) * sine
    got = hp.frequency_response_tangential(s, D, youngs_modulus=E, poisson_ratio=nu)
    assert got.real == 0
    assert got.imag == pytest.approx(numeric, rel=1e-4)


def test_eq41_nu_half_printed_second_line():
    # eq. 41 second line for nu = 0.5: (3 pi d |s| + 1/2) exp(-2 pi d |s|) / E, up to sign
    s = np.linspace(0, 300, 31)
    printed = (3 * np.pi * D * s + 0.5) * np.exp(-2 * np.pi * D * s) / E
    got = hp.frequency_response(s, D, youngs_modulus=E, poisson_ratio=0.5)
    np.testing.assert_allclose(-got, printed, rtol=1e-12)


@pytest.mark.parametrize("nu", [0.5, 0.4, 0.25])
def test_frequency_peak(nu):
    s = np.linspace(0, 200, 200001)
    numeric = s[np.argmin(hp.frequency_response(s, D, youngs_modulus=E, poisson_ratio=nu))]
    assert hp.frequency_peak(D, nu) == pytest.approx(numeric, abs=2e-3)
    if nu == 0.5:
        assert hp.frequency_peak(D, nu) == pytest.approx(1 / (3 * np.pi * D), rel=1e-12)


def test_dc_gain_eq54():
    # H(0) = (1 - nu)/E; eq. 54's 1/(2E) is the nu = 0.5 case
    assert -hp.frequency_response(0.0, D, youngs_modulus=E, poisson_ratio=0.5) == pytest.approx(
        1 / (2 * E)
    )


@pytest.mark.parametrize("beta", [0.0, 0.577])
@pytest.mark.parametrize("depth", [0.5e-3, 3.8e-3])
def test_strain_from_pressure_matches_quadrature(beta, depth):
    half = 1.5e-3
    edges = np.linspace(-half, half, 401)
    pressure_fn = lambda x: 1e4 * (1 - (x / half) ** 2)  # noqa: E731
    # exact cell average of the parabola, so only the kernel integration is tested
    lo, hi = edges[:-1], edges[1:]
    average = 1e4 * (1 - (hi**3 - lo**3) / (3 * half**2 * (hi - lo)))
    x_eval = np.array([-4e-3, -1e-3, 0.0, 0.7e-3, 5e-3])
    got = hp.strain_from_pressure(
        x_eval, depth, edges, average, beta=beta, youngs_modulus=E, poisson_ratio=0.4
    )

    def integrand(xp, x):
        hn = hp.impulse_response(x - xp, depth, youngs_modulus=E, poisson_ratio=0.4)
        ht = hp.impulse_response_tangential(x - xp, depth, youngs_modulus=E, poisson_ratio=0.4)
        return pressure_fn(xp) * (hn + beta * ht)

    want = [
        integrate.quad(
            integrand, -half, half, args=(x,), points=[x] if abs(x) < half else None, limit=200
        )[0]
        for x in x_eval
    ]
    np.testing.assert_allclose(got, want, rtol=2e-4)


def test_strain_from_pressure_integral_is_dc_gain():
    # eq. 55-56: the integral of strain is H(0) times the total load
    edges = np.linspace(-2e-3, 2e-3, 9)
    pressure = np.full(8, 5e4)
    x = np.linspace(-2.0, 2.0, 400001)
    strain = hp.strain_from_pressure(x, D, edges, pressure, youngs_modulus=E, poisson_ratio=0.4)
    total = 5e4 * 4e-3
    # far away h(x) ~ 2 nu d / (pi E x^2): the two tails beyond |x| = 2 m carry
    # 4 nu d total / (pi E 2), which the finite integral lacks
    tails = 4 * 0.4 * D * total / (np.pi * E * 2.0)
    assert np.trapezoid(strain, x) == pytest.approx(-(1 - 0.4) * total / E - tails, rel=1e-6)


def test_narrow_pressure_tends_to_line_load():
    edges = np.linspace(-1e-6, 1e-6, 3)
    x = np.linspace(-1e-2, 1e-2, 11)
    got = hp.strain_from_pressure(
        x, D, edges, np.full(2, 100.0 / 2e-6), youngs_modulus=E, poisson_ratio=0.4
    )
    want = hp.line_load_strain(x, D, 100.0, youngs_modulus=E, poisson_ratio=0.4)
    np.testing.assert_allclose(got, want, rtol=1e-6, atol=1e-9)


def test_bad_inputs_are_reported():
    with pytest.raises(ValueError, match="poisson_ratio"):
        hp.impulse_response(0.0, D, youngs_modulus=E, poisson_ratio=0.7)
    with pytest.raises(ValueError, match="depth"):
        hp.impulse_response(0.0, -1.0, youngs_modulus=E, poisson_ratio=0.4)
    with pytest.raises(ValueError, match="NaN"):
        hp.impulse_response([0.0, np.nan], D, youngs_modulus=E, poisson_ratio=0.4)
    with pytest.raises(ValueError, match="model"):
        hp.impulse_response(0.0, D, youngs_modulus=E, poisson_ratio=0.4, model="3d")
    with pytest.raises(ValueError, match="one per cell"):
        hp.strain_from_pressure(
            [0.0], D, [0, 1e-3, 2e-3], [1.0], youngs_modulus=E, poisson_ratio=0.4
        )


def test_strain_from_pressure_shapes():
    edges = np.linspace(-1e-3, 1e-3, 5)
    scalar = hp.strain_from_pressure(0.0, D, edges, np.ones(4), youngs_modulus=E, poisson_ratio=0.4)
    assert np.ndim(scalar) == 0
    batch = hp.strain_from_pressure(
        np.zeros((2, 3)), D, edges, np.ones((5, 4)), youngs_modulus=E, poisson_ratio=0.4
    )
    assert batch.shape == (5, 2, 3)
    assert np.allclose(batch, scalar)


@pytest.mark.parametrize("nu", [0.0, 0.25, 0.4, 0.5])
def test_odd_strain_peak_and_skew_coefficient(nu):
    # eqs. 64-67: maximise the odd and even parts of eq. 7 numerically
    from scipy.optimize import minimize_scalar

    alpha = np.radians(20.0)

    def odd(x):
        plus = hp.line_load_strain(x, D, 1.0, alpha, youngs_modulus=E, poisson_ratio=nu)
        minus = hp.line_load_strain(-x, D, 1.0, alpha, youngs_modulus=E, poisson_ratio=nu)
        return 0.5 * (plus - minus)

    best = minimize_scalar(
        lambda x: odd(x), bounds=(0, 3 * D), method="bounded", options={"xatol": 1e-12}
    )
    assert hp.odd_peak_offset(D, nu) == pytest.approx(best.x, rel=1e-5)
    even_peak = hp.line_load_strain(0.0, D, 1.0, alpha, youngs_modulus=E, poisson_ratio=nu)
    skew = odd(best.x) / even_peak
    assert hp.line_load_skew_coefficient(nu) * np.tan(alpha) == pytest.approx(skew, rel=1e-8)


def test_printed_skew_constant_is_a_misprint():
    # eq. 67 prints 0.2441 for nu = 0.5; the maximum is 0.2805. The printed eq. 65
    # (with -4 for -4 nu) puts the peak at 0.685 d, where the ratio is 0.2430.
    # The ratio is evaluated with the code's own eq. 7 (odd part at the offset over the
    # even peak, per tan alpha), at the printed location and at the code's location.
    nu, alpha = 0.5, np.radians(20.0)

    def ratio(x):
        plus = hp.line_load_strain(x, D, 1.0, alpha, youngs_modulus=E, poisson_ratio=nu)
        minus = hp.line_load_strain(-x, D, 1.0, alpha, youngs_modulus=E, poisson_ratio=nu)
        even = hp.line_load_strain(0.0, D, 1.0, alpha, youngs_modulus=E, poisson_ratio=nu)
        return 0.5 * (plus - minus) / even / np.tan(alpha)

    printed_t = np.sqrt((3 * (1 + nu) - np.sqrt(9 * (1 + nu) ** 2 - 4)) / (2 * nu))
    assert printed_t == pytest.approx(0.685, abs=1e-3)
    # the code's offset is not the printed one, and its ratio is the larger (the maximum)
    assert hp.odd_peak_offset(D, nu) / D == pytest.approx(0.4775, abs=1e-4)
    assert ratio(printed_t * D) == pytest.approx(0.2430, abs=5e-4)
    assert ratio(printed_t * D) == pytest.approx(0.2441, rel=0.01)  # the printed constant
    assert hp.line_load_skew_coefficient(nu) == pytest.approx(ratio(hp.odd_peak_offset(D, nu)))
    assert hp.line_load_skew_coefficient(nu) == pytest.approx(0.28055, abs=1e-5)
