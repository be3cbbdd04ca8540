"""The whole finger in three dimensions: cylinder, hemispherical tip, and core (scikit-fem).

:mod:`tactsense.physics.finger3d` models the cylindrical skin alone. This module adds
the hemispherical tip, as section 3.6 of the paper describes it: the rubber covering is
a cylinder of outer radius ``b`` = 12.7 mm closed by a hemisphere of the same radius;
the rigid Delrin core (radius ``a`` = 8.85 mm) "extends slightly into the tip area", and
"from the top of the hemisphere to its base, the rubber is about 10 mm thick", so the
core ends in a flat face ``c = b - 10 mm = 2.7 mm`` beyond the junction of cylinder and
hemisphere. The tip row's driven electrode is "a disc connected as the eighth ring"
(section 2.3): its capacitors lie on that end face.

Geometry and mesh. Surface coordinate ``s`` along a meridian, as in
:mod:`tactsense.geometry`: the axial position on the cylinder (``s >= 0``, toward the
base), minus the arc length on the hemisphere (``s = -b psi``, ``psi`` the latitude, the
apex at ``-pi b / 2``); ``theta`` the angle around the axis from the load's meridian;
``t`` in [0, 1] through the rubber from the core to the outer surface. On the cylinder
``rho = a + t (b - a)``; on the hemisphere a point lies on the ray from the sphere's
centre at latitude ``psi``, between the core (which contains the centre and is convex,
so every ray meets it once: the cylinder ``rho = a`` below the latitude of the core's
rim, the end face above it) and the outer sphere. The tensor-product grid in
``(s, theta, t)`` is split into six tetrahedra per box (Kuhn's triangulation, conforming
across boxes), mapped, and the nodes on the axis beyond the core (the apex's meridians,
where ``theta`` is undefined) merged; tetrahedra left with a repeated vertex have no
volume and are dropped. Quadratic tetrahedra (``ElementTetP2``) on this linear geometry
(the curved surfaces are faceted; the check against the spherical shell's closed form
measures the effect). One half is meshed (``theta`` in [0, pi], ``u_y = 0`` on the plane
through the load's meridian); the base of the cylinder is clamped.

Tactel responses by reciprocity. A tactel reads a linear functional of the displacement
(the normal strain at its capacitor, averaged over its plates). With ``K u = f`` and the
functional ``g . u``, the tactel's reading under any load ``f`` is ``g . K^-1 f = v . f``
where ``K v = g`` (``K`` symmetric): one solve per tactel gives its response to a probe
anywhere on the skin (:meth:`TipSolution.influence`), exactly as the direct solves
would (tested).

Forward model only: estimation code must never import this module.
"""

from __future__ import annotations

import dataclasses
import functools
import itertools
from dataclasses import dataclass

import numpy as np
from scipy import sparse
from scipy.sparse.linalg import splu
from skfem import (
    Basis,
    ElementTetP1,
    ElementTetP2,
    FacetBasis,
    LinearForm,
    MeshTet,
    MeshTet2,
    asm,
)
from skfem.models.elasticity import lame_parameters

from tactsense._validation import check_choice
from tactsense.physics.finger3d import CORE_M, OUTER_M, RING_DEPTH_M, _graded
from tactsense.physics.finger3d_forms import (
    YOUNGS_PA,
    _lame,
    _stiffness,
    mixed_layered,
    mixed_system,
)

RUBBER_AT_APEX_M = 10e-3
"""Rubber thickness from the top of the hemisphere to the core (section 3.6) [m]."""
CORE_END_M = OUTER_M - RUBBER_AT_APEX_M
"""How far the core's flat end face lies beyond the junction, toward the apex [m]."""
PLATE_ABOVE_CORE_M = OUTER_M - RING_DEPTH_M - CORE_M
"""Height of the top capacitor plate above the core: 3.85 mm of skin less the 3.2-mm
ring depth, 0.65 mm (the dielectric and the strip) [m]."""
APEX_S_M = -np.pi * OUTER_M / 2
"""Surface coordinate of the apex [m]."""


