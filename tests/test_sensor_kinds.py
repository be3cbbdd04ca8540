"""Pads and point sets: one schema, TOML and URDF round trips, clear errors."""

import json
import math
import tomllib
import xml.etree.ElementTree as ET

import numpy as np
import pytest
from typer.testing import CliRunner

from tactsense.cli import app
from tactsense.interop.urdf import sensor_from_urdf_any, sensor_to_urdf
from tactsense.sensor import (
    KINDS,
    PRESETS,
    PadSpec,
    PointsSpec,
    SensorSpec,
    SensorSpecError,
    load_sensor,
    preset,
    sensor_from_dict,
)

runner = CliRunner()


@pytest.mark.parametrize("name", list(PRESETS))
def test_every_preset_round_trips_through_toml(name, tmp_path):
    spec = preset(name)
    path = spec.to_toml(tmp_path / f"{name}.toml")
    back = load_sensor(path)
    assert back == spec
    assert type(back) is KINDS[spec.kind]


def test_a_finger_toml_has_no_kind_key_and_old_files_load():
    """Every existing finger description (no 'kind' key) still loads as a finger."""
    data = tomllib.loads(preset("initial").to_toml_string())
    assert "kind" not in data
    assert isinstance(sensor_from_dict(data), SensorSpec)


def test_pad_taxels_sit_where_the_urdf_toolbox_puts_them():
    """urdf_tactile's TaxelInfoIterator: taxel (row, col) at (row * spacing.x, col * spacing.y),
    normal +z; the pad's positions follow that convention (frame order, row-major)."""
    spec = preset("pad12x32")
    positions = spec.taxel_positions_mm()
    rows, cols = spec.shape
    for index in (0, 1, cols, cols * rows - 1, 5 * cols + 7):
        row, col = divmod(index, cols)
        expected = (row * spec.grid.row_pitch_mm, col * spec.grid.col_pitch_mm, 0.0)
        np.testing.assert_allclose(positions[index], expected)
    np.testing.assert_array_equal(spec.taxel_normals(), np.tile([0.0, 0.0, 1.0], (rows * cols, 1)))


def test_finger_taxel_normals_are_the_skin_normals():
    spec = preset("initial")
    positions, normals = spec.taxel_positions_mm(), spec.taxel_normals()
    np.testing.assert_allclose(np.linalg.norm(normals, axis=1), 1.0)
    cylinder = positions[:, 0] >= 0
    # on the cylinder the normal is radial: no axial part, parallel to (0, y, z)
    assert np.all(normals[cylinder, 0] == 0)
    radial = positions[cylinder, 1:] / np.linalg.norm(positions[cylinder, 1:], axis=1)[:, None]
    np.testing.assert_allclose(normals[cylinder, 1:], radial, atol=1e-12)
    # on the hemisphere the normal points from the sphere's centre (x = 0) through the point
    tip = ~cylinder
    np.testing.assert_allclose(normals[tip], positions[tip] / spec.radius_mm, atol=1e-9)


@pytest.mark.parametrize("name", ["pad4", "pad16", "pad12x32"])
def test_pad_round_trips_through_urdf(name, tmp_path):
    spec = preset(name)
    path = tmp_path / "pad.urdf"
    path.write_text(sensor_to_urdf(spec))
    back = sensor_from_urdf_any(path, extends=name)
    assert back.grid == spec.grid
    assert back.electronics.scan_rate_hz == spec.electronics.scan_rate_hz
    # what upstream's parser requires: the channel attribute, a known order
    tactile = ET.parse(path).getroot().find("sensor/tactile")
    assert tactile.get("channel") == spec.name
    assert tactile.find("array").get("order") in ("row-major", "col-major")


def test_point_set_round_trips_through_urdf_taxel_list(tmp_path):
    spec = preset("dome12")
    path = tmp_path / "dome.urdf"
    path.write_text(sensor_to_urdf(spec))
    back = sensor_from_urdf_any(path)
    np.testing.assert_allclose(back.taxel_positions_mm(), spec.taxel_positions_mm(), atol=1e-12)
    np.testing.assert_allclose(back.taxel_normals(), spec.taxel_normals(), atol=1e-12)
    np.testing.assert_allclose(back.areas_mm2, spec.areas_mm2, rtol=1e-12)


