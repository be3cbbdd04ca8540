"""Response of the whole array: how a load anywhere on the skin deflects every tactel.

The model is separable (``docs/model.md`` gives the derivation, assumptions
and sources):

* **Along the finger** each slice behaves as the plane-stress half plane of
  section 4 of the paper, with the effective depth and Poisson's ratio
  fitted in section 4.1 (3.8 mm, nu = 0.4). The tip row uses its own
  effective depth and the arc length along the meridian.
* **Around the finger** the load reaches the capacitor through a copper
  ring, which bends like a beam on the elastic foundation of the dielectric
  (section 2.3: "it does not stretch, but can only bend, approximately like
  a beam"). The ring spreads a point force as the Winkler beam Green's
  function ``(lambda / 2) exp(-lambda |s|) (cos lambda s + sin lambda |s|)``
  of arc length ``s`` at the ring radius: a unit-area distribution with a
  first zero at ``s = 3 pi / (4 lambda)`` and shallow negative lobes (the
  bulge of Fig. 22).

The fractional deflection of a tactel (eq. 3: ``dd / d_o ~ -eps_z``) is the
sum over load patches of ``F * A(axial) * C(around)``, with A the axial
line-load response [m/N] and C the ring's distribution [1/m].
"""

from __future__ import annotations

import numpy as np

from tactsense._signals import deferred_interrupts
from tactsense.physics._fast import probe_frames
from tactsense.physics.contact import Patches, Probe, contacts_to_patches, profile_cdf
from tactsense.physics.halfplane import (
    _plane_stress_constants,
    cumulative_normal,
    cumulative_tangential,
)
from tactsense.sensor import SensorSpec

_CELLS = 24  # cells per patch; exact cell integrals make 24 ample at 3.8 mm depth


def ring_kernel(s, flexural_length):
    """Share of a point load a ring passes per unit arc length at ``s`` [1/m].

    Parameters
    ----------
    s : array_like
        Arc length from the load along the ring [m].
    flexural_length : float
        1 / lambda of the ring on its foundation [m].
    """
    lam = 1.0 / flexural_length
    u = lam * np.abs(np.asarray(s, dtype=float))
    return 0.5 * lam * np.exp(-u) * (np.cos(u) + np.sin(u))


def ring_cumulative(s, flexural_length):
    """Antiderivative of :func:`ring_kernel`, zero at s = 0 and +-1/2 at +-inf [-]."""
    s = np.asarray(s, dtype=float)
    u = np.abs(s) / flexural_length
    return 0.5 * np.sign(s) * (1.0 - np.exp(-u) * np.cos(u))


def _cell_edges(half: np.ndarray, profiles: tuple[str, ...]):
    """Normalised cell edges and the load share of each cell, per patch."""
    u = np.linspace(-1.0, 1.0, _CELLS + 1)
    share = np.empty((half.size, _CELLS))
    for profile in set(profiles):
        mask = np.array([p == profile for p in profiles])
        if profile == "point":
            share[mask] = np.nan
        else:
            share[mask] = np.diff(profile_cdf(u, profile))
    return u, share


def axial_response(spec: SensorSpec, patches: Patches) -> np.ndarray:
    """Line-load response of each wired row to each patch, shape (P, rows) [m/N].

    ``-A[p, i] * F_p / width`` would be the plane-stress strain at row i for
    a line load F_p / width; A already includes the tangential part beta.
    """
    E, nu = _plane_stress_constants(
        spec.elastic.youngs_modulus_pa, spec.elastic.effective_poisson_ratio, spec.elastic.model
    )
    depth = spec.row_depth_mm[None, :, None] * 1e-3  # (1, rows, 1)
    row_x = spec.row_axial_mm[None, :, None] * 1e-3
    centre = patches.axial_mm[:, None, None] * 1e-3
    half = patches.half_length_mm * 1e-3
    beta = patches.beta[:, None]
    u, share = _cell_edges(half, patches.profile_axial)
    result = np.empty((len(patches), spec.shape[0]))
    point = half <= 0
    if np.any(point):
        offset = row_x - centre[point]  # (p, rows, 1)
        r2 = offset**2 + depth**2
        normal = 2.0 * depth * (depth**2 - nu * offset**2) / (np.pi * E * r2**2)
        tangential = 2.0 * offset * (depth**2 - nu * offset**2) / (np.pi * E * r2**2)
        result[point] = (normal + beta[point, :, None] * tangential)[..., 0]
    spread = ~point
    if np.any(spread):
        edges = centre[spread] + half[spread, None, None] * u[None, None, :]  # (p, 1, n+1)
        offset = row_x - edges  # (p, rows, n+1)
        density = share[spread][:, None, :] / (np.diff(edges, axis=-1))  # (p, 1, n)
        gn = np.diff(cumulative_normal(offset, depth, E, nu), axis=-1)
        gt = np.diff(cumulative_tangential(offset, depth, E, nu), axis=-1)
        # minus the strain: compressive deflection positive
        result[spread] = np.sum(density * (gn + beta[spread, :, None] * gt), axis=-1)
    return result


