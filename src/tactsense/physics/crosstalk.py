"""Crosstalk of a passive resistive matrix read by row/column scanning (ghosting).

A passive matrix has one conductance ``G_ij`` between row line ``i`` and column line
``j`` and no diode or switch at the cell. To read cell ``(i, j)`` the scan drives row
``i`` and senses column ``j``; when the other lines float, current also flows along every
path row ``i`` -> column ``l`` -> row ``k`` -> column ``j`` through the other cells, so
the scan measures the two-terminal conductance of the whole network between the two
lines, ``G_ij`` in parallel with the rest. The first-order term is the three-cell path
``1 / (1/G_il + 1/G_kl + 1/G_kj)``: a cell reads extra when the other three corners of a
rectangle are loaded (the "ghost" of two presses on a diagonal). Errors from such
parasitic parallel paths are studied at length; Hidalgo-Lopez et al. (J. Sensors 2018,
article 9735741) quote up to 30 % for a 4x4 array, and readout circuits (zero-potential,
voltage feedback) exist to hold the unscanned lines and suppress them.

:func:`effective_conductance` solves the network exactly (the Laplacian of the bipartite
row/column graph, inverted once per frame); :func:`scan_conductance` mixes it with the
isolated reading by the sensor's ``flaws.crosstalk`` (0: isolated scan, 1: every
unscanned line floating).
"""

from __future__ import annotations

import numpy as np

from tactsense._validation import TactsenseInputError

LEAK = 1e-6
"""Conductance of an unloaded cell relative to the largest in the frame [-]: keeps the
network connected so that it can be solved (an FSR at rest is > 10 MOhm; this is a
numerical floor, small enough to add well under a count)."""


def effective_conductance(g) -> np.ndarray:
    """Two-terminal conductance between row ``i`` and column ``j`` of a passive matrix,
    every other line floating, for every cell [same unit as ``g``].

    Parameters
    ----------
    g : array_like, shape (..., rows, cols)
        Conductance of each cell (any unit, >= 0).

    Returns
    -------
    ndarray, shape (..., rows, cols)
        ``1 / R_eff(i, j)`` with ``R_eff = (e_i - e_j)^T L^+ (e_i - e_j)``, ``L`` the
        Laplacian of the network (rows then columns as nodes).

    Notes
    -----
    ``L + 1 1^T / N`` is invertible for a connected network and its inverse differs from
    ``L^+`` by ``1 1^T / N``, which ``e_i - e_j`` does not see.
    """
    g = np.asarray(g, dtype=float)
    if g.ndim < 2:
        raise TactsenseInputError(f"g must have shape (..., rows, cols); got {g.shape}")
    if not np.all(np.isfinite(g)) or np.any(g < 0):
        raise TactsenseInputError("conductances must be finite and non-negative")
    rows, cols = g.shape[-2:]
    scale = g.max(axis=(-2, -1), keepdims=True)
    scale = np.where(scale > 0, scale, 1.0)
    unit = g / scale + LEAK
    n = rows + cols
    lap = np.zeros((*g.shape[:-2], n, n))
    r, c = np.arange(rows), rows + np.arange(cols)
    lap[..., r, r] = unit.sum(axis=-1)
    lap[..., c, c] = unit.sum(axis=-2)
    lap[..., :rows, rows:] = -unit
    lap[..., rows:, :rows] = -np.swapaxes(unit, -1, -2)
    inverse = np.linalg.inv(lap + 1.0 / n)
    diagonal = np.diagonal(inverse, axis1=-2, axis2=-1)
    resistance = (
        diagonal[..., :rows, None] + diagonal[..., None, rows:] - 2.0 * inverse[..., :rows, rows:]
    )
    return scale / resistance


def scan_conductance(g, strength: float = 1.0) -> np.ndarray:
    """What the scan reads of each cell: ``G_ij + s (G_eff - G_ij)`` [same unit as ``g``].

    ``G_eff - G_ij`` is the conductance of the parallel paths through the other cells
    (:func:`effective_conductance`, less the leak that keeps the network solvable);
    ``strength`` ``s`` in [0, 1] is the share of it the readout lets through.
    """
    if not (isinstance(strength, int | float) and np.isfinite(strength) and 0 <= strength <= 1):
        raise TactsenseInputError(
            f"crosstalk must lie in [0, 1] (0: isolated scan, 1: lines floating); got {strength!r}"
        )
    g = np.asarray(g, dtype=float)
    if strength == 0:
        return g.copy()
    scale = g.max(axis=(-2, -1), keepdims=True) if g.size else np.ones(g.shape)
    parallel = effective_conductance(g) - g - LEAK * np.where(scale > 0, scale, 1.0)
    return g + strength * np.maximum(parallel, 0.0)
