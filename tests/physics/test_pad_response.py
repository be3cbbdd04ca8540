"""The three-dimensional layer of pads and point sets, against closed forms and properties."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import tactsense as ts
from tactsense.flat_scenarios import centre_mm
from tactsense.physics.indenters import DiscProbe, SphereProbe
from tactsense.physics.pad_response import pad_strain, points_strain, strain_map
from tactsense.sensor import Layer


def _love_on_axis_strain(p0, a, z, nu, modulus):
    """Normal strain on the axis of a uniformly loaded disc on a half space (Love 1929;
    Johnson, Contact Mechanics, 1985, eqs. 3.41-3.42), compression negative."""
    r = math.hypot(a, z)
    sigma_z = -p0 * (1 - z**3 / r**3)
    sigma_r = -p0 / 2 * ((1 + 2 * nu) - 2 * (1 + nu) * z / r + z**3 / r**3)
    return (sigma_z - 2 * nu * sigma_r) / modulus


@pytest.mark.parametrize("nu", [0.3, 0.5])
@pytest.mark.parametrize("depth", [0.5, 2.0])
def test_thick_layer_is_the_half_space_of_boussinesq_and_love(nu, depth):
    """A layer 60 radii thick, read a few radii deep, is a half space: the on-axis strain
    under a uniform disc equals Love's closed form to 0.5 % (the grid of 0.1 radius, the
    cell-averaged rim of the disc and the far substrate account for the rest; measured
    -0.03 to +0.30 %)."""
    a, force, modulus = 1.0, 1.0, 2.5e5
    layer = Layer(thickness_mm=60.0, youngs_modulus_pa=modulus, poisson_ratio=nu,
                  sensing_depth_mm=depth)  # fmt: skip
    step = 0.1
    axis = np.arange(-15.0, 15.0 + 1e-9, step)
    disc = DiscProbe(0.0, 0.0, force, radius_mm=a)
    pressure = disc.pressure_pa(axis, axis, modulus_star_pa=1e6)
    centre = len(axis) // 2
    computed = strain_map(pressure, (step, step), layer)[centre, centre]
    p0 = force / (math.pi * (a * 1e-3) ** 2)
    assert computed == pytest.approx(_love_on_axis_strain(p0, a, depth, nu, modulus), rel=5e-3)


def test_bonded_incompressible_layer_does_not_compress_under_uniform_pressure():
    """nu = 0.5 bonded to a rigid base: a uniform pressure cannot squeeze the layer (the
    wavenumber-0 strain is -(1 - 2 nu) / (1 - nu) p / 2 mu = 0), with no singularity."""
    from tactsense.physics.pad_response import strain_transfer

    layer = Layer(thickness_mm=2.0, youngs_modulus_pa=2.5e5, poisson_ratio=0.5,
                  sensing_depth_mm=1.0)  # fmt: skip
    assert strain_transfer(0.0, 0.0, 1.0, layer) == 0.0
    near = Layer(thickness_mm=2.0, youngs_modulus_pa=2.5e5, poisson_ratio=0.3,
                 sensing_depth_mm=1.0)  # fmt: skip
    mu = 2.5e5 / (2 * 1.3)
    assert strain_transfer(0.0, 0.0, 1.0, near) == pytest.approx(-(0.4 / 0.7) / (2 * mu))


@settings(max_examples=15, deadline=None)
@given(st.floats(0.05, 2.0), st.floats(0.05, 2.0))
def test_pad_response_is_linear_in_the_load(f1, f2):
    spec = ts.preset("pad4")
    cx, cy = centre_mm(spec)
    one = SphereProbe(cx - 2.0, cy, f1, radius_mm=1.6)
    two = SphereProbe(cx + 2.0, cy + 1.0, f2, radius_mm=1.6)
    joint = pad_strain(spec, [one, two])
    np.testing.assert_allclose(
        joint, pad_strain(spec, [one]) + pad_strain(spec, [two]), rtol=1e-9, atol=1e-15
    )


def test_square_pad_response_is_symmetric_under_a_quarter_turn_and_a_mirror():
    """A load on the diagonal of a square pad: the response is symmetric about it, and a
    disc in the middle gives a response invariant under a quarter turn."""
    spec = ts.preset("pad16")
    cx, cy = centre_mm(spec)
    middle = pad_strain(spec, [DiscProbe(cx, cy, 0.5, radius_mm=2.0)])
    np.testing.assert_allclose(middle, np.rot90(middle), rtol=1e-9, atol=1e-14)
    np.testing.assert_allclose(middle, middle[::-1], rtol=1e-9, atol=1e-14)
    diagonal = pad_strain(spec, [SphereProbe(10.0, 10.0, 0.5, radius_mm=1.6)])
    np.testing.assert_allclose(diagonal, diagonal.T, rtol=1e-9, atol=1e-14)


def test_the_taxel_under_a_probe_reads_most_and_a_thicker_layer_spreads_more():
    """Section 2.3 of the paper: the response widens with depth. The same pad with its
    layer and sensing depth doubled shares more of the load with the neighbour."""
    spec = ts.preset("pad16")
    probe = [SphereProbe(7 * 2.5, 9 * 2.5, 0.5, radius_mm=1.6)]
    thin = pad_strain(spec, probe)
    assert np.unravel_index(thin.argmax(), thin.shape) == (7, 9)
    thick_spec = spec.replace(layer__thickness_mm=4.0, layer__sensing_depth_mm=3.0)
    thick = pad_strain(thick_spec, probe)
    assert np.unravel_index(thick.argmax(), thick.shape) == (7, 9)
    assert thick[7, 10] / thick[7, 9] > thin[7, 10] / thin[7, 9] + 0.05


def test_a_flat_point_set_reads_as_the_pad_with_the_same_taxels():
    """A point set whose taxels lie on a plane (normals +z) is a pad sampled at those
    points: locally flat is exactly flat there (up to the interpolation of the local map)."""
    pad = ts.preset("pad4")
    positions = pad.taxel_positions_mm()
    points = ts.sensor.PointsSpec(
        name="flat",
        taxels=ts.sensor.Taxels(
            positions_mm=tuple(map(tuple, positions)),
            normals=tuple([(0.0, 0.0, 1.0)] * len(positions)),
            area_mm2=tuple([16.0] * len(positions)),  # the pad's 4 x 4 mm electrodes
        ),
        layer=pad.layer,
        transduction=pad.transduction,
        electronics=pad.electronics,
    )
    probe_on_pad = SphereProbe(6.0, 8.0, 0.5, radius_mm=1.6)
    on_pad = pad_strain(pad, [probe_on_pad]).ravel()
    # the same probe in the tangent plane of taxel 0 (at the origin): (x, y) unchanged
    on_points = points_strain(points, [SphereProbe(6.0, 8.0, 0.5, radius_mm=1.6, at_taxel=0)])
    np.testing.assert_allclose(on_points.ravel(), on_pad, rtol=0.03, atol=2e-5)


@pytest.mark.parametrize("nu", [0.0, 0.3, 0.49, 0.5])
def test_three_dimensional_layer_mode_is_the_plane_strain_strip(nu):
    """A normal-load mode exp(i k.x) on the bonded layer has no displacement along its
    crests: it is the plane-strain strip of section 5 at |k|. Two independent derivations
    (tactsense.physics.layer's Papkovich-Neuber 3-D solve and tactsense.physics.strip's
    2-D one, itself checked by finite elements) agree to rounding."""
    from tactsense.physics.layer import transfer_functions
    from tactsense.physics.strip import strip_kernel, strip_strain_kernel

    h = 3e-3
    k = np.geomspace(1.0, 5e4, 40)  # [rad/m], k h from 0.003 to 150
    for z in (0.0, 1e-3, 2.5e-3):
        layer = transfer_functions(k, z, h, nu)
        s = k / (2 * np.pi)  # [cycles/m]
        np.testing.assert_allclose(
            layer["W_P"].real, strip_kernel(s, z, h, nu, "plane_strain"), rtol=1e-7, atol=1e-14
        )
        np.testing.assert_allclose(
            layer["dW_P"].real, strip_strain_kernel(s, z, h, nu, "plane_strain"), rtol=1e-7,
            atol=1e-12,
        )  # fmt: skip
