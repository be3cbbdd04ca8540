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
from pathlib import Path

from tactsense.kinds import kind_of
from tactsense.kinds.urdf import TactileArray, TactileTaxels, UrdfError
from tactsense.kinds.urdf import rpy_to_matrix as _rpy_to_matrix  # noqa: F401 (tests)
from tactsense.sensor import SensorSpec, preset

__all__ = [
    "TactileArray",
    "TactileTaxels",
    "UrdfError",
    "finger_array_to_urdf",
    "read_tactile_arrays",
    "read_tactile_taxels",
    "sensor_from_urdf",
    "sensor_from_urdf_any",
    "sensor_to_urdf",
]


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
    found = kind_of(base).from_urdf_array(array, base, path=path, preset=extends)
    if found is None:
        raise UrdfError(f"{path}: sensor {array.name!r} is an <array>; extend a finger or a pad")
    return found


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


def sensor_from_urdf_any(path: str | Path, *, name: str | None = None, extends: str | None = None):
    """A sensor of any kind from a URDF tactile sensor.

    An ``<array>`` becomes a finger (``extends`` a finger preset, the default ``initial``)
    or a pad (``extends`` a pad preset); a ``<taxel>`` list becomes a point set
    (``extends`` a point-set preset, default ``dome12``) with each taxel at its ``xyz``
    and its normal the ``rpy`` rotation of +z, as upstream's ``TaxelInfoIterator`` reads
    them; the taxel area comes from a ``<box>`` (x * y) or ``<cylinder>`` geometry, else
    from the preset.
    """
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
        array = next(a for a in arrays if a.name == wanted)
        found = kind_of(base).from_urdf_array(array, base, path=path, preset=extends or "initial")
        if found is None:
            raise UrdfError(f"{path}: sensor {wanted!r} is an <array>; extend a finger or a pad")
        return found
    base = preset(extends or "dome12")
    found = kind_of(base).from_urdf_taxels(taxels, base, path=path)
    if found is None:
        raise UrdfError(
            f"{path}: sensor {wanted!r} is a <taxel> list, a point set; --extends must name a "
            "point-set preset (dome12) or a finger preset (initial, improved)"
        )
    return found


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
    kind = kind_of(spec)
    array = kind.urdf_array(spec)
    if array is not None:
        (size_x, size_y), (spacing_x, spacing_y) = array["size_mm"], array["spacing_mm"]
        ET.SubElement(
            tactile,
            "array",
            rows=str(array["rows"]),
            cols=str(array["cols"]),
            order="row-major",
            size=f"{m(size_x)} {m(size_y)}",
            spacing=f"{m(spacing_x)} {m(spacing_y)}",
            offset="0 0",
        )
    else:
        positions, normals = spec.taxel_positions_mm(), spec.taxel_normals()
        boxes = kind.urdf_taxels(spec)
        note = kind.urdf_note(spec)
        if note is not None:
            tactile.append(ET.Comment(note))
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
