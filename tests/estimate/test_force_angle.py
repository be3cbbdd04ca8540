import numpy as np
import pytest

import tactsense as ts
from tactsense.estimate.finger import angle as ang
from tactsense.estimate.finger.force import force_per_deflection, ideal_force_per_deflection
from tactsense.physics import halfplane as hp

E, D = 2.5e5, 3.8e-3


def test_even_odd_split_and_skew_of_a_line_load():
    # eqs. 62-63 on the continuous profile of eq. 7: the skew is k(nu) tan(alpha)
    t = np.linspace(0, 3 * D, 3001)
    for nu, alpha in ((0.5, np.radians(30)), (0.4, np.radians(-15))):

        def strain(x, nu=nu, alpha=alpha):
            return -hp.line_load_strain(x, D, 1.0, alpha, youngs_modulus=E, poisson_ratio=nu)

        even, odd = ang.even_odd(strain(t), strain(-t))
        np.testing.assert_allclose(even + odd, strain(t))
        skew = ang.skew_index(even, odd)
        assert skew == pytest.approx(hp.line_load_skew_coefficient(nu) * np.tan(alpha), rel=1e-4)
        assert ang.angle_from_skew(skew, nu) == pytest.approx(alpha, rel=1e-3)


def test_knife_edge_at_30_degrees_skews_both_ways(initial):
    # Fig. 28: a knife edge at +-30 deg, 100 g, read by interpolation along the cylinder,
    # above a ring (elsewhere aliasing adds a skew of its own, up to ~0.04 for a normal load)
    centre = initial.row_axial_mm[4]
    skews = []
    for alpha in (30.0, -30.0, 0.0):
        edge = ts.knife_edge(centre, 0.0, ts.grams_force(100), alpha_deg=alpha)
        est = ts.locate(ts.tactel_deflection(initial, edge), initial, counts=False)
        skews.append(float(est.skew))
    plus, minus, normal = skews
    assert plus > 0 > minus
    # the skews mirror, and the normal edge does not skew
    assert abs(plus + minus) < 0.05 * plus
    assert abs(normal) < 0.05 * plus
    # sampled at 3.8 mm the odd lobe (peak 1.9 mm from the load) is under-resolved: the
    # skew is 0.051, a third of the continuous line-load value 0.288 tan 30 = 0.166; the
    # paper measured about 0.1
    assert 0.03 < plus < 0.166


def test_inverse_filter_recovers_load_and_angle():
    beta, load, half = np.tan(np.radians(20)), 150.0, 1.5e-3
    edges = np.linspace(-half, half, 61)
    lo, hi = edges[:-1], edges[1:]
    share = 0.75 * ((hi - hi**3 / (3 * half**2)) - (lo - lo**3 / (3 * half**2))) / half
    pressure = load * share / np.diff(edges)
    # the odd response decays as 1/x: the profile must be long for its transform
    spacing = 0.1e-3
    x = (np.arange(8192) - 4096) * spacing
    deflection = -hp.strain_from_pressure(
        x, D, edges, pressure, beta=beta, youngs_modulus=E, poisson_ratio=0.4
    )
    result = ang.inverse_filter(
        deflection, spacing, D, youngs_modulus=E, poisson_ratio=0.4, regularization=1e-3
    )
    assert result["beta"] == pytest.approx(beta, rel=0.05)
    assert result["line_load"] == pytest.approx(load, rel=0.02)


def test_force_conversion_is_the_ideal_one_corrected_for_the_finite_array(initial, improved):
    # an endless array would need E/(1-nu) b arc exactly; 7 rings miss the far lobes
    for spec in (initial, improved):
        ratio = ideal_force_per_deflection(spec) / force_per_deflection(spec)
        assert 1.0 < ratio < 1.35


def test_ideal_force_on_a_long_array_is_exact():
    # with 40 rings and fine strips nothing is lost: the integral is H(0) F (eqs. 55-56)
    spec = ts.SensorSpec(
        name="long",
        array=ts.sensor.ArrayLayout(
            cylinder_rows=40,
            cols=40,
            tip_row=False,
            wired_rows=40,
            wired_cols=40,
            spacing_axial_mm=1.0,
            spacing_angle_deg=9.0,
            first_row_axial_mm=1.0,
        ),
        body=ts.sensor.Body(cylinder_length_mm=45.0),
    )
    frame = ts.tactel_deflection(spec, ts.Probe(20.3, 0.0, 1.0))
    force = ideal_force_per_deflection(spec) * frame.sum()
    # what is left is the negative tail of the plane-stress response beyond the array's
    # ends, 2 nu d / (pi E x^2) per side: 1 + 2 nu d / (pi (1 - nu)) (1/L1 + 1/L2)
    nu, d = 0.4, 3.8
    ends = (20.3 - 0.5, 40.5 - 20.3)
    expected = 1 + 2 * nu * d / (np.pi * (1 - nu)) * (1 / ends[0] + 1 / ends[1])
    assert force == pytest.approx(expected, rel=0.01)
