"""The sensor description: the one place a tactile finger is described.

A :class:`SensorSpec` holds every parameter of a finger, grouped in sections
that mirror the paper: the array layout, the body, the elastic medium, the
copper rings, the electronics and the flaws. Two presets reproduce the
designs of Fearing (1990): :func:`fearing1990_initial` (3.8 mm by 45 degrees,
the finger of most of the paper's experiments) and
:func:`fearing1990_improved` (3.3 mm by 18 degrees).

A custom sensor is described in TOML with the same sections and keys as the
dataclasses below; :meth:`SensorSpec.from_toml` validates it and says exactly
what is wrong.

References
----------
.. [1] R. S. Fearing, "Tactile Sensing Mechanisms", The International Journal
   of Robotics Research 9(3), 1990.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np

from tactsense.sensor.checks import (
    check_electronics,
    check_flaws,
)
from tactsense.sensor.common import (
    VACUUM_PERMITTIVITY,
    Electronics,
    Flaws,
    SpecBase,
)


@dataclass(frozen=True)
class ArrayLayout:
    """Layout of the tactel array on the finger.

    Rows run along the finger: row 0 is the row under the hemispherical tip
    (when ``tip_row`` is true), rows 1.. are the rings on the cylinder, row 1
    nearest the tip. Columns run around the circumference.
    """

    cylinder_rows: int = 7
    """Rings (rows) on the cylindrical part of the finger [-]."""
    cols: int = 8
    """Strips (columns) around the circumference, physically present [-]."""
    tip_row: bool = True
    """Whether a row of tactels lies under the hemispherical tip."""
    wired_rows: int = 8
    """Rows connected to the electronics, counted from the tip row [-]."""
    wired_cols: int = 8
    """Columns connected to the electronics [-]."""
    wired_col_offset: int = 0
    """Index of the first wired physical column [-]."""
    spacing_axial_mm: float = 3.8
    """Centre-to-centre spacing of the rings along the finger [mm]."""
    spacing_angle_deg: float = 45.0
    """Angular spacing of the strips around the circumference [deg]."""
    first_row_axial_mm: float = 1.1
    """Axial position of the first cylinder ring, measured from the junction
    of hemisphere and cylinder toward the base [mm]."""
    tip_row_axial_mm: float = -9.975
    """Surface position of the tip row: arc length along a meridian from the
    junction, negative onto the hemisphere [mm]. -pi*R/4 is 45 deg latitude."""
    first_col_angle_deg: float = 0.0
    """Angle of physical column 0 around the finger [deg]."""

    @property
    def physical_rows(self) -> int:
        return self.cylinder_rows + int(self.tip_row)


@dataclass(frozen=True)
class Body:
    """Shape of the finger: a cylinder with a hemispherical end on a rigid core."""

    cylinder_length_mm: float = 25.0
    """Length of the cylindrical part [mm]."""
    diameter_mm: float = 25.4
    """Outer diameter of the finger [mm]."""
    core_diameter_mm: float = 17.7
    """Diameter of the rigid Delrin core [mm]."""


@dataclass(frozen=True)
class Elastic:
    """Elastic medium above the capacitors (section 4 of [1])."""

    youngs_modulus_pa: float = 2.5e5
    """Young's modulus of the skin rubber (DPR 4280-LV) [Pa]."""
    poisson_ratio: float = 0.5
    """Poisson's ratio of the rubber measured on a separate sample [-]."""
    effective_depth_mm: float = 3.8
    """Depth of the equivalent line-load model fitted in section 4.1 [mm]."""
    effective_poisson_ratio: float = 0.4
    """Poisson's ratio fitted in section 4.1 (plane stress) [-]."""
    model: str = "plane_stress"
    """Two-dimensional elastic model along the finger: plane_stress or plane_strain."""
    plate_depth_mm: float = 3.2
    """Physical depth of the top capacitor plate (the ring) [mm]."""
    tip_depth_mm: float = 6.0
    """Effective depth of the tip row under the hemisphere [mm]."""


