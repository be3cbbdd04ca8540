"""Equal-deflection contours by tracking (section 7, eqs. 49-51, Fig. 22)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from tactsense.estimate.interpolate import surface
from tactsense.geometry import tactel_to_surface
from tactsense.sensor import SensorSpec


@dataclass
class Contour:
    """One tracked contour line."""

    level: float
    """Deflection of the contour [-]."""
    row: np.ndarray
    """Fractional rows of the polyline [tactel]."""
    col: np.ndarray
    """Fractional columns of the polyline [tactel]."""
    axial_mm: np.ndarray
    """Surface positions along the finger [mm]."""
    angle_deg: np.ndarray
    """Surface positions around the finger [deg]."""
    closed: bool
    """Whether the line came back to its start (else it left the array)."""


def _correct(z, x, y, level, periodic):
    """Newton steps along the gradient back onto f = level."""
    for _ in range(3):
        f, fx, fy = surface(z, x, y, periodic=periodic, derivatives=1)
        g2 = fx * fx + fy * fy
        if g2 == 0:
            break
        x, y = x - (f - level) * fx / g2, y - (f - level) * fy / g2
    return x, y


def track_contour(
    deflection,
    level,
    start_row,
    start_col,
    *,
    sensor: SensorSpec | None = None,
    periodic: bool = False,
    step: float = 0.05,
    max_steps: int = 4000,
) -> Contour:
    """Follow the contour f = level around a peak (eqs. 49-51).

    From the peak, the start is found by walking along the finger until the
    surface falls below ``level``; the tracker then steps ``step`` tactels
    along the direction of constant height (eq. 50), ``(-f_y, f_x) / |grad f|``,
    and corrects the height error with Newton steps along the gradient, as the
    paper describes after eq. 51.

    Parameters
    ----------
    deflection : ndarray, shape (rows, cols)
    level : float
        Contour height k of eq. 49 [-].
    start_row, start_col : float
        A point inside the contour, usually the peak [tactel].
    sensor : SensorSpec, optional
        For surface coordinates; without it those are NaN.
    step : float
        Delta r of eq. 51 [tactel].

    Returns
    -------
    Contour
    """
    z = np.asarray(deflection, float)
    rows, cols = z.shape
    x, y = float(start_row), float(start_col)
    if surface(z, x, y, periodic=periodic) <= level:
        raise ValueError("the start point must lie inside the contour (above its level)")
    low = x
    while surface(z, low, y, periodic=periodic) > level:
        low += step
        if low > rows - 1:
            raise ValueError("the contour does not close along the finger within the array")
    high, low = low, low - step
    for _ in range(40):  # bisection onto the level
        mid = 0.5 * (low + high)
        if surface(z, mid, y, periodic=periodic) > level:
            low = mid
        else:
            high = mid
    x = 0.5 * (low + high)
    xs, ys = [x], [y]
    closed = False
    for k in range(max_steps):
        _, fx, fy = surface(z, x, y, periodic=periodic, derivatives=1)
        norm = np.hypot(fx, fy)
        if norm == 0:
            break
        x, y = _correct(z, x - step * fy / norm, y + step * fx / norm, level, periodic)
        if periodic:
            y = y % cols
        if not (0 <= x <= rows - 1) or (not periodic and not 0 <= y <= cols - 1):
            break
        xs.append(x)
        ys.append(y)
        d_col = ys[-1] - ys[0]
        if periodic:
            d_col = (d_col + cols / 2) % cols - cols / 2
        if k > 10 and np.hypot(xs[-1] - xs[0], d_col) < 0.75 * step:
            closed = True
            xs.append(xs[0])
            ys.append(ys[0])
            break
    row, col = np.array(xs), np.array(ys)
    if sensor is not None:
        axial, angle = tactel_to_surface(sensor, row, col)
    else:
        axial = angle = np.full(row.shape, np.nan)
    return Contour(
        level=float(level),
        row=row,
        col=col,
        axial_mm=np.asarray(axial),
        angle_deg=np.asarray(angle),
        closed=closed,
    )
