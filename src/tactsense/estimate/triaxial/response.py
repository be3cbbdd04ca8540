"""The response a three-axis estimator fits, tabulated once per sensor.

The kind answers it (``Kind.shear_response``: its own forward model, the estimator never
runs the simulator): the change of every taxel's three components [counts/N] per newton
of normal force and of tangential force along x and y, for the scenarios' probe (a
1.6-mm sphere) at each node of a grid of positions that covers the pad a half pitch
beyond its outer taxels, ``n_sub`` nodes per pitch. Between nodes the response is
interpolated bilinearly.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from tactsense.kinds import kind_of

N_SUB = 4
"""Nodes of the response grid per pitch along each axis [-]."""


@dataclass(frozen=True)
class ResponseTable:
    """The response of every taxel to the three loads at nodes ``(x_mm[i], y_mm[j])``.

    ``values[i, j, load, k]``: load 0 the normal force, 1 the tangential along x, 2
    along y; ``k`` runs over (row, col, component) in frame order (row-major, the
    component fastest) [counts/N].
    """

    x_mm: np.ndarray
    y_mm: np.ndarray
    values: np.ndarray

    @property
    def step_mm(self) -> tuple[float, float]:
        """Spacing of the nodes along x and y [mm]."""
        return float(self.x_mm[1] - self.x_mm[0]), float(self.y_mm[1] - self.y_mm[0])

    def at(self, x_mm: float, y_mm: float) -> np.ndarray:
        """The response at (x, y) [mm], bilinear between nodes (clamped to the grid),
        shape (3, rows*cols*3) [counts/N]."""
        hx, hy = self.step_mm
        fx = np.clip((x_mm - self.x_mm[0]) / hx, 0.0, len(self.x_mm) - 1.0)
        fy = np.clip((y_mm - self.y_mm[0]) / hy, 0.0, len(self.y_mm) - 1.0)
        i, j = min(int(fx), len(self.x_mm) - 2), min(int(fy), len(self.y_mm) - 2)
        a, b = fx - i, fy - j
        v = self.values
        return ((1 - a) * (1 - b) * v[i, j] + a * (1 - b) * v[i + 1, j]
                + (1 - a) * b * v[i, j + 1] + a * b * v[i + 1, j + 1])  # fmt: skip


def response_table(spec, n_sub: int = N_SUB) -> ResponseTable:
    """The kind's response to the three loads on a grid of positions over ``spec``'s
    pad (cached per sensor description). A kind without a three-axis response says so
    (:meth:`~tactsense.kinds.Kind.unsupported`)."""
    return _table(spec, int(n_sub))


@functools.lru_cache(maxsize=8)
def _table(spec, n_sub: int) -> ResponseTable:
    kind = kind_of(spec)
    respond = getattr(kind, "shear_response", None)
    if respond is None:
        raise kind.unsupported(spec, "three-axis contact estimation (no shear response)")
    rows, cols = spec.shape
    px, py = spec.grid.row_pitch_mm, spec.grid.col_pitch_mm
    x = px * (np.arange(rows * n_sub + 1) / n_sub - 0.5)
    y = py * (np.arange(cols * n_sub + 1) / n_sub - 0.5)
    xx, yy = np.meshgrid(x, y, indexing="ij")
    values = respond(spec, np.column_stack([xx.ravel(), yy.ravel()]))
    values = values.reshape(len(x), len(y), 3, rows * cols * 3)
    return ResponseTable(x, y, values)