@dataclass(frozen=True)
class TipMeshSpec:
    """Structured mesh of the half finger with its tip.

    Attributes
    ----------
    n_t : int
        Elements through the rubber.
    h_m : float
        Element size along the meridian over the hemisphere and the first
        ``fine_cylinder_m`` of the cylinder (at the outer surface) [m].
    n_fine_theta : int
        Elements over ``fine_theta_deg`` around the load's meridian.
    max_theta_deg : float
        Largest element in ``theta`` beyond the fine zone (:func:`angle_nodes`) [deg].
    fine_theta_deg : float
    fine_cylinder_m : float
    n_coarse_cylinder : int
        Graded elements from ``fine_cylinder_m`` to ``length_m``.
    length_m : float
        Length of the cylinder, junction to the clamped base [m] (the finger's 25 mm).
    core_end_m : float
        The core's flat end face lies this far beyond the junction [m].
    core : {"flat", "sphere"}
        ``"sphere"``: a hemispherical core of radius ``a`` instead (the closed-form check).
    """

    n_t: int = 3
    h_m: float = 1.0e-3
    n_fine_theta: int = 8
    max_theta_deg: float = 15.0
    fine_theta_deg: float = 30.0
    fine_cylinder_m: float = 8e-3
    n_coarse_cylinder: int = 6
    length_m: float = 25e-3
    core_end_m: float = CORE_END_M
    core: str = "flat"
    dielectric_m: float = 0.0
    """Thickness of a layer on the core (cylinder and end face) meshed apart, one element
    through it, for a dielectric of its own material (``assemble(dielectric=...)``) [m]."""


DIELECTRIC_T = 0.1
"""Grid coordinate ``t`` of the dielectric layer's top (when there is one)."""


def _radius(t, r_in, spec: TipMeshSpec):
    """Distance from the sphere's centre (on the cylinder: from the axis) of grid
    coordinate ``t`` on a ray that meets the core at ``r_in`` [m]: linear in ``t`` from
    the core to the skin, or, with a dielectric, from the core to its top over ``t`` in
    [0, DIELECTRIC_T] and from there to the skin."""
    if spec.dielectric_m <= 0:
        return r_in + t * (OUTER_M - r_in)
    d = spec.dielectric_m
    low = r_in + d * t / DIELECTRIC_T
    high = r_in + d + (t - DIELECTRIC_T) / (1 - DIELECTRIC_T) * (OUTER_M - r_in - d)
    return np.where(t <= DIELECTRIC_T, low, high)


def in_dielectric(x, spec: TipMeshSpec) -> np.ndarray:
    """1 where points ``x`` (3, ...) [m] lie in the dielectric layer on the core, else 0
    (the layer as the mesh maps it: along the rays of :func:`to_xyz`)."""
    rho = np.hypot(x[1], x[2])
    psi = np.clip(np.arctan2(-x[0], rho), 0.0, np.pi / 2)
    r = np.where(x[0] >= 0, rho, np.hypot(x[0], rho))
    r_in = np.where(x[0] >= 0, CORE_M, core_radius(psi, spec))
    return (r < r_in + spec.dielectric_m).astype(float)


TIP_LEVELS = (
    TipMeshSpec(3, 1.4e-3, 6, 20.0),
    TipMeshSpec(4, 1.0e-3, 8, 15.0),
    TipMeshSpec(5, 0.8e-3, 10, 12.0),
)
"""Mesh study levels (``docs/model.md``)."""


def _uniform(lo, hi, h):
    n = max(1, int(np.ceil((hi - lo) / h - 1e-9)))
    return np.linspace(lo, hi, n + 1)


def angle_nodes(spec: TipMeshSpec, growth=1.3, max_deg=15.0) -> np.ndarray:
    """Nodes in ``theta`` [rad]: uniform over the fine zone, then growing by ``growth``
    per element up to ``max_deg`` per element, then uniform to 180 deg (large curved
    elements would make the quadratic geometry's inverse mapping fail)."""
    h = spec.fine_theta_deg / spec.n_fine_theta
    nodes = list(np.linspace(0.0, spec.fine_theta_deg, spec.n_fine_theta + 1))
    while nodes[-1] < 180.0:
        h = min(h * growth, max_deg)
        nodes.append(nodes[-1] + h)
    nodes = np.array(nodes)
    # stretch the part beyond the fine zone so that it ends at 180 deg exactly
    tail = nodes > spec.fine_theta_deg
    start = spec.fine_theta_deg
    nodes[tail] = start + (nodes[tail] - start) * (180.0 - start) / (nodes[-1] - start)
    return np.radians(nodes)


