"""Finite-element check of the bonded layer (scikit-fem, axisymmetric, quadratic quads).

The finite-element solution lives in the truth module that tests and studies share
(:func:`tactsense.analysis.layer_truth.fem_disc`: a disc of radius a under a uniform
pressure on a layer bonded to a rigid base). It is compared with the simulator's
transfer functions integrated exactly (Hankel transform of the disc load,
``test_layer.hankel_disc``) and with the truth module's own Hankel evaluation of Love's
strain function (:func:`~tactsense.analysis.layer_truth.disc_field`): three
evaluations that share no code.
"""

import numpy as np
import pytest

from tactsense.analysis.layer_truth import disc_field
from tactsense.analysis.layer_truth import fem_disc as _fem
from tests.physics.test_layer import E, hankel_disc

H, A, P = 3e-3, 1.5e-3, 1e3
RADII = np.array([1e-9, 0.5 * A, A * 0.999, 2 * A])  # just inside the disc edge


def fem_disc(nu, nr=40, nz=16, depths=(0.75e-3, 1.5e-3, 2.25e-3)):
    out = _fem(H, A, P, E, nu, depths, RADII, nr=nr, nz=nz)
    return {z: (RADII, w, eps) for z, (w, eps) in out.items()}


@pytest.mark.parametrize("nu", [0.3, 0.45])
def test_fem_agrees_with_layer_transfer_functions(nu):
    results = fem_disc(nu)
    for z, (radii, w_fem, e_fem) in results.items():
        for r, w, e in zip(radii, w_fem, e_fem, strict=False):
            w_ref = hankel_disc(r, z, H, nu, A, P, "W_P")
            e_ref = hankel_disc(r, z, H, nu, A, P, "dW_P")
            assert w == pytest.approx(w_ref, rel=0.01, abs=0.002 * P * A / E), (z, r)
            assert e == pytest.approx(e_ref, rel=0.01, abs=0.005 * P / E), (z, r)


@pytest.mark.parametrize("nu", [0.3, 0.45])
def test_fem_agrees_with_the_truth_modules_love_solution(nu):
    # same tolerance as against the transfer functions: the FE mesh's discretization
    # error (1 %), not the Hankel rule's (1e-7, test_layer.test_hankel_rule_matches_quad)
    for z, (radii, w_fem, e_fem) in fem_disc(nu).items():
        for r, w, e in zip(radii, w_fem, e_fem, strict=False):
            w_ref, e_ref = disc_field(r, z, H, nu, A, P, E)
            assert w == pytest.approx(w_ref, rel=0.01, abs=0.002 * P * A / E), (z, r)
            assert e == pytest.approx(e_ref, rel=0.01, abs=0.005 * P / E), (z, r)


@pytest.mark.slow
def test_fem_fine_mesh_converges():
    for z, (radii, w_fem, e_fem) in fem_disc(0.45, nr=120, nz=48).items():
        for r, w, e in zip(radii, w_fem, e_fem, strict=False):
            w_ref = hankel_disc(r, z, H, 0.45, A, P, "W_P")
            e_ref = hankel_disc(r, z, H, 0.45, A, P, "dW_P")
            assert w == pytest.approx(w_ref, rel=2e-3, abs=5e-4 * P * A / E), (z, r)
            assert e == pytest.approx(e_ref, rel=2e-3, abs=1e-3 * P / E), (z, r)
