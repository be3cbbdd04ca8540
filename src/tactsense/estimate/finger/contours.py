"""Equal-deflection contours by tracking (section 7, eqs. 49-51, Fig. 22)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from tactsense.estimate.finger.interpolate import surface
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
    toward: float = 1.0,
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
        For surface coordinates; without it those are NaN. On a finger with a tip row
        the contour is tracked on the cylinder only: the tip row's samples lie about
        11 mm (three spacings) before the first ring, not one spacing, so they are left
        out of the interpolation (treated as beyond the array, zero) and a contour that
        reaches the first ring ends there, open.
    step : float
        Delta r of eq. 51 [tactel].
    toward : {1.0, -1.0}
        Which way along the finger the start is searched: toward the base (+1, the
        default) or toward the tip (-1). An open contour can have two separate branches,
        one on each side of the peak (a rod across the array): each is tracked from its
        own side.

    Returns
    -------
    Contour
    """
    z = np.asarray(deflection, float)
    rows, cols = z.shape
    first = 0
    if sensor is not None and sensor.array.tip_row:
        z = z.copy()
        z[0, :] = 0.0
        first = 1
    x, y = float(start_row), float(start_col)
    if surface(z, x, y, periodic=periodic) <= level:
        raise ValueError("the start point must lie inside the contour (above its level)")
    if toward not in (1.0, -1.0):
        raise ValueError(f"toward must be 1 or -1; got {toward!r}")
    low = x
    while surface(z, low, y, periodic=periodic) > level:
        low += toward * step
        if not first <= low <= rows - 1:
            raise ValueError("the contour does not close along the finger within the array")
    high, low = low, low - toward * step
    for _ in range(40):  # bisection onto the level
        mid = 0.5 * (low + high)
        if surface(z, mid, y, periodic=periodic) > level:
            low = mid
        else:
            high = mid
    x = 0.5 * (low + high)

    def walk(direction: float):
        """Points from the start along the contour; whether it came back to the start."""
        px, py = x, y
        xs, ys = [px], [py]
        for k in range(max_steps):
            _, fx, fy = surface(z, px, py, periodic=periodic, derivatives=1)
            norm = np.hypot(fx, fy)
            if norm == 0:
                break
            px, py = _correct(
                z,
                px - direction * step * fy / norm,
                py + direction * step * fx / norm,
                level,
                periodic,
            )
            if periodic:
                py = py % cols
            if not (first <= px <= rows - 1) or (not periodic and not 0 <= py <= cols - 1):
                break
            xs.append(px)
            ys.append(py)
            d_col = ys[-1] - ys[0]
            if periodic:
                d_col = (d_col + cols / 2) % cols - cols / 2
            if k > 10 and np.hypot(xs[-1] - xs[0], d_col) < 0.75 * step:
                xs.append(xs[0])
                ys.append(ys[0])
                return xs, ys, True
        return xs, ys, False

    xs, ys, closed = walk(1.0)
    if not closed:
        # it left the array (or the cylinder): follow the other branch from the start too
        back_x, back_y, _ = walk(-1.0)
        xs, ys = back_x[::-1] + xs[1:], back_y[::-1] + ys[1:]
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
