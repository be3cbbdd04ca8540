"""The ROS tactile toolbox's URDF description of a taxel array, to and from a sensor.

The toolbox (``urdf_tactile``) describes an array of identical rectangular taxels as::

    <sensor name="NAME" update_rate="HZ">
      <parent link="LINK"/>
      <origin xyz="0 0 0" rpy="0 0 0"/>
      <tactile>
        <array rows="R" cols="C" order="row-major" size="SX SY" spacing="DX DY"
               offset="OX OY"/>
      </tactile>
    </sensor>

in metres, on a plane (z is the normal). The data vector of its ``TactileState``
message holds the R x C values in ``order``. A tactsense finger is a cylinder, so the
flat grid is the unwrapped surface: rows along the finger (``spacing`` x = the ring
spacing), columns around it (``spacing`` y = the arc between strips at the skin's
surface). The tip row, when there is one, is data row 0 like every other row; its
real distance to row 1 (about 11 mm on the paper's fingers, not one spacing) has no
place in the array element and is kept in a comment.

What the array determines: the number of rows and columns, both spacings, the taxel
size and the update rate. Everything else (the body, the elastic skin, the
electronics and flaws) comes from the preset the import extends.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path

from tactsense._validation import TactsenseInputError
from tactsense.sensor import SensorSpec, SensorSpecError, preset


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


class UrdfError(TactsenseInputError):
    """A URDF file that is not XML or has no usable tactile array."""


def _pair(element, attribute: str, default, source: str) -> tuple[float, float]:
    text = element.get(attribute)
    if text is None:
        return default
    try:
        values = tuple(float(v) for v in text.split())
    except ValueError:
        values = ()
    if len(values) != 2 or not all(math.isfinite(v) for v in values):
        raise UrdfError(f"{source}: {attribute}={text!r} must be two numbers (x y) [m]")
    return values


def _positive_int(element, attribute: str, source: str) -> int:
    text = element.get(attribute)
    try:
        value = int(text)
    except (TypeError, ValueError):
        value = 0
    if value < 1:
        raise UrdfError(f"{source}: {attribute}={text!r} must be a whole number >= 1")
    return value


def _local(element) -> str:
    """An element's tag without its XML namespace."""
    return element.tag.rsplit("}", 1)[-1]


def _tactile_sensors(path: str | Path):
    """Every ``(<sensor>, <tactile>)`` pair of a URDF file, or UrdfError naming the file."""
    path = Path(path)
    try:
        root = ET.parse(path).getroot()
    except ET.ParseError as error:
        raise UrdfError(f"{path}: not XML ({error})") from None
    except OSError as error:
        raise UrdfError(f"cannot read {path}: {error.strerror or error}") from None
    for sensor in root.iter():
        if _local(sensor) != "sensor":
            continue
        tactile = next((c for c in sensor if _local(c) == "tactile"), None)
        if tactile is not None:
            yield sensor, tactile


def _update_rate(sensor, source: str) -> float | None:
    rate = sensor.get("update_rate")
    try:
        return None if rate is None else float(rate)
    except ValueError:
        raise UrdfError(f"{source}: update_rate={rate!r} is not a number [Hz]") from None


def read_tactile_arrays(path: str | Path) -> list[TactileArray]:
    """Every tactile array described in a URDF file (sensors without one are skipped)."""
    arrays = []
    for sensor, tactile in _tactile_sensors(path):
        array = next((c for c in tactile if _local(c) == "array"), None)
        if array is None:
            continue
        name = sensor.get("name") or f"sensor {len(arrays)}"
        source = f"{path}: sensor {name!r}"
        order = array.get("order", "row-major")
        if order == "column-major":  # written by tactsense before 0.2; upstream: col-major
            order = "col-major"
        if order not in ("row-major", "col-major"):
            raise UrdfError(f"{source}: order={order!r}; expected row-major or col-major")
        size = _pair(array, "size", None, source)
        if size is None:
            raise UrdfError(f"{source}: the array has no size (x y) [m]")
        spacing = _pair(array, "spacing", size, source)
        if spacing == (0.0, 0.0):
            spacing = size  # the toolbox: "equals size by default"
        rate_hz = _update_rate(sensor, source)
        parent = next((c for c in sensor if _local(c) == "parent"), None)
        arrays.append(
            TactileArray(
                name=name,
                rows=_positive_int(array, "rows", source),
                cols=_positive_int(array, "cols", source),
                order=order,
                size_m=size,
                spacing_m=spacing,
                offset_m=_pair(array, "offset", (0.0, 0.0), source),
                update_rate_hz=rate_hz,
                parent_link=None if parent is None else parent.get("link"),
            )
        )
    return arrays


