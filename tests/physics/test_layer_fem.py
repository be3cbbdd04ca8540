"""Finite-element check of the bonded layer (scikit-fem, axisymmetric, quadratic quads).

A disc of radius a under a uniform pressure p on a layer of thickness h bonded to a
rigid base (u_r = u_z = 0 at z = h), free elsewhere on top, meshed on r in [0, 15 h]
(clamped there: the bonded layer's response has died out), with u_r = 0 on the axis.
The weak form is the axisymmetric one (strains u_r,r, u_r / r, u_z,z, u_r,z + u_z,r,
weight r). The FEM displacement and strain are compared with the transfer functions
integrated exactly (Hankel transform of the disc load), ``test_layer.hankel_disc``.
"""

import numpy as np
import pytest
from skfem import (
    Basis,
    BilinearForm,
    ElementQuad2,
    ElementVector,
    FacetBasis,
    LinearForm,
    MeshQuad,
    asm,
    condense,
    solve,
)

from tests.physics.test_layer import E, hankel_disc

H, A, P = 3e-3, 1.5e-3, 1e3


def fem_disc(nu, nr=40, nz=16, depths=(0.75e-3, 1.5e-3, 2.25e-3)):
    mu = E / (2 * (1 + nu))
    lam = 2 * mu * nu / (1 - 2 * nu)
    side = 15 * H
    rs = np.unique(
        np.concatenate(
            [
                np.linspace(0, A, nr // 4 + 1),
                np.linspace(A, 3 * A, nr // 4 + 1),
                3 * A + (side - 3 * A) * np.linspace(0, 1, nr // 2 + 1) ** 2,
            ]
        )
    )
    ys = np.linspace(0, H, nz + 1)  # y = h - z
    mesh = MeshQuad.init_tensor(rs, ys)
    element = ElementVector(ElementQuad2())
    basis = Basis(mesh, element, intorder=5)

    @BilinearForm
    def stiffness(u, v, w):
        r = w.x[0]

        def strains(f):
            return f.grad[0, 0], f[0] / r, f.grad[1, 1], f.grad[0, 1] + f.grad[1, 0]

        err, ett, ezz, erz = strains(u)
        vrr, vtt, vzz, vrz = strains(v)
        tr = err + ett + ezz
        return (
            (2 * mu * err + lam * tr) * vrr
            + (2 * mu * ett + lam * tr) * vtt
            + (2 * mu * ezz + lam * tr) * vzz
            + mu * erz * vrz
        ) * r

    top = FacetBasis(
        mesh, element, facets=mesh.facets_satisfying(lambda x: np.isclose(x[1], H)), intorder=8
    )

    @LinearForm
    def pressure(v, w):
        r = w.x[0]
        return -np.where(r < A, P, 0.0) * v[1] * r

    K = asm(stiffness, basis)
    f = asm(pressure, top)
    fixed = np.concatenate(
        [
            basis.get_dofs(lambda x: np.isclose(x[1], 0.0)).all(),
            basis.get_dofs(lambda x: np.isclose(x[0], side)).all(),
            basis.get_dofs(lambda x: np.isclose(x[0], 0.0)).all("u^1"),
        ]
    )
    u = solve(*condense(K, f, D=fixed))
    radii = np.array([1e-9, 0.5 * A, A * 0.999, 2 * A])  # just inside the disc edge
    (_, _), (uy, vertical) = basis.split(u)  # [(values, basis)] per component
    results = {}
    step = H / nz / 4  # central differences inside one quadratic element are exact
    for z in depths:
        y = H - z
        ys_ = np.concatenate([np.full(4, y), np.full(4, y + step), np.full(4, y - step)])
        pts = np.array([np.tile(radii, 3), ys_])
        vals = vertical.probes(pts) @ uy
        w = -vals[:4]
        eps = (vals[4:8] - vals[8:12]) / (2 * step)  # d(-u_y)/dz = d u_y / dy
        results[z] = (radii, w, eps)
    return results


@pytest.mark.parametrize("nu", [0.3, 0.45])
def test_fem_agrees_with_layer_transfer_functions(nu):
    results = fem_disc(nu)
    for z, (radii, w_fem, e_fem) in results.items():
        for r, w, e in zip(radii, w_fem, e_fem, strict=False):
            w_ref = hankel_disc(r, z, H, nu, A, P, "W_P")
            e_ref = hankel_disc(r, z, H, nu, A, P, "dW_P")
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
