"""Trial 8's findings on the three-axis pad's command-line side (r8-fixa8): ``sensor
check`` takes a preset's name and states the threshold rule it prints the number of, a
rest field on the converter's rail is warned of, ``--sensor``'s help lists every
registered preset, and "wrote" lines name a frame's components."""

from __future__ import annotations

import math
import re

import pytest
from typer.testing import CliRunner

from tactsense.cli import app
from tactsense.estimate.reading import threshold_counts
from tactsense.sensor import preset

runner = CliRunner()


def _text(result) -> str:
    return " ".join(result.output.split())  # rich wraps long lines at the terminal width


@pytest.mark.parametrize("name", ["mag4x4", "magtip"])
def test_sensor_check_takes_a_preset_name_and_states_its_threshold_rule(name):
    """``sensor check mag4x4`` checks the preset (as ``sensor show mag4x4``); the rule it
    prints gives the number it prints: 8 x the read noise x sqrt(3), at least 10 counts."""
    result = runner.invoke(app, ["sensor", "check", name])
    text = _text(result)
    assert result.exit_code == 0, text
    assert f"{name}: valid" in text
    spec = preset(name)
    noise = float(spec.flaws.read_noise_counts)
    printed = float(re.search(r"contact threshold │ ([0-9.]+) counts", text).group(1))
    assert printed == pytest.approx(threshold_counts(spec), rel=2e-3)
    assert printed == pytest.approx(max(10.0, 8 * noise * math.sqrt(3)), rel=2e-3)
    assert f"8 x the read noise of {noise:.3g} counts x sqrt(3)" in text
    assert "5 x the read noise" not in text
    assert "warning" not in text


def test_scalar_pad_keeps_its_threshold_rule():
    text = _text(runner.invoke(app, ["sensor", "check", "pad16"]))
    assert "5 x the read noise of 0.3 counts" in text


@pytest.mark.parametrize(
    "change, axis, rail",
    [("moment_a_m2 = 0.01", "z", "65535 (full scale)"),
     ("earth_field_z_ut = -100000.0", "z", "0 (zero)")],
)  # fmt: skip
def test_a_rest_field_on_the_rail_is_warned_of(tmp_path, change, axis, rail):
    """Trial 8: a skin whose rest field saturates every taxel's z was "valid" and
    simulated silently; ``sensor check`` and ``simulate`` now name the axis and counts."""
    text = preset("mag4x4").to_toml_string()
    key = change.split(" = ")[0]
    text = re.sub(rf"^{key} = .*$", change, text, flags=re.M)
    path = tmp_path / "fixa8_rail.toml"
    path.write_text(text)
    want = f"the rest field saturates the converter on the {axis} axis of 16 of 16 taxels"
    result = runner.invoke(app, ["sensor", "check", str(path)])
    assert result.exit_code == 0 and want in _text(result) and rail in _text(result)
    out = tmp_path / "fixa8_rail.h5"
    args = ["simulate", "--sensor", str(path), "--scenario", "press", "-o", str(out)]
    result = runner.invoke(app, args)
    assert result.exit_code == 0 and want in _text(result), _text(result)
    assert "frames of 4x4x3 (x, y, z) counts" in _text(result)


HELP_AND_REGISTRY = """
import json, sys
from typer.testing import CliRunner
from tactsense.cli import app
from tactsense.sensor.registry import PRESETS
text = " ".join(CliRunner().invoke(app, [sys.argv[1], "--help"], terminal_width=400).output.split())
missing = [n for n in PRESETS if repr(n) not in text]
print(json.dumps({"presets": list(PRESETS), "missing": missing}))
"""


@pytest.mark.parametrize("command", ["simulate", "emulate", "mujoco"])
def test_sensor_help_lists_every_registered_preset(command):
    """The list comes from the registry: the three-axis kind's presets (a plug-in's) too.
    In a process of its own: the help is built when the command line is, from the kinds
    registered then (this suite registers a toy kind later, in this process)."""
    import json
    import subprocess
    import sys

    done = subprocess.run([sys.executable, "-c", HELP_AND_REGISTRY, command],
                          capture_output=True, text=True, timeout=300, check=True)  # fmt: skip
    said = json.loads(done.stdout.strip().splitlines()[-1])
    assert {"mag4x4", "magtip", "pad16"} <= set(said["presets"])
    assert said["missing"] == [], said["missing"]


def test_mujoco_on_a_three_axis_pad_writes_its_components(tmp_path):
    """Trial 8: ``mujoco --sensor mag4x4`` raised a reshape traceback; now it writes
    (T, 4, 4, 3) frames and says so, and warns of a rest field on the rail."""
    pytest.importorskip("mujoco")
    from tactsense.io.recording import read_recording

    out = tmp_path / "fixa8_mj.h5"
    args = ["mujoco", "--sensor", "mag4x4", "--seconds", "0.2", "--out", str(out), "--quiet"]
    result = runner.invoke(app, args)
    text = _text(result)
    assert result.exit_code == 0, text
    assert "frames of 4x4x3 (x, y, z) counts" in text and "warning" not in text
    frames = read_recording(out).frames
    assert frames.shape[1:] == (4, 4, 3)


def test_lerobot_export_of_one_recording_says_one_episode(tmp_path):
    """Trial 8: "1 episodes"."""
    pytest.importorskip("pyarrow")
    rec = tmp_path / "fixa8_press.h5"
    args = ["simulate", "--sensor", "pad4", "--scenario", "press", "-o", str(rec)]
    assert runner.invoke(app, args).exit_code == 0
    out = tmp_path / "fixa8_lerobot"
    result = runner.invoke(app, ["export", str(rec), "--format", "lerobot", "-o", str(out)])
    assert result.exit_code == 0, _text(result)
    assert " in 1 episode at " in _text(result)
