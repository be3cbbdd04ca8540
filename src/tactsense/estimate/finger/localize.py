"""Contact location by Newton-Raphson on the interpolated surface (section 7, eqs. 52-53)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from tactsense.estimate.finger.interpolate import surface

TOLERANCE = 0.01  # tactel: the paper's stopping rule
MAX_STEP = 0.5  # tactel: longest step, so a poor Hessian cannot throw the search away
MAX_ITERATIONS = 20


@dataclass
class Peak:
    """Result of a peak search, arrays of the batch shape."""

    row: np.ndarray
    """Fractional row of the maximum [tactel]."""
    col: np.ndarray
    """Fractional column of the maximum [tactel]."""
    value: np.ndarray
    """Interpolated deflection at the maximum [-]."""
    iterations: np.ndarray
    """Newton steps taken."""
    converged: np.ndarray
    """Whether the last step was shorter than 0.01 tactel."""


def newton_peak(
    deflection,
    start_row,
    start_col,
    *,
    periodic: bool = False,
    tolerance: float = TOLERANCE,
    max_iterations: int = MAX_ITERATIONS,
    tip_row: bool = False,
) -> Peak:
    """Find the maximum of the interpolated surface near a starting tactel (eq. 53).

    Where the Hessian is not negative definite (outside the peak's cap) a
    gradient step is taken instead; every step is shortened to at most half a
    tactel; rows are kept within the array, and columns too unless ``periodic``.

    Parameters
    ----------
    deflection : ndarray, shape (..., rows, cols)
        Fractional deflection [-].
    start_row, start_col : array_like, leading shape
        Starting point, usually the largest tactel [tactel].
    periodic : bool
        Columns close around the finger.
    tip_row : bool
        Row 0 is a tip row, a long step before row 1 (11.1 mm on the paper's fingers,
        not one spacing). A peak found between them (row < 1) is placed at the
        deflection-weighted mean of the two rows' true positions: the returned row is
        ``z1 / (z0 + z1)``, with ``z0``, ``z1`` the two rows interpolated at the peak's
        column (negative values as 0), which the geometry maps linearly onto the step.
        The sinc interpolation assumes equal spacing and cannot place a peak inside
        that step; ``docs/estimation.md`` gives the error this leaves.

    Returns
    -------
    Peak
    """
    z = np.asarray(deflection, dtype=float)
    rows, cols = z.shape[-2:]
    lead = z.shape[:-2]
    x = np.array(np.broadcast_to(start_row, lead), dtype=float).reshape(-1)
    y = np.array(np.broadcast_to(start_col, lead), dtype=float).reshape(-1)
    z = z.reshape(-1, rows, cols)
    iterations = np.zeros(x.shape, dtype=np.int64)
    converged = np.zeros(x.shape, dtype=bool)
    active = np.ones(x.shape, dtype=bool)
    for _ in range(max_iterations):
        if not active.any():
            break
        index = np.nonzero(active)
        _, fx, fy, fxx, fxy, fyy = surface(
            z[index], x[index], y[index], periodic=periodic, derivatives=2
        )
        det = fxx * fyy - fxy * fxy
        concave = (fxx < 0) & (det > 0)
        safe_det = np.where(concave, det, 1.0)
        newton_dx = -(fyy * fx - fxy * fy) / safe_det
        newton_dy = -(fxx * fy - fxy * fx) / safe_det
        gradient = np.hypot(fx, fy)
        scale = np.where(gradient > 0, MAX_STEP / np.where(gradient > 0, gradient, 1.0), 0.0)
        dx = np.where(concave, newton_dx, fx * scale)
        dy = np.where(concave, newton_dy, fy * scale)
        length = np.hypot(dx, dy)
        shrink = np.where(length > MAX_STEP, MAX_STEP / np.where(length > 0, length, 1.0), 1.0)
        dx, dy = dx * shrink, dy * shrink
        new_x = np.clip(x[index] + dx, 0.0, rows - 1.0)
        new_y = y[index] + dy
        new_y = np.mod(new_y, cols) if periodic else np.clip(new_y, 0.0, cols - 1.0)
        x[index], y[index] = new_x, new_y
        iterations[index] += 1
        done = concave & (length < tolerance)
        converged[index] = done
        active[index] = ~done
    value = surface(z, x, y, periodic=periodic)
    if tip_row:
        gap = x < 1.0
        if gap.any():
            tip = np.maximum(surface(z[gap], np.zeros(gap.sum()), y[gap], periodic=periodic), 0.0)
            ring = np.maximum(surface(z[gap], np.ones(gap.sum()), y[gap], periodic=periodic), 0.0)
            total = tip + ring
            x[gap] = np.where(total > 0, ring / np.where(total > 0, total, 1.0), x[gap])
    return Peak(
        row=x.reshape(lead),
        col=y.reshape(lead),
        value=value.reshape(lead),
        iterations=iterations.reshape(lead),
        converged=converged.reshape(lead),
    )


def tactel_maxima(frame, *, periodic: bool = False, threshold: float = 0.0):
    """Tactels larger than their 8 neighbours and than ``threshold``, largest first.

    Parameters
    ----------
    frame : ndarray, shape (rows, cols)
        Fractional deflection of one frame [-].

    Returns
    -------
    list of (row, col)
    """
    z = np.asarray(frame, dtype=float)
    padded = np.pad(z, 1, mode="constant", constant_values=-np.inf)
    if periodic:
        padded[1:-1, 0] = z[:, -1]
        padded[1:-1, -1] = z[:, 0]
    neighbours = np.stack(
        [
            padded[1 + dr : 1 + dr + z.shape[0], 1 + dc : 1 + dc + z.shape[1]]
            for dr in (-1, 0, 1)
            for dc in (-1, 0, 1)
            if (dr, dc) != (0, 0)
        ]
    )
    is_max = (z >= neighbours.max(axis=0)) & (z > threshold)
    rows, cols = np.nonzero(is_max)
    order = np.argsort(-z[rows, cols])
    return [(int(rows[k]), int(cols[k])) for k in order]


def locate_contacts(
    frame,
    *,
    periodic: bool = False,
    threshold: float = 0.005,
    relative: float = 0.2,
    min_separation: float = 1.5,
    tip_row: bool = False,
) -> list[Peak]:
    """Every separate contact of one frame, each located by Newton's method.

    Parameters
    ----------
    frame : ndarray, shape (rows, cols)
        Fractional deflection [-].
    threshold : float
        Smallest deflection that counts as contact [-].
    relative : float
        Smallest secondary maximum as a share of the largest [-].
    min_separation : float
        Two maxima closer than this after Newton are one contact [tactel].
    tip_row : bool
        Row 0 is a tip row (see :func:`newton_peak`).

    Returns
    -------
    list of Peak
        Largest first; each with scalar fields.
    """
    z = np.asarray(frame, dtype=float)
    candidates = tactel_maxima(z, periodic=periodic, threshold=threshold)
    if not candidates:
        return []
    floor = relative * z[candidates[0]]
    found: list[Peak] = []
    cols = z.shape[1]
    for row, col in candidates:
        if z[row, col] < floor:
            break
        peak = newton_peak(z, row, col, periodic=periodic, tip_row=tip_row)
        duplicate = False
        for other in found:
            d_col = peak.col - other.col
            if periodic:
                d_col = (d_col + cols / 2) % cols - cols / 2
            if np.hypot(peak.row - other.row, d_col) < min_separation:
                duplicate = True
                break
        if not duplicate:
            found.append(peak)
    return found