def test_taxel_normal_is_the_rpy_rotation_of_z_as_urdf_defines_it(tmp_path):
    """URDF rpy is fixed-axis roll, pitch, yaw: R = Rz(yaw) Ry(pitch) Rx(roll). A taxel
    rotated by pitch 90 deg about y has its normal along +x (Rz(0) Ry(90) z = +x)."""
    path = tmp_path / "one.urdf"
    path.write_text(
        '<robot name="r"><link name="l"/><sensor name="s" update_rate="10">'
        '<parent link="l"/><tactile channel="s">'
        f'<taxel idx="0" xyz="0.001 0.002 0.003" rpy="0 {math.pi / 2} 0">'
        '<geometry><box size="0.002 0.003 0"/></geometry></taxel>'
        f'<taxel idx="1" xyz="0 0 0" rpy="{math.pi / 2} 0 0">'
        '<geometry><cylinder radius="0.001" length="0.0001"/></geometry></taxel>'
        "</tactile></sensor></robot>"
    )
    spec = sensor_from_urdf_any(path)
    np.testing.assert_allclose(spec.taxel_normals()[0], [1.0, 0.0, 0.0], atol=1e-12)
    # roll 90 deg about x takes z to -y
    np.testing.assert_allclose(spec.taxel_normals()[1], [0.0, -1.0, 0.0], atol=1e-12)
    np.testing.assert_allclose(spec.taxel_positions_mm()[0], [1.0, 2.0, 3.0])
    np.testing.assert_allclose(spec.areas_mm2, [6.0, math.pi])


def test_json_taxel_list_imports_as_a_point_set(tmp_path):
    taxels = [
        {"xyz": [0, 0, 0], "normal": [0, 0, 2], "area": 4},
        {"xyz": [3, 0, 0], "normal": [0, 1, 1], "area": 5},
    ]
    source = tmp_path / "taxels.json"
    source.write_text(json.dumps(taxels))
    out = tmp_path / "mine.toml"
    result = runner.invoke(app, ["sensor", "import", str(source), "-o", str(out)])
    assert result.exit_code == 0, result.output
    spec = load_sensor(out)
    assert isinstance(spec, PointsSpec) and spec.shape == (1, 2)
    np.testing.assert_allclose(spec.taxel_normals()[1], [0, 1 / math.sqrt(2), 1 / math.sqrt(2)])


@pytest.mark.parametrize(
    ("change", "message"),
    [
        ({"grid": {"rows": 0}}, "[grid] rows must be positive"),
        ({"grid": {"electrode_x_mm": 3.0}}, "overlap at a pitch"),
        ({"layer": {"sensing_depth_mm": 5.0}}, "lies below the layer"),
        ({"layer": {"poisson_ratio": 0.7}}, "Poisson's ratio lies in (-1, 0.5]"),
        ({"layer": {"substrate": "foam"}}, "only 'rigid' is modelled"),
        ({"transduction": {"kind": "optical"}}, "'resistive' or 'piezoresistive'"),
        ({"flaws": {"dead_tactels": [[16, 0]]}}, "outside the wired array 16x16"),
        ({"grid": {"pitch": 2.0}}, "unknown key 'pitch' in [grid]"),
    ],
)
def test_bad_pad_descriptions_say_what_is_wrong(change, message):
    data = {"kind": "pad", "extends": "pad16", **change}
    with pytest.raises(SensorSpecError) as error:
        sensor_from_dict(data)
    assert message in str(error.value)


def test_kind_and_extends_must_agree():
    with pytest.raises(SensorSpecError, match="'initial' is a finger preset, and this desc"):
        sensor_from_dict({"kind": "pad", "extends": "initial"})
    with pytest.raises(SensorSpecError, match=r"available: initial \(finger\),.* fsr16 \(pad\)"):
        sensor_from_dict({"kind": "pad", "extends": "fsr-16"})
    with pytest.raises(SensorSpecError, match='kind = "pad" or kind = "points"'):
        sensor_from_dict({"grid": {"rows": 4}})
    with pytest.raises(SensorSpecError, match="kind = 'sphere' is not a sensor kind"):
        sensor_from_dict({"kind": "sphere"})


