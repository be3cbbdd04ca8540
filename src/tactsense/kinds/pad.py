"""A flat rectangular grid of taxels under an elastic layer on a rigid substrate."""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np

from tactsense.kinds.base import Kind
from tactsense.sensor.pad import PadSpec


class PadKind(Kind):
    name = "pad"
    spec_class = PadSpec
    image_grid = True
    multi_contact = True

    # ---- estimation (r5-estimate) ----------------------------------------------
    response_fit = True

    def contact_response(
        self, spec: PadSpec, *, half: int = 0, n_sub: int = 8, signed: bool = False
    ) -> np.ndarray:
        """The layer's response to the scenarios' probe (a 1.6-mm sphere) per newton at
        ``n_sub + 1`` sub-taxel offsets along each axis [-/N], computed on a pad of the
        same pitch, electrodes, layer and transduction large enough for the window (the
        layer's response does not depend on where it is applied)."""
        from tactsense.physics.indenters import SphereProbe
        from tactsense.physics.pad_response import pad_strain
        from tactsense.sensor.common import Flaws

        size = 2 * half + 2
        grid = dataclasses.replace(spec.grid, rows=size, cols=size)
        big = dataclasses.replace(spec, grid=grid, flaws=Flaws())
        g = big.grid
        newtons = 0.49
        kernel = np.empty((n_sub + 1, n_sub + 1, 2 * half + 1, 2 * half + 1))
        step = 1.0 / n_sub
        for a in range(n_sub + 1):
            for b in range(n_sub + 1):
                probe = SphereProbe(
                    (half + a * step) * g.row_pitch_mm, (half + b * step) * g.col_pitch_mm, newtons
                )
                strain = pad_strain(big, [probe])[: 2 * half + 1, : 2 * half + 1] / newtons
                if spec.transduction.kind != "capacitive":
                    kernel[a, b] = strain if signed else np.maximum(strain, 0.0)
                else:
                    kernel[a, b] = spec.transduction.strain_gain * strain
        return kernel


KIND: Any = PadKind()