def sensor_from_urdf(
    path: str | Path, *, name: str | None = None, extends: str = "initial"
) -> SensorSpec:
    """A sensor description from the tactile array of a URDF file.

    Parameters
    ----------
    path : path
        The URDF file.
    name : str, optional
        Which ``<sensor>`` to take; needed when the file describes more than one array.
    extends : {"initial", "improved"}
        The preset that gives what the array does not: body, skin, electronics, flaws,
        and whether row 0 is a tip row.

    Returns
    -------
    SensorSpec
        Checked like any sensor description (``SensorSpecError`` names what does not fit).
    """
    arrays = read_tactile_arrays(path)
    if not arrays:
        raise UrdfError(f"{path}: no <sensor> with a <tactile><array> element")
    if name is None:
        if len(arrays) > 1:
            names = ", ".join(repr(a.name) for a in arrays)
            raise UrdfError(f"{path} describes {len(arrays)} tactile arrays ({names}); pick one")
        array = arrays[0]
    else:
        matches = [a for a in arrays if a.name == name]
        if not matches:
            names = ", ".join(repr(a.name) for a in arrays)
            raise UrdfError(f"{path}: no tactile array named {name!r}; it has {names}")
        array = matches[0]
    base = preset(extends)
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


def finger_array_to_urdf(
    spec: SensorSpec, *, link: str = "finger", robot: str | None = None
) -> str:
    """A finger as the toolbox's flat ``<array>`` (older tactsense; tools that read only arrays).

    The grid lies on a plane, not on the skin: :func:`sensor_to_urdf` writes each taxel at
    its real position and normal instead.

    Spacing and size are in metres: along the finger the ring spacing and ring width,
    around it the arc between strips and the strip width at the skin's surface. The
    data vector is a frame in tactsense's order (rows x cols, row-major).
    """
    radius_mm = spec.body.diameter_mm / 2.0
    arc_mm = math.radians(spec.array.spacing_angle_deg) * radius_mm
    rows, cols = spec.shape
    m = lambda value_mm: f"{value_mm * 1e-3:.15g}"  # noqa: E731
    root = ET.Element("robot", name=robot or f"{spec.name}_finger")
    ET.SubElement(root, "link", name=link)
    sensor = ET.SubElement(
        root, "sensor", name=spec.name, update_rate=f"{spec.electronics.scan_rate_hz:g}"
    )
    ET.SubElement(sensor, "parent", link=link)
    ET.SubElement(sensor, "origin", xyz="0 0 0", rpy="0 0 0")
    tactile = ET.SubElement(sensor, "tactile", channel=spec.name)
    if spec.array.tip_row:
        tactile.append(
            ET.Comment(
                f" tactsense: row 0 is the tip row, at {spec.array.tip_row_axial_mm:g} mm "
                f"along the surface; rows 1..{rows - 1} are rings from "
                f"{spec.array.first_row_axial_mm:g} mm at {spec.array.spacing_axial_mm:g} mm "
                f"(the grid below puts row 0 one spacing before row 1) "
            )
        )
    ET.SubElement(
        tactile,
        "array",
        rows=str(rows),
        cols=str(cols),
        order="row-major",
        size=f"{m(spec.rings.ring_width_mm)} {m(spec.rings.strip_width_mm)}",
        spacing=f"{m(spec.array.spacing_axial_mm)} {m(arc_mm)}",
        offset="0 0",
    )
    ET.indent(root)
    return '<?xml version="1.0" encoding="utf-8"?>\n' + ET.tostring(root, encoding="unicode") + "\n"


# ---- pads and point sets ---------------------------------------------------------------


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


def _triple(element, attribute: str, source: str) -> tuple[float, float, float]:
    text = element.get(attribute, "0 0 0")
    try:
        values = tuple(float(v) for v in text.split())
    except ValueError:
        values = ()
    if len(values) != 3 or not all(math.isfinite(v) for v in values):
        raise UrdfError(f"{source}: {attribute}={text!r} must be three numbers")
    return values


def _taxel_box(taxel) -> tuple[float, float] | None:
    """Size (x, y) of a taxel's ``<box>`` geometry [m], if it has one."""
    geometry = next((c for c in taxel if _local(c) == "geometry"), None)
    shape = None if geometry is None else next(iter(geometry), None)
    if shape is None or _local(shape) != "box":
        return None
    try:
        x, y, _ = (abs(float(v)) for v in shape.get("size", "").split())
    except ValueError:
        return None
    return (x, y)


