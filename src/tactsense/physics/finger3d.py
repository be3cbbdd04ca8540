"""Three-dimensional finite-element model of the finger skin (scikit-fem).

The rubber skin is a thick cylindrical shell, outer radius ``b`` = 12.7 mm, bonded
to the rigid Delrin core of radius ``a`` = 8.85 mm (section 2.3 of the paper): the
displacement is zero on ``r = a``. Only the cylindrical part is modelled (no
hemispherical tip); it is cut ``length`` from the load, where the cut face is
clamped (the bonded layer's response has died out a few depths from the load).

The load sits on top of the finger at ``x = 0, theta = 0`` and is symmetric about
the planes ``x = 0`` and ``y = 0``, so one quarter is meshed: ``x`` in
``[0, length]``, ``theta`` in ``[0, pi]``, ``r`` in ``[a, b]``, with ``u_x = 0`` on
``x = 0`` and ``u_y = 0`` on ``y = 0``. Cartesian coordinates: ``x`` along the
finger, ``(y, z) = r (sin theta, cos theta)``.

The mesh is a structured tensor-product hexahedral mesh in ``(r, theta, x)``
(``MeshHex.init_tensor``) mapped onto the shell, graded toward the load, with
triquadratic elements (``ElementHex2``). Rubber is nearly incompressible
(nu = 0.5 in the paper); a pure displacement formulation locks as nu -> 0.5, so the
model solves for displacement and pressure together by default (Taylor-Hood, the forms
in :mod:`tactsense.physics.finger3d_forms`), with nu = 0.49 (``scripts/
finger3d_convergence.py`` gives the peak against nu from 0.45 to 0.5).

Strain is the radial (normal) strain ``eps_rr = du_r/dr`` [-] (compressive
negative), at the ring depth 3.2 mm under the outer surface by default.

Forward model only: estimation code must never import this module.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
from scipy import sparse
from scipy.sparse.linalg import splu
from skfem import (
    Basis,
    ElementHex1,
    ElementHex2,
    FacetBasis,
    LinearForm,
    MeshHex,
    MeshHex2,
    asm,
)
from skfem.models.elasticity import lame_parameters

from tactsense._validation import check_choice
from tactsense.physics.finger3d_forms import (
    LAYER_PRESSURE_NU as LAYER_PRESSURE_NU,
)
from tactsense.physics.finger3d_forms import (
    YOUNGS_PA,
    _stiffness,
    _stiffness_layered,
    mixed_layered,
)
from tactsense.physics.finger3d_forms import (
    mixed_system as mixed_system,
)

OUTER_M = 12.7e-3
CORE_M = 8.85e-3
RING_DEPTH_M = 3.2e-3


@dataclass(frozen=True)
class MeshSpec:
    """Structured mesh of the quarter shell.

    Attributes
    ----------
    n_r : int
        Elements through the thickness.
    n_fine : int
        Elements on the fine zone in theta and in x (each).
    n_coarse : int
        Graded elements from the fine zone to theta = pi and to ``length``.
    fine_m : float
        Half-size of the fine zone along the surface [m].
    length_m : float
        Distance from the load to the clamped cut [m].
    dielectric_m : float
        Thickness of a layer on the core meshed apart (``n_dielectric`` elements through
        it), so that a dielectric of its own material can fill it (:class:`Dielectric`)
        [m]; 0: none.
    """

    n_r: int = 2
    n_fine: int = 6
    n_coarse: int = 6
    fine_m: float = 6e-3
    length_m: float = 25e-3
    dielectric_m: float = 0.0
    n_dielectric: int = 1
    """Elements through the dielectric layer (when ``dielectric_m`` > 0)."""
    radial_growth: float = 1.0
    """Ratio of each element's thickness to the one below it, from the core out (1:
    uniform; above 1 the elements thin toward the core, where the strain's gradient
    through the nearly incompressible skin is steepest: ``docs/model.md`` section 3a)."""


def radial_nodes(start_m: float, n: int, growth: float) -> np.ndarray:
    """``n + 1`` radii [m] from ``start_m`` to the outer surface, each element
    ``growth`` times as thick as the one below it."""
    if growth == 1.0:
        return np.linspace(start_m, OUTER_M, n + 1)
    steps = growth ** np.arange(n)
    return start_m + (OUTER_M - start_m) * np.concatenate([[0.0], np.cumsum(steps)]) / steps.sum()


@dataclass(frozen=True)
class Dielectric:
    """The soft dielectric layer between the core's strips and the rings (section 2.3).

    The paper: "a compliant dielectric of about 0.5 mm thickness, which is a molded
    open-cell rubber layer"; section 4.1 postulates that it, "softer than the skin above
    it", widens the measured response. Its modulus and Poisson's ratio are not given.
    """

    thickness_m: float = 0.5e-3
    youngs_pa: float = 7.0e4
    poisson_ratio: float = 0.3


LEVELS = (MeshSpec(3, 6, 6, 4e-3), MeshSpec(4, 9, 7, 4e-3), MeshSpec(5, 12, 8, 4e-3))
"""The mesh study's levels of the displacement-only model (``docs/model.md`` section 3a)."""
TABLE_MESH = MeshSpec(6, 9, 7, 4e-3)
"""The mesh of the shipped tables (``scripts/finger3d_table.py``, mixed elements): six
elements through the skin, where the amplitude's error lies (``scripts/
finger3d_convergence.py``)."""


