"""The square stamp and the lying cylinder against their closed forms (flat punch:
separable Sneddon profiles; cylinder: Hertz line contact, Johnson 1985 eqs. 4.43-4.45)."""

import math

import numpy as np
import pytest

from tactsense._validation import TactsenseInputError
from tactsense.physics.indenters import CylinderProbe, SquareStamp, indenter_from_dict

E_STAR = 2.5e5 / 0.75  # the default plane-strain modulus of pressure_pa [Pa]


def _grid(half_mm: float, step_mm: float):
    x = np.arange(-half_mm, half_mm + 1e-9, step_mm)
    return x, x


@pytest.mark.parametrize("angle", [0.0, 17.0, 45.0, 90.0])
@pytest.mark.parametrize("width", [None, 3.0])
def test_square_stamp_carries_its_force(angle, width):
    """Wholly on the grid, the cells carry the force to rounding (the scaling's job;
    the shape's own integral is checked half off the grid below)."""
    stamp = SquareStamp(0.3, -0.2, 2.0, side_mm=6.0, width_mm=width, angle_deg=angle)
    x, y = _grid(6.0, 0.25)
    p = stamp.pressure_pa(x, y)
    assert p.min() >= 0.0
    assert p.sum() * 0.25e-3 * 0.25e-3 == pytest.approx(2.0, rel=1e-12)


def test_square_stamp_middle_carries_a_ninth():
    """p = F / (pi^2 sqrt((a^2 - u^2)(b^2 - v^2))): the share of the load with |u| < a/2
    and |v| < b/2 is (2/pi arcsin(1/2))^2 = (1/3)^2 = 1/9 exactly. Cells of 0.05 mm
    against a 3-mm half side: the band averages are exact, 1e-3 for the cells cut by
    the boundary."""
    stamp = SquareStamp(0.0, 0.0, 1.0, side_mm=6.0)
    x, y = _grid(3.5, 0.05)
    p = stamp.pressure_pa(x, y)
    inner = (np.abs(x)[:, None] < 1.5) & (np.abs(y)[None, :] < 1.5)
    assert p[inner].sum() / p.sum() == pytest.approx(1.0 / 9.0, rel=2e-3)


def test_square_stamp_edge_rises_as_one_over_sqrt():
    """Along the stamp's axis, p(u) / p(0) = 1 / sqrt(1 - (u/a)^2): 2.294 at u = 0.9 a
    (cells of 0.01 mm, far from the edge's band: 0.5 %)."""
    stamp = SquareStamp(0.0, 0.0, 1.0, side_mm=4.0)
    x = np.arange(-2.2, 2.2001, 0.01)
    p = stamp.pressure_pa(x, x)
    middle = np.argmin(np.abs(x))
    at = np.argmin(np.abs(x - 1.8))
    assert p[at, middle] / p[middle, middle] == pytest.approx(1.0 / math.sqrt(1 - 0.81), rel=5e-3)


def test_square_stamp_half_off_the_grid_keeps_half():
    """Centred on the grid's last cell edge, an axis-aligned stamp has half its face on
    the grid: half the force by symmetry (the shape's integral, pi^2 a b, is right)."""
    x = np.arange(-5.0, 5.0001, 0.1)  # cells reach 5.05 mm
    stamp = SquareStamp(5.05, 0.0, 2.0, side_mm=4.0)
    p = stamp.pressure_pa(x, x)
    assert p.sum() * 0.1e-3 * 0.1e-3 == pytest.approx(1.0, rel=1e-3)


def test_cylinder_is_hertz_line_contact():
    """F = 2 N on L = 10 mm, R = 5 mm, E* = 3.33e5 Pa: b = sqrt(4 F R / (pi L E*)) =
    1.954 mm; p0 = 2 F / (pi b L) = 65.1 kPa in the middle; the share within |u| < w
    is (2/pi)(t sqrt(1 - t^2) + arcsin t), t = w/b (cells of 0.02 mm: 0.5 %)."""
    force, length, radius = 2.0, 10.0, 5.0
    b = 1e3 * math.sqrt(4 * (force / (length * 1e-3)) * radius * 1e-3 / (math.pi * E_STAR))
    assert b == pytest.approx(1.9544, rel=1e-4)
    cylinder = CylinderProbe(0.0, 0.0, force, length_mm=length, radius_mm=radius)
    assert cylinder.half_width_mm(E_STAR) == pytest.approx(b, rel=1e-12)
    x = np.arange(-6.0, 6.0001, 0.02)
    p = cylinder.pressure_pa(x, x, modulus_star_pa=E_STAR)
    assert p.sum() * 0.02e-3 * 0.02e-3 == pytest.approx(force, rel=1e-12)
    middle = np.argmin(np.abs(x))
    p0 = 2 * force / (math.pi * b * 1e-3 * length * 1e-3)
    assert p[middle, middle] == pytest.approx(p0, rel=5e-3)
    # along the cylinder (x) uniform; across (y) elliptical
    assert p[np.argmin(np.abs(x - 3.0)), middle] == pytest.approx(p0, rel=5e-3)
    across = np.abs(x) < b / 2
    share = p[:, across].sum() / p.sum()
    # the cells kept reach w (a cell edge near b/2): the elliptical law's share within
    # |u| < w is (2/pi)(t sqrt(1 - t^2) + arcsin t), t = w/b (1/3 + sqrt(3)/(2 pi) at 1/2)
    t = (np.abs(x[across]).max() + 0.01) / b
    assert share == pytest.approx(2 / math.pi * (t * math.sqrt(1 - t * t) + math.asin(t)),
                                  rel=2e-3)  # fmt: skip
    assert abs(t - 0.5) < 0.01


def test_turned_cylinder_lies_along_its_angle():
    """At 90 degrees the cylinder lies along y: the pressure map is the 0-degree one
    transposed (same grid on both axes)."""
    x = np.arange(-6.0, 6.0001, 0.1)
    lying = CylinderProbe(0.0, 0.0, 1.0, length_mm=8.0).pressure_pa(x, x)
    turned = CylinderProbe(0.0, 0.0, 1.0, length_mm=8.0, angle_deg=90.0).pressure_pa(x, x)
    np.testing.assert_allclose(turned, lying.T, rtol=1e-9, atol=1e-9 * lying.max())


@pytest.mark.parametrize(
    "indenter",
    [
        SquareStamp(1.0, 2.0, 0.5, side_mm=4.0, width_mm=2.0, angle_deg=30.0),
        CylinderProbe(1.0, 2.0, 0.5, length_mm=8.0, radius_mm=4.0, angle_deg=-15.0),
    ],
)
def test_round_trip_through_dict(indenter):
    assert indenter_from_dict(indenter.to_dict()) == indenter


@pytest.mark.parametrize(
    "make, message",
    [
        (lambda: SquareStamp(0, 0, 1.0, side_mm=0.0), "side_mm must be a positive number"),
        (lambda: SquareStamp(0, 0, 1.0, width_mm=math.nan), "width_mm must be a positive"),
        (lambda: SquareStamp(0, 0, 1.0, angle_deg=math.inf), "angle_deg must be a finite"),
        (lambda: CylinderProbe(0, 0, 1.0, length_mm=-1.0), "length_mm must be a positive"),
        (lambda: CylinderProbe(0, 0, 1.0, radius_mm=math.inf), "radius_mm must be a positive"),
        (lambda: CylinderProbe(0, 0, 1.0, angle_deg="10"), "angle_deg must be a finite"),
    ],
)
def test_bad_shapes_are_refused(make, message):
    with pytest.raises(TactsenseInputError, match=message):
        make()