def meridian_nodes(spec: TipMeshSpec) -> np.ndarray:
    """Nodes in ``s`` [m]: uniform over the hemisphere (with a node at the latitude of
    the core's rim, where the core's outline has its corner) and the fine part of the
    cylinder, then graded to the base."""
    parts = []
    if spec.core == "flat":
        corner = -OUTER_M * np.arctan2(spec.core_end_m, CORE_M)
        parts += [_uniform(APEX_S_M, corner, spec.h_m), _uniform(corner, 0.0, spec.h_m)[1:]]
    else:
        parts.append(_uniform(APEX_S_M, 0.0, spec.h_m))
    if spec.length_m > 0:
        fine = min(spec.fine_cylinder_m, spec.length_m)
        n_fine = max(1, int(np.ceil(fine / spec.h_m - 1e-9)))
        if spec.length_m > fine:
            cyl = _graded(fine, spec.length_m, n_fine, spec.n_coarse_cylinder)
        else:
            cyl = np.linspace(0.0, fine, n_fine + 1)
        parts.append(cyl[1:])
    return np.concatenate(parts)


def core_radius(psi, spec: TipMeshSpec):
    """Distance from the sphere's centre to the core along latitude ``psi`` [m]."""
    psi = np.asarray(psi, float)
    if spec.core == "sphere":
        return np.full_like(psi, CORE_M)
    with np.errstate(divide="ignore"):
        end_face = np.where(psi > 0, spec.core_end_m / np.sin(np.abs(psi)), np.inf)
        return np.minimum(CORE_M / np.cos(psi), end_face)


def to_xyz(s, theta, t, spec: TipMeshSpec) -> np.ndarray:
    """Cartesian points (3, ...) [m] of surface-grid coordinates ``(s, theta, t)``.

    ``x`` along the axis toward the base (0 at the junction), ``(y, z) = rho (sin theta,
    cos theta)``: the load's meridian is ``theta = 0`` (``z`` up)."""
    s, theta, t = np.broadcast_arrays(*(np.asarray(q, float) for q in (s, theta, t)))
    psi = np.clip(-s / OUTER_M, 0.0, np.pi / 2)
    r_in = core_radius(psi, spec)
    r = _radius(t, r_in, spec)
    on_tip = s < 0
    x = np.where(on_tip, -r * np.sin(psi), s)
    rho = np.where(on_tip, r * np.cos(psi), _radius(t, CORE_M, spec))
    return np.stack([x, rho * np.sin(theta), rho * np.cos(theta)])


def surface_normal(s, theta) -> np.ndarray:
    """Outward unit normal (3, ...) of the outer surface at ``(s, theta)``."""
    s, theta = np.broadcast_arrays(np.asarray(s, float), np.asarray(theta, float))
    psi = np.clip(-s / OUTER_M, 0.0, np.pi / 2)
    return np.stack([-np.sin(psi), np.cos(psi) * np.sin(theta), np.cos(psi) * np.cos(theta)])


# Kuhn's triangulation: each box (i, j, k) is cut into six tetrahedra along the diagonal
# from corner (0, 0, 0) to (1, 1, 1), one per order in which the three axes are stepped.
_KUHN = [
    [np.zeros(3, int), *np.cumsum(np.eye(3, dtype=int)[list(order)], axis=0)]
    for order in itertools.permutations(range(3))
]


@dataclass
class TipMesh:
    """The tetrahedral mesh, each vertex's grid coordinates, and its boundary facets."""

    mesh: MeshTet2
    grid: np.ndarray  # (3, nvertices): s, theta, t of each vertex (theta = nan on the axis)
    core: np.ndarray
    outer: np.ndarray
    sym: np.ndarray
    base: np.ndarray
    spec: TipMeshSpec
    linear: MeshTet | None = None