def _graded(fine, end, n_fine, n_coarse):
    """Uniform nodes on [0, fine], then geometrically growing ones to ``end``."""
    head = np.linspace(0.0, fine, n_fine + 1)
    h0 = fine / n_fine
    # growth ratio q so that the n_coarse steps h0 q, h0 q^2, ... sum to end - fine
    span = end - fine
    lo, hi = 1.0 + 1e-9, 10.0
    for _ in range(200):
        q = 0.5 * (lo + hi)
        total = h0 * q * (q**n_coarse - 1) / (q - 1)
        lo, hi = (q, hi) if total < span else (lo, q)
    steps = h0 * q ** np.arange(1, n_coarse + 1)
    tail = fine + np.cumsum(steps * span / steps.sum())
    return np.concatenate([head, tail])


@dataclass
class ShellMesh:
    """The mapped quadratic mesh and its boundary facets (indices shared with the box)."""

    mesh: MeshHex2
    core: np.ndarray
    outer: np.ndarray
    sym_x: np.ndarray
    sym_y: np.ndarray
    end: np.ndarray
    nodes: tuple
    cell_of: np.ndarray
    dielectric_m: float = 0.0
    """Thickness of the layer meshed apart on the core [m] (0: none)."""

    def find_cells(self, x, theta, r):
        """Cell containing box coordinates (x, theta, r): exact on the structured box."""
        idx = [
            np.clip(np.searchsorted(n, q, side="right") - 1, 0, len(n) - 2)
            for n, q in zip(self.nodes, (x, theta, r), strict=True)
        ]
        return self.cell_of[idx[0], idx[1], idx[2]]


def build_mesh(spec: MeshSpec = LEVELS[0]) -> ShellMesh:
    """Quarter shell mesh mapped from a tensor-product box in (x, theta, r).

    The box is meshed with ``MeshHex.init_tensor``, promoted to triquadratic
    geometry (``MeshHex2``) and its nodes mapped to ``(x, r sin theta, r cos theta)``,
    so the curved faces are quadratic, not faceted. Boundary facets are found on the
    box, where they are planes.
    """
    if spec.dielectric_m > 0:
        top = CORE_M + spec.dielectric_m
        layer = np.linspace(CORE_M, top, spec.n_dielectric + 1)[:-1]
        r = np.concatenate([layer, radial_nodes(top, spec.n_r, spec.radial_growth)])
    else:
        r = radial_nodes(CORE_M, spec.n_r, spec.radial_growth)
    theta = _graded(spec.fine_m / OUTER_M, np.pi, spec.n_fine, spec.n_coarse)
    x = _graded(spec.fine_m, spec.length_m, spec.n_fine, spec.n_coarse)
    box = MeshHex.init_tensor(x, theta, r)
    box2 = MeshHex2.from_mesh(box)
    xx, th, rr = box2.doflocs
    mesh = replace(box2, doflocs=np.vstack([xx, rr * np.sin(th), rr * np.cos(th)]))

    def facets(axis, value):
        return box.facets_satisfying(lambda q: np.isclose(q[axis], value, rtol=0, atol=1e-9))

    centres = box.p[:, box.t].mean(axis=1)
    cell_of = np.empty((len(x) - 1, len(theta) - 1, len(r) - 1), dtype=np.int64)
    keys = [np.searchsorted(n, c) - 1 for n, c in zip((x, theta, r), centres, strict=True)]
    cell_of[keys[0], keys[1], keys[2]] = np.arange(box.t.shape[1])
    return ShellMesh(
        mesh,
        nodes=(x, theta, r),
        cell_of=cell_of,
        core=facets(2, CORE_M),
        outer=facets(2, OUTER_M),
        sym_x=facets(0, 0.0),
        sym_y=np.concatenate([facets(1, 0.0), facets(1, np.pi)]),
        end=facets(0, spec.length_m),
        dielectric_m=spec.dielectric_m,
    )


