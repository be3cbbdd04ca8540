"""The URDF form shared by every kind: the tactile elements a kind reads a sensor from.

:mod:`tactsense.interop.urdf` parses a URDF file into these plain records (metres, as
written) and writes a sensor back; what a record means for a kind of sensor is the
kind's own answer (:meth:`~tactsense.kinds.base.Kind.from_urdf_array`,
:meth:`~tactsense.kinds.base.Kind.from_urdf_taxels`, :meth:`~tactsense.kinds.base.Kind.
urdf_array`, :meth:`~tactsense.kinds.base.Kind.urdf_taxels`). It sits below the kinds,
so a kind raises :class:`UrdfError` without importing :mod:`tactsense.interop`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from tactsense._validation import TactsenseInputError


class UrdfError(TactsenseInputError):
    """A URDF file that is not XML or has no usable tactile array."""


@dataclass(frozen=True)
class TactileArray:
    """One ``<sensor>`` with a ``<tactile><array>`` element, in SI units as written."""

    name: str
    rows: int
    cols: int
    order: str
    size_m: tuple[float, float]
    spacing_m: tuple[float, float]
    offset_m: tuple[float, float]
    update_rate_hz: float | None
    parent_link: str | None


@dataclass(frozen=True)
class TactileTaxels:
    """One ``<sensor>`` with a ``<tactile>`` list of ``<taxel idx xyz rpy>`` elements [m]."""

    name: str
    idx: tuple[int, ...]
    xyz_m: tuple[tuple[float, float, float], ...]
    rpy: tuple[tuple[float, float, float], ...]
    area_m2: tuple[float | None, ...]
    box_m: tuple[tuple[float, float] | None, ...]
    update_rate_hz: float | None


def rpy_to_matrix(roll: float, pitch: float, yaw: float):
    """URDF's fixed-axis roll-pitch-yaw: R = Rz(yaw) Ry(pitch) Rx(roll)."""
    import numpy as np

    cr, sr, cp, sp, cy, sy = (
        math.cos(roll), math.sin(roll), math.cos(pitch),
        math.sin(pitch), math.cos(yaw), math.sin(yaw),
    )  # fmt: skip
    return np.array(
        [
            [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
            [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
            [-sp, cp * sr, cp * cr],
        ]
    )