@dataclass(frozen=True)
class Rings:
    """Copper rings and dielectric: the circumferential spreading of the load."""

    ring_width_mm: float = 2.5
    """Width of the driven copper rings (top plates) [mm]."""
    strip_width_mm: float = 5.1
    """Width of the sensing copper strips (bottom plates) [mm]."""
    ring_thickness_mm: float = 0.07
    """Thickness of the copper of the rings (2-oz copper) [mm]."""
    copper_modulus_pa: float = 1.2e11
    """Young's modulus of copper [Pa]."""
    dielectric_thickness_mm: float = 0.5
    """Nominal plate separation d_o, the molded dielectric layer [mm]."""
    dielectric_modulus_pa: float = 7.0e4
    """Effective Young's modulus of the molded dielectric layer [Pa]."""
    dielectric_constant: float = 4.0
    """Relative permittivity K_o of the dielectric [-]."""


_SECTIONS: dict[str, type] = {
    "array": ArrayLayout,
    "body": Body,
    "elastic": Elastic,
    "rings": Rings,
    "electronics": Electronics,
    "flaws": Flaws,
}


@dataclass(frozen=True)
class SensorSpec(SpecBase):
    """Complete description of a tactile finger.

    Construct from a preset (:func:`preset`), from TOML
    (:meth:`from_toml`) or directly. Instances are immutable and validated
    on construction; use :meth:`replace` to derive a variant.
    """

    name: str = "custom"
    description: str = ""
    array: ArrayLayout = field(default_factory=ArrayLayout)
    body: Body = field(default_factory=Body)
    elastic: Elastic = field(default_factory=Elastic)
    rings: Rings = field(default_factory=Rings)
    electronics: Electronics = field(default_factory=Electronics)
    flaws: Flaws = field(default_factory=Flaws)

    kind: ClassVar[str] = "finger"
    SECTIONS: ClassVar[dict[str, type]] = _SECTIONS

    def problems(self) -> list[str]:
        """Every problem with this description, as readable sentences (none: valid)."""
        return _validate(self)

    # ---- derived quantities -------------------------------------------------
    @property
    def shape(self) -> tuple[int, int]:
        """Shape ``(rows, cols)`` of a frame: the wired array [-]."""
        return (self.array.wired_rows, self.array.wired_cols)

    def summary(self) -> list[tuple[str, str]]:
        """Derived quantities worth printing, as (label, value with unit) rows."""
        return [
            ("kind", "finger"),
            ("frame shape (rows, cols)", f"{self.shape}"),
            ("closes the circumference", str(self.closes_circumference)),
            ("junction capacitance", f"{self.junction_capacitance_f * 1e12:.3f} pF"),
            ("ring flexural length", f"{self.ring_flexural_length_mm:.3f} mm"),
        ]

    def taxel_positions_mm(self) -> np.ndarray:
        """Skin point above every wired tactel, frame order, shape (rows*cols, 3) [mm].

        3-D axes of :mod:`tactsense.geometry`: x along the axis toward the base.
        """
        from tactsense.sensor.cylinder import surface_to_xyz, tactel_centers

        axial, angle = tactel_centers(self)
        return surface_to_xyz(self, axial, angle).reshape(-1, 3)

    def taxel_normals(self) -> np.ndarray:
        """Outward unit normal of the skin at every wired tactel, shape (rows*cols, 3) [-]."""
        points = self.taxel_positions_mm()
        normals = points.copy()
        normals[points[:, 0] >= 0, 0] = 0.0  # on the cylinder: radial
        return normals / np.linalg.norm(normals, axis=1, keepdims=True)

    @property
    def radius_mm(self) -> float:
        """Outer radius of the finger [mm]."""
        return self.body.diameter_mm / 2.0

    @property
    def ring_radius_mm(self) -> float:
        """Radius at which the rings (top plates) lie [mm]."""
        return self.radius_mm - self.elastic.plate_depth_mm

    @property
    def row_axial_mm(self) -> np.ndarray:
        """Surface axial position of each wired row, shape (rows,) [mm]."""
        layout = self.array
        cylinder = layout.first_row_axial_mm + layout.spacing_axial_mm * np.arange(
            layout.cylinder_rows
        )
        positions = (
            np.concatenate([[layout.tip_row_axial_mm], cylinder]) if layout.tip_row else cylinder
        )
        return positions[: layout.wired_rows]

    @property
    def col_angle_deg(self) -> np.ndarray:
        """Angle of each wired column around the finger, shape (cols,) [deg]."""
        layout = self.array
        index = layout.wired_col_offset + np.arange(layout.wired_cols)
        return _wrap_deg(layout.first_col_angle_deg + layout.spacing_angle_deg * index)

    @property
    def row_depth_mm(self) -> np.ndarray:
        """Effective elastic depth of each wired row, shape (rows,) [mm]."""
        depth = np.full(self.array.wired_rows, self.elastic.effective_depth_mm)
        if self.array.tip_row:
            depth[0] = self.elastic.tip_depth_mm
        return depth

    @property
    def closes_circumference(self) -> bool:
        """True when the wired columns cover the full circle, so the layout wraps."""
        span = self.array.wired_cols * self.array.spacing_angle_deg
        return bool(abs(span - 360.0) < 1e-6)

    @property
    def junction_capacitance_f(self) -> float:
        """Undeflected capacitance C_So of one junction, eq. 2 of [1] [F]."""
        area = self.rings.ring_width_mm * self.rings.strip_width_mm * 1e-6
        separation = self.rings.dielectric_thickness_mm * 1e-3
        return self.rings.dielectric_constant * VACUUM_PERMITTIVITY * area / separation

    @property
    def ring_flexural_length_mm(self) -> float:
        """Characteristic length 1/lambda of a ring as a beam on the dielectric [mm].

        A ring of thickness t and Young's modulus E_cu resting on a
        dielectric of thickness t_d and modulus E_d is a beam on a Winkler
        foundation of modulus k = E_d b / t_d; with EI = E_cu b t^3 / 12,
        lambda^4 = k / (4 EI) = 3 E_d / (E_cu t_d t^3) (the width b cancels).
        """
        rings = self.rings
        thickness = rings.ring_thickness_mm * 1e-3
        lam4 = (
            3.0
            * rings.dielectric_modulus_pa
            / (rings.copper_modulus_pa * rings.dielectric_thickness_mm * 1e-3 * thickness**3)
        )
        return 1e3 / lam4**0.25


