"""Checks of the 3-D finite-element finger (tactsense.physics.finger3d)."""

import numpy as np
import pytest

from tactsense.physics import finger3d as f

SMALL = f.MeshSpec(2, 6, 6, 6e-3)


@pytest.mark.parametrize("nu", [0.45, 0.49])
def test_lame_thick_cylinder_on_rigid_core(nu):
    """Uniform external pressure, plane strain: FEM eps_rr within 1 % of Lame's solution.

    The closed form (derived in ``lame_radial_strain``) is independent of the FEM;
    1 % allows for the quadratic geometry of a coarse mesh (0.3 % measured).
    """
    pressure = 1.0e3
    area = 4 * np.pi * f.OUTER_M * SMALL.length_m  # whole (unfolded) outer surface
    sol = f.solve_load(
        lambda x, s: 1.0 + 0 * x, pressure * area, spec=SMALL, poisson_ratio=nu, far_end="sliding"
    )
    depths = np.array([0.5e-3, 1.0e-3, 3.2e-3])
    got = sol.radial_strain([0.0, 5e-3, 10e-3], [0.0, 1.0, 3.0], depth=depths)
    want = f.lame_radial_strain(f.OUTER_M - depths, pressure, nu)
    np.testing.assert_allclose(got, want, rtol=1e-2)


def _probe_profile(spec, xs):
    pressure, _ = f.hertz_probe()
    sol = f.solve_load(pressure, 0.05 * 9.80665, spec=spec)
    return sol.radial_strain(xs, 0 * xs)


XS = np.array([0.0, 1e-3, 2e-3, 3e-3, 5e-3, 12e-3])


@pytest.fixture(scope="module")
def coarse_profiles():
    return [_probe_profile(spec, XS) for spec in f.LEVELS[:2]]


def test_probe_strain_is_compressive_and_local(coarse_profiles):
    """Under the 50 g probe eps_rr < 0; 12 mm away it is below 5 % of the peak."""
    for profile in coarse_profiles:
        assert profile[0] < 0
        assert abs(profile[-1]) < 0.05 * abs(profile[0])


def test_mesh_study_shape_converges(coarse_profiles):
    """The peak-normalised profile of levels 0 and 1 agrees within 4 % of the peak.

    (The amplitude converges more slowly, see the slow test.)
    """
    a, b = (p / abs(p[0]) for p in coarse_profiles)
    assert np.max(np.abs(a - b)) < 0.04


@pytest.mark.slow
def test_mesh_study_amplitude_converges(coarse_profiles):
    """Level 2: the peak's change shrinks (ratio < 0.7) and the shape agrees within 1 %."""
    fine = _probe_profile(f.LEVELS[2], XS)
    p0, p1 = (p[0] for p in coarse_profiles)
    assert abs(fine[0] - p1) < 0.7 * abs(p1 - p0)
    assert abs(fine[0] - p1) < 0.1 * abs(fine[0])
    assert np.max(np.abs(fine / abs(fine[0]) - coarse_profiles[1] / abs(p1))) < 0.01


def test_far_cut_does_not_matter(coarse_profiles):
    """Moving the clamped cut from 25 to 35 mm changes the probe profile < 1 % of peak.

    Same element sizes near the load (fine zone and its element count unchanged).
    """
    spec = f.LEVELS[0]
    longer = f.MeshSpec(spec.n_r, spec.n_fine, spec.n_coarse + 2, spec.fine_m, 35e-3)
    far = _probe_profile(longer, XS)
    near = coarse_profiles[0]
    assert np.max(np.abs(far - near)) < 0.01 * abs(near[0])