def _taxel_area(taxel, source: str) -> float | None:
    """Area of a taxel's ``<geometry>`` seen along its normal (box x*y, cylinder pi r^2) [m^2]."""
    geometry = next((c for c in taxel if _local(c) == "geometry"), None)
    if geometry is None:
        raise UrdfError(f"{source}: a <taxel> has no <geometry> (the toolbox's parser needs one)")
    shape = next(iter(geometry), None)
    if shape is None:
        return None
    kind = _local(shape)
    try:
        if kind == "box":
            x, y, _ = (float(v) for v in shape.get("size", "").split())
            return abs(x * y) or None
        if kind == "cylinder":
            return math.pi * float(shape.get("radius")) ** 2 or None
    except (TypeError, ValueError):
        raise UrdfError(f"{source}: a taxel's <{kind}> has no usable size") from None
    return None  # a mesh or a sphere: no area to read


def read_tactile_taxels(path: str | Path) -> list[TactileTaxels]:
    """Every tactile sensor of a URDF file given as a ``<taxel>`` list."""
    found = []
    for sensor, tactile in _tactile_sensors(path):
        taxels = [c for c in tactile if _local(c) == "taxel"]
        if not taxels:
            continue
        name = sensor.get("name") or f"sensor {len(found)}"
        source = f"{path}: sensor {name!r}"
        idx, xyz, rpy, area, box = [], [], [], [], []
        for taxel in taxels:
            try:
                idx.append(int(taxel.get("idx")))
            except (TypeError, ValueError):
                raise UrdfError(f"{source}: a <taxel> has no whole-number idx") from None
            xyz.append(_triple(taxel, "xyz", source))
            rpy.append(_triple(taxel, "rpy", source))
            area.append(_taxel_area(taxel, source))
            box.append(_taxel_box(taxel))
        rate_hz = _update_rate(sensor, source)
        found.append(
            TactileTaxels(
                name, tuple(idx), tuple(xyz), tuple(rpy), tuple(area), tuple(box), rate_hz
            )
        )
    return found


def _rpy_to_matrix(roll: float, pitch: float, yaw: float):
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


def _taxel_rpy(normal) -> tuple[float, float, float]:
    """Roll-pitch-yaw of a taxel frame: z along ``normal``, x along the part of +x (the
    finger's axis toward the base) tangent to the surface (+y where +x is normal)."""
    import numpy as np

    n = np.asarray(normal, dtype=float)
    n = n / np.linalg.norm(n)
    for axis in (np.array([1.0, 0.0, 0.0]), np.array([0.0, 1.0, 0.0])):
        t = axis - axis.dot(n) * n
        if np.linalg.norm(t) > 1e-9:
            break
    t = t / np.linalg.norm(t)
    r = np.column_stack([t, np.cross(n, t), n])
    roll = math.atan2(r[2, 1], r[2, 2])
    pitch = -math.asin(max(-1.0, min(1.0, r[2, 0])))
    yaw = math.atan2(r[1, 0], r[0, 0])
    return roll, pitch, yaw


def _finger_from_taxels(path, taxels: TactileTaxels, base):
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


def sensor_from_urdf_any(path: str | Path, *, name: str | None = None, extends: str | None = None):
    """A sensor of any kind from a URDF tactile sensor.

    An ``<array>`` becomes a finger (``extends`` a finger preset, the default ``initial``)
    or a pad (``extends`` a pad preset); a ``<taxel>`` list becomes a point set
    (``extends`` a point-set preset, default ``dome12``) with each taxel at its ``xyz``
    and its normal the ``rpy`` rotation of +z, as upstream's ``TaxelInfoIterator`` reads
    them; the taxel area comes from a ``<box>`` (x * y) or ``<cylinder>`` geometry, else
    from the preset.
    """
    from tactsense.sensor import PadSpec, PointsSpec, preset, sensor_from_dict

    lists = read_tactile_taxels(path)
    arrays = read_tactile_arrays(path)
    names = [t.name for t in lists] + [a.name for a in arrays]
    if not names:
        raise UrdfError(f"{path}: no <sensor> with a <tactile> <array> or <taxel> list")
    if name is None and len(names) > 1:
        listed = ", ".join(repr(n) for n in names)
        raise UrdfError(f"{path} describes {len(names)} tactile sensors ({listed}); pick one")
    wanted = name if name is not None else names[0]
    if wanted not in names:
        listed = ", ".join(repr(n) for n in names)
        raise UrdfError(f"{path}: no tactile sensor named {wanted!r}; it has {listed}")
    taxels = next((t for t in lists if t.name == wanted), None)
    if taxels is None:
        base = preset(extends or "initial")
        if base.kind == "finger":
            return sensor_from_urdf(path, name=wanted, extends=extends or "initial")
        if not isinstance(base, PadSpec):
            raise UrdfError(f"{path}: sensor {wanted!r} is an <array>; extend a finger or a pad")
        array = next(a for a in arrays if a.name == wanted)
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
    base = preset(extends or "dome12")
    if base.kind == "finger":
        return _finger_from_taxels(path, taxels, base)
    if not isinstance(base, PointsSpec):
        raise UrdfError(
            f"{path}: sensor {wanted!r} is a <taxel> list, a point set; --extends must name a "
            "point-set preset (dome12) or a finger preset (initial, improved)"
        )
    order = sorted(range(len(taxels.idx)), key=lambda k: taxels.idx[k])
    if sorted(taxels.idx) != list(range(len(taxels.idx))):
        raise UrdfError(
            f"{path}: sensor {wanted!r}: taxel idx must be 0..{len(taxels.idx) - 1}, each once; "
            f"got {sorted(taxels.idx)[:8]}..."
        )
    default_area = float(base.areas_mm2[0])
    positions, normals, areas = [], [], []
    for k in order:
        positions.append(tuple(v * 1e3 for v in taxels.xyz_m[k]))
        normal = _rpy_to_matrix(*taxels.rpy[k])[:, 2]
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


