"""A flat pad: a rectangular grid of taxels under an elastic layer on a rigid substrate.

Coordinates (``docs/nomenclature.md``), those of the ROS tactile toolbox's URDF
``<array>`` (``urdf_tactile``: taxel ``(row, col)`` at ``x = row * spacing.x``,
``y = col * spacing.y``, normal ``+z``): frames are ``(..., rows, cols)``; taxel ``(0, 0)``
is centred at ``x = y = 0`` on the free surface, ``x`` runs with the row index
(``row_pitch_mm`` apart), ``y`` with the column index (``col_pitch_mm`` apart), ``z`` is
the outward normal (the surface is ``z = 0``, the sensing elements lie at
``z = -sensing_depth_mm``, the substrate at ``z = -thickness_mm``).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np

from tactsense.sensor.checks import (
    check_electronics,
    check_flaws,
    check_layer,
    check_transduction,
    habit_rows,
    positive,
)
from tactsense.sensor.common import (
    Electronics,
    Flaws,
    Layer,
    SpecBase,
    Transduction,
    capacitance_f,
)


@dataclass(frozen=True)
class Grid:
    """The rectangular grid of taxels."""

    rows: int = 16
    """Taxel rows (axis -2 of a frame) [-]."""
    cols: int = 16
    """Taxel columns (axis -1 of a frame) [-]."""
    row_pitch_mm: float = 2.5
    """Centre-to-centre distance between rows, along x [mm]."""
    col_pitch_mm: float = 2.5
    """Centre-to-centre distance between columns, along y [mm]."""
    electrode_x_mm: float = 2.0
    """Extent of a taxel's electrode along x (the row direction) [mm]."""
    electrode_y_mm: float = 2.0
    """Extent of a taxel's electrode along y (the column direction) [mm]."""


class GridGeometry:
    """Where the taxels of a flat rectangular grid are (``grid``: a :class:`Grid`): the
    pad's coordinates, shared by every kind laid out on one (pads, three-axis pads)."""

    @property
    def shape(self) -> tuple[int, int]:
        """Shape ``(rows, cols)`` of the grid of taxels [-] (a frame is ``frame_shape``)."""
        return (self.grid.rows, self.grid.cols)

    @property
    def x_mm(self) -> np.ndarray:
        """x of each row's centre, shape (rows,) [mm]."""
        return self.grid.row_pitch_mm * np.arange(self.grid.rows, dtype=float)

    @property
    def y_mm(self) -> np.ndarray:
        """y of each column's centre, shape (cols,) [mm]."""
        return self.grid.col_pitch_mm * np.arange(self.grid.cols, dtype=float)

    @property
    def extent_mm(self) -> tuple[float, float]:
        """Size ``(along x, along y)`` of the pad, a half pitch beyond the outer taxels [mm]."""
        g = self.grid
        return (g.rows * g.row_pitch_mm, g.cols * g.col_pitch_mm)

    def taxel_positions_mm(self) -> np.ndarray:
        """Centre of every taxel on the free surface, frame order, shape (rows*cols, 3) [mm]."""
        x, y = np.meshgrid(self.x_mm, self.y_mm, indexing="ij")
        return np.column_stack([x.ravel(), y.ravel(), np.zeros(x.size)])

    def taxel_normals(self) -> np.ndarray:
        """Outward normal of every taxel, shape (rows*cols, 3) [-]."""
        normals = np.zeros((self.n_taxels, 3))
        normals[:, 2] = 1.0
        return normals


@dataclass(frozen=True)
class PadSpec(GridGeometry, SpecBase):
    """Complete description of a flat taxel pad.

    Construct from a preset (``tactsense.sensor.preset("pad16")``), from TOML with
    ``kind = "pad"``, or directly; immutable and validated on construction.
    """

    name: str = "pad"
    description: str = ""
    grid: Grid = field(default_factory=Grid)
    layer: Layer = field(default_factory=Layer)
    transduction: Transduction = field(default_factory=Transduction)
    electronics: Electronics = field(default_factory=Electronics)
    flaws: Flaws = field(default_factory=Flaws)

    kind: ClassVar[str] = "pad"
    SECTIONS: ClassVar[dict[str, type]] = {
        "grid": Grid,
        "layer": Layer,
        "transduction": Transduction,
        "electronics": Electronics,
        "flaws": Flaws,
    }

    def problems(self) -> list[str]:
        """Every problem with this description, as readable sentences (none: valid)."""
        return _validate(self)

    def summary(self) -> list[tuple[str, str]]:
        """Derived quantities worth printing, as (label, value with unit) rows."""
        g, layer, t = self.grid, self.layer, self.transduction
        rows = [
            ("kind", "pad"),
            ("frame shape (rows, cols)", f"{self.shape}"),
            ("pitch (rows x cols)", f"{g.row_pitch_mm:g} x {g.col_pitch_mm:g} mm"),
            ("pad size (x, y)", f"{self.extent_mm[0]:g} x {self.extent_mm[1]:g} mm"),
            (
                "layer",
                f"{layer.thickness_mm:g} mm, E = {layer.youngs_modulus_pa:g} Pa, "
                f"nu = {layer.poisson_ratio:g}",
            ),
            (
                "sensing depth / pitch",
                f"{layer.sensing_depth_mm / max(g.row_pitch_mm, g.col_pitch_mm):.2f}",
            ),
            ("transduction", f"{t.kind}, reading {t.polarity} under load"),
            (
                "rest reading",
                f"{self.electronics.nominal_counts:g} counts of {2**self.electronics.adc_bits - 1}",
            ),
        ]
        if t.kind == "capacitive":
            rows.append(("junction capacitance", f"{self.junction_capacitance_f * 1e12:.3f} pF"))
        rows += habit_rows(self)
        return rows

    @property
    def electrode_area_mm2(self) -> float:
        """Area of one taxel's electrode [mm^2]."""
        return self.grid.electrode_x_mm * self.grid.electrode_y_mm

    @property
    def junction_capacitance_f(self) -> float:
        """Undeflected capacitance of a capacitive taxel, eq. 2 of the paper [F]."""
        return capacitance_f(self.transduction, self.electrode_area_mm2)


def _validate(spec: PadSpec) -> list[str]:
    problems: list[str] = []
    g = spec.grid
    for fld in dataclasses.fields(g):
        positive(problems, "grid", fld.name, getattr(g, fld.name))
    if not problems:
        if g.electrode_x_mm > g.row_pitch_mm or g.electrode_y_mm > g.col_pitch_mm:
            problems.append(
                f"[grid] electrodes of {g.electrode_x_mm:g} x {g.electrode_y_mm:g} mm "
                f"overlap at a pitch of {g.row_pitch_mm:g} x {g.col_pitch_mm:g} mm"
            )
        if g.rows * g.cols > 65_536:
            problems.append(f"[grid] {g.rows} x {g.cols} taxels: at most 65,536 are supported")
    check_layer(spec.layer, problems)
    check_transduction(spec.transduction, problems)
    check_electronics(spec.electronics, problems, spec.transduction)
    if not problems:
        check_flaws(spec.flaws, spec.shape, problems)
    return problems
