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
import tomllib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import tomli_w

from tactsense._validation import TactsenseInputError

VACUUM_PERMITTIVITY = 8.8541878128e-12  # [F/m]
STANDARD_GRAVITY = 9.80665  # [m/s^2]


class SensorSpecError(TactsenseInputError):
    """Raised when a sensor description is invalid."""


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


@dataclass(frozen=True)
class Electronics:
    """Drive, amplifier and A/D converter (section 2.2 of [1])."""

    load_capacitance_pf: float = 100.0
    """Lumped load capacitance C_L: cable, amplifier input, strays [pF]."""
    load_resistance_ohm: float = 1.0e6
    """Amplifier input resistance R_L [ohm]."""
    drive_voltage_v: float = 10.0
    """Amplitude of the drive voltage V_d [V]."""
    drive_frequency_hz: float = 1.0e5
    """Frequency of the drive voltage [Hz]."""
    adc_bits: int = 12
    """Resolution of the A/D converter [bit]."""
    adc_full_scale_v: float = 5.0
    """Input voltage at the A/D converter's full scale [V]."""
    nominal_counts: float = 2000.0
    """Reading of an undeflected tactel, V_o in A/D units; sets the amplifier gain [counts]."""
    scan_rate_hz: float = 7.0
    """Frame rate of the row/column scan [Hz]."""


@dataclass(frozen=True)
class Flaws:
    """Parameters of the sensor's flaws (section 3 of [1]).

    Which flaws a simulation switches on is chosen when simulating; the
    numbers that describe them live here.
    """

    gain_spread_sd: float = 0.35
    """Relative standard deviation of the per-tactel force threshold (Fig. 8) [-]."""
    gain_min: float = 0.5
    """Smallest per-tactel gain multiplier (worst threshold 0.8 g at mean 0.4 g) [-]."""
    gain_max: float = 2.0
    """Largest per-tactel gain multiplier (best threshold 0.2 g at mean 0.4 g) [-]."""
    gain_seed: int = 1990
    """Seed of this finger's gain spread: the gains belong to the finger, not to a run."""
    force_jitter_n: float = 0.0098
    """Standard deviation of the applied force per application, 1 gram-force (Figs. 10-11) [N]."""
    position_jitter_mm: float = 0.05
    """Standard deviation of the probe position per application [mm]."""
    read_noise_counts: float = 0.3
    """Standard deviation of electronic noise before quantization [counts]."""
    nonlinear_saturation: float = 0.712
    """Deflection scale c of the stiffening law d_meas = d / (1 + d/c) (Fig. 6) [-]."""
    delayed_fraction: float = 0.538
    """Fraction of the elastic response that is delayed (Fig. 12) [-]."""
    delayed_time_constant_s: float = 0.0422
    """Time constant of the delayed elastic response (Fig. 12) [s]."""
    creep_fraction: float = 1.14
    """Creep gain relative to the elastic response, reached after long loading [-]."""
    creep_time_constant_s: float = 20.0
    """Time constant of creep and of the recovery of the elastic set [s]."""
    dead_tactels: tuple[tuple[int, int], ...] = ()
    """Wired tactels (row, col) that give no signal."""


_SECTIONS: dict[str, type] = {
    "array": ArrayLayout,
    "body": Body,
    "elastic": Elastic,
    "rings": Rings,
    "electronics": Electronics,
    "flaws": Flaws,
}


