"""What a page draws once: the layout message, each kind drawn the way its kind says.

:func:`layout_message` asks the sensor's kind (:attr:`tactsense.kinds.Kind.view_drawing`)
how to draw it: ``"unwrapped"`` (the paper's finger cut open), ``"grid"`` (a flat pad in
millimetres) or ``"dots"`` (any taxel set, projected onto the plane normal to its mean
normal). The page draws the interpolated surface itself from weights sent once here:
``surface = W_rows @ deflection[cylinder rows] @ W_cols.T`` is the windowed-sinc
reconstruction of eq. 48 (:func:`tactsense.estimate.finger.interpolate.surface`) on a grid
``SURFACE_STEPS`` times finer than the tactels, periodic around a closed finger.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from matplotlib import colormaps

from tactsense.estimate import Flag
from tactsense.estimate.finger.interpolate import col_weights, row_weights
from tactsense.kinds import kind_of
from tactsense.sensor import SensorSpec, SpecBase
from tactsense.stream.reader import LOSS_KINDS
from tactsense.view.locators import estimates, multi_contact
from tactsense.view.plane import project_points
from tactsense.view.vectors import is_vector, vector_layout

SURFACE_STEPS = 9
"""Points of the interpolated surface per tactel spacing, along and around: the centres
of bands 1/9 of a tactel wide (odd, so that one band is centred on each tactel)."""

COLORMAP = "viridis"
"""Matplotlib colour map of the heat map: its lightness rises monotonically."""


def _finger_geometry(sensor: SensorSpec) -> dict:
    """The finger unwrapped: rows along it (the tip row apart), columns around it."""
    rows, cols = sensor.shape
    first = 1 if sensor.array.tip_row else 0
    cylinder = rows - first
    periodic = bool(sensor.closes_circumference)
    # fine rows over the cylinder rows' span, fine columns over the tactels' span (one
    # whole turn, seam included, when the finger closes)
    # (beyond the first and last rows the surface is held flat, not extrapolated)
    fine_rows = (np.arange(cylinder * SURFACE_STEPS) + 0.5) / SURFACE_STEPS - 0.5
    fine_rows = np.clip(fine_rows, 0.0, cylinder - 1.0)
    fine_cols = (np.arange(cols * SURFACE_STEPS) + 0.5) / SURFACE_STEPS - 0.5
    w_rows = row_weights(fine_rows, cylinder, derivatives=0)
    w_cols = col_weights(fine_cols, cols, periodic, derivatives=0)
    return {
        "geometry": "finger",
        "first_row": first,
        "tip_row": bool(sensor.array.tip_row),
        "closes": periodic,
        "row_axial_mm": [float(v) for v in sensor.row_axial_mm],
        "col_angle_deg": [float(v) for v in sensor.col_angle_deg],
        "spacing_mm": float(sensor.array.spacing_axial_mm),
        "spacing_deg": float(sensor.array.spacing_angle_deg),
        "surface": {
            "row": fine_rows.tolist(),
            "col": fine_cols.tolist(),
            "w_rows": np.round(w_rows, 6).tolist(),
            "w_cols": np.round(w_cols, 6).tolist(),
        },
    }


MAX_FINE = 288
"""At most this many surface points along an axis of a pad (32 taxels at
:data:`SURFACE_STEPS`); a larger pad gets fewer points per pitch (an odd number, at least
one), so the page's work per frame stays bounded."""


