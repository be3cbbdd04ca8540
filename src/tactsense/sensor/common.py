"""What every kind of sensor shares: the electronics, the flaws, the elastic layer, the
transduction, TOML input and output, and the checks.

A sensor kind is a frozen dataclass with a ``name``, a ``description`` and one field per
TOML section; :class:`SpecBase` gives it TOML I/O, ``replace`` and the derived
quantities every command needs (``shape``, ``scan_period_s``, taxel positions).
"""

from __future__ import annotations

import dataclasses
import tomllib
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path
from types import MappingProxyType
from typing import Any, ClassVar

import numpy as np
import tomli_w

from tactsense._validation import TactsenseInputError

VACUUM_PERMITTIVITY = 8.8541878128e-12  # [F/m]
STANDARD_GRAVITY = 9.80665  # [m/s^2]


_KIND_WORDS = {"finger": "finger", "pad": "pad", "points": "point set"}
"""How a message names each kind of sensor."""


_PRESETS: Mapping[str, Callable[[], Any]] = MappingProxyType({})
"""The presets a description may extend (``extends = "NAME"``): the registry's
:data:`~tactsense.sensor.registry.PRESETS`, handed over by :func:`use_registry` when the
registry is imported (it imports this module, so this one does not import it)."""

_FROM_DICT: Callable[..., Any] | None = None
"""The registry's :func:`~tactsense.sensor.registry.sensor_from_dict` (the kind picks the
class), handed over by :func:`use_registry`."""


def use_registry(presets: Mapping[str, Callable[[], Any]], from_dict: Callable[..., Any]) -> None:
    """Let ``extends = "NAME"`` find ``presets`` and TOML pick its kind's class with
    ``from_dict`` (called once by :mod:`tactsense.sensor.registry`)."""
    global _PRESETS, _FROM_DICT
    _PRESETS, _FROM_DICT = presets, from_dict


class SensorSpecError(TactsenseInputError):
    """Raised when a sensor description is invalid."""


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
    """Reading of an untouched taxel (V_o of the paper, about 2000 A/D units) [counts].
    0 is allowed where the reading is not the capacitive chain's (a resistive or
    piezoresistive cell reads 0 at rest); below ``2**adc_bits`` always."""
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
    creep_known: bool = False
    """Whether the four creep values above were measured on this sensor (``true`` in its
    TOML) rather than left at the paper's rubber (the default). Measured frames (a live
    stream, an imported recording) get creep compensation only when it is ``true``; a
    simulation knows its own creep. The one key a description may leave out."""
    dead_tactels: tuple[tuple[int, int], ...] = ()
    """Wired tactels (row, col) that give no signal."""
    hysteresis: float = 0.0
    """Piezoresistive cells: excess conductance of the unloading branch over the loading
    one, at light load after a press, relative [-] (0: none). The unloading branch is
    ``g (1 + hysteresis (1 - g / g_peak))`` (:func:`tactsense.physics.piezo.hysteresis`);
    its mean excess over the branch is half this value (the FSR 400 data sheet's "+10 %
    average" is 0.2). Switched on by the flaw ``hysteresis``."""
    drift_per_decade: float = 0.0
    """Piezoresistive cells: rise of the conductance under a constant load per decade of
    time under load, relative [-] (FSR 400 data sheet: < 0.05 per log10(time)). Switched
    on by the flaw ``drift``."""
    temperature_coefficient_per_k: float = 0.0
    """Piezoresistive cells: relative change of the conductance per kelvin of warming
    [1/K] (FSR 400 data sheet: resistance -15 % after 1 h at +85 degC, about 0.003/K).
    Switched on by the flaw ``drift``."""
    temperature_rate_k_per_s: float = 0.0
    """Warming of the sensor during a simulated recording, from the start [K/s] (0: held
    at its calibration temperature). Switched on by the flaw ``drift``."""
    crosstalk: float = 0.0
    """Resistive and piezoresistive matrices: share of the conductance of the parallel
    paths through the other cells of a row/column scan that reaches a reading, in [0, 1]
    (0: isolated scan, the unscanned lines held at the sensed potential; 1: every
    unscanned line floating, the full ghost of a passive matrix;
    :func:`tactsense.physics.crosstalk.scan_conductance`). Switched on by the flaw
    ``crosstalk``."""