def _polar(x):
    """theta [rad] and radius [m] of points with Cartesian coordinates x (3, ...)."""
    return np.arctan2(x[1], x[2]), np.hypot(x[1], x[2])


def hertz_probe(force_n=0.05 * 9.80665, radius_m=1.6e-3, poisson_ratio=0.49):
    """Hertz pressure of a rigid sphere on the skin, as a function of (x, s).

    The contact radius ``a = (3 F R / (4 E*))^(1/3)`` with ``E* = E / (1 - nu^2)``
    (flat skin, as in the twin's :class:`~tactsense.physics.indenters` probe).

    Returns
    -------
    callable
        ``p(x, s)`` [Pa] (unnormalised: the load is scaled to ``force_n``), where
        ``s`` is the arc length from the load around the outer surface [m].
    float
        Contact radius [m].
    """
    e_star = YOUNGS_PA / (1 - poisson_ratio**2)
    a = (3 * force_n * radius_m / (4 * e_star)) ** (1 / 3)

    def p(x, s):
        return np.sqrt(np.clip(1 - (x * x + s * s) / (a * a), 0.0, None))

    return p, a


def knife_edge(half_width_m=0.25e-3, half_arc_m=4e-3, across=True):
    """Knife-edge pressure: parabolic over ``half_width_m``, uniform over ``half_arc_m``.

    ``across=True``: the edge lies around the circumference (narrow in x), the
    paper's section 4.1 set-up, moved along the finger. ``across=False``: the edge
    lies along the finger (narrow in the arc length s).
    """

    def p(x, s):
        narrow, wide = (x, s) if across else (s, x)
        return np.clip(1 - (narrow / half_width_m) ** 2, 0.0, None) * (np.abs(wide) <= half_arc_m)

    return p


@dataclass
class Solution:
    """A solved load case: the scalar basis and the displacement, shape (3, N) [m]."""

    basis: Basis
    u: np.ndarray
    shell: ShellMesh
    has_dielectric: bool = False

    def _probes(self, x, theta, r):
        """Interpolation matrix at points given by (x, theta, r), cells from the box."""
        cells = self.shell.find_cells(x, theta, r)
        pts = np.vstack([x, r * np.sin(theta), r * np.cos(theta)])
        ref = self.basis.mapping.invF(pts[:, :, np.newaxis], tind=cells)
        nb = self.basis.Nbfun
        phis = np.array(
            [self.basis.elem.gbasis(self.basis.mapping, ref, k, tind=cells)[0] for k in range(nb)]
        ).flatten()
        rows = np.tile(np.arange(pts.shape[1]), nb)
        cols = self.basis.element_dofs[:, cells].flatten()
        return sparse.coo_matrix((phis, (rows, cols)), shape=(pts.shape[1], self.basis.N)).tocsr()

    def radial_displacement(self, x, theta, r):
        """u_r [m] at axial ``x`` [m], angle ``theta`` [rad] and radius ``r`` [m]."""
        x, theta, r = np.broadcast_arrays(*(np.asarray(q, float) for q in (x, theta, r)))
        probe = self._probes(x.ravel(), theta.ravel(), r.ravel())
        sin, cos = np.sin(theta.ravel()), np.cos(theta.ravel())
        return ((probe @ self.u[1]) * sin + (probe @ self.u[2]) * cos).reshape(x.shape)

    def dielectric_strain(self, x, theta):
        """Mean radial strain of the dielectric layer [-] (compression negative): its
        top's radial displacement over its thickness (the bottom is bonded to the core),
        the capacitor's fractional deflection ``dd / d_o`` with a minus sign."""
        thickness = self.shell.dielectric_m
        if thickness <= 0 or not self.has_dielectric:
            raise ValueError("this solution has no dielectric layer")
        top = CORE_M + thickness
        return self.radial_displacement(x, theta, np.full(np.shape(x), top)) / thickness

    def radial_strain(self, x, theta, depth=RING_DEPTH_M, step=1e-6):
        """eps_rr at axial position ``x`` [m], angle ``theta`` [rad], ``depth`` [m].

        Central difference of the radial displacement over ``2 step`` [m]; inside
        an element this is the derivative of the quadratic interpolant.
        """
        x, theta, depth = np.broadcast_arrays(
            np.asarray(x, float), np.asarray(theta, float), np.asarray(depth, float)
        )
        r = OUTER_M - depth.ravel()
        sin, cos = np.sin(theta.ravel()), np.cos(theta.ravel())
        radial = []
        for rr in (r + step, r - step):
            probe = self._probes(x.ravel(), theta.ravel(), rr)
            radial.append((probe @ self.u[1]) * sin + (probe @ self.u[2]) * cos)
        return ((radial[0] - radial[1]) / (2 * step)).reshape(x.shape)