def around_response(spec: SensorSpec, patches: Patches) -> np.ndarray:
    """Share of each patch's load reaching each wired column per metre, shape (P, cols) [1/m]."""
    flex = spec.ring_flexural_length_mm
    radius = spec.radius_mm
    latitude = np.clip(-spec.row_axial_mm / radius, 0.0, np.pi / 2)
    ring_radius = spec.ring_radius_mm * np.cos(latitude)  # per row
    # one ring radius per column factor: use the cylinder's; tip rows rescale below
    delta = _wrap_rad(np.deg2rad(spec.col_angle_deg[None, :] - patches.angle_deg[:, None]))
    patch_lat = np.clip(-patches.axial_mm / radius, 0.0, np.pi / 2 - 1e-6)
    half_angle = patches.half_width_mm / (radius * np.cos(patch_lat))
    u, share = _cell_edges(half_angle, patches.profile_around)
    out = np.empty((len(patches), ring_radius.size, spec.shape[1]))
    for row, r_ring in enumerate(ring_radius):
        s = delta * r_ring  # (P, cols) [mm]
        point = half_angle <= 0
        values = np.empty_like(s)
        if np.any(point):
            values[point] = ring_kernel(s[point] * 1e-3, flex * 1e-3)
        spread = ~point
        if np.any(spread):
            edges = (
                s[spread][:, :, None] - r_ring * half_angle[spread, None, None] * u[None, None, :]
            ) * 1e-3
            cum = ring_cumulative(edges, flex * 1e-3)  # decreasing along u
            width = 2.0 * r_ring * half_angle[spread, None, None] * 1e-3 / _CELLS
            values[spread] = np.sum(
                share[spread][:, None, :] * (cum[..., :-1] - cum[..., 1:]) / width, axis=-1
            )
        out[:, row, :] = values
    return out


def _wrap_rad(angle):
    return np.mod(angle + np.pi, 2.0 * np.pi) - np.pi


def deflection_from_patches(spec: SensorSpec, patches: Patches) -> np.ndarray:
    """Fractional deflection ``dd / d_o`` of every wired tactel, shape (rows, cols) [-].

    Linear in the load: the sum over patches of force x axial response x
    ring spreading. Compression of the capacitor is positive.
    """
    if len(patches) == 0:
        return np.zeros(spec.shape)
    axial = axial_response(spec, patches)  # (P, rows)
    around = around_response(spec, patches)  # (P, rows, cols)
    return np.einsum("p,pr,prc->rc", patches.force_n, axial, around)


def tactel_deflection(spec: SensorSpec, contacts) -> np.ndarray:
    """Fractional deflection of every wired tactel under one or more contacts.

    Parameters
    ----------
    spec : SensorSpec
    contacts : contact or sequence of contacts
        :class:`~tactsense.physics.contact.Probe`, ``FlatContact`` or
        ``LineContact`` instances; several at once superpose.

    Returns
    -------
    ndarray, shape (rows, cols)
        ``dd / d_o`` [-], compression positive, before the sensor's flaws.
    """
    if not isinstance(contacts, list | tuple):
        contacts = [contacts]
    return deflection_from_patches(spec, contacts_to_patches(contacts, spec.radius_mm))


