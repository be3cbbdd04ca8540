"""The kinds of sensor and the presets, by name: the built-in ones and those other
packages register.

Adding a kind: a :class:`~tactsense.sensor.common.SpecBase` dataclass and a
:class:`tactsense.kinds.Kind` registered through the ``tactsense.kinds`` entry-point group
(``docs/kinds.md``); :data:`KINDS` and :data:`PRESETS` then find its description class
(the kind's ``spec_class``) and its presets (its ``presets``) without this package
importing :mod:`tactsense.kinds`. Nothing in ``cli/`` changes.
"""

from __future__ import annotations

import importlib.metadata
import math
from collections.abc import Callable, Iterator, Mapping
from pathlib import Path
from typing import Any

import numpy as np

from tactsense.sensor.common import (
    Electronics,
    Flaws,
    Layer,
    SensorSpecError,
    SpecBase,
    Transduction,
    read_toml,
    use_registry,
)
from tactsense.sensor.finger import SensorSpec, fearing1990_improved, fearing1990_initial
from tactsense.sensor.pad import Grid, PadSpec
from tactsense.sensor.points import PointsSpec, Taxels

GROUP = "tactsense.kinds"
"""The entry-point group other packages register their kinds in (as :mod:`tactsense.kinds`
reads it)."""


def _plugin_entry_points(name: str | None = None) -> list:
    """The ``tactsense.kinds`` entry points that are not built-in kinds (only ``name``'s)."""
    found = importlib.metadata.entry_points(group=GROUP)
    return [
        ep for ep in found if ep.name not in _BUILTIN_KINDS and (name is None or ep.name == name)
    ]


def _load_plugin(ep) -> Any:
    """The object an entry point names (a kind, or its class), or a one-line error."""
    try:
        kind = ep.load()
    except Exception as err:  # a broken plug-in: one line, not a traceback
        raise SensorSpecError(
            f"the sensor kind {ep.name!r} registered by {ep.value!r} failed to load: {err}"
        ) from None
    spec_class = getattr(kind, "spec_class", None)
    if not isinstance(spec_class, type) or not isinstance(getattr(spec_class, "kind", None), str):
        raise SensorSpecError(
            f"the sensor kind {ep.name!r} registered by {ep.value!r} has no spec_class (a "
            "SpecBase dataclass with a kind name); expected a tactsense.kinds.Kind"
        )
    return kind


class _Registered(Mapping):
    """Built-in entries first, then those the ``tactsense.kinds`` entry points add, read
    lazily: looking up a built-in name loads no plug-in; an unknown kind's name loads the
    plug-in of that name only; listing loads them all."""

    def __init__(self, builtin: dict[str, Any], read: Callable[[Any], dict[str, Any]]):
        self._builtin = builtin
        self._read = read

    def _plugins(self, name: str | None = None) -> dict[str, Any]:
        found: dict[str, Any] = {}
        for ep in _plugin_entry_points(name):
            for key, value in self._read(_load_plugin(ep)).items():
                if key not in self._builtin:
                    found.setdefault(key, value)
        return found

    def __getitem__(self, key: str) -> Any:
        if key in self._builtin:
            return self._builtin[key]
        if not isinstance(key, str):
            raise KeyError(key)
        found = self._plugins(key)  # a kind's entry point is named for it
        if key not in found:
            found = self._plugins()
        return found[key]

    def __contains__(self, key: object) -> bool:
        try:
            self[key]  # type: ignore[index]
        except KeyError:
            return False
        return True

    def __iter__(self) -> Iterator[str]:
        return iter({**self._builtin, **self._plugins()})

    def __len__(self) -> int:
        return len({**self._builtin, **self._plugins()})

    def __repr__(self) -> str:
        return f"{type(self).__name__}({dict(self)!r})"


_BUILTIN_KINDS: dict[str, type] = {"finger": SensorSpec, "pad": PadSpec, "points": PointsSpec}

KINDS: Mapping[str, type] = _Registered(
    _BUILTIN_KINDS, lambda kind: {kind.spec_class.kind: kind.spec_class}
)
"""TOML ``kind`` -> the class that describes it (a TOML without ``kind`` is a finger): the
built-in kinds and those registered through the ``tactsense.kinds`` entry points."""

_PAPER = "Fearing (1990)"
_PROVENANCE = (
    "Elastic layer: the paper's skin rubber (E = 2.5e5 Pa, nu = 0.5, " + _PAPER + ", "
    "section 2.3). Electronics and flaws: the paper's finger (sections 2-3), assumed to "
    "hold for this pad. Array size: a class of pad labs own; pitch, electrode size, layer "
    "thickness, sensing depth, scan rate and transduction gain are assumptions, not "
    "taken from a datasheet."
)


