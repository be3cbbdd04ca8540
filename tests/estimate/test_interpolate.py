import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tactsense.estimate.finger import interpolate as ip


def test_kernel_interpolates_samples_and_vanishes_outside_window():
    n = np.arange(-4, 5)
    np.testing.assert_allclose(ip.kernel(n, 8), (n == 0).astype(float), atol=1e-15)
    assert ip.kernel(3.6, 8) == 0.0 and ip.kernel(3.4, 8) != 0.0
    # eq. 47 as printed: w(n) = (1 - cos(2 pi n / (N - 1) + pi)) / 2
    t = np.linspace(-3.5, 3.5, 15)
    printed = 0.5 * (1 - np.cos(2 * np.pi * t / 7 + np.pi))
    np.testing.assert_allclose(ip.hann_derivatives(t, 8)[0], printed, atol=1e-15)


@given(t=st.floats(-3.4, 3.4))
@settings(max_examples=60, deadline=None)
def test_kernel_derivatives_match_finite_differences(t):
    h = 1e-5
    k, dk, d2k = ip.kernel(t, 8, derivatives=2)
    assert dk == pytest.approx((ip.kernel(t + h, 8) - ip.kernel(t - h, 8)) / (2 * h), abs=1e-7)
    numeric2 = (ip.kernel(t + h, 8) - 2 * k + ip.kernel(t - h, 8)) / h**2
    assert d2k == pytest.approx(numeric2, abs=2e-4)


def test_surface_passes_through_samples_and_derivatives_are_consistent():
    rng = np.random.default_rng(0)
    z = rng.normal(size=(8, 8))
    i, j = np.meshgrid(np.arange(8), np.arange(8), indexing="ij")
    np.testing.assert_allclose(ip.surface(z, i, j), z, atol=1e-12)
    x, y, h = 3.3, 4.6, 1e-5
    _f, fx, fy, fxx, fxy, fyy = ip.surface(z, x, y, derivatives=2)
    assert fx == pytest.approx(
        (ip.surface(z, x + h, y) - ip.surface(z, x - h, y)) / (2 * h), rel=1e-6
    )
    assert fy == pytest.approx(
        (ip.surface(z, x, y + h) - ip.surface(z, x, y - h)) / (2 * h), rel=1e-6
    )
    fx_y = ip.surface(z, x, y + h, derivatives=1)[1] - ip.surface(z, x, y - h, derivatives=1)[1]
    assert fxy == pytest.approx(fx_y / (2 * h), rel=1e-5)
    fx_x = ip.surface(z, x + h, y, derivatives=1)[1] - ip.surface(z, x - h, y, derivatives=1)[1]
    assert fxx == pytest.approx(fx_x / (2 * h), rel=1e-5)
    fy_y = ip.surface(z, x, y + h, derivatives=1)[2] - ip.surface(z, x, y - h, derivatives=1)[2]
    assert fyy == pytest.approx(fy_y / (2 * h), rel=1e-5)


def test_periodic_surface_is_continuous_across_the_seam():
    rng = np.random.default_rng(1)
    z = rng.normal(size=(8, 8))
    # column 7.999 and column -0.001 are the same place on a closed ring
    a = ip.surface(z, 3.2, 7.999, periodic=True)
    b = ip.surface(z, 3.2, -0.001, periodic=True)
    assert a == pytest.approx(b, rel=1e-12)
    # and on a closed ring, column 7.5 feels column 0
    z0 = np.zeros((8, 8))
    z0[3, 0] = 1.0
    assert ip.surface(z0, 3, 7.5, periodic=True) > 0.5
    assert ip.surface(z0, 3, 7.5, periodic=False) == pytest.approx(0.0, abs=1e-12)


def test_row_reconstruction_is_the_surface_along_a_row():
    rng = np.random.default_rng(2)
    z = rng.normal(size=(8, 8))
    x = np.linspace(0, 7, 29)
    np.testing.assert_allclose(ip.reconstruct_row(z[:, 5], x), ip.surface(z, x, 5.0), atol=1e-12)
    # eq. 46 with 7 samples
    np.testing.assert_allclose(ip.reconstruct_row(z[0, :7], np.arange(7.0)), z[0, :7], atol=1e-12)