def sensor_to_urdf(spec, *, link: str = "finger", robot: str | None = None) -> str:
    """Any sensor as a URDF tactile description the toolbox's parser accepts.

    A finger or a point set: a ``<taxel idx xyz rpy>`` list, each taxel on the skin at its
    real position, ``z`` its outward normal (for a finger ``x`` along the axis; a ``<box>``
    of the ring width by the strip width, or of a point set's taxel area). A pad: an
    ``<array>`` (x along rows, y along
    columns, as upstream's iterator places taxel (row, col) at (row * spacing.x,
    col * spacing.y)). Every
    ``<tactile>`` carries the ``channel`` attribute upstream's parser requires (the
    sensor's name: the ``TactileState`` channel that holds its data).
    """
    m = lambda value_mm: f"{value_mm * 1e-3:.15g}"  # noqa: E731
    root = ET.Element("robot", name=robot or f"{spec.name}_robot")
    ET.SubElement(root, "link", name=link)
    sensor = ET.SubElement(
        root, "sensor", name=spec.name, update_rate=f"{spec.electronics.scan_rate_hz:g}"
    )
    ET.SubElement(sensor, "parent", link=link)
    ET.SubElement(sensor, "origin", xyz="0 0 0", rpy="0 0 0")
    tactile = ET.SubElement(sensor, "tactile", channel=spec.name)
    if spec.kind == "pad":
        g = spec.grid
        ET.SubElement(
            tactile,
            "array",
            rows=str(g.rows),
            cols=str(g.cols),
            order="row-major",
            size=f"{m(g.electrode_x_mm)} {m(g.electrode_y_mm)}",
            spacing=f"{m(g.row_pitch_mm)} {m(g.col_pitch_mm)}",
            offset="0 0",
        )
    else:
        positions, normals = spec.taxel_positions_mm(), spec.taxel_normals()
        if spec.kind == "finger":  # ring width along the axis, strip width around it
            boxes = [(spec.rings.ring_width_mm, spec.rings.strip_width_mm)] * len(positions)
        else:
            boxes = [(math.sqrt(a), math.sqrt(a)) for a in spec.areas_mm2]
        if spec.kind == "finger" and spec.array.tip_row:
            tactile.append(
                ET.Comment(
                    f" tactsense: {spec.name}, row 0 under the hemispherical tip at "
                    f"{spec.array.tip_row_axial_mm:g} mm along the skin; each taxel on the "
                    "skin at its real position, z its outward normal, x along the finger "
                )
            )
        rows = zip(positions, normals, boxes, strict=True)
        for index, (position, normal, (size_x, size_y)) in enumerate(rows):
            rpy = _taxel_rpy(normal)
            taxel = ET.SubElement(
                tactile,
                "taxel",
                idx=str(index),
                xyz=" ".join(m(v) for v in position),
                rpy=" ".join(f"{v:.15g}" for v in rpy),
            )
            geometry = ET.SubElement(taxel, "geometry")
            ET.SubElement(geometry, "box", size=f"{m(size_x)} {m(size_y)} 0")
    ET.indent(root)
    return '<?xml version="1.0" encoding="utf-8"?>\n' + ET.tostring(root, encoding="unicode") + "\n"