def deflection_batch(spec: SensorSpec, states) -> np.ndarray:
    """Fractional deflection for a sequence of contact states, shape (S, rows, cols) [-].

    Each state is a sequence of contacts (empty: nothing touches).
    """
    out = np.zeros((len(states), *spec.shape))
    sizes = [len(s) for s in states]
    flat = [c for s in states for c in s]
    if not flat:
        return out
    probes = [s[0] for s in states if len(s) == 1 and type(s[0]) is Probe]
    if len(probes) == len(states) and len({p.contact_diameter_mm for p in probes}) == 1:
        # every state one probe: the compiled path
        return probe_response(
            spec,
            [p.axial_mm for p in probes],
            [p.angle_deg for p in probes],
            [p.force_n for p in probes],
            contact_diameter_mm=probes[0].contact_diameter_mm,
            alpha_deg=[p.alpha_deg for p in probes],
        )
    parts = [contacts_to_patches([c], spec.radius_mm) for c in flat]
    counts = np.array([len(p) for p in parts], dtype=int)
    patches = Patches.concatenate(parts)
    axial = axial_response(spec, patches)
    around = around_response(spec, patches)
    per_patch = np.einsum("p,pr,prc->prc", patches.force_n, axial, around)
    state_of_contact = np.repeat(np.arange(len(states)), sizes)
    state_of_patch = np.repeat(state_of_contact, counts)
    np.add.at(out, state_of_patch, per_patch)
    return out


def probe_response(
    spec: SensorSpec,
    axial_mm,
    angle_deg,
    force_n,
    *,
    contact_diameter_mm: float = 3.0,
    alpha_deg=0.0,
) -> np.ndarray:
    """Fractional deflection for many single-probe contacts at once, shape (N, rows, cols).

    The vectorized equivalent of calling :func:`tactel_deflection` with one
    :class:`~tactsense.physics.contact.Probe` per element of the broadcast inputs,
    without building contact objects (the fast path of the simulator and of
    model-based estimation).

    Parameters
    ----------
    axial_mm, angle_deg, force_n, alpha_deg : array_like, broadcast to (N,)
        Probe position [mm], [deg], total force [N] and angle from the normal [deg].
    contact_diameter_mm : float
        [mm].
    """
    axial, angle, force, alpha = np.broadcast_arrays(
        *(
            np.atleast_1d(np.asarray(v, dtype=float))
            for v in (axial_mm, angle_deg, force_n, alpha_deg)
        )
    )
    half = contact_diameter_mm / 2.0
    alpha_rad = np.deg2rad(alpha.ravel())
    if half <= 0:
        n = axial.size
        patches = Patches(
            axial.ravel(),
            angle.ravel(),
            force.ravel() * np.cos(alpha_rad),
            np.zeros(n),
            np.zeros(n),
            ("point",) * n,
            ("point",) * n,
            np.tan(alpha_rad),
        )
        return np.einsum(
            "p,pr,prc->prc",
            patches.force_n,
            axial_response(spec, patches),
            around_response(spec, patches),
        )
    E, nu = _plane_stress_constants(
        spec.elastic.youngs_modulus_pa, spec.elastic.effective_poisson_ratio, spec.elastic.model
    )
    u = np.linspace(-1.0, 1.0, _CELLS + 1)
    latitude = np.clip(-spec.row_axial_mm / spec.radius_mm, 0.0, np.pi / 2)
    with deferred_interrupts():
        return probe_frames(
            spec.row_axial_mm * 1e-3,
            spec.row_depth_mm * 1e-3,
            spec.ring_radius_mm * np.cos(latitude),
            np.deg2rad(spec.col_angle_deg),
            E,
            nu,
            spec.ring_flexural_length_mm * 1e-3,
            spec.radius_mm,
            np.ascontiguousarray(axial.ravel()),
            np.ascontiguousarray(angle.ravel()),
            np.ascontiguousarray(force.ravel() * np.cos(alpha_rad)),
            half,
            np.ascontiguousarray(np.tan(alpha_rad)),
            u,
            np.diff(profile_cdf(u, "parabolic")),
        )
