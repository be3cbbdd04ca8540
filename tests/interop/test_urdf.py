"""URDF tactile arrays (ROS tactile toolbox syntax): export, import, round trip."""

import math
import textwrap

import pytest
from typer.testing import CliRunner

import tactsense as ts
from tactsense.cli import app
from tactsense.interop.urdf import (
    UrdfError,
    finger_array_to_urdf,
    read_tactile_arrays,
    sensor_from_urdf,
)

runner = CliRunner()

TOOLBOX_STYLE = textwrap.dedent(
    """\
    <?xml version="1.0" encoding="utf-8"?>
    <robot name="hand" version="1.0" xmlns="http://www.ros.org">
      <link name="index_distal"/>
      <sensor name="index_tip" update_rate="100">
        <parent link="index_distal"/>
        <origin xyz="0 0 0.01" rpy="0 0 0"/>
        <tactile>
          <array rows="6" cols="10" order="row-major" size="0.002 0.003" spacing="0.0025 0.004"
                 offset="0. 0."/>
        </tactile>
      </sensor>
      <sensor name="camera" update_rate="30"><parent link="index_distal"/><camera/></sensor>
      <sensor name="palm" update_rate="50">
        <parent link="index_distal"/>
        <tactile><array rows="16" cols="16" size="0.005 0.005"/></tactile>
      </sensor>
    </robot>
    """
)


@pytest.mark.parametrize("name", ["initial", "improved"])
def test_export_then_import_gives_the_same_layout(tmp_path, name):
    spec = ts.preset(name)
    path = tmp_path / "finger.urdf"
    path.write_text(finger_array_to_urdf(spec))
    back = sensor_from_urdf(path, extends=name)
    assert back.shape == spec.shape
    assert back.array.spacing_axial_mm == pytest.approx(spec.array.spacing_axial_mm, rel=1e-12)
    assert back.array.spacing_angle_deg == pytest.approx(spec.array.spacing_angle_deg, rel=1e-12)
    assert back.electronics.scan_rate_hz == spec.electronics.scan_rate_hz
    assert back.rings.ring_width_mm == pytest.approx(spec.rings.ring_width_mm)
    assert back.rings.strip_width_mm == pytest.approx(spec.rings.strip_width_mm)
    assert back.name == spec.name


def test_exported_file_is_urdf_that_a_general_parser_reads(tmp_path):
    """urdf_parser_py (ROS's Python URDF parser) reads the robot; it ignores <sensor>, which
    only the toolbox's C++ parser knows, so the array is checked by hand from the XML."""
    import xml.etree.ElementTree as ET

    from urdf_parser_py.urdf import URDF

    spec = ts.fearing1990_initial()
    text = finger_array_to_urdf(spec, link="index_distal")
    robot = URDF.from_xml_string(text.split("\n", 1)[1])
    assert [link.name for link in robot.links] == ["index_distal"]
    array = ET.fromstring(text.split("\n", 1)[1]).find("sensor/tactile/array")
    # the arc between strips at the skin: 45 deg on a 12.7-mm radius
    spacing = [float(v) for v in array.get("spacing").split()]
    assert spacing[0] == pytest.approx(3.8e-3)
    assert spacing[1] == pytest.approx(math.pi / 4 * 12.7e-3, rel=1e-12)
    assert (array.get("rows"), array.get("cols"), array.get("order")) == ("8", "8", "row-major")


def test_import_of_a_toolbox_style_file(tmp_path):
    path = tmp_path / "hand.urdf"
    path.write_text(TOOLBOX_STYLE)
    arrays = read_tactile_arrays(path)
    assert [a.name for a in arrays] == ["index_tip", "palm"]  # the camera has no array
    assert arrays[1].spacing_m == arrays[1].size_m  # spacing defaults to size
    with pytest.raises(UrdfError, match=r"2 tactile arrays \('index_tip', 'palm'\); pick one"):
        sensor_from_urdf(path)
    spec = sensor_from_urdf(path, name="index_tip", extends="improved")
    assert spec.shape == (6, 10)
    assert spec.array.cylinder_rows == 5 and spec.array.tip_row
    assert spec.array.spacing_axial_mm == pytest.approx(2.5)
    radius = ts.fearing1990_improved().body.diameter_mm / 2
    assert spec.array.spacing_angle_deg == pytest.approx(math.degrees(4.0 / radius))
    assert spec.electronics.scan_rate_hz == 100
    with pytest.raises(UrdfError, match="no tactile array named 'thumb'"):
        sensor_from_urdf(path, name="thumb")


@pytest.mark.parametrize(
    "text, message",
    [
        ("<robot", "not XML"),
        ("<robot name='r'><link name='l'/></robot>", "no <sensor> with a <tactile><array>"),
        (
            "<robot><sensor name='s'><tactile><array rows='0' cols='4' size='0.001 0.001'/>"
            "</tactile></sensor></robot>",
            "rows='0' must be a whole number >= 1",
        ),
        (
            "<robot><sensor name='s'><tactile><array rows='4' cols='4' size='0.001'/>"
            "</tactile></sensor></robot>",
            "size='0.001' must be two numbers",
        ),
        (
            "<robot><sensor name='s'><tactile><array rows='4' cols='4'/></tactile></sensor>"
            "</robot>",
            "has no size",
        ),
        (
            "<robot><sensor name='s'><tactile><array rows='8' cols='40' size='0.005 0.005'/>"
            "</tactile></sensor></robot>",
            "does not fit the 'initial' finger",
        ),
    ],
)
def test_bad_urdf_files_are_named(tmp_path, text, message):
    path = tmp_path / "bad.urdf"
    path.write_text(text)
    with pytest.raises(UrdfError, match=message):
        sensor_from_urdf(path)


def test_command_line_round_trip(tmp_path):
    urdf, toml = tmp_path / "f.urdf", tmp_path / "f.toml"
    result = runner.invoke(
        app, ["sensor", "export", "--urdf", "--sensor", "improved", "-o", str(urdf)]
    )
    assert result.exit_code == 0, result.output
    result = runner.invoke(
        app, ["sensor", "import", str(urdf), "--extends", "improved", "-o", str(toml)]
    )
    assert result.exit_code == 0, result.output
    spec = ts.SensorSpec.from_toml(toml)
    assert spec.shape == ts.fearing1990_improved().shape
    assert spec.array.spacing_angle_deg == pytest.approx(18.0, rel=1e-12)