def pad4() -> PadSpec:
    """A 4x4 capacitive pad at 5 mm pitch under 4 mm of rubber (a bench-top skin patch).

    The dielectric is softer than the rubber, as the paper's (7e4 Pa under 2.5e5 Pa,
    section 2.3): its plates close by about 3.6 times the rubber's strain.
    """
    return PadSpec(
        name="pad4",
        description="4x4 capacitive pad, 5 mm pitch, 4 mm rubber layer. " + _PROVENANCE,
        grid=Grid(
            rows=4,
            cols=4,
            row_pitch_mm=5.0,
            col_pitch_mm=5.0,
            electrode_x_mm=4.0,
            electrode_y_mm=4.0,
        ),
        layer=Layer(
            thickness_mm=4.0, youngs_modulus_pa=2.5e5, poisson_ratio=0.5, sensing_depth_mm=2.0
        ),
        transduction=Transduction(
            kind="capacitive", strain_gain=3.6, dielectric_thickness_mm=0.5, dielectric_constant=4.0
        ),
        electronics=Electronics(scan_rate_hz=100.0),
        flaws=Flaws(),
    )


def pad16() -> PadSpec:
    """A 16x16 piezoresistive pad at 2.5 mm pitch under 2 mm of rubber (a gripper pad)."""
    return PadSpec(
        name="pad16",
        description="16x16 piezoresistive pad, 2.5 mm pitch, 2 mm rubber layer. " + _PROVENANCE,
        grid=Grid(
            rows=16,
            cols=16,
            row_pitch_mm=2.5,
            col_pitch_mm=2.5,
            electrode_x_mm=2.0,
            electrode_y_mm=2.0,
        ),
        layer=Layer(
            thickness_mm=2.0, youngs_modulus_pa=2.5e5, poisson_ratio=0.5, sensing_depth_mm=1.5
        ),
        transduction=Transduction(kind="resistive", counts_per_strain=20000.0),
        electronics=Electronics(nominal_counts=100.0, scan_rate_hz=100.0),
        flaws=Flaws(),
    )


def pad12x32() -> PadSpec:
    """A 12x32 piezoresistive strip at 2 mm pitch under 1.5 mm of rubber (a palm patch)."""
    return PadSpec(
        name="pad12x32",
        description="12x32 piezoresistive pad, 2 mm pitch, 1.5 mm rubber layer. " + _PROVENANCE,
        grid=Grid(
            rows=12,
            cols=32,
            row_pitch_mm=2.0,
            col_pitch_mm=2.0,
            electrode_x_mm=1.6,
            electrode_y_mm=1.6,
        ),
        layer=Layer(
            thickness_mm=1.5, youngs_modulus_pa=2.5e5, poisson_ratio=0.5, sensing_depth_mm=1.0
        ),
        transduction=Transduction(kind="resistive", counts_per_strain=20000.0),
        electronics=Electronics(nominal_counts=100.0, scan_rate_hz=50.0),
        flaws=Flaws(),
    )


def dome12() -> PointsSpec:
    """Twelve taxels on a 7.5-mm dome, a fingertip module given as a point set.

    A ring of eight at 50 deg from the apex, a ring of three at 20 deg and one at the
    apex: the layout is an assumption in the spirit of capacitive fingertips with about a
    dozen taxels (for example the iCub fingertip's 12), not a copy of one.
    """
    radius = 7.5
    directions = [(0.0, 0.0)]
    directions += [(20.0, 120.0 * k) for k in range(3)]
    directions += [(50.0, 45.0 * k) for k in range(8)]
    normals = []
    for polar, azimuth in directions:
        p, a = math.radians(polar), math.radians(azimuth)
        normals.append((math.sin(p) * math.cos(a), math.sin(p) * math.sin(a), math.cos(p)))
    positions = [tuple(float(radius * c) for c in n) for n in normals]
    return PointsSpec(
        name="dome12",
        description="12 taxels on a 7.5-mm dome, 2 mm rubber layer (point set). " + _PROVENANCE,
        taxels=Taxels(
            positions_mm=tuple(positions),
            normals=tuple(tuple(float(v) for v in n) for n in normals),
            area_mm2=tuple([6.0] * len(positions)),
        ),
        layer=Layer(
            thickness_mm=2.0, youngs_modulus_pa=2.5e5, poisson_ratio=0.5, sensing_depth_mm=1.5
        ),
        transduction=Transduction(kind="capacitive"),
        electronics=Electronics(scan_rate_hz=50.0),
        flaws=Flaws(),
    )