@dataclass(frozen=True)
class Layer:
    """The elastic layer over a flat array, bonded to a rigid substrate."""

    thickness_mm: float = 3.0
    """Thickness h of the elastic layer, from the free surface to the substrate [mm]."""
    youngs_modulus_pa: float = 2.5e5
    """Young's modulus of the layer [Pa]."""
    poisson_ratio: float = 0.5
    """Poisson's ratio of the layer (0.5: incompressible rubber) [-]."""
    sensing_depth_mm: float = 2.5
    """Depth below the free surface at which the sensing element reads the strain [mm]."""
    substrate: str = "rigid"
    """What the layer is bonded to: only ``rigid`` (perfect adhesion, no displacement)."""


@dataclass(frozen=True)
class Transduction:
    """From the strain at the sensing depth to the reading of a taxel.

    ``capacitive``: the paper's chain (eqs. 1-4): the plates close by a fraction
    ``strain_gain * eps`` of their separation (eq. 3 when 1) and the reading rises as
    the capacitance, from ``nominal_counts`` untouched. ``resistive``: a generic
    linear transducer, reading ``nominal_counts + counts_per_strain * eps``.
    ``piezoresistive``: an FSR or conductive-rubber cell read through a voltage divider:
    conductance as a power of the compressive strain, a reading that saturates at the
    converter's full scale (:mod:`tactsense.physics.piezo`).

    ``polarity = "falling"`` mirrors the reading about its rest value: it reads
    ``nominal_counts`` minus the change the rising sensor would read (iCub's capacitive
    fingertips read about 245 untouched and less when pressed), down to 0.
    """

    kind: str = "capacitive"
    """``capacitive`` (the paper's chain), ``resistive`` (a generic gain) or
    ``piezoresistive`` (power law through a divider)."""
    polarity: str = "rising"
    """``rising``: the reading rises under load (the paper's finger, FSR and
    piezoresistive cells); ``falling``: it falls from its rest reading."""
    strain_gain: float = 1.0
    """Capacitive: fractional plate deflection per unit compressive strain (eq. 3: 1) [-]."""
    dielectric_thickness_mm: float = 0.5
    """Capacitive: nominal plate separation d_o [mm]."""
    dielectric_constant: float = 4.0
    """Capacitive: relative permittivity K_o of the dielectric [-]."""
    counts_per_strain: float = 20000.0
    """Resistive: change of the reading per unit compressive strain [counts].
    Piezoresistive: the span of the divider (full scale minus the rest reading) over the
    strain at which the cell's conductance equals the divider resistor's (half the span);
    the slope of the reading at small strain when ``exponent`` is 1."""
    exponent: float = 1.0
    """Piezoresistive: the cell's conductance rises as the compressive strain to this power
    (an FSR's resistance falls roughly as 1/force: 1) [-]."""


def convert(annotation: Any, value: Any) -> Any:
    """A TOML value converted to a field's type, or TypeError saying what was expected."""
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
    if kind.startswith("tuple[tuple[int"):
        pairs = []
        for item in value:
            if len(item) != 2 or not all(isinstance(v, int) for v in item):
                raise TypeError("expected a list of [row, col] integer pairs")
            pairs.append((int(item[0]), int(item[1])))
        return tuple(pairs)
    if kind.startswith("tuple[tuple[float"):
        try:
            rows = tuple(tuple(float(v) for v in item) for item in value)
        except (TypeError, ValueError):
            raise TypeError("expected a list of lists of numbers") from None
        return rows
    if kind.startswith("tuple[float"):
        try:
            return tuple(float(v) for v in value)
        except (TypeError, ValueError):
            raise TypeError("expected a list of numbers") from None
    return value


def _plain(value: Any) -> Any:
    if isinstance(value, tuple):
        return [_plain(v) for v in value]
    return value


