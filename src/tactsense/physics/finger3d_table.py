"""The three-dimensional finger as a forward model: its tabulated response, interpolated.

``simulate(..., forward="finger3d")`` (``tactsense simulate --forward finger3d``)
replaces the twin's two-dimensional skin (plane stress along the finger with the
fitted depth and Poisson's ratio, ring spreading around it; ``docs/model.md``) by the
finite-element solution of the skin as a thick shell of nu 0.49 bonded to the rigid
core (:mod:`tactsense.physics.finger3d`), tabulated by ``scripts/finger3d_table.py``:
the radial strain at the ring depth per newton of a 1.6-mm-radius Hertz sphere, against
the axial distance (0-24 mm) and the angle (0-180 deg) from the load. The copper ring
at that depth then spreads what the rubber passes it around the finger as in the twin
(section 2.3: a beam on the dielectric's elastic foundation; the ring's Green's function
of :func:`~tactsense.physics.array_response.ring_kernel`, convolved around). A tactel's
fractional deflection is minus that strain (eq. 3, ``dd / d_o ~ -eps_z``) at its
offset from each probe, bilinearly interpolated, times the probe's force (the skin is
linear). The skin is three-dimensional and nearly incompressible (nu 0.49), not the
plane-stress slice of fitted depth and Poisson's ratio the estimators assume, so frames
made this way are structurally different from those the estimators assume; only the
rings are the twin's. What the table does not cover is taken
from the 2-D twin and said so: the tip row and probes on the hemispherical tip (the
3-D model is the cylinder only), and tangential components of a probe's force.

Probes (:class:`~tactsense.physics.contact.Probe`) and section 4.1's knife edge (a
:class:`~tactsense.physics.contact.LineContact` 10 mm long across the finger, 0.2 mm
wide, as :func:`~tactsense.simulate.knife_edge_sweep` presses it) are tabulated; other
contacts are an error with this forward model.
"""

from __future__ import annotations

import functools
from pathlib import Path

import numpy as np

from tactsense._validation import TactsenseInputError
from tactsense.physics.contact import LineContact, Probe

TABLE = Path(__file__).with_name("data") / "finger3d_probe.npz"

FORWARDS = ("twin", "finger3d")
"""The forward models of a finger: the paper's 2-D twin, or the 3-D skin's table."""


@functools.lru_cache(maxsize=2)
def table(load: str = "probe"):
    """(axial_mm, angle_deg, strain_per_n, metadata) of the tabulated 3-D response to the
    probe, or to the knife edge (``load="knife"``)."""
    key = {"probe": "strain_per_n", "knife": "knife_strain_per_n"}[load]
    with np.load(TABLE) as data:
        meta = {k: data[k].item() for k in data.files if data[k].ndim == 0}
        return data["axial_mm"], data["angle_deg"], data[key], meta


STEP_DEG = 0.25
"""Angle step of the ring convolution [deg] (the table's finest)."""


@functools.lru_cache(maxsize=8)
def ring_table(flexural_length_mm: float, ring_radius_mm: float, load: str = "probe"):
    """The table spread around by the ring: (axial_mm, angle_deg, strain_per_n) on a
    uniform angle grid of :data:`STEP_DEG` from 0 to 180 deg."""
    from tactsense.physics.array_response import ring_kernel

    axial, angle, strain, _ = table(load)
    full = np.arange(-180.0, 180.0, STEP_DEG)
    values = np.stack([np.interp(np.abs(full), angle, row) for row in strain])
    s = np.radians(full) * ring_radius_mm * 1e-3  # arc length at the ring [m]
    weights = (
        ring_kernel(s, flexural_length_mm * 1e-3) * np.radians(STEP_DEG) * ring_radius_mm * 1e-3
    )
    weights = np.fft.ifftshift(weights)  # centred on index 0 for a circular convolution
    spread = np.fft.irfft(np.fft.rfft(values, axis=1) * np.fft.rfft(weights), n=len(full), axis=1)
    # (the kernel is centred on index 0: the result keeps the angles' order)
    half = full >= 0.0
    return axial, full[half], spread[:, half]


