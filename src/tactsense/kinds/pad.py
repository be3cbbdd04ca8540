"""A flat rectangular grid of taxels under an elastic layer on a rigid substrate."""

from __future__ import annotations

from typing import Any

from tactsense.kinds.base import Kind
from tactsense.sensor.pad import PadSpec


class PadKind(Kind):
    name = "pad"
    spec_class = PadSpec
    image_grid = True
    multi_contact = True

    # ---- the view and the commands (r5-cliview) ----
    view_drawing = "grid"


KIND: Any = PadKind()