def _fixed_dofs(basis, shell: ShellMesh, far_end):
    n = basis.N
    core = basis.get_dofs(facets=shell.core).all()
    end = basis.get_dofs(facets=shell.end).all()
    fixed = [
        core,
        core + n,
        core + 2 * n,
        basis.get_dofs(facets=shell.sym_x).all(),
        basis.get_dofs(facets=shell.sym_y).all() + n,
        end,
    ]
    if far_end == "clamped":
        fixed += [end + n, end + 2 * n]
    return np.unique(np.concatenate(fixed))


def solve_load(
    pressure,
    force_n,
    *,
    spec: MeshSpec = LEVELS[0],
    poisson_ratio=0.49,
    far_end="clamped",
    dielectric: Dielectric | None = None,
    formulation: str = "mixed",
):
    """Solve the quarter shell under a surface pressure shape scaled to ``force_n`` [N].

    Parameters
    ----------
    pressure : callable
        ``p(x, s)``: pressure shape on the outer surface (compressive positive),
        ``s = b theta`` the arc length [m]. It is scaled so that the pressure on the
        whole finger sums to ``force_n`` [N] (the quarter model carries a quarter),
        so only its shape matters.
    force_n : float
        Total pressure integral over the whole (unfolded) finger [N].
    spec : MeshSpec
    poisson_ratio : float
        nu [-].
    far_end : {"clamped", "sliding"}
        The cut at ``x = length``: clamped, or free to slide in its plane
        (``u_x = 0``: with a uniform pressure, plane strain, Lame's problem).
    dielectric : Dielectric, optional
        A soft layer of its own material on the core, under the rubber (meshed as one
        element through its thickness); :meth:`Solution.dielectric_strain` then reads
        its mean radial strain, the capacitor's ``dd / d_o``.
    formulation : {"mixed", "displacement"}
        ``"mixed"``: triquadratic displacement and trilinear pressure in the rubber
        (Taylor-Hood, :func:`mixed_system`), free of volumetric locking, so nu may be
        0.5; ``"displacement"``: triquadratic displacement only, which locks as nu ->
        0.5 (the model before issue 34: its amplitude converged at order ~0.8 and level
        1 read about a quarter low, ``docs/model.md`` section 3a).

    Returns
    -------
    Solution
    """
    (solution,) = solve_loads(
        [(pressure, force_n)],
        spec=spec,
        poisson_ratio=poisson_ratio,
        far_end=far_end,
        dielectric=dielectric,
        formulation=formulation,
    )
    return solution


