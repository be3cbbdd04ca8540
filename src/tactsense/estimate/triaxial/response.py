"""The response a three-axis estimator fits, tabulated once per sensor.

The kind answers it (``Kind.shear_response``: its own forward model, the estimator never
runs the simulator): the change of every taxel's three components [counts/N] per newton
of normal force and of tangential force along x and y, for a sphere of a given radius
(by default the scenarios' probe, a 1.6-mm sphere; :func:`response_table`'s
``radius_mm``: the indenter in use, the bench's ball for a calibration) at each node of
a grid of positions that covers the pad a half pitch beyond its outer taxels, ``n_sub``
nodes per pitch. Between nodes the response is a cubic B-spline through them, within
2 % of the largest value of the kind's own response at random places
(``tests/estimate/test_triaxial_estimate.py``).
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np
from scipy import ndimage

from tactsense.kinds import kind_of

N_SUB = 6
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
    coefficients: np.ndarray
    """The cubic B-spline's coefficients over the nodes, mirrored two nodes beyond each
    edge, shape (nx + 4, ny + 4, 3, K)."""

    @property
    def step_mm(self) -> tuple[float, float]:
        """Spacing of the nodes along x and y [mm]."""
        return float(self.x_mm[1] - self.x_mm[0]), float(self.y_mm[1] - self.y_mm[0])

    def at(self, x_mm: float, y_mm: float, pick=None) -> np.ndarray:
        """The response at (x, y) [mm] (clamped to the grid), the cubic B-spline
        through the nodes, shape (3, K) [counts/N]; ``pick`` (a boolean mask over K)
        keeps some of the values only."""
        hx, hy = self.step_mm
        fx = float(np.clip((x_mm - self.x_mm[0]) / hx, 0.0, len(self.x_mm) - 1.0))
        fy = float(np.clip((y_mm - self.y_mm[0]) / hy, 0.0, len(self.y_mm) - 1.0))
        i, j = min(int(fx), len(self.x_mm) - 2), min(int(fy), len(self.y_mm) - 2)
        wx, wy = _bspline_weights(fx - i), _bspline_weights(fy - j)
        c = self.coefficients[i + 1 : i + 5, j + 1 : j + 5]  # nodes i-1 .. i+2 (mirrored)
        if pick is not None:
            c = c[..., pick]
        return np.einsum("a,b,abik->ik", wx, wy, c)


def _bspline_weights(t: float) -> np.ndarray:
    """The cubic B-spline's weights of the nodes -1, 0, 1, 2 at ``t`` in [0, 1]."""
    return np.array([(1 - t) ** 3, 3 * t**3 - 6 * t**2 + 4, -3 * t**3 + 3 * t**2 + 3 * t + 1,
                     t**3]) / 6.0  # fmt: skip


def response_table(spec, n_sub: int = N_SUB, *, radius_mm: float | None = None) -> ResponseTable:
    """The kind's response to the three loads on a grid of positions over ``spec``'s
    pad (cached per sensor description and radius). A kind without a three-axis response
    says so (:meth:`~tactsense.kinds.Kind.unsupported`).

    ``radius_mm``: the radius of the sphere whose response is tabulated [mm] (the
    indenter in use: a contact's Hertz radius and so the shape of its load follow from
    it); None: the kind's default probe. A magnet under a contact reads a change that
    depends on the contact's size, so a response tabulated for another indenter biases
    the force fitted to it and, more, a calibration judged against it
    (``docs/mujoco.md``: a 2-mm ball against the 1.6-mm probe's table gave z gains of
    1.06 instead of 1)."""
    if radius_mm is None:
        return _table(spec, int(n_sub), _default_radius_mm(spec))
    return _table(spec, int(n_sub), check_radius_mm(radius_mm))


def _default_radius_mm(spec) -> float | None:
    """The radius of the kind's default probe [mm] (its ``shear_response``'s
    ``size_mm``), so that asking for it by number shares the table; None if unknown."""
    import inspect

    try:
        size = inspect.signature(kind_of(spec).shear_response).parameters.get("size_mm")
    except (TypeError, ValueError):
        return None
    if size is None or not isinstance(size.default, int | float):
        return None
    return float(size.default)


RADIUS_RANGE_MM = (0.2, 50.0)
"""Radii of an indenter's sphere the response is tabulated for [mm]."""


def check_radius_mm(radius_mm) -> float:
    """``radius_mm`` checked: a finite radius in :data:`RADIUS_RANGE_MM` [mm], else a
    one-line error."""
    from tactsense._validation import TactsenseInputError

    lo, hi = RADIUS_RANGE_MM
    ok = isinstance(radius_mm, int | float | np.floating | np.integer) and not isinstance(
        radius_mm, bool
    )
    if not (ok and np.isfinite(radius_mm) and lo <= float(radius_mm) <= hi):
        raise TactsenseInputError(
            f"the indenter's radius must be a number of millimetres in {lo:g}-{hi:g}; "
            f"got {radius_mm!r}"
        )
    return float(radius_mm)


@functools.lru_cache(maxsize=8)
def _table(spec, n_sub: int, radius_mm: float | None = None) -> ResponseTable:
    respond = functools.partial(kind_of(spec).shear_response, spec)  # unsupported: says so
    if radius_mm is not None:
        respond = functools.partial(respond, size_mm=radius_mm)
    rows, cols = spec.shape
    px, py = spec.grid.row_pitch_mm, spec.grid.col_pitch_mm
    x = px * (np.arange(rows * n_sub + 1) / n_sub - 0.5)
    y = py * (np.arange(cols * n_sub + 1) / n_sub - 0.5)
    xx, yy = np.meshgrid(x, y, indexing="ij")
    values = respond(np.column_stack([xx.ravel(), yy.ravel()]))
    values = values.reshape(len(x), len(y), 3, rows * cols * 3)
    coefficients = ndimage.spline_filter1d(values, order=3, axis=0, mode="mirror")
    coefficients = ndimage.spline_filter1d(coefficients, order=3, axis=1, mode="mirror")
    coefficients = np.pad(coefficients, ((2, 2), (2, 2), (0, 0), (0, 0)), mode="reflect")
    return ResponseTable(x, y, values, coefficients)