def _wrap_deg(angle):
    return (np.asarray(angle, dtype=float) + 180.0) % 360.0 - 180.0


def _validate(spec: SensorSpec) -> list[str]:
    """Every problem with a sensor description, as readable sentences."""
    problems: list[str] = []

    def positive(section: str, key: str, value: float) -> None:
        if not (isinstance(value, int | float) and math.isfinite(value) and value > 0):
            problems.append(f"[{section}] {key} must be positive; got {value!r}")

    a, b, e, r, el, f = (
        spec.array,
        spec.body,
        spec.elastic,
        spec.rings,
        spec.electronics,
        spec.flaws,
    )
    for section, obj in (
        ("array", a),
        ("body", b),
        ("elastic", e),
        ("rings", r),
    ):
        for fld in dataclasses.fields(obj):
            value = getattr(obj, fld.name)
            if fld.name in {
                "first_row_axial_mm",
                "tip_row_axial_mm",
                "first_col_angle_deg",
                "wired_col_offset",
                "tip_row",
                "model",
            }:
                continue
            positive(section, fld.name, value)
    if problems:
        return problems
    if a.wired_rows > a.physical_rows:
        problems.append(
            f"[array] wired_rows = {a.wired_rows} is larger than the array "
            f"({a.physical_rows} rows: {a.cylinder_rows} on the cylinder"
            f"{' + 1 under the tip' if a.tip_row else ''})"
        )
    if a.wired_col_offset < 0 or a.wired_col_offset + a.wired_cols > a.cols:
        problems.append(
            f"[array] wired columns {a.wired_col_offset}..{a.wired_col_offset + a.wired_cols - 1} "
            f"do not fit in the array of {a.cols} columns"
        )
    if a.cols * a.spacing_angle_deg > 360.0 + 1e-6:
        problems.append(
            f"[array] {a.cols} columns at {a.spacing_angle_deg} deg span "
            f"{a.cols * a.spacing_angle_deg:g} deg, more than the full circle"
        )
    last_row = a.first_row_axial_mm + a.spacing_axial_mm * (a.cylinder_rows - 1)
    if a.first_row_axial_mm < 0 or last_row > b.cylinder_length_mm:
        problems.append(
            f"[array] cylinder rings from {a.first_row_axial_mm:g} to {last_row:g} mm do not fit "
            f"on the cylinder (0 to {b.cylinder_length_mm:g} mm)"
        )
    quarter = math.pi * spec.radius_mm / 2.0
    if a.tip_row and not (-quarter <= a.tip_row_axial_mm < 0):
        problems.append(
            f"[array] tip_row_axial_mm = {a.tip_row_axial_mm:g} must lie on the hemisphere, "
            f"in [-{quarter:.3f}, 0) mm"
        )
    if b.core_diameter_mm >= b.diameter_mm:
        problems.append(
            f"[body] core_diameter_mm = {b.core_diameter_mm:g} must be smaller than "
            f"diameter_mm = {b.diameter_mm:g}"
        )
    skin = (b.diameter_mm - b.core_diameter_mm) / 2.0
    if e.plate_depth_mm >= spec.radius_mm:
        problems.append(f"[elastic] plate_depth_mm = {e.plate_depth_mm:g} exceeds the radius")
    elif e.plate_depth_mm > skin:
        problems.append(
            f"[elastic] plate_depth_mm = {e.plate_depth_mm:g} lies below the core "
            f"(skin is {skin:g} mm thick)"
        )
    for key in ("poisson_ratio", "effective_poisson_ratio"):
        nu = getattr(e, key)
        if not (-1.0 < nu <= 0.5):
            problems.append(
                f"[elastic] {key} = {nu:g} is out of range; Poisson's ratio lies in (-1, 0.5]"
            )
    if e.model not in ("plane_stress", "plane_strain"):
        problems.append(f"[elastic] model = {e.model!r}; expected 'plane_stress' or 'plane_strain'")
    check_electronics(el, problems)
    check_flaws(f, spec.shape, problems)
    return problems


