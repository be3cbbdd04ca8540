"""The whole-array response: references, symmetries and the paper's observations."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy import integrate

import tactsense as ts
from tactsense.physics import halfplane as hp
from tactsense.physics.array_response import (
    deflection_batch,
    ring_cumulative,
    ring_kernel,
    tactel_deflection,
)
from tactsense.physics.contact import profile_cdf
from tactsense.physics.transduction import deflection_to_counts

G50 = ts.grams_force(50)


def test_ring_kernel_is_a_unit_distribution():
    flex = 3.15e-3
    total = integrate.quad(ring_kernel, -np.inf, np.inf, args=(flex,))[0]
    assert total == pytest.approx(1.0, rel=1e-9)
    s = np.linspace(-0.02, 0.02, 9)
    numeric = [integrate.quad(ring_kernel, 0, v, args=(flex,))[0] for v in s]
    np.testing.assert_allclose(ring_cumulative(s, flex), numeric, atol=1e-12)
    # Winkler beam: first zero of the deflection at 3 pi / (4 lambda)
    assert ring_kernel(3 * np.pi / 4 * flex, flex) == pytest.approx(0.0, abs=1e-9)


@pytest.mark.parametrize("profile", ["uniform", "parabolic", "elliptic"])
def test_profile_cdf_matches_quadrature(profile):
    shapes = {
        "uniform": lambda u: 1.0,
        "parabolic": lambda u: 1 - u * u,
        "elliptic": lambda u: np.sqrt(1 - u * u),
    }
    norm = integrate.quad(shapes[profile], -1, 1)[0]
    for u in (-0.8, -0.1, 0.0, 0.5, 1.0):
        want = integrate.quad(shapes[profile], -1, u)[0] / norm
        assert profile_cdf(u, profile) == pytest.approx(want, abs=1e-12)


def test_hertz_sphere_integrates_to_a_parabola():
    # the probe's pressure p0 sqrt(1 - r^2/a^2), integrated across, is parabolic along
    a = 1.5
    for x in (0.0, 0.6, 1.2):

        def pressure(y, x=x):
            return np.sqrt(max(0.0, 1 - (x * x + y * y) / a**2))

        across = integrate.quad(pressure, -a, a)[0]
        assert across == pytest.approx(np.pi / 2 * (a * a - x * x) / a, rel=1e-6)


def test_axial_profile_is_the_plane_stress_model(initial):
    # a narrow knife edge along the finger: the rows follow eq. 7 of the paper
    spec = initial.replace(flaws__gain_spread_sd=0.0)
    edge_axial = spec.row_axial_mm[4] + 1.3
    point = ts.Probe(edge_axial, 0.0, 1.0, contact_diameter_mm=0.0)
    frame = tactel_deflection(spec, point)
    rows = slice(1, 8)
    x = (spec.row_axial_mm[rows] - edge_axial) * 1e-3
    model = -hp.impulse_response(x, 3.8e-3, youngs_modulus=2.5e5, poisson_ratio=0.4)
    ratio = frame[rows, 0] / model
    np.testing.assert_allclose(ratio, ratio[0], rtol=1e-12)
    # and the ring spreading of a point load is the Winkler kernel at the ring radius
    assert ratio[0] == pytest.approx(ring_kernel(0.0, spec.ring_flexural_length_mm * 1e-3))


@given(scale=st.floats(0.01, 10.0))
@settings(max_examples=25, deadline=None)
def test_linear_in_load(initial, scale):
    probe = ts.Probe(10.0, 20.0, G50)
    np.testing.assert_allclose(
        tactel_deflection(initial, probe.moved(force_scale=scale)),
        scale * tactel_deflection(initial, probe),
        rtol=1e-10,
        atol=1e-15,
    )


@given(offset=st.floats(-20.0, 20.0))
@settings(max_examples=25, deadline=None)
def test_mirror_symmetry_around(initial, offset):
    # a probe at +offset deg from column 0 gives the mirror frame of one at -offset
    plus = tactel_deflection(initial, ts.Probe(10.0, offset, G50))
    minus = tactel_deflection(initial, ts.Probe(10.0, -offset, G50))
    mirrored = np.roll(minus[:, ::-1], 1, axis=1)  # col j <-> col -j on the closed ring
    np.testing.assert_allclose(plus, mirrored, atol=1e-14)


def test_mirror_symmetry_along(initial):
    # about a ring in the interior, rows i+k and i-k respond alike to +-x offsets
    centre = initial.row_axial_mm[4]
    plus = tactel_deflection(initial, ts.Probe(centre + 0.9, 0.0, G50))
    minus = tactel_deflection(initial, ts.Probe(centre - 0.9, 0.0, G50))
    np.testing.assert_allclose(plus[3:6], minus[5:2:-1], atol=1e-14)


def test_invariance_along_cylinder_interior(initial):
    # shifting the probe by one ring spacing shifts the frame by one row (cylinder rows)
    step = initial.array.spacing_axial_mm
    a = tactel_deflection(initial, ts.Probe(9.0, 10.0, G50))
    b = tactel_deflection(initial, ts.Probe(9.0 + step, 10.0, G50))
    np.testing.assert_allclose(b[2:8], a[1:7], atol=1e-14)


def test_two_probes_superpose(initial):
    # Fig. 9: the sum of the single responses is the joint response (linear model)
    p1, p2 = ts.Probe(6.0, 0.0, G50), ts.Probe(14.0, 10.0, G50)
    joint = tactel_deflection(initial, [p1, p2])
    np.testing.assert_allclose(
        joint, tactel_deflection(initial, p1) + tactel_deflection(initial, p2), atol=1e-15
    )
    batch = deflection_batch(initial, [(p1,), (), (p1, p2)])
    np.testing.assert_allclose(batch[2], joint, atol=1e-15)
    assert np.all(batch[1] == 0)


def test_response_falls_to_zero_one_tactel_around_at_45_deg(initial):
    # section 7: "the strain profile decreases to zero at just one tactel unit spacing
    # around the circumference" for 45-deg spacing
    angles = np.linspace(0, 90, 181)
    response = np.array(
        [
            tactel_deflection(initial, ts.Probe(8.7, a, G50, contact_diameter_mm=0.0))[3, 0]
            for a in angles
        ]
    )
    first_zero = angles[np.argmax(response <= 0)]
    assert first_zero == pytest.approx(45.0, abs=3.0)
    assert response.min() < 0  # the outward bulge beyond the zero (Fig. 22)


def test_fifty_grams_gives_about_100_counts(initial):
    # section 3: "a force sensitivity of about 0.5 gm (about 100 A/D units for 50-gm load)"
    frame = tactel_deflection(initial, ts.Probe(initial.row_axial_mm[3], 0.0, G50))
    counts = deflection_to_counts(initial, frame[3, 0], quantize=False) - 2000
    assert counts == pytest.approx(100, rel=0.10)


def test_rod_and_flat_contacts_spread_and_conserve_shape(initial):
    rod = ts.rod(12.0, 0.0, G50, orientation_deg=45.0)
    frame = tactel_deflection(initial, rod)
    # linear elasticity: twice the force, twice every tactel (to rounding)
    double = tactel_deflection(initial, ts.rod(12.0, 0.0, 2 * G50, orientation_deg=45.0))
    np.testing.assert_allclose(double, 2 * frame, rtol=1e-9, atol=1e-15)
    # the largest tactel lies under the rod's centre (12 mm: between rows 3 and 4, column
    # 0), and spreading the force along the rod lowers it below a probe's
    assert np.unravel_index(frame.argmax(), frame.shape) in {(3, 0), (4, 0)}
    probe = tactel_deflection(initial, ts.Probe(12.0, 0.0, G50))
    assert 0.1 * probe.max() < frame.max() < probe.max()
    # a rod at 45 deg loads neighbouring columns at neighbouring rows (Fig. 22)
    assert frame[2, 7] > frame[2, 1] and frame[4, 1] > frame[4, 7]
    small = tactel_deflection(initial, ts.soft_object(12.0, 0.0, G50, length_mm=2.0))
    large = tactel_deflection(initial, ts.soft_object(12.0, 0.0, G50, length_mm=12.0))
    # the same force on a larger area gives a lower, wider peak (section 3, Fig. 26)
    assert large.max() < small.max()


def test_tangential_traction_skews_the_response(initial):
    centre = initial.row_axial_mm[4]
    edge = ts.knife_edge(centre, 0.0, 1.0, alpha_deg=30.0)
    frame = tactel_deflection(initial, edge)
    # the side the tangential force pushes toward (+axial) is compressed more
    assert frame[5, 0] > frame[3, 0]
    normal = tactel_deflection(initial, ts.knife_edge(centre, 0.0, 1.0))
    assert frame[4, 0] == pytest.approx(normal[4, 0] * np.cos(np.radians(30)), rel=1e-2)


def test_bad_contacts_are_reported():
    with pytest.raises(ValueError, match="alpha_deg"):
        ts.Probe(1.0, 0.0, 1.0, alpha_deg=95.0)
    with pytest.raises(ValueError, match="force_n"):
        ts.Probe(1.0, 0.0, -1.0)
    with pytest.raises(ValueError, match="profile"):
        ts.FlatContact(1.0, 0.0, 1.0, profile="square")
    with pytest.raises(ValueError, match="finite"):
        ts.Probe(float("nan"), 0.0, 1.0)


def test_fast_response_agrees_with_straightforward_evaluation(initial):
    # the benchmark's per-tactel reference: strain_from_pressure on 200 cells along,
    # scipy.quad of the ring kernel around
    from benchmarks.bench_forward import straightforward

    for probe in (ts.Probe(7.3, 12.0, 0.5), ts.Probe(16.0, -100.0, 0.2), ts.Probe(2.0, 44.0, 1)):
        want = straightforward(initial, probe)
        got = tactel_deflection(initial, probe)
        np.testing.assert_allclose(got, want, atol=1e-3 * np.abs(want).max())