def test_bad_point_sets_say_what_is_wrong():
    with pytest.raises(SensorSpecError, match="give one of each per taxel"):
        PointsSpec(**{**_points_fields(), "taxels": _taxels(normals=((0, 0, 1),))})
    with pytest.raises(SensorSpecError, match=r"normals\[1\] is zero"):
        PointsSpec(**{**_points_fields(), "taxels": _taxels(normals=((0, 0, 1), (0, 0, 0)))})


def _taxels(**change):
    from tactsense.sensor import Taxels

    base = {
        "positions_mm": ((0.0, 0.0, 0.0), (1.0, 0.0, 0.0)),
        "normals": ((0.0, 0.0, 1.0), (0.0, 0.0, 1.0)),
        "area_mm2": (1.0, 1.0),
    }
    return Taxels(**{**base, **change})


def _points_fields():
    spec = preset("dome12")
    return {name: getattr(spec, name) for name in ("layer", "transduction", "electronics")}


def test_sensor_check_and_show_take_every_kind(tmp_path):
    for name in ("pad16", "dome12"):
        path = tmp_path / f"{name}.toml"
        shown = runner.invoke(app, ["sensor", "show", "--sensor", name, "-o", str(path)])
        assert shown.exit_code == 0, shown.output
        checked = runner.invoke(app, ["sensor", "check", str(path)])
        assert checked.exit_code == 0, checked.output
        assert preset(name).kind in checked.output


def test_pad_capacitance_is_eq_2_of_its_electrode():
    spec = preset("pad4")
    assert isinstance(spec, PadSpec)
    area = spec.grid.electrode_x_mm * spec.grid.electrode_y_mm * 1e-6
    expected = 4.0 * 8.8541878128e-12 * area / 0.5e-3  # K eps0 A / d_o, eq. 2
    assert spec.junction_capacitance_f == pytest.approx(expected, rel=1e-12)


@pytest.mark.parametrize("name", ["initial", "improved"])
def test_finger_exports_each_taxel_on_the_skin_and_imports_back(name, tmp_path):
    """The finger as a <taxel> list: every taxel at its real skin position and normal (as
    upstream's TaxelInfoIterator reads them: position = xyz, normal = R(rpy) z), and the
    import recovers the wired layout from the positions."""
    from tactsense.interop.urdf import _rpy_to_matrix

    spec = preset(name)
    path = tmp_path / "finger.urdf"
    path.write_text(sensor_to_urdf(spec))
    root = ET.parse(path).getroot()
    taxels = root.findall("sensor/tactile/taxel")
    assert len(taxels) == spec.n_taxels
    for element, position, normal in zip(
        taxels, spec.taxel_positions_mm(), spec.taxel_normals(), strict=True
    ):
        xyz = np.array([float(v) for v in element.get("xyz").split()]) * 1e3
        rpy = [float(v) for v in element.get("rpy").split()]
        np.testing.assert_allclose(xyz, position, atol=1e-9)
        np.testing.assert_allclose(_rpy_to_matrix(*rpy)[:, 2], normal, atol=1e-12)
    back = sensor_from_urdf_any(path, extends=name)
    assert back.shape == spec.shape
    np.testing.assert_allclose(back.taxel_positions_mm(), spec.taxel_positions_mm(), atol=1e-9)
    assert back.array.spacing_axial_mm == pytest.approx(spec.array.spacing_axial_mm, rel=1e-12)
    assert back.array.spacing_angle_deg == pytest.approx(spec.array.spacing_angle_deg, rel=1e-12)
    assert back.rings.ring_width_mm == pytest.approx(spec.rings.ring_width_mm, rel=1e-12)


def test_extends_a_pad_preset_makes_a_pad_and_the_file_names_it(tmp_path):
    """A description that extends pad16 is a pad without saying kind = "pad"; without a
    name it takes its file's."""
    path = tmp_path / "gripper.toml"
    path.write_text('extends = "pad16"\n[grid]\nrows = 8\n')
    spec = load_sensor(path)
    assert isinstance(spec, PadSpec) and spec.shape == (8, 16) and spec.name == "gripper"
