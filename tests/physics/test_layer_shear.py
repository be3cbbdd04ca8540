"""The layer model's tangential path (``LayerResponse(..., tangential=True)``), checked.

Issue 35 item 1. The fields under a tangential disc traction (all three displacements
and the six strains, at depths inside the layer) against two solutions that share no
code with ``physics.layer`` (``tactsense.analysis.layer_truth_shear``):

* Cerruti's closed-form point force on the half space (Johnson 1985, eq. 2.19)
  integrated over the disc numerically;
* the bonded layer of finite thickness by Hankel transforms of the azimuthal order-1
  fields in cylindrical coordinates, solved per wavenumber by a numerical 4x4 system.

The second is itself checked here: against the first in the half space, and against
Navier's equations, the bonded base and the surface tractions for a finite layer.
Tolerances are relative to each field's largest magnitude over the probed points.
``scripts/shear_check_numbers.py`` writes the measured figures into ``docs/model.md``.
"""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tactsense._validation import TactsenseInputError
from tactsense.analysis import layer_truth_shear as truth
from tactsense.physics import layer

E = 2.5e5  # [Pa]
A = 1.5e-3  # disc radius [m]
F = 0.1  # tangential force [N]
H = 3e-3  # layer thickness [m]
DX = A / 12  # load sample spacing [m]
PROBES = [(0, 0), (0, 8), (0, -8), (10, 0), (12, 16), (-6, 24)]  # (row, col) from the centre


def sampled_traction(n, profile):
    return truth.sampled_disc_traction(n, DX, A, F, profile)


def probe_positions():
    """(x, y) [m] of the probes."""
    return (
        np.array([c * DX for _, c in PROBES]),
        np.array([r * DX for r, _ in PROBES]),
    )


def fft_fields(load, depth, thickness, nu, direction_deg=0.0, padding=None):
    n = load.shape[0]
    response = layer.LayerResponse(
        load.shape,
        DX,
        depth,
        thickness=thickness,
        youngs_modulus=E,
        poisson_ratio=nu,
        quantities=truth.QUANTITIES,
        tangential=True,
        padding=padding,
    )
    phi = np.deg2rad(direction_deg)
    out = response(np.zeros_like(load), np.cos(phi) * load, np.sin(phi) * load)
    c = n // 2
    return {q: np.array([out[q][c + r, c + k] for r, k in PROBES]) for q in truth.QUANTITIES}


def relative_errors(got, ref):
    return {q: np.max(np.abs(got[q] - ref[q])) / np.max(np.abs(ref[q])) for q in ref}


# --- the reference solution, checked -----------------------------------------------


@pytest.mark.parametrize("nu", [0.3, 0.5])
@pytest.mark.parametrize("depth_in_radii", [0.5, 2.0])
def test_hankel_half_space_matches_cerruti(nu, depth_in_radii):
    # two derivations that share nothing (cylindrical Hankel solution; Cartesian point
    # force integrated over the disc); measured agreement <= 5e-8 of each field's peak,
    # limited by the central differences of the Cerruti strains. 1e-6 allowed.
    x, y = probe_positions()
    z = depth_in_radii * A
    kw = dict(youngs_modulus=E, poisson_ratio=nu, radius=A, force=F)
    hankel = truth.bonded_layer_shear_fields(x, y, z, thickness=np.inf, **kw)
    cerruti = truth.cerruti_disc_fields(x, y, z, **kw)
    for q, err in relative_errors(hankel, cerruti).items():
        assert err < 1e-6, (q, err)