@dataclass(frozen=True)
class SensorSpec:
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

    def __post_init__(self) -> None:
        problems = _validate(self)
        if problems:
            raise SensorSpecError(
                f"invalid sensor description {self.name!r}:\n  - " + "\n  - ".join(problems)
            )

    # ---- derived quantities -------------------------------------------------
    @property
    def shape(self) -> tuple[int, int]:
        """Shape ``(rows, cols)`` of a frame: the wired array [-]."""
        return (self.array.wired_rows, self.array.wired_cols)

    def check_tactel(self, row: int, col: int) -> tuple[int, int]:
        """Return ``(row, col)`` after checking it addresses a wired tactel."""
        rows, cols = self.shape
        if not (0 <= row < rows and 0 <= col < cols):
            raise SensorSpecError(
                f"tactel ({row}, {col}) is outside the {rows}x{cols} array of wired tactels "
                f"of {self.name!r}"
            )
        return int(row), int(col)

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

    @property
    def scan_period_s(self) -> float:
        """Time between the starts of two frames [s]."""
        return 1.0 / self.electronics.scan_rate_hz

    # ---- (de)serialization -------------------------------------------------
    def to_dict(self) -> dict[str, Any]:
        """The description as nested plain dictionaries (TOML sections)."""
        data: dict[str, Any] = {"name": self.name, "description": self.description}
        for section in _SECTIONS:
            values = dataclasses.asdict(getattr(self, section))
            if section == "flaws":
                values["dead_tactels"] = [list(t) for t in values["dead_tactels"]]
            data[section] = values
        return data

    @classmethod
    def from_dict(cls, data: dict[str, Any], *, source: str = "sensor description") -> SensorSpec:
        """Build a sensor from nested dictionaries, naming every unknown key.

        Every key of every section must be given, unless the description names a
        preset to start from with ``extends = "initial"`` (or ``"improved"``): then
        the keys it leaves out take that preset's values. A description that leaves
        keys out without saying where their values come from is an error, so that a
        typo or a forgotten section never silently becomes the initial finger.
        """
        if not isinstance(data, dict):
            raise SensorSpecError(
                f"{source}: expected a table of sections, got {type(data).__name__}"
            )
        problems: list[str] = []
        allowed_top = {"name", "description", "extends", *_SECTIONS}
        for key in data:
            if key not in allowed_top:
                problems.append(
                    f"unknown key {key!r} at top level; allowed: {', '.join(sorted(allowed_top))}"
                )
        base: dict[str, Any] | None = None
        if "extends" in data:
            extends = data["extends"]
            if not isinstance(extends, str) or extends.removeprefix("fearing1990_") not in PRESETS:
                raise SensorSpecError(
                    f"{source}: extends = {extends!r} is not a preset; "
                    f"available: {', '.join(PRESETS)}"
                )
            base = preset(extends).to_dict()
        elif not any(section in data for section in _SECTIONS):
            raise SensorSpecError(
                f"{source}: no sections ({', '.join(f'[{s}]' for s in _SECTIONS)}); describe "
                'every section, or start from a preset with extends = "initial" '
                "(tactsense sensor show prints a complete description to edit)"
            )
        sections: dict[str, Any] = {}
        for section, kind in _SECTIONS.items():
            values = data.get(section, {})
            if not isinstance(values, dict):
                problems.append(f"[{section}] must be a table, got {type(values).__name__}")
                continue
            known = {f.name: f for f in dataclasses.fields(kind)}
            if base is None:
                missing = [key for key in known if key not in values]
                if missing:
                    problems.append(f"[{section}] is missing {', '.join(missing)}")
            else:
                values = {**base[section], **values}
            converted: dict[str, Any] = {}
            for key, value in values.items():
                if key not in known:
                    problems.append(
                        f"unknown key {key!r} in [{section}]; allowed: {', '.join(sorted(known))}"
                    )
                    continue
                try:
                    converted[key] = _convert(known[key].type, value)
                except (TypeError, ValueError) as error:
                    problems.append(f"[{section}] {key} = {value!r}: {error}")
            sections[section] = converted
        if problems:
            hint = ""
            if any(" is missing " in problem for problem in problems):
                hint = (
                    '\n  (give every key, or add extends = "initial" at the top to take '
                    "the keys left out from a preset)"
                )
            raise SensorSpecError(f"{source}:\n  - " + "\n  - ".join(problems) + hint)
        return cls(
            name=str(data.get("name", "custom")),
            description=str(data.get("description", "")),
            **{s: kind(**sections[s]) for s, kind in _SECTIONS.items()},
        )

    @classmethod
    def from_toml(cls, path: str | Path) -> SensorSpec:
        """Load and validate a sensor description from a TOML file."""
        path = Path(path)
        try:
            text = path.read_text(encoding="utf-8")
        except OSError as error:
            raise SensorSpecError(f"cannot read sensor file {path}: {error.strerror}") from None
        try:
            data = tomllib.loads(text)
        except tomllib.TOMLDecodeError as error:
            raise SensorSpecError(f"{path} is not valid TOML: {error}") from None
        return cls.from_dict(data, source=str(path))

    @classmethod
    def from_toml_string(cls, text: str) -> SensorSpec:
        """Validate a sensor description given as TOML text."""
        try:
            data = tomllib.loads(text)
        except tomllib.TOMLDecodeError as error:
            raise SensorSpecError(f"sensor description is not valid TOML: {error}") from None
        return cls.from_dict(data)

    def to_toml_string(self) -> str:
        """The description as TOML text."""
        return tomli_w.dumps(self.to_dict())

    def to_toml(self, path: str | Path, *, overwrite: bool = False) -> Path:
        """Write the description as TOML; an existing file is kept unless ``overwrite``."""
        path = Path(path)
        if path.exists() and not overwrite:
            raise FileExistsError(f"{path} exists; not replacing it (overwrite=True replaces it)")
        path.write_text(self.to_toml_string(), encoding="utf-8")
        return path

    def replace(self, **sections: Any) -> SensorSpec:
        """A copy with whole sections or ``section__key`` values replaced.

        Examples
        --------
        >>> spec = fearing1990_initial().replace(elastic__effective_depth_mm=3.0)
        >>> spec.elastic.effective_depth_mm
        3.0
        """
        updates: dict[str, Any] = {}
        nested: dict[str, dict[str, Any]] = {}
        for key, value in sections.items():
            if "__" in key:
                section, sub = key.split("__", 1)
                nested.setdefault(section, {})[sub] = value
            else:
                updates[key] = value
        for section, values in nested.items():
            if section not in _SECTIONS:
                raise SensorSpecError(
                    f"unknown section {section!r}; allowed: {', '.join(_SECTIONS)}"
                )
            current = updates.get(section, getattr(self, section))
            try:
                updates[section] = dataclasses.replace(current, **values)
            except TypeError as error:
                raise SensorSpecError(f"[{section}]: {error}") from None
        return dataclasses.replace(self, **updates)