def build_tip_mesh(spec: TipMeshSpec = TIP_LEVELS[1]) -> TipMesh:
    """Half-finger tetrahedral mesh with its tip (see the module's docstring)."""
    check_choice(spec.core, "core", ("flat", "sphere"))
    s = meridian_nodes(spec)
    theta = angle_nodes(spec, max_deg=spec.max_theta_deg)
    t = np.linspace(0.0, 1.0, spec.n_t + 1)
    if spec.dielectric_m > 0:
        t = np.concatenate([[0.0], np.linspace(DIELECTRIC_T, 1.0, spec.n_t + 1)])
    ns, nth, nt = len(s), len(theta), len(t)
    ii, jj, kk = np.meshgrid(np.arange(ns), np.arange(nth), np.arange(nt), indexing="ij")
    index = np.ravel_multi_index((ii, jj, kk), (ns, nth, nt))
    # the apex meridians (s = apex, every theta) meet on the axis: one vertex per t
    merged = index.copy()
    merged[0] = merged[0, :1]
    boxes = np.stack(np.meshgrid(*(np.arange(n - 1) for n in (ns, nth, nt)), indexing="ij"))
    boxes = boxes.reshape(3, -1)
    tets = np.concatenate(
        [np.stack([merged[tuple(boxes + corner[:, None])] for corner in path]) for path in _KUHN],
        axis=1,
    )
    keep = np.all(np.diff(np.sort(tets, axis=0), axis=0) > 0, axis=0)
    tets = tets[:, keep]
    grid = np.stack([s[ii].ravel(), theta[jj].ravel(), t[kk].ravel()])
    xyz = to_xyz(*grid, spec)
    used, tets = np.unique(tets, return_inverse=True)
    tets = tets.reshape(4, -1)
    points, grid = xyz[:, used], grid[:, used]
    grid[1, grid[0] == s[0]] = np.nan  # on the axis: no angle
    # orient every tetrahedron positively
    e1, e2, e3 = (points[:, tets[k]] - points[:, tets[0]] for k in (1, 2, 3))
    volume = np.einsum("ij,ij->j", np.cross(e1, e2, axis=0), e3)
    flip = volume < 0
    tets[[1, 2]] = np.where(flip, tets[[2, 1]], tets[[1, 2]])
    if np.min(np.abs(volume)) <= 1e-6 * np.median(np.abs(volume)):
        raise RuntimeError("the tip mesh has a flat tetrahedron: check the mesh spec")
    points, tets = np.ascontiguousarray(points), np.ascontiguousarray(tets)
    linear = MeshTet(points, tets)
    # quadratic geometry: each edge's midpoint mapped from the grid, so curved faces are
    # curved (on the axis, an edge takes the angle of its other end)
    ends = grid[:, linear.edges]  # (3, 2, nedges)
    angle = np.where(np.isnan(ends[1]), ends[1, ::-1], ends[1])
    angle = np.nan_to_num(angle, nan=0.0)
    middle = np.stack([ends[0].mean(axis=0), angle.mean(axis=0), ends[2].mean(axis=0)])
    mesh = MeshTet2(doflocs=np.hstack([points, to_xyz(*middle, spec)]), t=tets)

    def on_boundary(test):
        corners = grid[:, linear.facets]  # (3, 3 vertices, nfacets)
        return np.nonzero(np.all(test(corners), axis=0) & (linear.f2t[1] == -1))[0]

    tol = 1e-12
    return TipMesh(
        mesh,
        grid,
        core=on_boundary(lambda g: g[2] < tol),
        outer=on_boundary(lambda g: g[2] > 1 - tol),
        sym=on_boundary(lambda g: np.isnan(g[1]) | (g[1] < tol) | (np.abs(g[1] - np.pi) < tol)),
        base=on_boundary(lambda g: np.abs(g[0] - spec.length_m) < tol)
        if spec.length_m > 0
        else on_boundary(lambda g: np.abs(g[0]) < tol),
        spec=spec,
    )


def exact_volume(spec: TipMeshSpec) -> float:
    """Volume of the half finger's rubber [m^3] (closed form)."""
    b, a, c, length = OUTER_M, CORE_M, spec.core_end_m, spec.length_m
    outer = np.pi * b**2 * length + 2 / 3 * np.pi * b**3
    if spec.core == "flat":
        core = np.pi * a**2 * (length + c)
    else:
        core = np.pi * a**2 * length + 2 / 3 * np.pi * a**3
    return outer / 2 - core / 2