@pytest.mark.parametrize("nu", [0.3, 0.45])
def test_hankel_layer_solves_navier_with_the_bonded_base(nu):
    """The finite layer's reference (its growing exponentials and base conditions are not
    exercised by the half-space comparison): Navier's equations by central differences
    of the displacement (step d = 1e-5 m; truncation ~ (d / a)^2: measured residual
    0.9e-4 and 1.9e-4 of mu |lap u|, and 4x more at twice the step), u = 0 on the base,
    and the surface tractions sigma_xz = -tau, sigma_yz = sigma_zz = 0."""
    lam = E * nu / ((1 + nu) * (1 - 2 * nu))
    mu = E / (2 * (1 + nu))
    kw = dict(thickness=H, youngs_modulus=E, poisson_ratio=nu, radius=A, force=F)
    d, z0 = 1e-5, 1.2e-3
    points = np.array([[0.3 * A, 0.2 * A], [1.2 * A, -0.7 * A], [-0.5 * A, 1.5 * A]])
    steps = np.array([-1, 0, 1])
    u = np.empty((3, len(points), 3, 3, 3))  # component, point, x, y, z offsets
    for iz, sz in enumerate(steps):
        gx = points[:, 0, None, None] + d * steps[:, None]
        gy = points[:, 1, None, None] + d * steps[None, :]
        gx, gy = np.broadcast_arrays(gx, gy)
        f = truth.bonded_layer_shear_fields(gx, gy, z0 + sz * d, **kw)
        for ic, q in enumerate(("u_x", "u_y", "u_z")):
            u[ic, :, :, :, iz] = f[q]

    def second(i, j):
        centre = [1, 1, 1]
        if i == j:
            plus, minus = list(centre), list(centre)
            plus[i], minus[i] = 2, 0
            return (u[(..., *plus)] - 2 * u[(..., *centre)] + u[(..., *minus)]) / d**2
        total = 0
        for si in (1, -1):
            for sj in (1, -1):
                idx = list(centre)
                idx[i], idx[j] = 1 + si, 1 + sj
                total = total + si * sj * u[(..., *idx)]
        return total / (4 * d * d)

    hess = [[second(i, j) for j in range(3)] for i in range(3)]  # each (component, point)
    laplacian = sum(hess[i][i] for i in range(3))
    grad_div = np.stack([sum(hess[i][j][j] for j in range(3)) for i in range(3)])
    residual = (lam + mu) * grad_div + mu * laplacian
    assert np.max(np.abs(residual)) < 1e-3 * mu * np.max(np.abs(laplacian))

    base = truth.bonded_layer_shear_fields(points[:, 0], points[:, 1], H, **kw)
    for q in ("u_x", "u_y", "u_z"):
        assert np.max(np.abs(base[q])) < 1e-12 * np.max(np.abs(u))
    top = truth.bonded_layer_shear_fields(points[:, 0], points[:, 1], 0.0, **kw)
    tau = truth.traction_profile(np.hypot(points[:, 0], points[:, 1]), A, F)
    peak = 3 * F / (2 * np.pi * A**2)
    np.testing.assert_allclose(2 * mu * top["eps_xz"], -tau, atol=1e-4 * peak)
    np.testing.assert_allclose(2 * mu * top["eps_yz"], 0.0, atol=1e-4 * peak)
    volumetric = top["eps_xx"] + top["eps_yy"] + top["eps_zz"]
    np.testing.assert_allclose(lam * volumetric + 2 * mu * top["eps_zz"], 0.0, atol=1e-4 * peak)


# --- the layer model against the references -----------------------------------------


@pytest.mark.parametrize("nu", [0.3, 0.5])
@pytest.mark.parametrize(
    ("profile", "depth"),
    [("hertz", 0.5e-3), ("hertz", 1.5e-3), ("hertz", 2.5e-3), ("uniform", 1.5e-3)],
)
def test_finite_layer_matches_the_hankel_solution(nu, profile, depth):
    # h = 3 mm, a = 1.5 mm sampled at a / 12: measured at most 0.22 % (Hertz) and
    # 0.15 % (uniform at z >= h / 2) of each field's peak; the rest is the sampling of
    # the load's square-root (or step) edge on the grid. 0.5 % allowed. (A uniform disc
    # at z = 0.5 mm, four samples deep, gives 1.3 % in eps_zz: its step edge on the grid.)
    load = sampled_traction(128, profile)
    got = fft_fields(load, depth, H, nu)
    x, y = probe_positions()
    ref = truth.bonded_layer_shear_fields(
        x,
        y,
        depth,
        thickness=H,
        youngs_modulus=E,
        poisson_ratio=nu,
        radius=A,
        force=F,
        profile=profile,
    )
    for q, err in relative_errors(got, ref).items():
        assert err < 5e-3, (q, err)