def flat_steps(n: int) -> int:
    """Surface points per pitch along a pad's axis of ``n`` taxels (odd, 1 to 9)."""
    steps = min(SURFACE_STEPS, max(1, MAX_FINE // max(n, 1)))
    return steps if steps % 2 else steps - 1


def _flat_weights(n: int) -> tuple[np.ndarray, np.ndarray]:
    """Fine positions [taxel] over ``n`` taxels' span and the windowed-sinc weights (eq. 48's
    kernel, not periodic: the edges are not wrapped) at them, held flat beyond the outer
    taxels; an axis of one taxel is constant."""
    steps = flat_steps(n)
    fine = (np.arange(n * steps) + 0.5) / steps - 0.5
    if n < 2:
        return np.zeros_like(fine), np.ones((fine.size, 1))
    fine = np.clip(fine, 0.0, n - 1.0)
    return fine, row_weights(fine, n, derivatives=0)


def _transduction(sensor) -> dict:
    """How a reading follows from the deflection (the page's counts mode needs it)."""
    t = sensor.transduction
    if is_vector(sensor):  # r8-triview: vector_layout says it
        return {"kind": t.kind, "counts_per_strain": 1.0, "falling": False}
    return {
        "kind": t.kind,
        "counts_per_strain": float(t.counts_per_strain),
        "falling": t.polarity == "falling",
    }


def _pad_geometry(sensor) -> dict:
    """A pad: a flat grid in millimetres, x with the row, y with the column
    (``docs/nomenclature.md``), and the separable interpolated surface."""
    rows, cols = sensor.shape
    g = sensor.grid
    positions = sensor.taxel_positions_mm()
    fine_x, w_x = _flat_weights(rows)
    fine_y, w_y = _flat_weights(cols)
    return {
        "geometry": "plane",
        "u_mm": positions[:, 0].tolist(),
        "v_mm": positions[:, 1].tolist(),
        "u_label": f"x [mm] (rows, {g.row_pitch_mm:g} mm apart)",
        "v_label": f"y [mm] (columns, {g.col_pitch_mm:g} mm apart)",
        "bounds_mm": [
            -0.5 * g.row_pitch_mm,
            (rows - 0.5) * g.row_pitch_mm,
            -0.5 * g.col_pitch_mm,
            (cols - 0.5) * g.col_pitch_mm,
        ],
        "spacing_mm": float(min(g.row_pitch_mm, g.col_pitch_mm)),
        "dot_mm": 0.32 * float(min(g.row_pitch_mm, g.col_pitch_mm)),
        "projection": "the pad seen from outside (its normal +z toward you)",
        "transduction": _transduction(sensor),
        "surface": {
            "row": fine_x.tolist(),
            "col": fine_y.tolist(),
            "w_rows": np.round(w_x, 6).tolist(),
            "w_cols": np.round(w_y, 6).tolist(),
        },
    }


def _points_geometry(sensor) -> dict:
    """Any taxel set: dots at their positions projected onto the plane normal to the mean
    normal (:func:`project_points`); no surface between scattered points. Asks the sensor
    only where its taxels are, so a kind without a drawing of its own shows this way."""
    plane = project_points(sensor.taxel_positions_mm(), sensor.taxel_normals())
    u, v = plane["u_mm"], plane["v_mm"]
    points = np.column_stack([u, v])
    if len(points) > 1:
        gaps = np.linalg.norm(points[:, None] - points[None, :], axis=-1)
        np.fill_diagonal(gaps, np.inf)
        spacing = float(np.median(gaps.min(axis=1)))
    else:
        spacing = 1.0
    if not spacing > 0:
        spacing = 1.0
    areas = getattr(sensor, "areas_mm2", None)
    dot = 0.32 * spacing
    if areas is not None:  # the electrode's own size where it is smaller than that
        dot = min(dot, float(np.sqrt(np.median(areas) / np.pi)))
    margin = max(spacing, 2.0 * dot)
    m = plane["normal"]
    along_z = bool(m[2] > 1.0 - 1e-9)
    return {
        "geometry": "plane",
        "u_mm": u.tolist(),
        "v_mm": v.tolist(),
        "u_label": "x [mm]" if along_z else "u [mm] (in the plane normal to the mean normal)",
        "v_label": "y [mm]" if along_z else "v [mm]",
        "bounds_mm": [
            float(u.min() - margin),
            float(u.max() + margin),
            float(v.min() - margin),
            float(v.max() + margin),
        ],
        "spacing_mm": spacing,
        "dot_mm": dot,
        "projection": (
            "x-y, seen from +z (the mean normal)"
            if along_z
            else "projected along the mean normal "
            f"({m[0]:.2f}, {m[1]:.2f}, {m[2]:.2f}), seen from outside"
        ),
        "transduction": _transduction(sensor),
        "surface": None,
    }


DRAWINGS: dict[str, Callable[[SpecBase], dict]] = {
    "unwrapped": _finger_geometry,
    "grid": _pad_geometry,
    "dots": _points_geometry,
}
"""How the page draws a kind, by its :attr:`~tactsense.kinds.Kind.view_drawing`; a drawing
not listed is drawn as dots at its taxels' positions (:func:`_points_geometry` asks only
``taxel_positions_mm`` and ``taxel_normals``)."""


def not_estimated_note(sensor: SpecBase) -> str | None:
    """The page's one line where there is no contact estimate for the sensor's kind."""
    if estimates(sensor):
        return None
    return f"contact estimation: not yet for {kind_of(sensor).plural}"


def layout_message(sensor: SpecBase, source: dict) -> dict:
    """Everything a page needs once: geometry, surface weights, colour map, source."""
    rows, cols = sensor.shape
    lut = (colormaps[COLORMAP](np.linspace(0.0, 1.0, 256))[:, :3] * 255).round().astype(int)
    message = {
        "type": "layout",
        "sensor": sensor.name,
        "kind": sensor.kind,
        "rows": rows,
        "cols": cols,
        "estimation": not_estimated_note(sensor),
        # several tracked contacts a frame (pads, point sets), or the finger's one
        "multi_contact": multi_contact(sensor),
    }
    message.update(DRAWINGS.get(kind_of(sensor).view_drawing, _points_geometry)(sensor))
    message.update(
        {
            "full_scale": int(2**sensor.electronics.adc_bits - 1),
            "colormap": {"name": COLORMAP, "lut": lut.tolist()},
            "loss_kinds": list(LOSS_KINDS),
            "flags": {flag.name: int(flag) for flag in Flag if flag},
            "source": source,
        }
    )
    if is_vector(sensor):  # r8-triview: the normal component as the map, arrows
        message.update(vector_layout(sensor))
    return message
