"""A flat rectangular grid of taxels under an elastic layer on a rigid substrate."""

from __future__ import annotations

import dataclasses
from types import MappingProxyType
from typing import Any

import numpy as np

from tactsense.kinds.base import RESPONSE_PROBE_N, Kind, signal_per_strain
from tactsense.sensor.pad import PadSpec
from tactsense.sensor.registry import dsa9205, fsr16, pad4, pad12x32, pad16


class PadKind(Kind):
    name = "pad"
    spec_class = PadSpec
    presets = MappingProxyType(
        {"pad4": pad4, "pad16": pad16, "pad12x32": pad12x32, "fsr16": fsr16, "dsa9205": dsa9205}
    )
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

    # ---- forms for other tools: LSL, URDF (r5-interop) -------------------------
    def urdf_array(self, spec: PadSpec) -> dict:
        """Rows along x, columns along y: the electrode's size and the pitches [mm]."""
        g = spec.grid
        return {
            "rows": g.rows,
            "cols": g.cols,
            "size_mm": (g.electrode_x_mm, g.electrode_y_mm),
            "spacing_mm": (g.row_pitch_mm, g.col_pitch_mm),
        }

    def from_urdf_array(self, array, base: PadSpec, *, path, preset: str) -> PadSpec:
        """Rows, columns, pitches (``spacing``) and electrode size (``size``) [m]."""
        from pathlib import Path

        from tactsense._validation import TactsenseInputError
        from tactsense.kinds.urdf import UrdfError
        from tactsense.sensor import sensor_from_dict

        data = base.to_dict()
        data["name"] = array.name
        data["description"] = (
            f"imported from {Path(path).name} (URDF tactile array), on {base.name}"
        )
        data["grid"].update(
            rows=array.rows,
            cols=array.cols,
            row_pitch_mm=abs(array.spacing_m[0]) * 1e3,
            col_pitch_mm=abs(array.spacing_m[1]) * 1e3,
            electrode_x_mm=abs(array.size_m[0]) * 1e3,
            electrode_y_mm=abs(array.size_m[1]) * 1e3,
        )
        if array.update_rate_hz is not None:
            data["electronics"]["scan_rate_hz"] = array.update_rate_hz
        try:
            return sensor_from_dict(data, source=str(path))
        except TactsenseInputError as error:
            raise UrdfError(f"{path}: the array does not fit {base.name!r}: {error}") from None

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
        from tactsense.sensor.common import Flaws

        size = 2 * half + 2
        grid = dataclasses.replace(spec.grid, rows=size, cols=size)
        big = dataclasses.replace(spec, grid=grid, flaws=Flaws())
        g = big.grid
        newtons = RESPONSE_PROBE_N
        kernel = np.empty((n_sub + 1, n_sub + 1, 2 * half + 1, 2 * half + 1))
        step = 1.0 / n_sub
        for a in range(n_sub + 1):
            for b in range(n_sub + 1):
                probe = SphereProbe(
                    (half + a * step) * g.row_pitch_mm, (half + b * step) * g.col_pitch_mm, newtons
                )
                strain = self.layer_strain(big, [probe])[: 2 * half + 1, : 2 * half + 1]
                kernel[a, b] = signal_per_strain(spec, strain / newtons, signed=signed)
        return kernel

    # ---- frames from contacts (r6-fast) ----------------------------------------
    def contact_forward(self, spec: PadSpec):
        """The layer's response tabulated once per layer, electrode and shape and
        superposed per contact (:mod:`tactsense.physics._contact_kernel`)."""
        from tactsense.physics._contact_kernel import PadContactForward

        return PadContactForward(spec)

    # ---- contacts of any size (r6-padfit) ----------------------------------------
    def contact_model(self, spec: PadSpec):
        """The layer's response to Hertzian contacts of any radius, superposed
        (:class:`tactsense.physics._pad_model.PadContactModel`)."""
        from tactsense.physics._pad_model import pad_contact_model

        return pad_contact_model(spec)


KIND: Any = PadKind()