@dataclass
class TipSolution:
    """The assembled, factorised half finger: solve for loads and tactel functionals."""

    tip: TipMesh
    basis: Basis
    free: np.ndarray
    lu: object
    poisson_ratio: float
    n_pressure: int = 0
    """Pressure unknowns after the displacement's (``formulation="mixed"``), else 0."""

    @property
    def n_dofs(self) -> int:
        return 3 * self.basis.N

    def solve(self, rhs: np.ndarray) -> np.ndarray:
        """Displacement (3, N) [m] for a load vector (component-major, length 3 N)."""
        full = np.zeros(self.n_dofs + self.n_pressure)
        full[: self.n_dofs] = rhs
        u = np.zeros_like(full)
        u[self.free] = self.lu.solve(full[self.free])
        return u[: self.n_dofs].reshape(3, -1)

    @functools.cached_property
    def skin(self) -> FacetBasis:
        """Quadrature on the outer skin's facets (built once: loads and influences)."""
        return FacetBasis(self.tip.mesh, ElementTetP2(), facets=self.tip.outer, intorder=6)

    def pressure_load(self, pressure, force_n) -> np.ndarray:
        """Load vector of a pressure shape ``p(x)`` (x: (3, ...) points [m], compressive
        positive) on the outer surface, scaled so that the whole finger carries
        ``force_n`` [N] (the half model carries half)."""
        top = self.skin
        scale = 0.5 * force_n / asm(LinearForm(lambda v, w: pressure(w.x) * v), top).sum()
        return np.concatenate(
            [
                asm(LinearForm(lambda v, w, c=c: -scale * pressure(w.x) * w.n[c] * v), top)
                for c in range(3)
            ]
        )

    def _probe_matrix(self, points) -> sparse.csr_matrix:
        """Values of the scalar basis at ``points`` (3, P) [m], a (P, N) matrix.

        The cell is found on the linear (faceted) mesh, whose finder is exact, and the
        reference coordinates in that cell's curved map by Newton's method, started from
        the linear cell's barycentric coordinates and not clipped to the cell: a point in
        the faceted cell may lie just outside the curved one, where skfem's own inverse
        (started at the centre, clipped to [0, 1]) stalls."""
        points = np.asarray(points, float)
        tip = self.tip
        if tip.linear is None:
            tip.linear = MeshTet(np.ascontiguousarray(tip.mesh.p), np.ascontiguousarray(tip.mesh.t))
        cells = tip.linear.element_finder()(*points)
        ref = self._reference(points, cells)
        nb = self.basis.Nbfun
        phis = np.array(
            [self.basis.elem.gbasis(self.basis.mapping, ref, k, tind=cells)[0] for k in range(nb)]
        ).flatten()
        rows = np.tile(np.arange(points.shape[1]), nb)
        cols = self.basis.element_dofs[:, cells].flatten()
        shape = (points.shape[1], self.basis.N)
        return sparse.coo_matrix((phis, (rows, cols)), shape=shape).tocsr()

    def _reference(self, points, cells, iterations=30, tol=1e-13):
        corners = self.tip.mesh.p[:, self.tip.mesh.t[:, cells]]  # (3, 4, P)
        edges = corners[:, 1:] - corners[:, :1]  # (3, 3, P): columns are the edges
        ref = np.linalg.solve(
            np.moveaxis(edges, -1, 0), np.moveaxis(points - corners[:, 0], -1, 0)[..., None]
        )[..., 0].T[:, :, np.newaxis]  # (3, P, 1)
        target = points[:, :, np.newaxis]
        mapping = self.basis.mapping
        for _ in range(iterations):
            step = np.einsum(
                "ijkl,jkl->ikl", mapping.invDF(ref, cells), target - mapping.F(ref, cells)
            )
            ref = ref + step
            if np.max(np.abs(step)) < tol:
                return ref
        raise RuntimeError("the inverse of the curved map did not converge")

    def _normal_strain_matrix(self, points, normals, step=1e-6) -> sparse.csr_matrix:
        """The (P, 3 N) matrix that maps the displacement (component-major) to the normal
        strain ``n . (du/dn)`` at ``points`` (3, P) with unit ``normals`` (3, P) [m].

        Central difference of the displacement over ``2 step`` along the normal; inside
        an element this is the derivative of the quadratic interpolant."""
        points, normals = np.asarray(points, float), np.asarray(normals, float)
        difference = self._probe_matrix(points + step * normals) - self._probe_matrix(
            points - step * normals
        )
        return sparse.hstack(
            [sparse.diags(normals[c] / (2 * step)) @ difference for c in range(3)], format="csr"
        )

    def normal_strain_functional(self, points, normals, weights=None, step=1e-6):
        """The functional ``g`` (length 3 N) of the weighted mean normal strain at
        ``points`` (3, P) with unit ``normals`` (3, P) [m] (equal weights by default)."""
        n_points = np.shape(points)[1]
        weights = np.full(n_points, 1.0 / n_points) if weights is None else weights
        return self._normal_strain_matrix(points, normals, step).T @ np.asarray(weights, float)

    def normal_displacement_functional(self, points, normals, weights=None):
        """The functional ``g`` (length 3 N) of the weighted mean displacement along unit
        ``normals`` (3, P) at ``points`` (3, P) [m] (equal weights by default)."""
        n_points = np.shape(points)[1]
        weights = np.full(n_points, 1.0 / n_points) if weights is None else weights
        probe = self._probe_matrix(points).T @ sparse.diags(np.asarray(weights, float))
        normals = np.asarray(normals, float)
        return np.concatenate([probe @ normals[c] for c in range(3)])

    def normal_strain(self, u, points, normals, step=1e-6) -> np.ndarray:
        """Normal strain ``n . (du/dn)`` [-] of displacement ``u`` (3, N) at ``points``."""
        return self._normal_strain_matrix(points, normals, step) @ np.ravel(u)

    def influence(self, v, s_mm, theta_deg, *, probe_radius_m=1.6e-3, force_n=0.05 * 9.80665):
        """A tactel's reading per newton of the Hertz probe at surface points (reciprocity).

        ``v`` (3, N) solves ``K v = g`` for the tactel's functional ``g``; the reading
        under a probe centred at ``(s, theta)`` is ``v . f`` with ``f`` the probe's load
        vector: the Hertz pressure (contact radius for ``force_n`` on flat skin, as in
        :func:`~tactsense.physics.finger3d.hertz_probe`) over the outer surface,
        integrated with the facets' quadrature. Returns an array of
        ``np.broadcast(s_mm, theta_deg).shape`` [1/N].
        """
        from scipy.spatial import cKDTree

        from tactsense.physics.finger3d import hertz_probe

        top = self.skin
        x = np.asarray(top.global_coordinates()).reshape(3, -1)
        w = top.dx.ravel()
        n = np.asarray(top.normals).reshape(3, -1)
        vn = -sum(np.asarray(top.interpolate(v[c])).ravel() * n[c] for c in range(3))  # inward
        # the whole surface: the half model's quadrature and its mirror image (v is the
        # half of a symmetric field, so the mirror carries the same normal displacement)
        x = np.hstack([x, x * np.array([[1.0], [-1.0], [1.0]])])
        w, vn = np.tile(w, 2), np.tile(vn, 2)
        s_mm, theta_deg = np.broadcast_arrays(np.asarray(s_mm, float), np.asarray(theta_deg, float))
        centres = to_xyz(s_mm.ravel() * 1e-3, np.radians(theta_deg.ravel()), 1.0, self.tip.spec)
        _, radius = hertz_probe(force_n, probe_radius_m, self.poisson_ratio)
        pairs = cKDTree(centres.T).sparse_distance_matrix(
            cKDTree(x.T), radius, output_type="coo_matrix"
        )
        p = np.sqrt(np.clip(1.0 - (pairs.data / radius) ** 2, 0.0, None)) * w[pairs.col]
        total = np.bincount(pairs.row, weights=p, minlength=centres.shape[1])
        reading = np.bincount(pairs.row, weights=p * vn[pairs.col], minlength=centres.shape[1])
        if np.any(total <= 0):
            raise RuntimeError("a probe centre saw no quadrature point: refine the mesh")
        # K_half v = g_half makes v twice the whole finger's symmetric solution on the
        # half (on the plane the half model carries half of each nodal load): hence 1/2
        return (0.5 * reading / total).reshape(s_mm.shape)


