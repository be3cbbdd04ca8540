"""The finger's fast forward for ``frames_from_contacts`` (r9-fastpath): every contact
of a batch as one patch of the paper's 2-D twin, compiled (:func:`patch_frames`)."""

from __future__ import annotations

import numpy as np

from tactsense.physics._fast import patch_frames
from tactsense.physics.array_response import _CELLS, _plane_stress_constants
from tactsense.physics.contact import profile_cdf


class FingerContactForward:
    """The finger's fast forward (``Kind.contact_forward``): every contact of a batch as
    the paper's probe (a parabolic pressure across its Hertz diameter, a sphere) or a
    uniform square (a disc), on the 2-D twin compiled (:func:`patch_frames`): the same
    model and cells as ``elastic_batch``'s (tests/simulate/test_contact_frames_wide.py
    checks the two to 1e-9), without contact objects."""

    def __init__(self, spec):
        self.spec = spec
        e = spec.elastic
        self.E, self.nu = _plane_stress_constants(
            e.youngs_modulus_pa, e.effective_poisson_ratio, e.model
        )
        self.modulus_star_pa = e.youngs_modulus_pa / (1.0 - e.poisson_ratio**2)
        self.u = np.linspace(-1.0, 1.0, _CELLS + 1)
        self.shares = np.stack([np.diff(profile_cdf(self.u, p)) for p in ("parabolic", "uniform")])
        latitude = np.clip(-spec.row_axial_mm / spec.radius_mm, 0.0, np.pi / 2)
        self.rows = (
            np.ascontiguousarray(spec.row_axial_mm * 1e-3),
            np.ascontiguousarray(spec.row_depth_mm * 1e-3),
            np.ascontiguousarray(spec.ring_radius_mm * np.cos(latitude)),
            np.ascontiguousarray(np.deg2rad(spec.col_angle_deg)),
        )

    def prepare(self, contacts):
        """A function ``(first, last) -> (last - first, rows * cols)``: the fractional
        deflection [-] of every taxel for those frames of ``contacts``."""
        spec = self.spec
        force = contacts.normal_force_n
        shear = (
            np.zeros_like(force)
            if contacts.tangential_force_n is None
            else contacts.tangential_force_n[..., 0]
        )
        radius = contacts.radius_mm
        sphere = (
            np.full(force.shape, contacts.shape == "sphere")
            if isinstance(contacts.shape, str)
            else contacts.shape == "sphere"
        )
        hertz = 1e3 * np.cbrt(3.0 * force * radius * 1e-3 / (4.0 * self.modulus_star_pa))
        half = np.where(sphere, np.minimum(hertz, radius), radius)
        with np.errstate(divide="ignore", invalid="ignore"):
            beta = np.where(force > 0, shear / force, 0.0)
        rows, cols = spec.shape

        def block(first: int, last: int) -> np.ndarray:
            frame, slot = np.nonzero(force[first:last] > 0)
            at = (frame + first, slot)
            out = patch_frames(
                *self.rows, self.E, self.nu, spec.ring_flexural_length_mm * 1e-3,
                spec.radius_mm,
                np.ascontiguousarray(contacts.position_mm[at][:, 0]),
                np.ascontiguousarray(np.degrees(contacts.position_mm[at][:, 1] / spec.radius_mm)),
                np.ascontiguousarray(force[at]), np.ascontiguousarray(half[at]),
                np.ascontiguousarray(beta[at]),
                np.ascontiguousarray(np.where(sphere[at], 0, 1).astype(np.int64)),
                self.u, self.shares, np.ascontiguousarray(frame.astype(np.int64)), last - first,
            )  # fmt: skip
            return out.reshape(last - first, rows * cols)

        return block
