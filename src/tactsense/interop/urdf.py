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


def read_tactile_arrays(path: str | Path) -> list[TactileArray]:
    """Every tactile array described in a URDF file (sensors without one are skipped)."""
    path = Path(path)
    try:
        root = ET.parse(path).getroot()
    except ET.ParseError as error:
        raise UrdfError(f"{path}: not XML ({error})") from None
    except OSError as error:
        raise UrdfError(f"cannot read {path}: {error.strerror or error}") from None
    arrays = []
    for sensor in root.iter():
        if sensor.tag.rsplit("}", 1)[-1] != "sensor":
            continue
        tactile = next((c for c in sensor if c.tag.rsplit("}", 1)[-1] == "tactile"), None)
        if tactile is None:
            continue
        array = next((c for c in tactile if c.tag.rsplit("}", 1)[-1] == "array"), None)
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
        rate = sensor.get("update_rate")
        try:
            rate_hz = None if rate is None else float(rate)
        except ValueError:
            raise UrdfError(f"{source}: update_rate={rate!r} is not a number [Hz]") from None
        parent = next((c for c in sensor if c.tag.rsplit("}", 1)[-1] == "parent"), None)
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
        raise UrdfError(f"{path}: the array does not fit the {extends!r} finger: {error}") from None


def sensor_to_urdf(spec: SensorSpec, *, link: str = "finger", robot: str | None = None) -> str:
    """The sensor's array as a URDF document the tactile toolbox reads (RViz's display).

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


def _local(element) -> str:
    return element.tag.rsplit("}", 1)[-1]


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
    path = Path(path)
    try:
        root = ET.parse(path).getroot()
    except ET.ParseError as error:
        raise UrdfError(f"{path}: not XML ({error})") from None
    except OSError as error:
        raise UrdfError(f"cannot read {path}: {error.strerror or error}") from None
    found = []
    for sensor in root.iter():
        if _local(sensor) != "sensor":
            continue
        tactile = next((c for c in sensor if _local(c) == "tactile"), None)
        if tactile is None:
            continue
        taxels = [c for c in tactile if _local(c) == "taxel"]
        if not taxels:
            continue
        name = sensor.get("name") or f"sensor {len(found)}"
        source = f"{path}: sensor {name!r}"
        idx, xyz, rpy, area = [], [], [], []
        for taxel in taxels:
            try:
                idx.append(int(taxel.get("idx")))
            except (TypeError, ValueError):
                raise UrdfError(f"{source}: a <taxel> has no whole-number idx") from None
            xyz.append(_triple(taxel, "xyz", source))
            rpy.append(_triple(taxel, "rpy", source))
            area.append(_taxel_area(taxel, source))
        rate = sensor.get("update_rate")
        try:
            rate_hz = None if rate is None else float(rate)
        except ValueError:
            raise UrdfError(f"{source}: update_rate={rate!r} is not a number [Hz]") from None
        found.append(TactileTaxels(name, tuple(idx), tuple(xyz), tuple(rpy), tuple(area), rate_hz))
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


def _normal_to_rpy(normal) -> tuple[float, float, float]:
    """A roll-pitch-yaw whose rotation takes +z to ``normal`` (roll 0)."""
    nx, ny, nz = normal
    pitch = math.atan2(math.hypot(nx, ny), nz)
    yaw = math.atan2(ny, nx) if math.hypot(nx, ny) > 1e-12 else 0.0
    return 0.0, pitch, yaw


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
    if not isinstance(base, PointsSpec):
        raise UrdfError(
            f"{path}: sensor {wanted!r} is a <taxel> list, a point set; --extends must name a "
            "point-set preset (dome12)"
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


def sensor_to_urdf_any(spec, *, link: str = "finger", robot: str | None = None) -> str:
    """Any sensor as a URDF tactile description the toolbox's parser accepts.

    A finger: :func:`sensor_to_urdf`. A pad: an ``<array>`` (x along rows, y along
    columns, as upstream's iterator places taxel (row, col) at (row * spacing.x,
    col * spacing.y)). A point set: a ``<taxel idx xyz rpy>`` list with a ``<box>``
    geometry of the taxel's area (a square) and its normal as the rotated +z. Every
    ``<tactile>`` carries the ``channel`` attribute upstream's parser requires (the
    sensor's name: the ``TactileState`` channel that holds its data).
    """
    if spec.kind == "finger":
        return sensor_to_urdf(spec, link=link, robot=robot)
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
        positions, normals, areas = (
            spec.taxel_positions_mm(), spec.taxel_normals(), spec.areas_mm2,
        )  # fmt: skip
        rows = zip(positions, normals, areas, strict=True)
        for index, (position, normal, area) in enumerate(rows):
            rpy = _normal_to_rpy(normal)
            taxel = ET.SubElement(
                tactile,
                "taxel",
                idx=str(index),
                xyz=" ".join(m(v) for v in position),
                rpy=" ".join(f"{v:.15g}" for v in rpy),
            )
            side = math.sqrt(area)
            geometry = ET.SubElement(taxel, "geometry")
            ET.SubElement(geometry, "box", size=f"{m(side)} {m(side)} 0")
    ET.indent(root)
    return '<?xml version="1.0" encoding="utf-8"?>\n' + ET.tostring(root, encoding="unicode") + "\n"