def strain_per_newton(
    d_axial_mm, d_angle_deg, *, rings: tuple[float, float] | None = None, load: str = "probe"
):
    """Radial strain at the ring depth per newton [1/N] at offsets from the load
    (symmetric: absolute values are used; 0 beyond the table's 24 mm); with ``rings``
    (flexural length, ring radius [mm]) as the ring passes it around (:func:`ring_table`)."""
    if rings is None:
        axial, angle, strain, _ = table(load)
    else:
        axial, angle, strain = ring_table(*rings, load)
    x = np.abs(np.asarray(d_axial_mm, dtype=float))
    a = np.abs((np.asarray(d_angle_deg, dtype=float) + 180.0) % 360.0 - 180.0)
    inside = x <= axial[-1]
    x = np.clip(x, axial[0], axial[-1])
    i = np.clip(np.searchsorted(axial, x, side="right") - 1, 0, len(axial) - 2)
    j = np.clip(np.searchsorted(angle, a, side="right") - 1, 0, len(angle) - 2)
    tx = (x - axial[i]) / (axial[i + 1] - axial[i])
    ta = (a - angle[j]) / (angle[j + 1] - angle[j])
    value = (
        (1 - tx) * (1 - ta) * strain[i, j]
        + tx * (1 - ta) * strain[i + 1, j]
        + (1 - tx) * ta * strain[i, j + 1]
        + tx * ta * strain[i + 1, j + 1]
    )
    return np.where(inside, value, 0.0)


def deflection_batch_3d(spec, states) -> np.ndarray:
    """Fractional deflection of every tactel for each state of probes, (S, rows, cols).

    Tactels of the tip row and probes on the tip (axial < 0) take the 2-D twin's
    response (the 3-D model has no hemisphere).
    """
    from tactsense.physics.array_response import deflection_batch

    out = np.zeros((len(states), *spec.shape))
    rows_mm = np.asarray(spec.row_axial_mm, dtype=float)
    cols_deg = np.asarray(spec.col_angle_deg, dtype=float)
    cylinder = rows_mm >= 0.0
    twin_states = []
    for k, state in enumerate(states):
        twin_part = []
        for contact in state:
            load = _tabulated(contact)
            if contact.axial_mm < 0.0:  # on the hemisphere: not in the 3-D model
                twin_part.append(contact)
                continue
            normal = contact.force_n * np.cos(np.radians(contact.alpha_deg))
            d = -normal * strain_per_newton(
                rows_mm[cylinder, None] - contact.axial_mm, cols_deg[None, :] - contact.angle_deg,
                rings=(spec.ring_flexural_length_mm, spec.ring_radius_mm), load=load,
            )  # fmt: skip
            out[k, cylinder] += d
        twin_states.append(tuple(twin_part))
    # the 2-D twin where the table does not reach: the tip row, probes on the tip
    tip_rows = ~cylinder
    if tip_rows.any() or any(twin_states):
        whole = [tuple(s) for s in states]
        twin = deflection_batch(spec, whole)
        out[:, tip_rows] = twin[:, tip_rows]
        on_tip = [k for k, s in enumerate(twin_states) if s]
        if on_tip:
            tip_only = deflection_batch(spec, [twin_states[k] for k in on_tip])
            for n, k in enumerate(on_tip):
                out[k, cylinder] += tip_only[n, cylinder]
    return out


def _tabulated(contact) -> str:
    """Which table holds ``contact``'s response: the probe's, or the knife edge's (a line
    of the table's length and width across the finger); anything else is an error."""
    if type(contact) is Probe:
        return "probe"
    meta = table("knife")[3]
    if (
        type(contact) is LineContact
        and abs(contact.orientation_deg - 90.0) < 1e-9
        and abs(contact.length_mm - meta["knife_length_mm"]) < 1e-9
        and abs(contact.width_mm - meta["knife_width_mm"]) < 1e-9
    ):
        return "knife"
    raise TactsenseInputError(
        "the 3-D forward model is tabulated for the probe and section 4.1's knife edge "
        f"(across the finger, {meta['knife_length_mm']:g} mm by {meta['knife_width_mm']:g} "
        f"mm); this scenario presses a {getattr(contact, 'kind', type(contact).__name__)} "
        "of another shape: use --forward twin"
    )


def check_forward(forward: str, spec) -> str:
    """The forward model's name, checked against the sensor's kind."""
    if forward not in FORWARDS:
        raise TactsenseInputError(f"forward {forward!r}: expected one of {', '.join(FORWARDS)}")
    if forward == "finger3d" and getattr(spec, "kind", "finger") != "finger":
        raise TactsenseInputError(
            f"--forward finger3d is the paper's finger in 3-D; {spec.name!r} is a {spec.kind} "
            "(its layer model is already three-dimensional)"
        )
    return forward
