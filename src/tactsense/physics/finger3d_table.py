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
rings are the twin's. The tip row, and the cylinder's rows under probes on the
hemispherical tip, come from the whole finger's 3-D model with its tip
(:mod:`tactsense.physics.finger3d_tip`, tabulated by ``scripts/finger3d_tip.py``). What
the tables do not cover is taken from the 2-D twin and said so: the knife edge's share
of the tip row and a knife on the hemisphere, and the tangential part of a tilted probe's
force.

Probes (:class:`~tactsense.physics.contact.Probe`) and section 4.1's knife edge (a
:class:`~tactsense.physics.contact.LineContact` 10 mm long across the finger, 0.2 mm
wide, as :func:`~tactsense.simulate.knife_edge_sweep` presses it) are tabulated; other
contacts are an error with this forward model.
"""

from __future__ import annotations

import dataclasses
import functools
from pathlib import Path

import numpy as np

from tactsense._validation import TactsenseInputError
from tactsense.physics.contact import LineContact, Probe

TABLE = Path(__file__).with_name("data") / "finger3d_probe.npz"
TIP_TABLE = TABLE.with_name("finger3d_tip.npz")

FORWARDS = ("twin", "finger3d", "finger3d-foam")
"""The forward models of a finger: the paper's 2-D twin, the 3-D skin's table, or the 3-D
skin on section 2.3's foam dielectric (what the capacitor reads: the layer's strain)."""
TABLES = {"finger3d": TABLE, "finger3d-foam": TABLE.with_name("finger3d_probe_foam.npz")}
TIP_TABLES = {"finger3d": TIP_TABLE, "finger3d-foam": TIP_TABLE.with_name("finger3d_tip_foam.npz")}


@functools.lru_cache(maxsize=4)
def table(load: str = "probe", forward: str = "finger3d"):
    """(axial_mm, angle_deg, strain_per_n, metadata) of the tabulated 3-D response to the
    probe, or to the knife edge (``load="knife"``), of the solid skin (``forward=
    "finger3d"``) or of the skin on the foam dielectric (``"finger3d-foam"``)."""
    key = {"probe": "strain_per_n", "knife": "knife_strain_per_n"}[load]
    with np.load(TABLES[forward]) as data:
        meta = {k: data[k].item() for k in data.files if data[k].ndim == 0}
        return data["axial_mm"], data["angle_deg"], data[key], meta


STEP_DEG = 0.25
"""Angle step of the ring convolution [deg] (the table's finest)."""


def _ring_spread(angle, values, flexural_length_mm, ring_radius_mm):
    """Angle profiles ``values`` (..., len(angle)) of the strain at the ring, spread around
    by the ring (section 4's beam Green's function, a circular convolution): returns the
    uniform angles 0-180 deg of :data:`STEP_DEG` and the spread profiles."""
    from tactsense.physics.array_response import ring_kernel

    full = np.arange(-180.0, 180.0, STEP_DEG)
    flat = values.reshape(-1, values.shape[-1])
    profiles = np.stack([np.interp(np.abs(full), angle, row) for row in flat])
    s = np.radians(full) * ring_radius_mm * 1e-3  # arc length at the ring [m]
    weights = (
        ring_kernel(s, flexural_length_mm * 1e-3) * np.radians(STEP_DEG) * ring_radius_mm * 1e-3
    )
    weights = np.fft.ifftshift(weights)  # centred on index 0 for a circular convolution
    spread = np.fft.irfft(
        np.fft.rfft(profiles, axis=1) * np.fft.rfft(weights), n=len(full), axis=1
    )  # (the kernel is centred on index 0: the result keeps the angles' order)
    half = full >= 0.0
    return full[half], spread[:, half].reshape(*values.shape[:-1], -1)


@functools.lru_cache(maxsize=8)
def ring_table(
    flexural_length_mm: float, ring_radius_mm: float, load: str = "probe", forward="finger3d"
):
    """The table spread around by the ring: (axial_mm, angle_deg, strain_per_n) on a
    uniform angle grid of :data:`STEP_DEG` from 0 to 180 deg."""
    axial, angle, strain, _ = table(load, forward)
    spread_angle, spread = _ring_spread(angle, strain, flexural_length_mm, ring_radius_mm)
    return axial, spread_angle, spread


def _bilinear(xs, ys, values, x, y):
    """Bilinear interpolation of ``values`` (len(xs), len(ys)) at (x, y), clipped to the
    grid (the caller zeroes what lies beyond it)."""
    x = np.clip(x, xs[0], xs[-1])
    y = np.clip(y, ys[0], ys[-1])
    i = np.clip(np.searchsorted(xs, x, side="right") - 1, 0, len(xs) - 2)
    j = np.clip(np.searchsorted(ys, y, side="right") - 1, 0, len(ys) - 2)
    tx = (x - xs[i]) / (xs[i + 1] - xs[i])
    ty = (y - ys[j]) / (ys[j + 1] - ys[j])
    return (
        (1 - tx) * (1 - ty) * values[i, j]
        + tx * (1 - ty) * values[i + 1, j]
        + (1 - tx) * ty * values[i, j + 1]
        + tx * ty * values[i + 1, j + 1]
    )


def _angle_offset(d_angle_deg):
    """|angle| wrapped to [0, 180] deg."""
    return np.abs((np.asarray(d_angle_deg, dtype=float) + 180.0) % 360.0 - 180.0)


def strain_per_newton(
    d_axial_mm,
    d_angle_deg,
    *,
    rings: tuple[float, float] | None = None,
    load: str = "probe",
    forward: str = "finger3d",
):
    """Radial strain at the ring depth per newton [1/N] at offsets from the load
    (symmetric: absolute values are used; 0 beyond the table's 24 mm); with ``rings``
    (flexural length, ring radius [mm]) as the ring passes it around (:func:`ring_table`)."""
    if rings is None:
        axial, angle, strain, _ = table(load, forward)
    else:
        axial, angle, strain = ring_table(*rings, load, forward)
    x = np.abs(np.asarray(d_axial_mm, dtype=float))
    value = _bilinear(axial, angle, strain, x, _angle_offset(d_angle_deg))
    return np.where(x <= axial[-1], value, 0.0)


@functools.lru_cache(maxsize=2)
def tip_table(forward: str = "finger3d") -> dict:
    """The tip's tables (``scripts/finger3d_tip.py``, with ``--foam`` for
    ``"finger3d-foam"``): every array of the file."""
    with np.load(TIP_TABLES[forward]) as data:
        return {k: data[k] if data[k].ndim else data[k].item() for k in data.files}


def tip_row_strain_per_newton(s_mm, d_angle_deg, *, plate: str = "tip", forward="finger3d"):
    """Normal strain of the tip row's tactel per newton of the probe [1/N], as its
    capacitor reads it: the mean strain of the gap between the core's end face and the
    plate (the plate's displacement over the gap), averaged over the plate; the probe at
    surface coordinate ``s_mm`` (apex -19.95 mm to 12 mm; 0 beyond) and ``d_angle_deg``
    from the tactel. The gap is the 0.65 mm of rubber under the plate for ``"finger3d"``
    (the cylinder's rows read the point strain instead: ``docs/model.md`` section 3d) and
    the foam layer for ``"finger3d-foam"``. ``plate="tip_rim"``: the outer quarter of the
    face only (the plate-size sensitivity)."""
    t = tip_table(forward)
    s = np.asarray(s_mm, dtype=float)
    values = t[f"{plate}_strain_per_n"]
    value = _bilinear(t["s_mm"], t["angle_deg"], values, s, _angle_offset(d_angle_deg))
    return np.where(s <= t["s_mm"][-1], value, 0.0)


@functools.lru_cache(maxsize=8)
def _cylinder_from_tip(flexural_length_mm: float, ring_radius_mm: float, forward="finger3d"):
    t = tip_table(forward)
    angle, spread = _ring_spread(
        t["angle_deg"], t["cylinder_strain_per_n"].astype(float), flexural_length_mm, ring_radius_mm
    )
    return t["row_mm"], t["s_tip_mm"], angle, spread


def deflection_batch_3d(spec, states, forward: str = "finger3d") -> np.ndarray:
    """Fractional deflection of every tactel for each state of probes, (S, rows, cols).

    Probes on the cylinder reach the cylinder's rows through the cylinder's table; the
    tip row, and the cylinder's rows under probes on the hemisphere, through the tip's
    (:func:`tip_row_strain_per_newton`; the cylinder's rows spread around by the rings as
    on the cylinder). The knife edge is tabulated on the cylinder only: its share of the
    tip row, and a knife on the hemisphere, take the 2-D twin's response; so does the
    tangential part of a tilted probe's force (the twin's response to the tilted probe
    less its response to the probe's normal part). ``forward="finger3d-foam"``: the
    cylinder's and the tip's tables of the skin on the foam dielectric.
    """
    from tactsense.physics.array_response import deflection_batch

    check_forward(forward, spec)
    if forward == "twin":
        raise TactsenseInputError("deflection_batch_3d is the 3-D model: forward 'twin' is not")

    out = np.zeros((len(states), *spec.shape))
    rows_mm = np.asarray(spec.row_axial_mm, dtype=float)
    cols_deg = np.asarray(spec.col_angle_deg, dtype=float)
    cylinder = rows_mm >= 0.0
    rings = (spec.ring_flexural_length_mm, spec.ring_radius_mm)
    twin_states, knife_states, tilted_states = [], [], []
    for k, state in enumerate(states):
        twin_part, knives, tilted = [], [], []
        for contact in state:
            load = _tabulated(contact)
            normal = contact.force_n * np.cos(np.radians(contact.alpha_deg))
            d_angle = cols_deg[None, :] - contact.angle_deg
            if load == "knife":
                if contact.axial_mm < 0.0:  # a knife on the hemisphere: not tabulated
                    twin_part.append(contact)
                    continue
                out[k, cylinder] -= normal * strain_per_newton(
                    rows_mm[cylinder, None] - contact.axial_mm,
                    d_angle,
                    rings=rings,
                    load=load,
                    forward=forward,
                )
                knives.append(contact)  # its share of the tip row: the twin's, below
                continue
            if contact.alpha_deg != 0.0:  # the tangential share: the twin's, below
                tilted.append(contact)
            out[k, ~cylinder] -= normal * tip_row_strain_per_newton(
                contact.axial_mm, d_angle, forward=forward
            )
            if contact.axial_mm >= 0.0:
                offset = rows_mm[cylinder, None] - contact.axial_mm
                out[k, cylinder] -= normal * strain_per_newton(
                    offset, d_angle, rings=rings, forward=forward
                )
            else:
                near = cylinder & (rows_mm <= tip_table(forward)["row_mm"][-1])
                for r in np.nonzero(near)[0]:
                    out[k, r] -= normal * _cylinder_row_from_tip(
                        rows_mm[r], contact.axial_mm, d_angle[0], rings, forward
                    )
        twin_states.append(tuple(twin_part))
        knife_states.append(tuple(knives))
        tilted_states.append(tuple(tilted))
    on_tip = [k for k, s in enumerate(twin_states) if s]
    if on_tip:
        tip_only = deflection_batch(spec, [twin_states[k] for k in on_tip])
        for n, k in enumerate(on_tip):
            out[k] += tip_only[n]
    with_knife = [k for k, s in enumerate(knife_states) if s]
    if with_knife and (~cylinder).any():
        knife_twin = deflection_batch(spec, [knife_states[k] for k in with_knife])
        for n, k in enumerate(with_knife):
            out[k, ~cylinder] += knife_twin[n, ~cylinder]
    with_tilt = [k for k, s in enumerate(tilted_states) if s]
    if with_tilt:  # the twin's response to the tilted probe less its normal part
        whole = deflection_batch(spec, [tilted_states[k] for k in with_tilt])
        normal_only = [
            tuple(
                dataclasses.replace(
                    p, force_n=p.force_n * np.cos(np.radians(p.alpha_deg)), alpha_deg=0.0
                )
                for p in tilted_states[k]
            )
            for k in with_tilt
        ]
        tangential = whole - deflection_batch(spec, normal_only)
        for n, k in enumerate(with_tilt):
            out[k] += tangential[n]
    return out


def _cylinder_row_from_tip(row_mm, s_mm, d_angle_deg, rings, forward="finger3d"):
    """One cylinder row's strain (cols,) under a probe on the hemisphere, interpolated
    linearly between the table's rows."""
    rows, s_grid, angle, spread = _cylinder_from_tip(*rings, forward)
    k = int(np.clip(np.searchsorted(rows, row_mm, side="right") - 1, 0, len(rows) - 2))
    w = float(np.clip((row_mm - rows[k]) / (rows[k + 1] - rows[k]), 0.0, 1.0))
    a = _angle_offset(d_angle_deg)
    s = np.full_like(a, s_mm)
    return (1 - w) * _bilinear(s_grid, angle, spread[k], s, a) + w * _bilinear(
        s_grid, angle, spread[k + 1], s, a
    )


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


def check_forward(forward: str, spec=None) -> str:
    """The forward model's name, checked (whether the sensor's kind has it is the kind's
    question: ``Kind.check_forward``)."""
    if forward not in FORWARDS:
        raise TactsenseInputError(f"forward {forward!r}: expected one of {', '.join(FORWARDS)}")
    return forward