def icub_fingertip() -> PointsSpec:
    """The iCub humanoid's capacitive fingertip: 12 taxels, 8 bits, readings fall under load.

    Taxel centres and normals: the layout IIT publishes for the fingertip's flexible PCB
    (:data:`ICUB_FTX2_TAXELS`, positions precise to about 0.5 mm by its own note). That
    is the current fingertip's board; the fingertips of 2010-2014 (Schmitz et al., IROS
    2010: 12 taxels on a flexible PCB over silicone foam, 14.5 mm long, 13 mm wide) have
    no published taxel coordinates, and the 12-taxel layout is taken to be the same.
    Electronics: 8-bit readings (the AD7147 capacitance-to-digital converter's output as
    the skin firmware sends it) of 255 in principle and about 241-248 untouched in fact
    (the iCub grasp dataset, Soh et al. 2012), falling under pressure; the rest reading
    is taken as 245. Assumed, not measured: electrode area (12 mm^2), layer (2 mm, the
    paper's rubber) and the 50-Hz scan.
    """
    positions = tuple(tuple(float(v) for v in p) for _, p, _ in ICUB_FTX2_TAXELS)
    normals = tuple(tuple(float(v) for v in n) for _, _, n in ICUB_FTX2_TAXELS)
    return PointsSpec(
        name="icub_fingertip",
        description=(
            "iCub fingertip: 12 capacitive taxels, 8-bit readings that fall under load "
            "(rest about 245). Taxel centres and normals: IIT's published layout of the "
            "fingertip's flexible PCB (icub-tech-iit/electronics-boards-public, "
            "sensor-boards/ftx2). Electrode area, layer and scan rate are assumptions, not "
            "taken from a datasheet."
        ),
        taxels=Taxels(positions_mm=positions, normals=normals, area_mm2=(12.0,) * 12),
        layer=Layer(
            thickness_mm=2.0, youngs_modulus_pa=2.5e5, poisson_ratio=0.5, sensing_depth_mm=1.5
        ),
        transduction=Transduction(kind="capacitive", polarity="falling"),
        electronics=Electronics(adc_bits=8, nominal_counts=245.0, scan_rate_hz=50.0),
        flaws=Flaws(),
    )


ICUB_FTX2_TAXELS = (
    # (taxel, centre [mm], outward normal) in taxel order, as published for the iCub
    # fingertip's flexible PCB ("ftx2"): icub-tech-iit/electronics-boards-public,
    # sensor-boards/ftx2/README.md (commit 81734f5903de5d72ec09c02317186ed51c6b32ab).
    # Root frame at the centre of the rotation axis of the fingertip's support; x runs
    # along the finger towards its base (the tip end is taxel 11 at x = -20.9 mm).
    (0, (-10.3, 2.2, -3.8), (0.0, 0.5, -0.866025)),
    (1, (-10.3, 4.4, 0.0), (0.0, 1.0, 0.0)),
    (2, (-10.3, 2.2, 3.8), (0.0, 0.5, 0.866025)),
    (3, (-12.5, -1.4, 4.4), (0.0, 0.0, 1.0)),
    (4, (-12.5, -1.4, -4.4), (0.0, 0.0, -1.0)),
    (5, (-14.1, 2.2, 3.8), (0.0, 0.5, 0.866025)),
    (6, (-14.1, 4.4, 0.0), (0.0, 1.0, 0.0)),
    (7, (-14.1, 2.2, -3.8), (0.0, 0.5, -0.866025)),
    (8, (-18.7, 1.6, -2.5), (-0.5, 0.471671, -0.72631)),
    (9, (-18.7, 3.15, 0.0), (-0.5, 0.866025, 0.0)),
    (10, (-18.7, 1.6, 2.5), (-0.5, 0.471671, 0.72631)),
    (11, (-20.9, 0.0, 0.0), (-1.0, 0.0, 0.0)),
)
"""The iCub fingertip's 12 taxels: published centres [mm] and normals, in frame order."""


_FSR_SHEET = (
    "Interlink FSR 400 Series Data Sheet: open at rest (> 10 MOhm), hysteresis +10 % "
    "average, drift < 5 % per log10(time), resistance -15 % after 1 h at +85 degC"
)
_FSR_GUIDE = (
    "Interlink FSR Integration Guide: resistance about 1/force (conductance exponent 1), "
    "read through a voltage divider"
)


