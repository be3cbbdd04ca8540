"""Finite-element check of the bonded layer under a tangential disc traction.

A third solution, by another method: scikit-fem, quadratic quadrilaterals on the
(r, z) half-plane, for the azimuthal order-1 fields ``u_r = U cos theta``, ``u_theta =
V sin theta``, ``u_z = W cos theta`` (the theta integral of the strain energy is pi times
that of the coefficients, for every term). The unknowns are ``S = U + V``, ``D = U - V``
and W, so the axis conditions of an order-1 field (u_x, u_y single-valued: S = W = 0 on
r = 0) are Dirichlet conditions. Strains (coefficients of cos theta or sin theta)::

    e_rr = U_r, e_tt = S / r, e_zz = W_z, g_rz = U_z + W_r,
    g_rtheta = V_r - S / r, g_thetaz = V_z - W / r

The traction ``q_x = tau(r)`` (``t_r = tau cos theta``, ``t_theta = -tau sin theta``) does
the virtual work ``pi int tau (dU - dV) r dr = pi int tau dD r dr``. The layer (h = 3 mm)
is bonded at z = h, meshed on r in [0, 15 h] and clamped there (the bonded layer's
response has died out). Compared with ``analysis.layer_truth_shear`` (Hankel) and with
``physics.layer`` (FFT) at three depths and four radii.
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

from tactsense.analysis import layer_truth_shear as truth
from tactsense.physics import layer

E, H, A, F = 2.5e5, 3e-3, 1.5e-3, 0.1  # [Pa], [m], [m], [N]
DEPTHS = (0.75e-3, 1.5e-3, 2.25e-3)  # [m]
RADII = np.array([0.05, 0.45, 0.95, 1.9]) * A  # [m]
# the probes sit inside elements (depths at 3.75, 7.5, 11.25 of the 15 element rows;
# radii at 0.6, 5.4, 11.4 of the a / 12 columns and 5.4 of the a / 6 ones) so that the
# central differences, of step a quarter of the distance to an element's edge, stay
# within one quadratic element, where they are exact for a quadratic


def fem_shear(nu, nr=48, nz=15):
    """U, V, W [m] and W_z, (U_z + W_r) / 2 [-] at DEPTHS x RADII by finite elements."""
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
    ys = np.linspace(0, H, nz + 1)  # y = h - z: the base at y = 0, the surface at y = h
    mesh = MeshQuad.init_tensor(rs, ys)
    element = ElementVector(ElementQuad2(), dim=3)  # (S, D, W)
    basis = Basis(mesh, element, intorder=5)

    def strains(f, r):
        s, d, w = f[0], f[1], f[2]
        s_r, s_z = f.grad[0, 0], -f.grad[0, 1]
        d_r, d_z = f.grad[1, 0], -f.grad[1, 1]
        w_r, w_z = f.grad[2, 0], -f.grad[2, 1]
        u_r, u_z = (s_r + d_r) / 2, (s_z + d_z) / 2
        v_r, v_z = (s_r - d_r) / 2, (s_z - d_z) / 2
        e_tt = s / r
        return u_r, e_tt, w_z, u_z + w_r, v_r - e_tt, v_z - w / r, d

    @BilinearForm
    def stiffness(u, v, w):
        r = w.x[0]
        err, ett, ezz, grz, grt, gtz, _ = strains(u, r)
        vrr, vtt, vzz, vrz, vrt, vtz, _ = strains(v, r)
        tr, tv = err + ett + ezz, vrr + vtt + vzz
        return (
            lam * tr * tv
            + 2 * mu * (err * vrr + ett * vtt + ezz * vzz)
            + mu * (grz * vrz + grt * vrt + gtz * vtz)
        ) * r

    top = FacetBasis(
        mesh, element, facets=mesh.facets_satisfying(lambda x: np.isclose(x[1], H)), intorder=10
    )

    @LinearForm
    def traction(v, w):
        r = w.x[0]
        return truth.traction_profile(r, A, F, "hertz") * v[1] * r

    stiff = asm(stiffness, basis)
    load = asm(traction, top)
    fixed = np.concatenate(
        [
            basis.get_dofs(lambda x: np.isclose(x[1], 0.0)).all(),
            basis.get_dofs(lambda x: np.isclose(x[0], side)).all(),
            basis.get_dofs(lambda x: np.isclose(x[0], 0.0)).all("u^1"),
            basis.get_dofs(lambda x: np.isclose(x[0], 0.0)).all("u^3"),
        ]
    )
    u = solve(*condense(stiff, load, D=fixed))
    parts = basis.split(u)  # [(values, basis)] per component: S, D, W
    step = H / nz / 16
    out = {}
    for z in DEPTHS:
        y = H - z
        pts_r = np.concatenate([RADII, RADII, RADII, RADII + step, RADII - step])
        pts_y = np.concatenate(
            [
                np.full(4, y),
                np.full(4, y - step),
                np.full(4, y + step),
                np.full(4, y),
                np.full(4, y),
            ]
        )
        pts = np.array([pts_r, pts_y])
        s, d, w = (sub.probes(pts) @ values for values, sub in parts)
        # rows: at the point, z + step (y - step), z - step, r + step, r - step
        s, d, w = (v.reshape(5, 4) for v in (s, d, w))
        big_u, big_v = (s + d) / 2, (s - d) / 2
        u_z = (big_u[1] - big_u[2]) / (2 * step)
        w_z = (w[1] - w[2]) / (2 * step)
        w_r = (w[3] - w[4]) / (2 * step)
        out[z] = {
            "U": big_u[0],
            "V": big_v[0],
            "W": w[0],
            "eps_zz": w_z,
            "eps_rz": (u_z + w_r) / 2,
        }
    return out


def hankel_coefficients(nu, z):
    """The same five quantities from the Hankel solution, read on the axes: along theta = 0
    (y = 0) u_x = U, u_z = W, eps_zz = W_z, eps_xz = (U_z + W_r) / 2; along theta = 90 deg
    (x = 0) u_x = -V."""
    kw = dict(thickness=H, youngs_modulus=E, poisson_ratio=nu, radius=A, force=F)
    on_x = truth.bonded_layer_shear_fields(RADII, 0.0, z, **kw)
    on_y = truth.bonded_layer_shear_fields(0.0, RADII, z, **kw)
    return {
        "U": on_x["u_x"],
        "V": -on_y["u_x"],
        "W": on_x["u_z"],
        "eps_zz": on_x["eps_zz"],
        "eps_rz": on_x["eps_xz"],
    }


def worst_errors(results, nu):
    """Largest |FEM - Hankel| over depths and radii per quantity, relative to its peak."""
    worst = {}
    for z, got in results.items():
        ref = hankel_coefficients(nu, z)
        for name in got:
            err = np.max(np.abs(got[name] - ref[name])) / np.max(np.abs(ref[name]))
            worst[name] = max(worst.get(name, 0.0), float(err))
    return worst


@pytest.fixture(scope="module", params=[0.3, 0.45])
def fem(request):
    return request.param, fem_shear(request.param)


def test_fem_agrees_with_the_hankel_solution(fem):
    # the FEM (48 x 15 quadratic elements) against the exact layer: measured at most
    # 4e-4 (displacements) and 7.3e-3 (eps_zz at z = h/4, nu = 0.45) of each quantity's
    # peak over the probes; 1 % allowed
    nu, results = fem
    for name, err in worst_errors(results, nu).items():
        assert err < 0.01, (nu, name, err)


def test_fem_converges_to_the_hankel_solution():
    # halving the elements: the largest strain error falls from 7.3e-3 to 1.3e-3, the
    # displacements' from 4e-4 to 3e-5 (nu = 0.45); at least 3x asked
    coarse = worst_errors(fem_shear(0.45, 48, 15), 0.45)
    fine = worst_errors(fem_shear(0.45, 96, 31), 0.45)
    for name in coarse:
        assert fine[name] < coarse[name] / 3, (name, coarse[name], fine[name])


def test_fem_agrees_with_the_layer_model(fem):
    # layer.py by FFT on a grid of a / 20 (the load sampled as each cell's mean; the
    # probes fall on samples) against the FEM, with no reference solution in between:
    # measured at most 7.5e-4 (displacements) and 5.6e-3 (eps_zz, nu = 0.45, mostly the
    # FEM's own error above); 1 % allowed
    nu, results = fem
    dx, n = A / 20, 128
    load = truth.sampled_disc_traction(n, dx, A, F, "hertz")
    cols = np.rint(RADII / dx).astype(int)
    assert np.allclose(cols * dx, RADII, atol=1e-9 * dx)
    c = n // 2
    for z, fe in results.items():
        response = layer.LayerResponse(
            load.shape,
            dx,
            z,
            thickness=H,
            youngs_modulus=E,
            poisson_ratio=nu,
            quantities=("u_x", "u_z", "eps_zz", "eps_xz"),
            tangential=True,
        )
        out = response(np.zeros_like(load), load, None)
        pairs = (("u_x", "U"), ("u_z", "W"), ("eps_zz", "eps_zz"), ("eps_xz", "eps_rz"))
        for name, fe_name in pairs:
            got = out[name][c, c + cols]
            ref = fe[fe_name]
            err = np.max(np.abs(got - ref)) / np.max(np.abs(fe[fe_name]))
            assert err < 0.01, (nu, z, name, err)
