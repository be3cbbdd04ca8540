import numpy as np
import pytest
from contourpy import contour_generator

import tactsense as ts
from tactsense.estimate.finger.contours import track_contour
from tactsense.estimate.finger.interpolate import surface


@pytest.mark.parametrize("share", [0.3, 0.6])
def test_tracked_contour_matches_an_independent_contouring(initial, share):
    # Fig. 22: a rod at 45 deg to the axis on the 45-deg finger
    frame = ts.tactel_deflection(initial, ts.rod(12.0, 90.0, 1.0, orientation_deg=45.0))
    est = ts.locate(frame, initial, counts=False)
    level = share * float(est.peak_deflection)
    line = track_contour(frame, level, est.row, est.col, sensor=initial, periodic=True)
    # the 30 % contour of this long rod reaches the first ring, where the cylinder ends
    assert line.closed == (share == 0.6)
    assert line.row.min() >= 1.0
    # the documented surface: the cylinder's rows, the tip row left out
    frame = frame.copy()
    frame[0] = 0.0
    # every tracked point lies on the level
    np.testing.assert_allclose(
        surface(frame, line.row, line.col, periodic=True), level, atol=1e-6 * level
    )
    # and on contourpy's line of the same surface sampled on a fine grid
    x = np.linspace(0, 7, 281)
    y = np.linspace(0, 7.9, 317)
    values = surface(frame, x[:, None], y[None, :], periodic=True)
    lines = contour_generator(y, x, values).lines(level)
    reference = np.concatenate(lines)  # (col, row) pairs
    distance = np.hypot(
        line.row[:, None] - reference[None, :, 1], line.col[:, None] - reference[None, :, 0]
    ).min(axis=1)
    assert distance.max() < 0.03
    assert np.all(np.isfinite(line.axial_mm)) and np.all(np.isfinite(line.angle_deg))


def test_start_outside_the_contour_is_an_error(initial):
    frame = ts.tactel_deflection(initial, ts.Probe(12.5, 0.0, 0.5))
    with pytest.raises(ValueError, match="inside the contour"):
        track_contour(frame, 10.0, 4.0, 0.0, periodic=True)


def test_contours_stay_on_the_cylinder(initial):
    """The tip row lies about 11 mm before the first ring; contours must not be smeared
    toward it by interpolating it as one spacing away (issue 12: they reached -4 mm)."""
    probe = ts.Probe(float(initial.row_axial_mm[1]) + 0.5, 0.0, ts.grams_force(100))
    frame = ts.tactel_deflection(initial, [probe])
    est = ts.locate(frame, initial, counts=False)
    line = track_contour(
        frame, 0.3 * float(est.peak_deflection), est.row, est.col, sensor=initial, periodic=True
    )
    assert np.nanmin(line.axial_mm) >= initial.row_axial_mm[1] - 1e-9