def assemble(
    spec: TipMeshSpec = TIP_LEVELS[1],
    *,
    poisson_ratio=0.49,
    base="clamped",
    formulation="displacement",
    dielectric=None,
):
    """Mesh, assemble and factorise the half finger.

    ``base``: ``"clamped"`` (the finger's base) or ``"sliding"`` (``u_x = 0`` only: with
    ``length_m = 0`` and a spherical core, half a spherical shell, the closed-form check).
    ``formulation``: ``"displacement"`` (quadratic tetrahedra; the shipped tip table) or
    ``"mixed"`` (quadratic displacement with linear continuous pressure, Taylor-Hood
    P2-P1: free of volumetric locking, :func:`~tactsense.physics.finger3d.mixed_system`).
    ``dielectric``: a :class:`~tactsense.physics.finger3d.Dielectric` on the core (cylinder
    and end face; mixed elements only), meshed as one element through its thickness.
    """
    check_choice(base, "base", ("clamped", "sliding"))
    check_choice(formulation, "formulation", ("mixed", "displacement"))
    if dielectric is not None:
        if formulation != "mixed":
            raise ValueError("a dielectric on the tip needs formulation='mixed'")
        spec = dataclasses.replace(spec, dielectric_m=dielectric.thickness_m)
    tip = build_tip_mesh(spec)
    basis = Basis(tip.mesh, ElementTetP2(), intorder=4)
    n_pressure = 0
    if dielectric is not None:
        stiffness, n_pressure = mixed_layered(
            basis,
            Basis(tip.mesh, ElementTetP1(), intorder=4),
            poisson_ratio,
            dielectric,
            lambda x: 1.0 - in_dielectric(x, spec),
        )
    elif formulation == "mixed":
        lam, mu = _lame(YOUNGS_PA, poisson_ratio)
        stiffness, keep = mixed_system(
            _stiffness(basis, 0.0, mu),
            basis,
            Basis(tip.mesh, ElementTetP1(), intorder=4),
            lambda x: 0 * x[0] + 1 / lam,
        )
        n_pressure = len(keep)
    else:
        stiffness = _stiffness(basis, *lame_parameters(YOUNGS_PA, poisson_ratio))
    n = basis.N
    core = basis.get_dofs(facets=tip.core).all()
    end = basis.get_dofs(facets=tip.base).all()
    fixed = [core, core + n, core + 2 * n, basis.get_dofs(facets=tip.sym).all() + n, end]
    if base == "clamped":
        fixed += [end + n, end + 2 * n]
    free = np.setdiff1d(np.arange(3 * n + n_pressure), np.unique(np.concatenate(fixed)))
    lu = splu(stiffness[free][:, free].tocsc())
    return TipSolution(tip, basis, free, lu, poisson_ratio, n_pressure)


