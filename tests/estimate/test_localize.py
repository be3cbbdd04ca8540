import numpy as np
import pytest

import tactsense as ts
from tactsense.estimate.finger import interpolate as ip
from tactsense.estimate.finger.localize import locate_contacts, newton_peak


def bump(row0, col0, width=1.0):
    i, j = np.meshgrid(np.arange(8), np.arange(8), indexing="ij")
    return np.exp(-((i - row0) ** 2 + (j - col0) ** 2) / (2 * width**2))


@pytest.mark.parametrize(("row0", "col0"), [(3.3, 4.1), (4.5, 2.5), (2.05, 5.9)])
def test_newton_finds_the_surface_maximum(row0, col0):
    z = bump(row0, col0)
    start = np.unravel_index(z.argmax(), z.shape)
    peak = newton_peak(z, *start)
    # reference: brute-force search of the same interpolated surface on a fine grid
    x = np.linspace(start[0] - 1, start[0] + 1, 401)
    y = np.linspace(start[1] - 1, start[1] + 1, 401)
    values = ip.surface(z, x[:, None], y[None, :])
    k = np.unravel_index(values.argmax(), values.shape)
    assert peak.converged and peak.iterations <= 4
    assert peak.row == pytest.approx(x[k[0]], abs=0.01)
    assert peak.col == pytest.approx(y[k[1]], abs=0.01)


def test_newton_is_safe_from_a_poor_start():
    z = bump(3.5, 3.5, width=0.7)
    peak = newton_peak(z, 2.0, 5.0)  # outside the peak's cap: the Hessian is indefinite there
    _, _, _, fxx, fxy, fyy = ip.surface(z, 2.0, 5.0, derivatives=2)
    assert not (fxx < 0 and fxx * fyy - fxy**2 > 0)
    assert 0 <= peak.row <= 7 and 0 <= peak.col <= 7
    assert peak.converged
    assert peak.row == pytest.approx(3.5, abs=0.05) and peak.col == pytest.approx(3.5, abs=0.05)


def test_flat_frame_does_not_move_or_crash():
    peak = newton_peak(np.zeros((8, 8)), 3.0, 3.0)
    assert peak.row == 3.0 and peak.col == 3.0 and not peak.converged


def test_two_separated_contacts_are_found_and_located(initial):
    p1 = ts.Probe(initial.row_axial_mm[2] + 0.7, 0.0, 0.5)
    p2 = ts.Probe(initial.row_axial_mm[6] - 0.4, 180.0, 0.4)
    frame = ts.tactel_deflection(initial, [p1, p2])
    found = locate_contacts(frame, periodic=True)
    assert len(found) == 2
    first, second = found
    axial, angle = ts.geometry.tactel_to_surface(
        initial, np.array([first.row, second.row]), np.array([first.col, second.col])
    )
    assert axial[0] == pytest.approx(p1.axial_mm, abs=0.6)
    assert axial[1] == pytest.approx(p2.axial_mm, abs=0.6)
    assert abs(angle[0]) < 2 and abs(abs(angle[1]) - 180) < 2
    estimates = ts.locate(frame, initial, counts=False)
    assert estimates.flags & ts.Flag.MULTIPLE