def _percent_of_full_scale(percent: float, bits: int = 12) -> float:
    """Read noise of ``percent`` of a ``bits``-bit converter's full scale [counts]."""
    return round(percent / 100.0 * (2**bits - 1), 1)


def fsr16() -> PadSpec:
    """A 16x16 force-sensing-resistor matrix, zero at rest, read through a divider.

    The cells' habits come from Interlink's FSR 400 data sheet and integration guide
    (:mod:`tactsense.physics.piezo`): open at rest (reads 0), conductance about
    proportional to the load, hysteresis (+10 % average: ``hysteresis = 0.2``), drift
    under load (< 5 % per decade of time: 0.05), about 0.003/K with temperature; a
    passive matrix scanned with its unscanned lines floating (``crosstalk = 1``). Read
    noise 1 % of full scale (41 counts of 12 bits), the issue's 1-2 %. The creep is the
    FSR's own (``drift_per_decade``), not the paper's rubber's: the viscoelastic
    fractions are 0 (the overlay is taken not to creep). Assumed: the
    geometry (4 mm pitch, 3.5-mm cells, under 4 mm of the paper's rubber, sensed 3 mm
    deep), the divider's resistor (equal to a cell's resistance under about 1 N, the
    geometric middle of the FSR 402's 0.1-10 N, as Sensitronics' AN-1 advises), and
    100 Hz.
    """
    return PadSpec(
        name="fsr16",
        description=(
            "16x16 FSR matrix, 4 mm pitch, reads 0 at rest, 12-bit divider readout. "
            f"Cells: {_FSR_SHEET}; {_FSR_GUIDE}. Assumed: geometry, 4 mm rubber overlay, "
            "divider at 1 N, 100 Hz, noise 1 % of full scale."
        ),
        grid=Grid(
            rows=16,
            cols=16,
            row_pitch_mm=4.0,
            col_pitch_mm=4.0,
            electrode_x_mm=3.5,
            electrode_y_mm=3.5,
        ),
        layer=Layer(
            thickness_mm=4.0, youngs_modulus_pa=2.5e5, poisson_ratio=0.5, sensing_depth_mm=3.0
        ),
        transduction=Transduction(kind="piezoresistive", counts_per_strain=40000.0, exponent=1.0),
        electronics=Electronics(adc_bits=12, nominal_counts=0.0, scan_rate_hz=100.0),
        flaws=Flaws(
            read_noise_counts=_percent_of_full_scale(1.0),
            hysteresis=0.2,
            drift_per_decade=0.05,
            temperature_coefficient_per_k=0.003,
            crosstalk=1.0,
            delayed_fraction=0.0,
            creep_fraction=0.0,
        ),
    )


def dsa9205() -> PadSpec:
    """A piezoresistive robot-hand matrix like the Weiss Robotics DSA 9205 of the
    Schunk SDH: 14 rows of 6 cells at 3.4 mm pitch, 12 bits, zero at rest.

    Sizes: the SDH's six pads are 6 cells wide and 14 (proximal) or 13 (distal) long
    (SDHLibrary-C++ ``dsa.h``: ``DSA_MAX_PREAMBLE_SEARCH = 2*3*(6*(14+13)) + 16``); the
    3.4-mm pitch and 12 bits are the DSA 9205's commonly quoted figures, not checked
    against a Weiss datasheet here. The conductive rubber's habits are taken as an FSR's
    (hysteresis 0.2, drift 0.05 per decade, an assumption); its controller is taken to
    isolate the scan (``crosstalk = 0``, an assumption). Read noise 1 % of full scale;
    creep as ``fsr16``'s (the drift, no viscoelastic fractions).
    Assumed: 3 mm of rubber sensed 2 mm deep, 3-mm cells, the divider at 1 N, 30 Hz.
    """
    return PadSpec(
        name="dsa9205",
        description=(
            "6x14 piezoresistive robot-hand matrix (Weiss Robotics DSA 9205-like, Schunk "
            "SDH), 3.4 mm pitch, reads 0 at rest, 12 bits. Sizes: SDHLibrary dsa.h (6x14 "
            "and 6x13 pads); pitch and bits: the DSA 9205's quoted figures. Assumed: "
            "FSR-like habits, isolated scan, 3 mm rubber, divider at 1 N, 30 Hz, noise "
            "1 % of full scale."
        ),
        grid=Grid(
            rows=14,
            cols=6,
            row_pitch_mm=3.4,
            col_pitch_mm=3.4,
            electrode_x_mm=3.0,
            electrode_y_mm=3.0,
        ),
        layer=Layer(
            thickness_mm=3.0, youngs_modulus_pa=2.5e5, poisson_ratio=0.5, sensing_depth_mm=2.0
        ),
        transduction=Transduction(kind="piezoresistive", counts_per_strain=24000.0, exponent=1.0),
        electronics=Electronics(adc_bits=12, nominal_counts=0.0, scan_rate_hz=30.0),
        flaws=Flaws(
            read_noise_counts=_percent_of_full_scale(1.0),
            hysteresis=0.2,
            drift_per_decade=0.05,
            temperature_coefficient_per_k=0.003,
            crosstalk=0.0,
            delayed_fraction=0.0,
            creep_fraction=0.0,
        ),
    )


