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
    # ---- simulation, scenarios and design (r5-sim) ----
    design_model = "layer"

    def layer_strain(self, spec, indenters):
        from tactsense.physics.pad_response import pad_strain

        return pad_strain(spec, indenters)

    def surface_grid(self, spec):
        g = spec.grid
        return (g.row_pitch_mm, g.rows), (g.col_pitch_mm, g.cols)

    def size_text(self, spec):
        g = spec.grid
        return f"{g.rows} x {g.cols} taxels", f"{g.row_pitch_mm:g} x {g.col_pitch_mm:g} mm"


KIND: Any = PadKind()
