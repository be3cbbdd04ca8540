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
        if order not in ("row-major", "column-major"):
            raise UrdfError(f"{source}: order={order!r}; expected row-major or column-major")
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
    tactile = ET.SubElement(sensor, "tactile")
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
