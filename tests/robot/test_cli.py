"""``tactsense sensor show|check|export|list`` on a robot skin."""

from typer.testing import CliRunner

from tactsense.cli import app
from tactsense.interop.robot_urdf import read_robot_urdf
from tactsense.robot import skin_from_toml, skin_preset

runner = CliRunner()


def _run(*args):
    result = runner.invoke(app, list(args), terminal_width=400)
    return result, " ".join(result.output.split())


def test_show_lists_every_patch_and_the_totals():
    result, text = _run("sensor", "show", "--sensor", "hand4")
    assert result.exit_code == 0, text
    skin = skin_preset("hand4")
    for patch in skin.patches:
        assert patch.name in text
    assert "20 patches" in text and "4000" in text and "4 devices" in text
    assert "17 links, 16 moving joints" in text and "250 Hz" in text


def test_export_urdf_then_show_and_check_it(tmp_path):
    out = tmp_path / "hand.urdf"
    result, text = _run("sensor", "export", "--sensor", "hand4", "--format", "urdf", "-o", str(out))
    assert result.exit_code == 0, text
    back = read_robot_urdf(out)
    assert [p.name for p in back.patches] == [p.name for p in skin_preset("hand4").patches]
    result, text = _run("sensor", "show", "--sensor", str(out))
    assert result.exit_code == 0 and "4000" in text
    result, text = _run("sensor", "check", str(out))
    assert result.exit_code == 0 and "valid (20 sensors, 4000 taxels)" in text, text
    # never over an input, even with --force
    before = out.read_text()
    result, text = _run(
        "sensor", "export", "--sensor", str(out), "--format", "toml", "-o", str(out), "--force"
    )
    assert result.exit_code == 2 and out.read_text() == before


def test_export_toml_round_trips_and_show_out_writes_toml(tmp_path):
    out = tmp_path / "icub.toml"
    result, text = _run(
        "sensor", "export", "--sensor", "icub_hand", "--format", "toml", "-o", str(out)
    )
    assert result.exit_code == 0, text
    assert skin_from_toml(out) == skin_preset("icub_hand")
    again = tmp_path / "again.toml"
    result, _ = _run("sensor", "show", "--sensor", str(out), "-o", str(again))
    assert result.exit_code == 0 and skin_from_toml(again) == skin_preset("icub_hand")
    result, text = _run("sensor", "show", "--sensor", str(out), "-o", str(again))
    assert result.exit_code == 2 and "--force" in text  # an existing file needs --force


def test_check_warns_of_mixed_rates_and_overlapping_patches(tmp_path):
    path = tmp_path / "skin.toml"
    path.write_text(
        'name = "s"\nbase_link = "a"\n'
        '[[sensors]]\nname = "p"\nlink = "a"\nsensor = "pad4"\ndevice = "board"\n'
        '[[sensors]]\nname = "q"\nlink = "a"\nsensor = "dome12"\ndevice = "board"\n'
        "xyz_m = [0.0, 0.0, -0.0075]\n"
    )
    result, text = _run("sensor", "check", str(path))
    assert result.exit_code == 0, text
    assert "device 'board' reads its patches at different rates (50, 100 Hz)" in text
    # dome12's apex taxel at (0, 0, 7.5 mm) lands on pad4's taxel (0, 0) at the origin
    assert "patches 'p' and 'q': 1 pair(s) of taxels closer than 0.5 mm" in text


def test_check_reports_every_sensors_problem(tmp_path):
    path = tmp_path / "skin.toml"
    path.write_text(
        'name = "s"\nbase_link = "a"\n'
        '[[sensors]]\nname = "p"\nlink = "a"\nsensor = "pad99"\n'
        '[[sensors]]\nname = "q"\nlink = "a"\nsensor = "nothere.toml"\n'
    )
    result, text = _run("sensor", "check", str(path))
    assert result.exit_code == 2
    assert "sensors[0]" in text and "sensors[1]" in text and "nothere.toml" in text


def test_list_shows_the_skin_presets():
    result, text = _run("sensor", "list")
    assert result.exit_code == 0
    text = " ".join(text.replace("│", " ").split())
    assert "hand4 20 4000 4" in text and "icub_hand 5 60 1" in text


def test_single_sensors_still_export_as_before(tmp_path):
    result, text = _run("sensor", "export", "--sensor", "pad4", "--format", "urdf")
    assert result.exit_code == 0 and "<array" in text
    _, text_old = _run("sensor", "export", "--sensor", "pad4", "--urdf")
    assert text_old == text


# ---- r7-fixb: show gives poses and joints, takes the skin positionally, help ----


def test_show_gives_each_patchs_pose_and_the_joints_with_limits():
    """Issue 36 trial defect 3: a user must find where the patches are from the CLI."""
    import math

    result, text = _run("sensor", "show", "hand4")  # positionally, as the docs say
    assert result.exit_code == 0, text
    skin = skin_preset("hand4")
    palm = skin.patch("palm_0")
    xyz = ", ".join(f"{v * 1e3:.4g}" for v in palm.origin.xyz_m)
    rpy = ", ".join(f"{v * 180 / math.pi:.4g}" for v in palm.origin.rpy_rad)
    assert f"palm_0 │ palm │ {xyz} │ {rpy}" in text, text
    for joint in skin.joints:
        if joint.type != "fixed":
            assert f"{joint.name} │ {joint.type} │ {joint.parent} │ {joint.child}" in text
    (index1,) = [j for j in skin.joints if j.name == "index_joint1"]
    assert f"{index1.lower:.4g} rad │ {index1.upper:.4g} rad" in text
    same, again = _run("sensor", "show", "--sensor", "hand4")
    assert same.exit_code == 0 and again == text
    both, message = _run("sensor", "show", "hand4", "--sensor", "icub_hand")
    assert both.exit_code == 2 and "not both" in message


