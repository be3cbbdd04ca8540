import numpy as np
import pytest
from scipy import integrate

from tactsense.analysis import aliasing as al


@pytest.mark.parametrize(
    ("depth", "spacing", "nu"),
    [(3.8, 3.8, 0.5), (3.8, 3.3, 0.4), (7.6, 3.8, 0.5), (2.0, 5.0, 0.25)],
)
def test_eq45_closed_form_matches_quadrature(depth, spacing, nu):
    g2 = lambda s: al.normalized_response(s, depth, nu) ** 2  # noqa: E731
    total = integrate.quad(g2, 0, np.inf)[0]
    inside = integrate.quad(g2, 0, 1 / (2 * spacing))[0]
    assert al.reconstruction_error(depth, spacing, nu) == pytest.approx(
        1 - inside / total, rel=1e-9
    )


def test_eq45_for_the_paper_design():
    # the paper: "xi ~ 0.20" for 3.8 mm depth and spacing; eq. 45 gives 0.032; its square
    # root, the RMS amplitude error, is 0.18
    xi = float(al.reconstruction_error(3.8, 3.8, 0.5))
    assert xi == pytest.approx(0.0317, abs=2e-4)
    assert np.sqrt(xi) == pytest.approx(0.178, abs=2e-3)
    # depth twice the spacing (Fearing and Hollerbach's rule) leaves almost nothing
    assert al.reconstruction_error(7.6, 3.8, 0.5) < 1e-3


def test_aliased_spectrum_is_eq44():
    s = np.linspace(-0.1, 0.1, 11)
    want = al.normalized_response(s + 1 / 3.8, 3.8, 0.5) + al.normalized_response(
        s - 1 / 3.8, 3.8, 0.5
    )
    np.testing.assert_allclose(al.aliased_spectrum(s, 3.8, 3.8, 0.5), want)
    assert al.normalized_response(0.0, 3.8, 0.5) == pytest.approx(1.0)


def test_fig20_errors_vanish_on_the_sensors_and_are_odd():
    positions = np.array([-0.5, -0.25, 0.0, 0.25, 0.5])
    pos_err, amp_err = al.interpolation_errors(positions, 3.8, 3.8, 0.5)
    assert pos_err[2] == pytest.approx(0.0, abs=1e-3) and amp_err[2] == pytest.approx(0, abs=1e-4)
    assert pos_err[1] == pytest.approx(-pos_err[3], abs=1e-3)
    # sampling at the depth loses up to a third of a line load's peak between sensors
    assert 0.2 < np.abs(amp_err).max() < 0.4