def fearing1990_initial() -> SensorSpec:
    """The initial finger of [1]: 7x8 cylinder + 1x8 tip, 3.8 mm by 45 deg.

    Most experiments of [1] (Figs. 7, 13, 16, 20, 22-25) were made on this
    finger. Eight strips at 45 deg close the circle, and all 8x8 tactels are
    wired.
    """
    return SensorSpec(
        name="fearing1990_initial",
        description="Fearing (1990) initial finger: 3.8 mm along the length, 45 deg around",
        array=ArrayLayout(
            cylinder_rows=7,
            cols=8,
            tip_row=True,
            wired_rows=8,
            wired_cols=8,
            wired_col_offset=0,
            spacing_axial_mm=3.8,
            spacing_angle_deg=45.0,
            first_row_axial_mm=1.1,
            tip_row_axial_mm=-9.975,
            first_col_angle_deg=0.0,
        ),
    )


def fearing1990_improved() -> SensorSpec:
    """The improved finger of [1]: 7x12 cylinder + 1x12 tip, 3.3 mm by 18 deg.

    Only an 8x8 subset (7x8 on the cylinder, 1x8 under the tip) is wired,
    the middle eight columns; they span 126 deg and do not close the circle.
    """
    return SensorSpec(
        name="fearing1990_improved",
        description="Fearing (1990) improved finger: 3.3 mm along the length, 18 deg around",
        array=ArrayLayout(
            cylinder_rows=7,
            cols=12,
            tip_row=True,
            wired_rows=8,
            wired_cols=8,
            wired_col_offset=2,
            spacing_axial_mm=3.3,
            spacing_angle_deg=18.0,
            first_row_axial_mm=2.6,
            tip_row_axial_mm=-9.975,
            first_col_angle_deg=-99.0,
        ),
    )
