"""Any set of taxels given as surface positions, normals and areas under a locally flat
elastic layer."""

from __future__ import annotations

from typing import Any

from tactsense.kinds.base import Kind
from tactsense.sensor.points import PointsSpec


class PointsKind(Kind):
    name = "points"
    spec_class = PointsSpec
    label = "point set"
    image_grid = False
    multi_contact = True


KIND: Any = PointsKind()