class SpecBase:
    """TOML I/O, ``replace`` and shared derived quantities of every sensor kind.

    A kind sets ``kind`` (its name in TOML) and ``SECTIONS`` (TOML section -> dataclass),
    and defines ``shape`` and ``taxel_positions_mm``/``taxel_normals``.
    """

    kind: ClassVar[str]
    SECTIONS: ClassVar[dict[str, type]]
    components: ClassVar[int] = 1
    """Numbers each taxel reports per frame: 1 (a scalar: the paper's finger, pads, point
    sets) or 3 (a three-axis taxel, :mod:`tactsense.sensor.triaxial`)."""
    component_names: ClassVar[tuple[str, ...]] = ()
    """Names of a taxel's components, in the order of the frame's last axis (``("x",
    "y", "z")``); empty for a scalar taxel."""

    @property
    def frame_shape(self) -> tuple[int, ...]:
        """Shape of one frame: ``shape`` for scalar taxels, ``shape + (components,)``
        when each taxel reports several numbers (the component axis is last)."""
        return tuple(self.shape) if self.components == 1 else (*self.shape, self.components)

    def __post_init__(self) -> None:
        problems = self.problems()
        if problems:
            raise SensorSpecError(
                f"invalid sensor description {self.name!r}:\n  - " + "\n  - ".join(problems)
            )

    def problems(self) -> list[str]:  # pragma: no cover - every kind defines it
        raise NotImplementedError

    # ---- shared derived quantities -------------------------------------------
    @property
    def scan_period_s(self) -> float:
        """Time between the starts of two frames [s]."""
        return 1.0 / self.electronics.scan_rate_hz

    @property
    def n_taxels(self) -> int:
        """Number of taxels in a frame [-]."""
        rows, cols = self.shape
        return rows * cols

    def check_tactel(self, row: int, col: int) -> tuple[int, int]:
        """Return ``(row, col)`` after checking it addresses a wired taxel."""
        rows, cols = self.shape
        if not (0 <= row < rows and 0 <= col < cols):
            raise SensorSpecError(
                f"tactel ({row}, {col}) is outside the {rows}x{cols} array of wired tactels "
                f"of {self.name!r}"
            )
        return int(row), int(col)

    @property
    def kind_label(self) -> str:
        """The kind in words for a message: ``finger``, ``pad`` or ``point set``."""
        return "point set" if self.kind == "points" else self.kind

    def require_kind(self, *kinds: str, what: str = "this command") -> None:
        """Raise a one-line error when this sensor's kind is not one ``what`` handles."""
        if self.kind not in kinds:
            raise SensorSpecError(
                f"{what} works on {' and '.join(f'{k} sensors' for k in kinds)}; "
                f"{self.name!r} is a {self.kind_label}"
            )

    # ---- (de)serialization ---------------------------------------------------
    def to_dict(self) -> dict[str, Any]:
        """The description as nested plain dictionaries (TOML sections)."""
        data: dict[str, Any] = {}
        if self.kind != "finger":  # a finger's TOML is unchanged: no kind key
            data["kind"] = self.kind
        data["name"] = self.name
        data["description"] = self.description
        for section in self.SECTIONS:
            values = dataclasses.asdict(getattr(self, section))
            data[section] = {key: _plain(value) for key, value in values.items()}
        return data

    @classmethod
    def from_dict(cls, data: dict[str, Any], *, source: str = "sensor description"):
        """Build a sensor from nested dictionaries, naming every unknown key.

        Every key of every section must be given, unless the description names a
        preset to start from with ``extends = "NAME"``: then the keys it leaves out take
        that preset's values. A description that leaves keys out without saying where
        their values come from is an error, so that a typo or a forgotten section never
        silently becomes a preset.
        """
        PRESETS = _PRESETS  # the registry's: built-in and registered presets

        if not isinstance(data, dict):
            raise SensorSpecError(
                f"{source}: expected a table of sections, got {type(data).__name__}"
            )
        problems: list[str] = []
        allowed_top = {"kind", "name", "description", "extends", *cls.SECTIONS}
        for key in data:
            if key not in allowed_top:
                problems.append(
                    f"unknown key {key!r} at top level; allowed: {', '.join(sorted(allowed_top))}"
                )
        base: dict[str, Any] | None = None
        if "extends" in data:
            extends = data["extends"]
            key = extends.removeprefix("fearing1990_") if isinstance(extends, str) else None
            if key in PRESETS and PRESETS[key]().kind != cls.kind:
                other = PRESETS[key]().kind
                raise SensorSpecError(
                    f"{source}: extends = {extends!r} is a {_KIND_WORDS.get(other, other)} "
                    f"preset, and this description is a {_KIND_WORDS.get(cls.kind, cls.kind)}"
                    f"'s: add kind = {other!r} at the top"
                )
            if key not in PRESETS:
                every = ", ".join(f"{name} ({make().kind})" for name, make in PRESETS.items())
                raise SensorSpecError(
                    f"{source}: extends = {extends!r} is not a preset; available: {every}"
                )
            base = PRESETS[key]().to_dict()
        elif not any(section in data for section in cls.SECTIONS):
            raise SensorSpecError(
                f"{source}: no sections ({', '.join(f'[{s}]' for s in cls.SECTIONS)}); "
                'describe every section, or start from a preset with extends = "NAME" '
                "(tactsense sensor show prints a complete description to edit)"
                + (
                    '; a pad or a point set says so first: kind = "pad" or kind = "points"'
                    if cls.kind == "finger"
                    else ""
                )
            )
        sections: dict[str, Any] = {}
        for section, section_type in cls.SECTIONS.items():
            values = data.get(section, {})
            if not isinstance(values, dict):
                problems.append(f"[{section}] must be a table, got {type(values).__name__}")
                continue
            known = {f.name: f for f in dataclasses.fields(section_type)}
            if base is None:
                missing = [key for key in known if key not in values and key not in OPTIONAL]
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
                    converted[key] = convert(known[key].type, value)
                except (TypeError, ValueError) as error:
                    problems.append(f"[{section}] {key} = {value!r}: {error}")
            sections[section] = converted
        if problems:
            hint = ""
            if any(" is missing " in problem for problem in problems):
                hint = (
                    '\n  (give every key, or add extends = "PRESET" at the top to take '
                    "the keys left out from a preset)"
                )
            raise SensorSpecError(f"{source}:\n  - " + "\n  - ".join(problems) + hint)
        try:
            built = {s: kind(**sections[s]) for s, kind in cls.SECTIONS.items()}
        except TypeError as error:
            raise SensorSpecError(f"{source}: {error}") from None
        return cls(
            name=str(data.get("name", "custom")),
            description=str(data.get("description", "")),
            **built,
        )

    @classmethod
    def from_toml(cls, path: str | Path):
        """Load and validate a sensor description from a TOML file.

        The file's ``kind`` decides the class returned (a finger when it has none), so
        ``SensorSpec.from_toml`` of a pad's file gives a :class:`PadSpec`.
        """
        return _FROM_DICT(read_toml(path), source=str(path))

    @classmethod
    def from_toml_string(cls, text: str):
        """Validate a sensor description given as TOML text (its ``kind`` picks the class)."""
        try:
            data = tomllib.loads(text)
        except tomllib.TOMLDecodeError as error:
            raise SensorSpecError(f"sensor description is not valid TOML: {error}") from None
        return _FROM_DICT(data)

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

    def replace(self, **sections: Any):
        """A copy with whole sections or ``section__key`` values replaced.

        Examples
        --------
        >>> from tactsense.sensor import fearing1990_initial
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
            if section not in self.SECTIONS:
                raise SensorSpecError(
                    f"unknown section {section!r}; allowed: {', '.join(self.SECTIONS)}"
                )
            current = updates.get(section, getattr(self, section))
            try:
                updates[section] = dataclasses.replace(current, **values)
            except TypeError as error:
                raise SensorSpecError(f"[{section}]: {error}") from None
        return dataclasses.replace(self, **updates)


OPTIONAL = frozenset(
    {
        "creep_known",
        "polarity",
        "exponent",
        "hysteresis",
        "drift_per_decade",
        "temperature_coefficient_per_k",
        "temperature_rate_k_per_s",
        "crosstalk",
    }
)
"""Keys a complete description may leave out: they default (``creep_known``: false, so
that a description written before it existed is not taken to know its creep;
``polarity``: ``rising``, as every description written before it existed; the
piezoresistive exponent and the habits of issue 32, off, so that every description
written before them reads as it did)."""


def read_toml(path: str | Path) -> dict[str, Any]:
    """The tables of a TOML file, or SensorSpecError naming the file."""
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except UnicodeDecodeError:
        raise SensorSpecError(f"{path} is not a text (TOML) file") from None
    except OSError as error:
        raise SensorSpecError(f"cannot read sensor file {path}: {error.strerror}") from None
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as error:
        raise SensorSpecError(f"{path} is not valid TOML: {error}") from None


def capacitance_f(t: Transduction, area_mm2: float) -> float:
    """Undeflected capacitance of a parallel-plate taxel of ``area_mm2``, eq. 2 [F]."""
    return (
        t.dielectric_constant
        * VACUUM_PERMITTIVITY
        * area_mm2
        * 1e-6
        / (t.dielectric_thickness_mm * 1e-3)
    )


def as_unit_vectors(vectors: np.ndarray) -> np.ndarray:
    """Rows of ``vectors`` scaled to unit length."""
    vectors = np.asarray(vectors, dtype=float)
    return vectors / np.linalg.norm(vectors, axis=-1, keepdims=True)
