"""Indenters on a flat surface: their pressure laws against closed forms."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tactsense._validation import TactsenseInputError
from tactsense.physics.indenters import (
    DiscProbe,
    FlatPunch,
    KnifeEdge,
    SphereProbe,
    indenter_from_dict,
    pressure_map,
)

E_STAR = 2.5e5 / 0.75  # the paper's rubber, plane-strain modulus [Pa]
GRID = np.arange(0.0, 30.0 + 1e-9, 0.25)  # [mm]


@pytest.mark.parametrize(
    "indenter",
    [
        SphereProbe(15.0, 15.0, 0.5, radius_mm=1.6),
        DiscProbe(15.0, 15.0, 0.5, radius_mm=1.5),
        FlatPunch(15.0, 15.0, 0.5, radius_mm=3.0),
        KnifeEdge(15.0, 15.0, 0.5, length_mm=10.0, angle_deg=30.0, width_mm=0.5),
    ],
)
def test_pressure_carries_the_force(indenter):
    pressure = indenter.pressure_pa(GRID, GRID, modulus_star_pa=E_STAR)
    cell = 0.25e-3**2  # [m^2]
    assert pressure.sum() * cell == pytest.approx(0.5, rel=1e-12)
    assert pressure.min() >= 0


def test_hertz_contact_radius_and_peak():
    """Johnson (1985) eq. 4.22: a = (3 F R / 4 E*)^(1/3), p0 = 3 F / (2 pi a^2)."""
    probe = SphereProbe(0.0, 0.0, 0.5, radius_mm=1.6)
    a = (3 * 0.5 * 1.6e-3 / (4 * E_STAR)) ** (1 / 3)
    assert probe.contact_radius_mm(E_STAR) == pytest.approx(a * 1e3, rel=1e-12)
    fine = np.arange(-2.0, 2.0 + 1e-9, 0.02)
    pressure = probe.pressure_pa(fine, fine, modulus_star_pa=E_STAR)
    centre = pressure[len(fine) // 2, len(fine) // 2]
    assert centre == pytest.approx(3 * 0.5 / (2 * math.pi * a**2), rel=2e-3)
    # zero beyond the contact radius (cells wholly outside it)
    r = np.hypot(*np.meshgrid(fine, fine, indexing="ij"))
    assert np.all(pressure[r > a * 1e3 + 0.03] == 0)


def test_flat_punch_pressure_follows_boussinesq():
    """p(r) = F / (2 pi a sqrt(a^2 - r^2)) (Johnson 1985, eq. 3.35) away from the edge."""
    punch = FlatPunch(0.0, 0.0, 1.0, radius_mm=3.0)
    fine = np.arange(-4.0, 4.0 + 1e-9, 0.05)
    pressure = punch.pressure_pa(fine, fine, modulus_star_pa=E_STAR)
    a = 3e-3
    for r_mm in (0.0, 1.0, 2.0):
        i = np.argmin(abs(fine - r_mm))
        expected = 1.0 / (2 * math.pi * a * math.sqrt(a**2 - (fine[i] * 1e-3) ** 2))
        assert pressure[i, len(fine) // 2] == pytest.approx(expected, rel=5e-3)


def test_a_contact_half_off_the_grid_keeps_only_its_part_on_it():
    disc = DiscProbe(0.0, 15.0, 0.5, radius_mm=1.5)
    half = np.arange(0.125, 30.0, 0.25)  # cells from 0 mm: the disc's centre on the edge
    pressure = disc.pressure_pa(half, GRID, modulus_star_pa=E_STAR)
    assert pressure.sum() * 0.25e-3**2 == pytest.approx(0.25, rel=0.02)


@settings(max_examples=25, deadline=None)
@given(st.floats(5.0, 25.0), st.floats(5.0, 25.0), st.floats(0.01, 2.0), st.floats(0.01, 2.0))
def test_superposition_of_indenters_is_the_sum(x, y, f1, f2):
    one = SphereProbe(x, y, f1, radius_mm=1.6)
    two = DiscProbe(30.0 - x, y, f2, radius_mm=1.5)
    joint = pressure_map([one, two], GRID, GRID, modulus_star_pa=E_STAR)
    separate = one.pressure_pa(GRID, GRID, modulus_star_pa=E_STAR) + two.pressure_pa(
        GRID, GRID, modulus_star_pa=E_STAR
    )
    np.testing.assert_allclose(joint, separate, rtol=1e-12, atol=0)


def test_knife_edge_is_symmetric_under_a_half_turn():
    edge = KnifeEdge(15.0, 15.0, 0.5, length_mm=8.0, angle_deg=30.0)
    turned = KnifeEdge(15.0, 15.0, 0.5, length_mm=8.0, angle_deg=210.0)
    np.testing.assert_allclose(
        edge.pressure_pa(GRID, GRID, modulus_star_pa=E_STAR),
        turned.pressure_pa(GRID, GRID, modulus_star_pa=E_STAR),
        rtol=1e-7,  # the sub-samples differ by rounding of cos/sin of 210 deg
        atol=0,
    )


def test_round_trip_through_dict_and_bad_values():
    probe = SphereProbe(1.0, 2.0, 0.3, radius_mm=2.0, at_taxel=4)
    assert indenter_from_dict(probe.to_dict()) == probe
    with pytest.raises(TactsenseInputError, match="force_n must be >= 0"):
        SphereProbe(0.0, 0.0, -1.0)
    with pytest.raises(TactsenseInputError, match="radius_mm must be a positive"):
        DiscProbe(0.0, 0.0, 1.0, radius_mm=0.0)
    with pytest.raises(TactsenseInputError, match="x_mm must be a finite"):
        SphereProbe(float("nan"), 0.0, 1.0)
    with pytest.raises(TactsenseInputError, match="unknown indenter kind"):
        indenter_from_dict({"kind": "hammer"})
