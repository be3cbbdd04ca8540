"""A pad's signal under round contacts of any size, for the estimator's fit (issue 34).

The layer is linear and the same everywhere: a frame under k round contacts is
``sum_c F_c G(a_c; x_i - x_c, y_j - y_c)``, ``G`` the layer's taxel response per newton
to a round pressure of radius a (:mod:`tactsense.physics._hertz_table`, exact transfer
function, no sampled pressure). The ``joint`` method fits (x_c, y_c, F_c, a_c) of every contact
of a frame jointly through :class:`PadContactModel` (a pad kind's ``contact_model``).
"""

from __future__ import annotations

import functools
import math

import numpy as np

from tactsense.physics._contact_kernel import superpose
from tactsense.physics._hertz_table import cached_response_table

FIT_A_STEP_MM = 0.1
"""Step of the fit's table in the pressure radius a [mm], linear between (the model
within 3e-4 of the peak of an exact Hankel-transform solution between steps, measured
5e-5 to 1.3e-4, the truth's electrode mean converged: tests/estimate/test_pad_model.py)."""

SPHERE_RADII_MM = (1.0, 10.0)
"""Sphere radii the fit's table covers at :data:`LOADS_N` [mm] (issue 34 item 1)."""

LOADS_N = (0.098, 4.9)
"""Loads the fit's table covers (10-500 g) [N]."""

DISC_PITCHES = 1.5
"""Largest disc radius the table covers [taxel pitch] (discs 1-3 pitches across)."""


def hertz_radius_mm(force_n, sphere_radius_mm, modulus_star_pa):
    """Hertz contact radius ``(3 F R / 4 E*)^(1/3)`` [mm] of a sphere of radius R [mm]
    under F [N] on a half space of plane-strain modulus E* [Pa] (at most R)."""
    f = np.asarray(force_n, float)
    r = np.asarray(sphere_radius_mm, float)
    a = (3.0 * f * r * 1e-3 / (4.0 * modulus_star_pa)) ** (1.0 / 3.0) * 1e3
    return np.minimum(a, r)


def sphere_radius_mm(force_n, contact_radius_mm, modulus_star_pa):
    """The sphere radius [mm] whose Hertz contact radius under F [N] is a [mm]
    (inverse of :func:`hertz_radius_mm`; nan at F = 0)."""
    f = np.asarray(force_n, float)
    a = np.asarray(contact_radius_mm, float) * 1e-3
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(f > 0, 4.0 * modulus_star_pa * a**3 / (3.0 * f) * 1e3, np.nan)


class PadContactModel:
    """A pad's signal [-] under round contacts at (x, y) [mm], force [N], contact radius
    a [mm] and flat share (a Hertzian sphere's pressure, a flat disc's, or a mix): what
    ``find_contacts``' ``joint`` method fits."""

    def __init__(self, spec):
        g = spec.grid
        layer = spec.layer
        self.modulus_star_pa = layer.youngs_modulus_pa / (1.0 - layer.poisson_ratio**2)
        top = max(
            float(hertz_radius_mm(LOADS_N[1], SPHERE_RADII_MM[1], self.modulus_star_pa)),
            DISC_PITCHES * max(g.row_pitch_mm, g.col_pitch_mm),
        )
        self.a_top_mm = FIT_A_STEP_MM * math.ceil(top / FIT_A_STEP_MM + 1e-9)
        electrode = (float(g.electrode_x_mm), float(g.electrode_y_mm))
        self.tables = {
            shape: cached_response_table(layer, electrode, shape, self.a_top_mm, FIT_A_STEP_MM)
            for shape in ("sphere", "disc")
        }
        self.factors = {
            shape: (table.padded_x, table.padded_y) for shape, table in self.tables.items()
        }
        self.x_taxel = g.row_pitch_mm * np.arange(g.rows, dtype=float)
        self.y_taxel = g.col_pitch_mm * np.arange(g.cols, dtype=float)
        self.pitch_mm = (float(g.row_pitch_mm), float(g.col_pitch_mm))
        t = spec.transduction
        self.capacitive = t.kind == "capacitive"
        self.scale = t.strain_gain if self.capacitive else 1.0

    def signal(self, position_mm, force_n, radius_mm, flat=None, *, signed=False) -> np.ndarray:
        """The frame's signal (rows, cols) [-] under contacts at ``position_mm`` (k, 2),
        forces (k,) [N] and contact radii (k,) [mm] (clipped to the table), each a share
        ``flat`` (k,) [-] (default 0) of its force as a flat disc's uniform pressure and
        the rest as a Hertzian sphere's; a resistive taxel's strain clipped at zero unless
        ``signed``."""
        position = np.ascontiguousarray(np.reshape(position_mm, (1, -1, 2)), dtype=float)
        force = np.maximum(np.reshape(np.asarray(force_n, float), (1, -1)) * self.scale, 0.0)
        radius = np.clip(np.reshape(np.asarray(radius_mm, float), (1, -1)), 0.0, self.a_top_mm)
        radius = np.ascontiguousarray(radius)
        share = 0.0 if flat is None else np.clip(np.reshape(flat, (1, -1)), 0.0, 1.0)
        out = np.zeros((1, self.x_taxel.size, self.y_taxel.size))
        for shape, part in (("sphere", 1.0 - share), ("disc", share)):
            if np.all(np.asarray(part) == 0.0):
                continue
            table = self.tables[shape]
            x_factors, y_factors = self.factors[shape]
            superpose(
                self.x_taxel, self.y_taxel, position, np.ascontiguousarray(force * part),
                radius, x_factors, y_factors, table.step_mm, table.a_step_mm, out,
            )  # fmt: skip
        if self.capacitive or signed:
            return out[0]
        return np.maximum(out[0], 0.0)


@functools.lru_cache(maxsize=8)
def pad_contact_model(spec) -> PadContactModel:
    """:class:`PadContactModel` of a pad, built once per process (its table takes some
    seconds: one FFT per tabulated radius)."""
    return PadContactModel(spec)
