"""The frames one patch reads under a grasp's contact, on any kind that places contacts
on its surface.

A kind with a taxel grid in millimetres (``Kind.surface_grid``: a pad) takes the
contact through :func:`~tactsense.simulate.frames_from_contacts` at its centre's (x, y)
in the sensor frame (a pad's surface coordinates are its sensor frame's x and y), on its
reference path (``fast=False``: the kind's own layer model, each distinct load computed
once: a grasp's hold is one load, its ramps a few hundred, far fewer than the fast
path's table of responses costs to build; ``scripts/grasp_numbers.py`` measures both). A kind
without one that places indenters on its surface (``Kind.surface_scenarios``: a point
set) takes it in the tangent plane of the pressed taxel nearest the centre (the
indenter's ``at_taxel``), since a curved set's "(x, y) seen from +z" is ambiguous where
its surface turns away from +z (an iCub fingertip's sides); the frames then come from
the same scan loop ``frames_from_contacts``'s reference path runs, with the same
per-frame flaws. Other kinds say they do not take a grasp.
"""

from __future__ import annotations

import math
import warnings

import numpy as np

from tactsense.kinds import kind_of
from tactsense.physics.indenters import DiscProbe, SphereProbe
from tactsense.physics.transduction import sample_offsets
from tactsense.simulate._grasp_geometry import PatchContact, tangents
from tactsense.simulate.contact_frames import (
    ContactBatch,
    ShearIgnoredWarning,
    check_gains,
    frames_from_contacts,
    resolve_flaws,
)


def takes_grasp(spec) -> bool:
    """Whether a sensor of this kind can be pressed by a grasped object."""
    kind = kind_of(spec)
    return kind.surface_grid(spec) is not None or bool(kind.surface_scenarios)


def patch_frames(
    spec,
    contact: PatchContact | None,
    force_n: np.ndarray,
    *,
    tangential_n: np.ndarray | None = None,
    radius_mm: float,
    shape: str,
    flaws,
    rng: np.random.Generator,
) -> tuple[np.ndarray, np.ndarray]:
    """(frames (N, rows, cols) [counts], per-taxel gains (rows, cols) [-]) of a sensor
    pressed at ``contact`` with normal force ``force_n`` [N] (N,) in each frame (0: not
    touched; ``contact`` None: never touched) and tangential force ``tangential_n``
    (N, 3) [N] in the sensor frame (a pad takes its x and y parts, and its kind says
    whether it senses them; a point set's contacts take none)."""
    kind = kind_of(spec)
    if not takes_grasp(spec):
        raise kind.unsupported(spec, "a simulated grasp (contacts placed on its surface)")
    force_n = np.asarray(force_n, float)
    n = len(force_n)
    active = resolve_flaws(flaws)
    gains = check_gains(spec, None, active)
    rows, cols = spec.shape
    if contact is None:
        force_n = np.zeros(n)
    if contact is None or kind.surface_grid(spec) is not None:
        centre = (0.0, 0.0) if contact is None else contact.position_mm[:2]
        shear = None
        if tangential_n is not None and contact is not None:
            shear = np.asarray(tangential_n, float)[:, None, :2]
        batch = ContactBatch(
            position_mm=np.broadcast_to(np.asarray(centre, float), (n, 1, 2)),
            normal_force_n=force_n[:, None],
            tangential_force_n=shear,
            radius_mm=radius_mm,
            shape=shape,
        )
        # the reference path: a grasp's frames hold few distinct loads (the hold is one,
        # computed once), far fewer than the fast path's table of responses costs
        with warnings.catch_warnings():  # the truth keeps the shear; the docs say who senses it
            warnings.simplefilter("ignore", ShearIgnoredWarning)
            frames = frames_from_contacts(
                spec, batch, flaws=active, rng=rng, gains=gains, fast=False
            )
        return frames.reshape(n, rows, cols), gains
    return _frames_at_taxel(spec, contact, force_n, radius_mm, shape, active, gains, rng), gains


def _frames_at_taxel(spec, contact, force_n, radius_mm, shape, active, gains, rng):
    """The scan loop of ``frames_from_contacts``'s reference path, the contact in the
    tangent plane of taxel ``contact.taxel``."""
    from tactsense.simulate.run import _frame_blocks, _Run

    taxel = contact.taxel
    positions = np.asarray(spec.taxel_positions_mm(), float)
    normals = np.asarray(spec.taxel_normals(), float)
    t1, t2 = tangents(normals[taxel : taxel + 1])
    offset = contact.position_mm - positions[taxel]
    u, v = float(offset @ t1[0]), float(offset @ t2[0])
    probe = SphereProbe if shape == "sphere" else DiscProbe
    applied = [
        (probe(u, v, float(f), radius_mm=radius_mm, at_taxel=taxel),) if f > 0 else ()
        for f in force_n
    ]
    n = len(force_n)
    run = _Run(
        active=tuple(active),
        rng=rng,
        gains=gains,
        applied=applied,
        n_frames=n,
        boundaries=np.arange(n + 1) * spec.scan_period_s,
        offsets=sample_offsets(spec),
    )
    out = np.empty((n, *spec.shape))
    if n == 0:
        return out
    for first, last, counts in _frame_blocks(spec, run):
        out[first:last] = counts.reshape(last - first, *spec.shape)
    return out


def frame_count(duration_s: float, rate_hz: float) -> int:
    """Frames a sensor scanning at ``rate_hz`` [Hz] starts in ``duration_s`` [s]: the
    frames at ``i / rate`` for ``i / rate < duration`` (a product within 1e-6 of a whole
    number counts as that number: rounding of the decimal inputs)."""
    return max(0, math.ceil(duration_s * rate_hz - 1e-6))