def _convert(annotation: Any, value: Any) -> Any:
    kind = str(annotation)
    if kind == "bool":
        if not isinstance(value, bool):
            raise TypeError("expected true or false")
        return value
    if kind == "int":
        if isinstance(value, bool) or not isinstance(value, int):
            raise TypeError("expected an integer")
        return value
    if kind == "float":
        if isinstance(value, bool) or not isinstance(value, int | float):
            raise TypeError("expected a number")
        return float(value)
    if kind == "str":
        if not isinstance(value, str):
            raise TypeError("expected a string")
        return value
    if kind.startswith("tuple"):
        pairs = []
        for item in value:
            if len(item) != 2 or not all(isinstance(v, int) for v in item):
                raise TypeError("expected a list of [row, col] integer pairs")
            pairs.append((int(item[0]), int(item[1])))
        return tuple(pairs)
    return value


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
        ("electronics", el),
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
    if not 1 <= el.adc_bits <= 24:
        problems.append(f"[electronics] adc_bits = {el.adc_bits} must lie in 1..24")
    elif el.nominal_counts >= 2**el.adc_bits:
        problems.append(
            f"[electronics] nominal_counts = {el.nominal_counts:g} does not fit in a "
            f"{el.adc_bits}-bit converter (max {2**el.adc_bits - 1})"
        )
    for key in (
        "gain_spread_sd",
        "force_jitter_n",
        "position_jitter_mm",
        "read_noise_counts",
        "creep_fraction",
    ):
        value = getattr(f, key)
        if not (math.isfinite(value) and value >= 0):
            problems.append(f"[flaws] {key} must be non-negative; got {value!r}")
    for key in (
        "nonlinear_saturation",
        "delayed_time_constant_s",
        "creep_time_constant_s",
        "gain_min",
        "gain_max",
    ):
        positive("flaws", key, getattr(f, key))
    if f.gain_min > 1.0 or f.gain_max < 1.0:
        problems.append(
            f"[flaws] gain_min <= 1 <= gain_max is required; got {f.gain_min}, {f.gain_max}"
        )
    if not 0.0 <= f.delayed_fraction <= 1.0:
        problems.append(f"[flaws] delayed_fraction must lie in [0, 1]; got {f.delayed_fraction!r}")
    for row, col in f.dead_tactels:
        if not (0 <= row < a.wired_rows and 0 <= col < a.wired_cols):
            problems.append(
                f"[flaws] dead tactel ({row}, {col}) is outside the wired array "
                f"{a.wired_rows}x{a.wired_cols}"
            )
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


PRESETS = {
    "initial": fearing1990_initial,
    "improved": fearing1990_improved,
}


def preset(name: str = "initial") -> SensorSpec:
    """A built-in sensor by short name: ``"initial"`` or ``"improved"``."""
    key = name.removeprefix("fearing1990_")
    if key not in PRESETS:
        raise SensorSpecError(f"unknown preset {name!r}; available: {', '.join(PRESETS)}")
    return PRESETS[key]()


def load_sensor(source: str | Path | SensorSpec | None = None) -> SensorSpec:
    """A sensor from a preset name, a TOML path, or an existing spec (default: initial)."""
    if source is None:
        return fearing1990_initial()
    if isinstance(source, SensorSpec):
        return source
    text = str(source)
    if text.removeprefix("fearing1990_") in PRESETS:
        return preset(text)
    if not Path(text).exists():
        raise SensorSpecError(
            f"no preset or sensor file named {text!r}; presets: {', '.join(PRESETS)}, "
            "or give the path of a sensor TOML file"
        )
    return SensorSpec.from_toml(text)
