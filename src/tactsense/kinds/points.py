"""Any set of taxels given as surface positions, normals and areas under a locally flat
elastic layer."""

from __future__ import annotations

from typing import Any

import numpy as np

from tactsense.kinds.base import Kind
from tactsense.sensor.points import PointsSpec


class PointsKind(Kind):
    name = "points"
    spec_class = PointsSpec
    label = "point set"
    image_grid = False
    multi_contact = True

    # ---- estimation (r5-estimate) ----------------------------------------------
    def contact_response(
        self, spec: PointsSpec, *, half: int = 0, n_sub: int = 8, signed: bool = False
    ) -> np.ndarray:
        """The signal of every taxel per newton of the scenarios' probe (1.6-mm sphere)
        centred on each taxel, shape (N, N) [-/N]: row i for the probe on taxel i
        (clipped at zero on resistive taxels whatever ``signed``)."""
        from tactsense.physics.indenters import SphereProbe
        from tactsense.physics.pad_response import points_strain

        newtons = 0.49
        n = spec.shape[1]
        kernel = np.empty((n, n))
        for i in range(n):
            probe = SphereProbe(0.0, 0.0, newtons, at_taxel=i)
            strain = points_strain(spec, [probe])[0] / newtons
            if spec.transduction.kind != "capacitive":
                kernel[i] = np.maximum(strain, 0.0)
            else:
                kernel[i] = spec.transduction.strain_gain * strain
        return kernel


KIND: Any = PointsKind()
