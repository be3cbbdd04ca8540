"""Kinds and presets other packages register through the ``tactsense.kinds`` entry points
are found by the sensor registry (``KINDS``, ``PRESETS``, ``preset``, ``load_sensor``,
``sensor_from_dict``) without ``tactsense.sensor`` importing ``tactsense.kinds``."""

from __future__ import annotations

import dataclasses
import importlib.metadata
import sys
import types

import pytest

from tactsense.sensor import (
    KINDS,
    PRESETS,
    PadSpec,
    SensorSpecError,
    load_sensor,
    preset,
    sensor_from_dict,
)
from tactsense.sensor.registry import pad4


@dataclasses.dataclass(frozen=True)
class RingSpec(PadSpec):
    kind = "ring_test"


def ring8() -> RingSpec:
    return RingSpec(**{f.name: getattr(pad4(), f.name) for f in dataclasses.fields(PadSpec)})


class RingKind:
    name = "ring_test"
    spec_class = RingSpec
    presets = types.MappingProxyType({"ring8_test": ring8})


@pytest.fixture
def plugins(monkeypatch):
    """A module ``ring_test_kind`` with a good kind and an entry point to a broken one."""
    module = types.ModuleType("ring_test_kind")
    module.KIND = RingKind()
    monkeypatch.setitem(sys.modules, "ring_test_kind", module)
    group = "tactsense.kinds"
    found = [
        importlib.metadata.EntryPoint("ring_test", "ring_test_kind:KIND", group),
        importlib.metadata.EntryPoint("broken_test", "no_such_module_xyz:KIND", group),
    ]
    real = importlib.metadata.entry_points

    def entry_points(**selection):
        if selection.get("group") == group:
            return importlib.metadata.EntryPoints(found)
        return real(**selection)

    monkeypatch.setattr(importlib.metadata, "entry_points", entry_points)
    return found


def test_builtins_load_no_plugin(plugins):
    assert KINDS["pad"] is PadSpec
    assert preset("pad16").kind == "pad"
    assert load_sensor("initial").kind == "finger"


def test_a_plugin_kind_is_found_by_name(plugins):
    assert KINDS["ring_test"] is RingSpec
    assert "ring_test" in KINDS
    data = ring8().to_dict()
    assert data["kind"] == "ring_test"
    assert type(sensor_from_dict(data)) is RingSpec


def test_a_broken_plugin_is_one_line(plugins):
    with pytest.raises(SensorSpecError) as error:
        KINDS["broken_test"]
    message = str(error.value)
    assert "\n" not in message
    assert "'broken_test'" in message and "no_such_module_xyz:KIND" in message
    with pytest.raises(SensorSpecError, match="failed to load"):
        list(PRESETS)


def test_a_plugin_preset_is_found(plugins):
    plugins.pop()  # only the good one
    assert "ring8_test" in PRESETS
    assert "ring_test" in list(KINDS)
    assert type(preset("ring8_test")) is RingSpec
    assert type(load_sensor("ring8_test")) is RingSpec
    with pytest.raises(SensorSpecError, match="ring8_test"):
        preset("nope")