def solve_loads(
    loads,
    *,
    spec: MeshSpec = LEVELS[0],
    poisson_ratio=0.49,
    far_end="clamped",
    dielectric: Dielectric | None = None,
    formulation: str = "mixed",
) -> list[Solution]:
    """:func:`solve_load` for several loads ``[(pressure, force_n), ...]`` on one mesh:
    assembled and factorised once (the same numbers as one call per load)."""
    check_choice(far_end, "far_end", ("clamped", "sliding"))
    check_choice(formulation, "formulation", ("mixed", "displacement"))
    if dielectric is not None:
        spec = replace(spec, dielectric_m=dielectric.thickness_m)
    shell = build_mesh(spec)
    basis = Basis(shell.mesh, ElementHex2(), intorder=4)
    if formulation == "mixed":
        stiffness, n_pressure = _mixed_stiffness(basis, shell, poisson_ratio, dielectric)
    elif dielectric is None:
        stiffness = _stiffness(basis, *lame_parameters(YOUNGS_PA, poisson_ratio))
        n_pressure = 0
    else:
        soft = lame_parameters(dielectric.youngs_pa, dielectric.poisson_ratio)
        # quadrature points lie inside elements: below the interface only in the layer
        top = CORE_M + dielectric.thickness_m
        rubber = lame_parameters(YOUNGS_PA, poisson_ratio)
        stiffness = _stiffness_layered(basis, rubber, soft, top)
        n_pressure = 0
    top = FacetBasis(shell.mesh, ElementHex2(), facets=shell.outer, intorder=6)

    fixed = _fixed_dofs(basis, shell, far_end)
    free = np.setdiff1d(np.arange(3 * basis.N + n_pressure), fixed)
    lu = splu(stiffness[free][:, free].tocsc())
    solutions = []
    for pressure, force_n in loads:
        f = np.concatenate([_load_vector(top, pressure, force_n), np.zeros(n_pressure)])
        u = np.zeros(3 * basis.N + n_pressure)
        u[free] = lu.solve(f[free])
        solutions.append(
            Solution(basis, u[: 3 * basis.N].reshape(3, -1), shell, dielectric is not None)
        )
    return solutions


def _load_vector(top: FacetBasis, pressure, force_n) -> np.ndarray:
    """The outer surface's load vector (component-major) of the pressure shape
    ``pressure(x, s)`` scaled to ``force_n`` [N] on the whole finger."""

    def shape(w):
        theta, _ = _polar(w.x)
        return pressure(w.x[0], OUTER_M * theta)

    scale = 0.25 * force_n / asm(LinearForm(lambda v, w: shape(w) * v), top).sum()
    return np.concatenate(
        [asm(LinearForm(lambda v, w, c=c: -scale * shape(w) * w.n[c] * v), top) for c in range(3)]
    )


def _mixed_stiffness(basis, shell: ShellMesh, poisson_ratio, dielectric):
    """The u-p matrix (:func:`mixed_system`) of the rubber, on the dielectric if any,
    restricted to the pressure dofs that carry anything: (matrix, their count)."""
    pressure_basis = Basis(shell.mesh, ElementHex1(), intorder=4)
    if dielectric is None:
        return mixed_layered(basis, pressure_basis, poisson_ratio)
    top = CORE_M + dielectric.thickness_m

    def rubber(x):  # quadrature points lie inside elements: the interface is a face
        return (np.hypot(x[1], x[2]) >= top).astype(float)

    return mixed_layered(basis, pressure_basis, poisson_ratio, dielectric, rubber)


def lame_radial_strain(r, pressure_pa, poisson_ratio, youngs_modulus=YOUNGS_PA):
    """eps_rr in a shell bonded to a rigid core under uniform external pressure.

    Plane strain (``eps_x = 0``), ``u_r = A r + B / r`` with ``u_r(a) = 0`` so
    ``B = -A a^2``; ``sigma_rr = 2 (lam + mu) A - 2 mu B / r^2`` equals
    ``-pressure`` at ``r = b``: ``A = -p / (2 (lam + mu) + 2 mu a^2 / b^2)``, and
    ``eps_rr = A - B / r^2 = A (1 + a^2 / r^2)``.

    Parameters
    ----------
    r : array_like
        Radius [m].
    pressure_pa : float
        External pressure, compressive positive [Pa].
    """
    lam, mu = lame_parameters(youngs_modulus, poisson_ratio)
    a2 = CORE_M**2
    big_a = -pressure_pa / (2 * (lam + mu) + 2 * mu * a2 / OUTER_M**2)
    return big_a * (1 + a2 / np.asarray(r, float) ** 2)