@pytest.mark.parametrize("nu", [0.3, 0.5])
def test_surface_displacements_match_the_hankel_solution(nu):
    # z = 0, what a sensor reading the surface's motion sees: measured at most 0.15 %
    # (the surface strains see the sampled load's edge unsmoothed, up to 2 %: not asserted)
    load = sampled_traction(128, "hertz")
    got = fft_fields(load, 0.0, H, nu)
    x, y = probe_positions()
    ref = truth.bonded_layer_shear_fields(
        x, y, 0.0, thickness=H, youngs_modulus=E, poisson_ratio=nu, radius=A, force=F
    )
    err = relative_errors(got, ref)
    for q in ("u_x", "u_y", "u_z"):
        assert err[q] < 5e-3, (q, err[q])


@pytest.mark.parametrize("direction_deg", [90.0, 30.0])
def test_traction_along_any_direction(direction_deg):
    # q_x and q_y together (traction_y's path); the reference rotates the x solution
    load = sampled_traction(96, "hertz")
    got = fft_fields(load, 1.0e-3, H, 0.45, direction_deg=direction_deg)
    x, y = probe_positions()
    ref = truth.bonded_layer_shear_fields(
        x,
        y,
        1.0e-3,
        thickness=H,
        youngs_modulus=E,
        poisson_ratio=0.45,
        radius=A,
        force=F,
        direction_deg=direction_deg,
    )
    for q, err in relative_errors(got, ref).items():
        assert err < 5e-3, (q, err)


def test_half_space_matches_cerruti_but_for_the_periodic_offset_of_u_x():
    """The half space (thickness=np.inf) against Cerruti: strains, u_y and u_z within
    0.5 % with 7 grids of padding (measured <= 0.21 %; 1.3 % with 3 grids, the probes
    reaching the grid's edge); u_x (which decays as 1 / r) is offset by the periodic
    images of the padded FFT, nearly uniformly, by an amount that halves as the period
    doubles (measured -6.1, -2.7, -1.3, -0.7 % at 1, 3, 7, 15 grids of padding on a
    64-sample grid)."""
    n, nu, z = 64, 0.5, 1.5e-3
    load = sampled_traction(n, "hertz")
    x, y = probe_positions()
    ref = truth.cerruti_disc_fields(
        x, y, z, youngs_modulus=E, poisson_ratio=nu, radius=A, force=F, order=64
    )
    errors = {}
    for grids in (3, 7):
        got = fft_fields(load, z, np.inf, nu, padding=(grids * n, grids * n))
        errors[grids] = relative_errors(got, ref)
        for q, err in errors[grids].items():
            if q != "u_x" and grids == 7:
                assert err < 5e-3, (grids, q, err)
        on_axis = got["u_x"][0] / ref["u_x"][0] - 1
        assert -0.05 < on_axis < 0
    assert 1.6 < errors[3]["u_x"] / errors[7]["u_x"] < 2.6  # ~ 1 / period (8 / 4 = 2)


def test_thick_layer_tends_to_cerruti():
    # the bonded base changes the fields by O(a / h) (displacements) and faster
    # (strains); measured at z = a, nu = 0.5: strains 7.7e-3, 1.6e-3 of the peak at
    # h = 10 a, 20 a, displacements 10 %, 4.5 %
    n, nu, z = 96, 0.5, A
    load = sampled_traction(n, "hertz")
    x, y = probe_positions()
    ref = truth.cerruti_disc_fields(
        x, y, z, youngs_modulus=E, poisson_ratio=nu, radius=A, force=F, order=64
    )
    worst = {}
    for ratio in (10, 20):
        err = relative_errors(fft_fields(load, z, ratio * A, nu), ref)
        worst[ratio] = (
            max(err[q] for q in ("u_x", "u_y", "u_z")),
            max(v for q, v in err.items() if q.startswith("eps")),
        )
    assert worst[20][0] < 0.6 * worst[10][0] and worst[20][0] < 0.06
    assert worst[20][1] < 0.4 * worst[10][1] and worst[20][1] < 3e-3


