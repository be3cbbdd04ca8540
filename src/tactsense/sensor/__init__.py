"""Sensor descriptions: the one place a tactile array is described.

Three kinds share one schema (TOML sections, one validator each, TOML in and out):

* ``finger`` (:class:`SensorSpec`): the paper's cylindrical finger with a hemispherical
  tip, rings along it and strips around it; presets ``initial`` and ``improved``.
* ``pad`` (:class:`PadSpec`): a flat rectangular grid under an elastic layer on a rigid
  substrate; presets ``pad4``, ``pad16``, ``pad12x32``.
* ``points`` (:class:`PointsSpec`): any taxel set as surface positions, normals and
  areas under a locally flat layer; preset ``dome12``.

A TOML without a ``kind`` key is a finger, so every existing description still loads.
Kinds and presets other packages register through the ``tactsense.kinds`` entry points
are found too (:data:`KINDS`, :data:`PRESETS`, :func:`load_sensor`; ``docs/kinds.md``).
"""

from tactsense.sensor.common import (
    STANDARD_GRAVITY,
    VACUUM_PERMITTIVITY,
    Electronics,
    Flaws,
    Layer,
    SensorSpecError,
    SpecBase,
    Transduction,
)
from tactsense.sensor.finger import (
    ArrayLayout,
    Body,
    Elastic,
    Rings,
    SensorSpec,
    fearing1990_improved,
    fearing1990_initial,
)
from tactsense.sensor.pad import Grid, PadSpec
from tactsense.sensor.points import PointsSpec, Taxels, taxels_from_json
from tactsense.sensor.registry import (
    KINDS,
    PRESETS,
    load_sensor,
    preset,
    sensor_from_dict,
    taxel_frame,
)

__all__ = [
    "KINDS",
    "PRESETS",
    "STANDARD_GRAVITY",
    "VACUUM_PERMITTIVITY",
    "ArrayLayout",
    "Body",
    "Elastic",
    "Electronics",
    "Flaws",
    "Grid",
    "Layer",
    "PadSpec",
    "PointsSpec",
    "Rings",
    "SensorSpec",
    "SensorSpecError",
    "SpecBase",
    "Taxels",
    "Transduction",
    "fearing1990_improved",
    "fearing1990_initial",
    "load_sensor",
    "preset",
    "sensor_from_dict",
    "taxel_frame",
    "taxels_from_json",
]