_BUILTIN_PRESETS: dict[str, Callable[[], SpecBase]] = {
    "initial": fearing1990_initial,
    "improved": fearing1990_improved,
    "pad4": pad4,
    "pad16": pad16,
    "pad12x32": pad12x32,
    "dome12": dome12,
    "icub_fingertip": icub_fingertip,
    "fsr16": fsr16,
    "dsa9205": dsa9205,
}

PRESETS: Mapping[str, Callable[[], SpecBase]] = _Registered(
    _BUILTIN_PRESETS, lambda kind: dict(getattr(kind, "presets", None) or {})
)
"""Sensors by short name (the fingers also answer to ``fearing1990_...``): the built-in
ones, then the ``presets`` of the kinds registered through the ``tactsense.kinds`` entry
points."""


def preset(name: str = "initial") -> SpecBase:
    """A sensor by short name, built-in or a registered kind's (``tactsense sensor show
    NAME`` prints it)."""
    key = name.removeprefix("fearing1990_")
    if key not in PRESETS:
        raise SensorSpecError(f"unknown preset {name!r}; available: {', '.join(PRESETS)}")
    return PRESETS[key]()


def sensor_from_dict(
    data: dict[str, Any], *, source: str = "sensor description", expected: type | None = None
) -> SpecBase:
    """Any kind of sensor from TOML tables: ``kind`` picks the class (default finger)."""
    if not isinstance(data, dict):
        raise SensorSpecError(f"{source}: expected a table of sections, got {type(data).__name__}")
    kind = data.get("kind")
    extends = data.get("extends")
    if (
        kind is None
        and isinstance(extends, str)
        and extends.removeprefix("fearing1990_") in PRESETS
    ):
        kind = preset(extends).kind  # extends = "pad16" says it is a pad
    kind = kind or "finger"
    if kind not in KINDS:
        raise SensorSpecError(
            f"{source}: kind = {kind!r} is not a sensor kind; expected one of {', '.join(KINDS)}"
        )
    cls = KINDS[kind]
    named = getattr(expected, "kind", None)
    if expected is not None and expected is not cls and KINDS.get(named) is expected:
        raise SensorSpecError(
            f"{source} describes a {kind} sensor; expected a {expected.kind} sensor"
        )
    try:
        return cls.from_dict(data, source=source)
    except SensorSpecError:
        raise
    except (ValueError, TypeError, KeyError, AttributeError) as err:
        # a kind from another package whose description checks by raising: one line
        raise SensorSpecError(f"{source}: invalid {kind} description: {err}") from None


use_registry(PRESETS, sensor_from_dict)


def load_sensor(source: str | Path | SpecBase | None = None) -> SpecBase:
    """A sensor from a preset name, a TOML path, or an existing spec (default: initial)."""
    if source is None:
        return fearing1990_initial()
    if isinstance(source, SpecBase):
        return source
    text = str(source)
    if text.removeprefix("fearing1990_") in _BUILTIN_PRESETS:
        return preset(text)
    if not Path(text).exists() and text.removeprefix("fearing1990_") in PRESETS:
        return preset(text)  # a plug-in's (a file of that name would come first)
    if not Path(text).exists():
        raise SensorSpecError(
            f"no preset or sensor file named {text!r}; presets: {', '.join(PRESETS)}, "
            "or give the path of a sensor TOML file"
        )
    if Path(text).is_dir():
        raise SensorSpecError(f"sensor {text} is a folder; expected a preset or a TOML file")
    data = read_toml(text)
    if isinstance(data, dict):
        data.setdefault("name", Path(text).stem)  # a description without a name: its file's
    return sensor_from_dict(data, source=text)


def taxel_frame(spec: SpecBase) -> tuple[np.ndarray, np.ndarray]:
    """Surface positions [mm] and outward unit normals of every taxel, frame order, (N, 3).

    Asked of any kind: estimation and display ask "where is taxel i" here instead of
    testing which kind a sensor is.
    """
    return spec.taxel_positions_mm(), spec.taxel_normals()