def test_references_reject_bad_input():
    kw = dict(youngs_modulus=E, poisson_ratio=0.3, radius=A, force=F)
    with pytest.raises(TactsenseInputError, match="depth"):
        truth.bonded_layer_shear_fields(0.0, 0.0, 2 * H, thickness=H, **kw)
    with pytest.raises(TactsenseInputError, match="profile"):
        truth.bonded_layer_shear_fields(0.0, 0.0, 1e-3, thickness=H, profile="cone", **kw)
    with pytest.raises(TactsenseInputError, match="depth > 0"):
        truth.cerruti_disc_fields(0.0, 0.0, 0.0, **kw)


# --- properties of the tangential operator --------------------------------------------

_BETTI_SHAPE = (11, 12)
_BETTI = {
    h: layer.LayerResponse(
        _BETTI_SHAPE,
        0.5e-3,
        0.0,
        thickness=h,
        youngs_modulus=E,
        poisson_ratio=0.45,
        quantities=("u_z", "u_x", "u_y"),
        tangential=True,
    )
    for h in (2e-3, np.inf)
}


def _random_loads(seed, sparsity):
    """(p, q_x, q_y) [Pa] on the grid: normal samples, a fraction ``sparsity`` zeroed."""
    rng = np.random.default_rng(seed)
    loads = rng.normal(0.0, 1e3, (3, *_BETTI_SHAPE))
    return loads * (rng.uniform(size=loads.shape) >= sparsity)


@settings(max_examples=25, deadline=None)
@given(
    st.integers(0, 2**32),
    st.integers(0, 2**32),
    st.sampled_from([0.0, 0.5, 0.95]),
    st.sampled_from([2e-3, np.inf]),
)
def test_betti_reciprocity_on_the_surface(seed_one, seed_two, sparsity, thickness):
    """The work of load set 1 (p, q_x, q_y) on the surface displacements (w, u, v) of
    set 2 equals that of 2 on 1: the coupling of pressure to u and of traction to w
    (and of q_x to v) must be each other's transpose on the grid. Measured to 1e-15 of
    the work; a sign slip in one coupling breaks it at order one."""
    one, two = _random_loads(seed_one, sparsity), _random_loads(seed_two, sparsity)
    response = _BETTI[thickness]
    out_one, out_two = response(*one), response(*two)
    fields = ("u_z", "u_x", "u_y")
    w12 = sum(np.sum(one[i] * out_two[f]) for i, f in enumerate(fields))
    w21 = sum(np.sum(two[i] * out_one[f]) for i, f in enumerate(fields))
    scale = sum(
        np.sum(np.abs(one[i] * out_two[f])) + np.sum(np.abs(two[i] * out_one[f]))
        for i, f in enumerate(fields)
    )
    assert abs(w12 - w21) <= 1e-10 * scale + 1e-300


@pytest.mark.parametrize("step", [2, 4])
def test_decimated_tangential_equals_the_full_field_sampled(step):
    rng = np.random.default_rng(5)
    shape = (16, 12)
    loads = rng.uniform(-1e3, 1e3, (3, 2, *shape))
    response = layer.LayerResponse(
        shape,
        0.4e-3,
        0.8e-3,
        thickness=2e-3,
        youngs_modulus=E,
        poisson_ratio=0.5,
        quantities=truth.QUANTITIES,
        tangential=True,
        electrode=(0.8e-3, 0.6e-3),
        shift=(0.2e-3, 0.1e-3),
        multiple_of=step,
    )
    full = response(*loads)
    part = response.decimated(step, *loads)
    for name in full:
        expected = full[name][..., ::step, ::step]
        np.testing.assert_allclose(part[name], expected, atol=1e-12 * np.max(np.abs(expected)))


def test_layer_response_passes_the_tractions():
    load = sampled_traction(48, "hertz")
    kw = dict(thickness=H, youngs_modulus=E, poisson_ratio=0.45, quantities=("u_x", "eps_xz"))
    direct = layer.LayerResponse(load.shape, DX, 1e-3, tangential=True, **kw)(
        np.zeros_like(load), None, load
    )
    cached = layer.layer_response(np.zeros_like(load), DX, 1e-3, traction_y=load, **kw)
    for name in direct:
        np.testing.assert_array_equal(cached[name], direct[name])
    assert np.max(np.abs(direct["eps_xz"])) > 0  # q_y moves u_x only off the axes
