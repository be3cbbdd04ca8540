"""Finite-element check of the strip solution (scikit-fem, quadratic quadrilaterals).

The strip of section 5 is meshed on its right half (symmetry at x = 0), bonded at
the core (u = v = 0), free of shear on top, loaded by the parabolic probe pressure,
and clamped at a side 15 h away, where the bonded layer's response has died out.
Plane stress uses the plane-stress Lame constant lambda* = E nu / (1 - nu^2) directly,
not the paper's substitution, so the substitution is checked too.
"""

import itertools

import numpy as np
import pytest
from skfem import (
    Basis,
    ElementQuad2,
    ElementVector,
    FacetBasis,
    LinearForm,
    MeshQuad,
    asm,
    condense,
    solve,
)
from skfem.models.elasticity import linear_elasticity

from tactsense.analysis import strip_capacitor_design
from tactsense.physics import strip

E = 2.5e5
LOAD, WIDTH = 200.0, 3e-3


def fem_centre_deflection(h, nu, model, nx=30, ny=12, plates=(3.3e-3, 3.8e-3)):
    """Deflection toward the core along x = 0: depths z and w(0, z) [m].

    The mesh has nodes at the plate depths ``plates`` (where they lie inside).
    """
    mu = E / (2 * (1 + nu))
    lam = E * nu / (1 - nu * nu) if model == "plane_stress" else 2 * mu * nu / (1 - 2 * nu)
    a = WIDTH / 2
    side = 15 * h
    xs = np.concatenate(
        [
            np.linspace(0, a, nx // 3 + 1),
            a + (2 * h - a) * np.linspace(0, 1, nx // 2 + 1)[1:],
            2 * h + (side - 2 * h) * np.linspace(0, 1, nx // 2 + 1)[1:] ** 2,
        ]
    )
    breaks = np.unique([0.0, h, *(h - d for d in plates if 0 < d < h)])
    ys = np.unique(
        np.concatenate(
            [
                np.linspace(lo, hi, max(2, round(ny * (hi - lo) / h) + 1))
                for lo, hi in itertools.pairwise(breaks)
            ]
        )
    )
    mesh = MeshQuad.init_tensor(xs, ys)  # y = h - z
    element = ElementVector(ElementQuad2())
    basis = Basis(mesh, element, intorder=4)
    stiffness = asm(linear_elasticity(lam, mu), basis)
    top = FacetBasis(
        mesh, element, facets=mesh.facets_satisfying(lambda x: np.isclose(x[1], h)), intorder=6
    )
    peak = 1.5 * LOAD / WIDTH

    @LinearForm
    def pressure(v, w):
        x = w.x[0]
        return -np.where(x < a, peak * (1 - (x / a) ** 2), 0.0) * v[1]

    load = asm(pressure, top)
    fixed = np.concatenate(
        [
            basis.get_dofs(lambda x: np.isclose(x[1], 0.0)).all(),
            basis.get_dofs(lambda x: np.isclose(x[0], side)).all(),
            basis.get_dofs(lambda x: np.isclose(x[0], 0.0)).all("u^1"),
        ]
    )
    u = solve(*condense(stiffness, load, D=fixed))
    x_loc, y_loc = basis.doflocs
    vertical = np.arange(u.size) % 2 == 1
    on_axis = np.flatnonzero(np.isclose(x_loc, 0) & vertical)
    order = np.argsort(-y_loc[on_axis])
    return h - y_loc[on_axis][order], -u[on_axis][order]


@pytest.mark.parametrize(
    ("model", "nu"), [("plane_strain", 0.4), ("plane_stress", 0.5), ("plane_stress", 0.3)]
)
def test_fem_agrees_with_analytic_deflection(model, nu):
    H = 3.8e-3
    z, w_fem = fem_centre_deflection(H, nu, model)
    inside = z < H - 1e-9
    w_ana = strip.displacement(
        0.0, z[inside], H, LOAD, WIDTH, youngs_modulus=E, poisson_ratio=nu, model=model
    )
    # measured at most 1.7e-4 (plane strain, nu = 0.4), 8e-5 and 4e-5 (plane stress)
    np.testing.assert_allclose(w_fem[inside], w_ana, rtol=3e-4)
    # and the gain of the paper's capacitor (top plate at 3.3 mm, bottom on the core)
    top = np.argmin(np.abs(z - 3.3e-3))
    assert z[top] == pytest.approx(3.3e-3, abs=1e-9)
    fem_gain = w_fem[top] / (H - z[top])
    ana_gain = strip_capacitor_design(
        H, 0.5e-3, LOAD, WIDTH, youngs_modulus=E, poisson_ratio=nu, model=model
    )["gain"]
    assert fem_gain == pytest.approx(ana_gain, rel=1e-4)  # measured at most 4e-5


def test_fem_agrees_with_soft_backing():
    # Fig. 17's second case: bottom plate at 3.8 mm, 1.9 mm of rubber beneath it
    h = 5.7e-3
    z, w_fem = fem_centre_deflection(h, 0.5, "plane_stress", nx=30, ny=18)
    top, bottom = (np.argmin(np.abs(z - d)) for d in (3.3e-3, 3.8e-3))
    fem_gain = (w_fem[top] - w_fem[bottom]) / 0.5e-3
    ana = strip_capacitor_design(3.8e-3, 0.5e-3, LOAD, WIDTH, backing=1.9e-3)["gain"]
    assert fem_gain == pytest.approx(ana, rel=1e-4)  # measured 7e-6


@pytest.mark.slow
def test_fem_fine_mesh_converges_to_analytic():
    z, w_fem = fem_centre_deflection(3.8e-3, 0.45, "plane_strain", nx=240, ny=96)
    inside = z < 3.8e-3 - 1e-9
    w_ana = strip.displacement(
        0.0,
        z[inside],
        3.8e-3,
        LOAD,
        WIDTH,
        youngs_modulus=E,
        poisson_ratio=0.45,
        model="plane_strain",
    )
    np.testing.assert_allclose(w_fem[inside], w_ana, rtol=5e-4)