def test_sensor_help_lists_the_skin_presets_and_export_formats():
    for command in ("show", "export"):
        _result, text = _run("sensor", command, "--help")
        assert "hand4" in text and "icub_hand" in text, text
    _result, text = _run("sensor", "export", "--help")
    assert "only format" not in text and "--format urdf" in text


def test_every_sensor_command_of_the_docs_skin_block_runs(tmp_path, monkeypatch):
    """docs/robot.md's skin block: each `tactsense sensor ...` line, in order (the later
    ones read the files the earlier ones write)."""
    import shlex
    from pathlib import Path

    doc = (Path(__file__).resolve().parents[2] / "docs" / "robot.md").read_text()
    block = doc[doc.index("<!-- r7-skin -->") : doc.index("<!-- /r7-skin -->")]
    lines = [
        line.split(" #")[0].strip()
        for line in block.splitlines()
        if line.strip().startswith("tactsense sensor")
    ]
    assert len(lines) >= 5
    monkeypatch.chdir(tmp_path)
    for line in lines:
        result, text = _run(*shlex.split(line)[1:])
        assert result.exit_code == 0, f"{line}: {text}"


def test_a_urdf_round_trip_through_the_cli_keeps_the_physics(tmp_path):
    """Issue 36 trial defect 8: toml -> urdf -> toml gave pad4's patch pad16's physics."""
    import re

    skin = skin_preset("hand4")
    urdf, toml = tmp_path / "h.urdf", tmp_path / "h.toml"
    result, text = _run(
        "sensor", "export", "--sensor", "hand4", "--format", "urdf", "-o", str(urdf)
    )
    assert result.exit_code == 0, text
    result, text = _run(
        "sensor", "export", "--sensor", str(urdf), "--format", "toml", "-o", str(toml)
    )
    assert result.exit_code == 0 and "warning" not in text, text
    back = skin_from_toml(toml)
    for ours, theirs in zip(skin.patches, back.patches, strict=True):
        assert theirs.sensor.to_dict() == ours.sensor.to_dict(), ours.name
    plain = tmp_path / "plain.urdf"
    plain.write_text(
        re.sub(r"<tactsense:sensor .*?</tactsense:sensor>", "", urdf.read_text(), flags=re.S)
    )
    result, text = _run("sensor", "show", str(plain))
    assert result.exit_code == 0 and "warning:" in text and "taken from presets" in text, text


_TWO_SENSORS = (
    'name = "arm2"\nbase_link = "base"\nlinks = ["base"]\n'
    '[[sensors]]\nname = "base_pad"\nlink = "base"\nsensor = "pad16"\n{first}\n'
    '[[sensors]]\nname = "fore_pad"\nlink = "base"\nsensor = "{preset}"\n{second}\n'
)


def test_check_gives_one_line_per_problem_at_its_own_index(tmp_path):
    """Issue 36 trial defect 11: a problem was printed twice, the second time as
    "sensors[1]: sensors[0] (...)"; two sensors' problems both as sensors[0]."""
    path = tmp_path / "skin.toml"
    path.write_text(_TWO_SENSORS.format(first="", second="", preset="pad5"))
    result = runner.invoke(app, ["sensor", "check", str(path)], terminal_width=400)
    lines = [line for line in result.output.splitlines() if "pad5" in line]
    assert result.exit_code == 2 and len(lines) == 1, result.output
    assert "sensors[1] (fore_pad)" in lines[0] and "sensors[0]" not in lines[0]
    path.write_text(
        _TWO_SENSORS.format(first="xyz_m = [1, 2]", second='xyz_m = "x"', preset="pad4")
    )
    result = runner.invoke(app, ["sensor", "check", str(path)], terminal_width=400)
    lines = [line for line in result.output.splitlines() if "xyz_m" in line]
    assert result.exit_code == 2 and len(lines) == 2, result.output
    assert "sensors[0]: xyz_m = [1, 2]" in lines[0] and "sensors[1]: xyz_m = 'x'" in lines[1]
    assert all(line.count("sensors[") == 1 for line in lines), result.output


def test_the_skin_blocks_hand_written_figures_are_the_codes():
    """docs/robot.md's skin block, outside its generated table: the overlap distance of
    `sensor check` and hand4's thumb rotation limits are the code's."""
    from pathlib import Path

    from tactsense.cli._robot_sensor import OVERLAP_M

    doc = (Path(__file__).resolve().parents[2] / "docs" / "robot.md").read_text()
    block = " ".join(doc[doc.index("<!-- r7-skin -->") : doc.index("<!-- /r7-skin -->")].split())
    assert f"closer than {OVERLAP_M * 1e3:g} mm" in block
    (thumb,) = [j for j in skin_preset("hand4").joints if j.name == "thumb_abduction"]
    assert f"(joint 12, limits {thumb.lower:.3f}-{thumb.upper:.3f} rad)" in block