def sphere_radial_strain(r, pressure_pa, poisson_ratio, youngs_modulus=YOUNGS_PA):
    """eps_rr in a spherical shell bonded to a rigid spherical core under uniform pressure.

    ``u_r = A r + B / r^2`` with ``u_r(a) = 0``: ``B = -A a^3``; ``sigma_rr = (3 lam + 2
    mu) A - 4 mu B / r^3 = -p`` at ``r = b``: ``A = -p / (3 lam + 2 mu + 4 mu a^3 / b^3)``,
    and ``eps_rr = A - 2 B / r^3 = A (1 + 2 a^3 / r^3)``.
    """
    a3 = CORE_M**3
    big_a = _shell_coefficient(pressure_pa, poisson_ratio, youngs_modulus)
    return big_a * (1 + 2 * a3 / np.asarray(r, float) ** 3)


def sphere_radial_displacement(r, pressure_pa, poisson_ratio, youngs_modulus=YOUNGS_PA):
    """u_r [m] in the same shell (:func:`sphere_radial_strain`): ``A (r - a^3 / r^2)``,
    zero on the core; ``u_r(a + d) / d`` is the mean radial strain of the layer of
    thickness ``d`` on the core, what a capacitor whose dielectric is that layer reads."""
    r = np.asarray(r, float)
    big_a = _shell_coefficient(pressure_pa, poisson_ratio, youngs_modulus)
    return big_a * (r - CORE_M**3 / r**2)


def _shell_coefficient(pressure_pa, poisson_ratio, youngs_modulus):
    lam, mu = lame_parameters(youngs_modulus, poisson_ratio)
    return -pressure_pa / (3 * lam + 2 * mu + 4 * mu * CORE_M**3 / OUTER_M**3)
