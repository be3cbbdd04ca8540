import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tactsense import geometry as g


@given(row=st.floats(-0.5, 7.5), col=st.floats(-0.49, 7.49))
@settings(max_examples=80, deadline=None)
def test_tactel_surface_round_trip(initial, row, col):
    axial, angle = g.tactel_to_surface(initial, row, col)
    back_row, back_col = g.surface_to_tactel(initial, axial, angle)
    assert back_row == pytest.approx(row, abs=1e-9)
    assert back_col == pytest.approx(col, abs=1e-9)


def test_tactel_centres_are_integer_coordinates(any_preset):
    axial, angle = g.tactel_centers(any_preset)
    row, col = g.surface_to_tactel(any_preset, axial, angle)
    np.testing.assert_allclose(row, np.arange(8)[:, None] + 0 * col, atol=1e-12)
    np.testing.assert_allclose(col, np.arange(8)[None, :] + 0 * row, atol=1e-12)


def test_closed_layout_wraps(initial):
    # column 7.6 is 0.4 of a tactel before column 0 on a closed ring of 8
    axial, angle = g.tactel_to_surface(initial, 3, 7.6)
    assert g.surface_to_tactel(initial, axial, angle)[1] == pytest.approx(-0.4)


def test_cylinder_points_lie_on_surface(initial):
    axial = np.linspace(0, 25, 11)
    angle = np.linspace(-170, 170, 11)
    xyz = g.surface_to_xyz(initial, axial, angle)
    np.testing.assert_allclose(np.hypot(xyz[:, 1], xyz[:, 2]), initial.radius_mm)
    np.testing.assert_allclose(xyz[:, 0], axial)


def test_tip_points_lie_on_hemisphere(initial):
    axial = np.linspace(-np.pi * initial.radius_mm / 2, 0, 9)
    xyz = g.surface_to_xyz(initial, axial, 30.0)
    np.testing.assert_allclose(np.linalg.norm(xyz, axis=-1), initial.radius_mm)
    # the apex is on the axis
    np.testing.assert_allclose(xyz[0], [-initial.radius_mm, 0, 0], atol=1e-12)


@given(axial=st.floats(-19.9, 25), angle=st.floats(-179.9, 180), depth=st.floats(0, 3))
@settings(max_examples=80, deadline=None)
def test_xyz_round_trip(initial, axial, angle, depth):
    xyz = g.surface_to_xyz(initial, axial, angle, depth)
    back_axial, back_angle, back_depth = g.xyz_to_surface(initial, xyz)
    assert back_axial == pytest.approx(axial, abs=1e-9)
    assert back_depth == pytest.approx(depth, abs=1e-9)
    if abs(axial + np.pi * initial.radius_mm / 2) > 1e-3:  # angle undefined at the apex
        assert g.wrap_angle_deg(back_angle - angle) == pytest.approx(0, abs=1e-7)


def test_unwrapped_round_trip(initial):
    u, v = g.surface_to_unwrapped(initial, [1.0, 10.0], [90.0, -45.0])
    np.testing.assert_allclose(v, [initial.radius_mm * np.pi / 2, -initial.radius_mm * np.pi / 4])
    axial, angle = g.unwrapped_to_surface(initial, u, v)
    np.testing.assert_allclose(axial, [1.0, 10.0])
    np.testing.assert_allclose(angle, [90.0, -45.0])


def test_wrong_shapes_and_nan_are_reported(initial):
    with pytest.raises(ValueError, match=r"expected \(\.\.\., 3\)"):
        g.xyz_to_surface(initial, np.zeros((4, 2)))
    with pytest.raises(ValueError, match="NaN"):
        g.tactel_to_surface(initial, np.nan, 0)
    with pytest.raises(ValueError, match="apex"):
        g.surface_to_xyz(initial, -30.0, 0.0)
