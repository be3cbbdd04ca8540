"""The finger's URDF form read back: an ``<array>`` (the unwrapped cylinder) or a
``<taxel>`` list (each taxel on the skin) as a finger. The methods of
:class:`~tactsense.kinds.finger.FingerKind` call these; see :mod:`tactsense.interop.urdf`
for the file."""

from __future__ import annotations

import math
from pathlib import Path

from tactsense._validation import TactsenseInputError
from tactsense.kinds.urdf import TactileArray, TactileTaxels, UrdfError
from tactsense.sensor import SensorSpec, SensorSpecError


def finger_from_array(array: TactileArray, base: SensorSpec, path, extends: str) -> SensorSpec:
    """A finger from a URDF ``<array>``: rows along the finger (``spacing`` x = the ring
    spacing), columns around it (``spacing`` y = the arc between strips at the skin's
    surface); the rest from ``base`` (the preset named ``extends``)."""
    data = base.to_dict()
    radius_mm = base.body.diameter_mm / 2.0
    spacing_along_mm = abs(array.spacing_m[0]) * 1e3
    spacing_around_mm = abs(array.spacing_m[1]) * 1e3
    tip = bool(base.array.tip_row)
    if tip and array.rows < 2:
        raise UrdfError(
            f"{path}: sensor {array.name!r} has {array.rows} row; the {extends!r} finger has "
            "a tip row (row 0) and needs at least one more"
        )
    cylinder_rows = array.rows - int(tip)
    data["name"] = array.name
    data["description"] = f"imported from {Path(path).name} (URDF tactile array), on {base.name}"
    layout = data["array"]
    layout.update(
        cylinder_rows=cylinder_rows,
        cols=array.cols,
        wired_rows=array.rows,
        wired_cols=array.cols,
        wired_col_offset=0,
        spacing_axial_mm=spacing_along_mm,
        spacing_angle_deg=math.degrees(spacing_around_mm / radius_mm),
    )
    data["rings"].update(
        ring_width_mm=abs(array.size_m[0]) * 1e3, strip_width_mm=abs(array.size_m[1]) * 1e3
    )
    if array.update_rate_hz is not None:
        data["electronics"]["scan_rate_hz"] = array.update_rate_hz
    try:
        return SensorSpec.from_dict(data, source=str(path))
    except SensorSpecError as error:
        first = str(error).splitlines()[1].strip(" -") if "\n" in str(error) else str(error)
        raise UrdfError(
            f"{path}: the array does not fit the {extends!r} finger ({first}); a flat pad? "
            "give --extends pad16 (or another pad preset)"
        ) from None


def finger_from_taxels(taxels: TactileTaxels, base: SensorSpec, path) -> SensorSpec:
    """A finger whose rows and columns are read back from its taxels' skin positions."""
    import numpy as np

    from tactsense.geometry import wrap_angle_deg, xyz_to_surface
    from tactsense.sensor import sensor_from_dict

    source = f"{path}: sensor {taxels.name!r}"
    order = np.argsort(taxels.idx)
    points = np.asarray(taxels.xyz_m, dtype=float)[order] * 1e3
    on_cylinder = points[:, 0] >= 0
    if not on_cylinder.any():
        raise UrdfError(f"{source}: no taxel on the cylinder (x >= 0); not a finger")
    radius = float(np.median(np.hypot(points[on_cylinder, 1], points[on_cylinder, 2])))
    data = base.to_dict()
    data["body"]["diameter_mm"] = 2.0 * radius
    try:
        spec0 = sensor_from_dict(data, source=source)
    except TactsenseInputError as error:
        raise UrdfError(
            f"{source}: radius {radius:g} mm does not fit {base.name!r}: {error}"
        ) from None
    axial, angle, _ = xyz_to_surface(spec0, points)
    distinct = np.unique(np.round(axial, 6))
    rows = distinct.size
    if len(points) % rows:
        raise UrdfError(f"{source}: {len(points)} taxels on {rows} rows is not a grid")
    cols = len(points) // rows
    axial = axial.reshape(rows, cols)
    angle = angle.reshape(rows, cols)
    if not np.allclose(axial, axial[:, :1], atol=1e-6):
        raise UrdfError(f"{source}: the taxels are not in row-major order of rings")
    tip = bool(base.array.tip_row)
    ring_axial = axial[int(tip) :, 0]
    spacing_axial = (
        float(np.mean(np.diff(ring_axial))) if ring_axial.size > 1 else base.array.spacing_axial_mm
    )
    spacing_angle = (
        float(wrap_angle_deg(angle[-1, 1] - angle[-1, 0]))
        if cols > 1
        else base.array.spacing_angle_deg
    )
    layout = data["array"]
    layout.update(
        cylinder_rows=rows - int(tip),
        cols=cols,
        wired_rows=rows,
        wired_cols=cols,
        wired_col_offset=0,
        spacing_axial_mm=spacing_axial,
        spacing_angle_deg=spacing_angle,
        first_row_axial_mm=float(ring_axial[0]),
        first_col_angle_deg=float(angle[-1, 0]),
    )
    if tip:
        layout["tip_row_axial_mm"] = float(axial[0, 0])
    sizes = [taxels.box_m[k] for k in order if taxels.box_m[k] is not None]
    if sizes:
        data["rings"].update(ring_width_mm=sizes[0][0] * 1e3, strip_width_mm=sizes[0][1] * 1e3)
    if taxels.update_rate_hz is not None:
        data["electronics"]["scan_rate_hz"] = taxels.update_rate_hz
    data["name"] = taxels.name
    data["description"] = f"imported from {Path(path).name} (URDF taxel list), on {base.name}"
    try:
        return sensor_from_dict(data, source=str(path))
    except TactsenseInputError as error:
        raise UrdfError(
            f"{path}: the taxels do not fit the {base.name!r} finger: {error}"
        ) from None
