"""The paper's finger (Fearing 1990): a cylinder of rings and strips with a tip row."""

from __future__ import annotations

import math
from types import MappingProxyType
from typing import Any

from tactsense.kinds.base import Kind
from tactsense.sensor.finger import SensorSpec, fearing1990_improved, fearing1990_initial


class FingerKind(Kind):
    name = "finger"
    spec_class = SensorSpec
    presets = MappingProxyType({"initial": fearing1990_initial, "improved": fearing1990_improved})
    position_names = ("axial_mm", "angle_deg")
    position_units = ("mm", "deg")
    image_grid = True
    multi_contact = False

    def periodic(self, spec: SensorSpec) -> bool:
        return bool(spec.closes_circumference)

    def jitter(self, spec: SensorSpec, first_mm: float, second_mm: float) -> tuple[float, float]:
        """Along the finger [mm] and around it [deg]."""
        return first_mm, math.degrees(second_mm / spec.radius_mm)

    # ---- estimation (r5-estimate) ----------------------------------------------
    array_calibration = False


KIND: Any = FingerKind()
