"""Any set of taxels given as surface positions, normals and areas under a locally flat
elastic layer."""

from __future__ import annotations

from types import MappingProxyType
from typing import Any

import numpy as np

from tactsense.kinds.base import RESPONSE_PROBE_N, Kind, signal_per_strain
from tactsense.sensor.points import PointsSpec
from tactsense.sensor.registry import dome12, icub_fingertip


class PointsKind(Kind):
    name = "points"
    spec_class = PointsSpec
    presets = MappingProxyType({"dome12": dome12, "icub_fingertip": icub_fingertip})
    label = "point set"
    image_grid = False
    multi_contact = True

    # ---- forms for other tools: LSL, URDF (r5-interop) -------------------------
    def from_urdf_taxels(self, taxels, base: PointsSpec, *, path) -> PointsSpec:
        """Each taxel at its ``xyz``, its normal the ``rpy`` rotation of +z (as upstream's
        ``TaxelInfoIterator`` reads them), its area from a ``<box>`` or ``<cylinder>``,
        else the preset's first."""
        from pathlib import Path

        from tactsense._validation import TactsenseInputError
        from tactsense.kinds.urdf import UrdfError, rpy_to_matrix
        from tactsense.sensor import sensor_from_dict

        order = sorted(range(len(taxels.idx)), key=lambda k: taxels.idx[k])
        if sorted(taxels.idx) != list(range(len(taxels.idx))):
            raise UrdfError(
                f"{path}: sensor {taxels.name!r}: taxel idx must be 0..{len(taxels.idx) - 1}, "
                f"each once; got {sorted(taxels.idx)[:8]}..."
            )
        default_area = float(base.areas_mm2[0])
        positions, normals, areas = [], [], []
        for k in order:
            positions.append(tuple(v * 1e3 for v in taxels.xyz_m[k]))
            normal = rpy_to_matrix(*taxels.rpy[k])[:, 2]
            normals.append(tuple(float(v) for v in normal))
            area = taxels.area_m2[k]
            areas.append(area * 1e6 if area else default_area)
        data = base.to_dict()
        data["name"] = taxels.name
        data["description"] = f"imported from {Path(path).name} (URDF taxel list), on {base.name}"
        data["taxels"] = {
            "positions_mm": [list(p) for p in positions],
            "normals": [list(n) for n in normals],
            "area_mm2": areas,
        }
        if taxels.update_rate_hz is not None:
            data["electronics"]["scan_rate_hz"] = taxels.update_rate_hz
        try:
            return sensor_from_dict(data, source=str(path))
        except TactsenseInputError as error:
            raise UrdfError(f"{path}: the taxels do not fit {base.name!r}: {error}") from None

    # ---- estimation (r5-estimate) ----------------------------------------------
    def contact_response(
        self, spec: PointsSpec, *, half: int = 0, n_sub: int = 8, signed: bool = False
    ) -> np.ndarray:
        """The signal of every taxel per newton of the scenarios' probe (1.6-mm sphere)
        centred on each taxel, shape (N, N) [-/N]: row i for the probe on taxel i
        (clipped at zero on resistive taxels whatever ``signed``)."""
        from tactsense.physics.indenters import SphereProbe

        newtons = RESPONSE_PROBE_N
        n = spec.shape[1]
        kernel = np.empty((n, n))
        for i in range(n):
            probe = SphereProbe(0.0, 0.0, newtons, at_taxel=i)
            kernel[i] = signal_per_strain(spec, self.layer_strain(spec, [probe])[0] / newtons)
        return kernel


KIND: Any = PointsKind()
