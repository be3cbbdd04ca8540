"""Commands given a pad or a point set they cannot handle yet: one line naming the sensor
and its kind, exit status 2, no traceback, nothing written."""

import pytest
from typer.testing import CliRunner

import tactsense as ts
from tactsense.cli import app
from tactsense.flat_scenarios import press

runner = CliRunner()


@pytest.fixture(scope="module")
def folder(tmp_path_factory):
    where = tmp_path_factory.mktemp("kinds")
    pad = ts.preset("pad4")
    ts.write_recording(where / "pad.h5", ts.simulate(pad, press(pad), rng=0, flaws="none"))
    (where / "taxels.json").write_text('[{"xyz": [0, 0, 0], "normal": [0, 0, 1]}]')
    twin = '{"xyz": [1, 2, 3], "normal": [0, 0, 1], "area": 4}'
    (where / "twins.json").write_text(f"[{twin}, {twin}]")
    from tactsense.interop.urdf import sensor_to_urdf

    (where / "pad.urdf").write_text(sensor_to_urdf(ts.preset("pad16")))
    return where


CASES = [
    ("calibrate pad.h5 --out OUT.json", "this is not a probe pressed on every taxel"),
    ("reproduce --sensor pad16 --out OUT", "works on finger sensors; 'pad16' is a pad"),
    (
        "design bound --sensor dome12",
        "works on finger sensors and pad sensors; 'dome12' is a point set",
    ),
    ("design sweep --sensor dome12 --out OUT.nc", "fingers and pads; 'dome12' is a point set"),
    ("sensor import pad.h5 --extends bogus", "--extends 'bogus' is not a preset"),
    ("sensor import taxels.json", "taxel 0 must be"),
    ("sensor import twins.json", "repeats another taxel's position"),
    ("sensor import pad.urdf", "a flat pad? give --extends pad16"),
    (
        "simulate --scenario repeated --repeats 1000000 --dwell-s 3600 --out OUT.h5",
        "at most 100,000,000 frames",
    ),
]


@pytest.mark.parametrize("line, message", CASES)
def test_kind_refusals_are_one_line(folder, monkeypatch, line, message):
    monkeypatch.chdir(folder)
    result = runner.invoke(app, line.split())
    assert result.exit_code == 2, result.output
    assert message in result.output
    assert "Traceback" not in result.output
    assert not list(folder.glob("OUT*"))
