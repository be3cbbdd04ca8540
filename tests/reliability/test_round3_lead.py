"""Issue 31, found by a new user's trial of round three: an export whose extension names
another format wrote that format under the wrong name (``export --format mcap --out
x.csv``: an MCAP file called x.csv, exit 0), and ``python -m tactsense`` did not run.
Each bad line ends with exit status 2, one line naming what was wrong, and nothing
written."""

import subprocess
import sys

import pytest
from typer.testing import CliRunner

import tactsense as ts
from tactsense.cli import app
from tactsense.flat_scenarios import press

runner = CliRunner()


@pytest.fixture(scope="module")
def rec(tmp_path_factory):
    folder = tmp_path_factory.mktemp("lead")
    spec = ts.preset("pad4")
    path = folder / "rec.h5"
    ts.write_recording(path, ts.simulate(spec, press(spec, lift_s=0.2), rng=0))
    return path


BAD = [
    ("--format mcap --out OUT.csv", "the extension .csv is for --format csv, not --format mcap"),
    ("--format csv --out OUT.mcap", "the extension .mcap is for --format mcap, not --format csv"),
    ("--format rerun --out OUT.mcap", "not --format rerun; name the output with .rrd"),
    ("--format lerobot --out OUT.rrd", "name the output a folder without an extension"),
]  # fmt: skip


@pytest.mark.parametrize("options, expected", BAD)
def test_an_extension_of_another_format_is_refused(tmp_path, rec, options, expected):
    words = options.replace("OUT", str(tmp_path / "out")).split()
    result = runner.invoke(app, ["export", str(rec), *words])
    assert result.exit_code == 2, result.output
    said = " ".join(result.output.split())
    assert expected in said, said
    assert "Traceback" not in result.output
    assert list(tmp_path.iterdir()) == []


def test_python_dash_m_tactsense_is_the_command():
    done = subprocess.run([sys.executable, "-m", "tactsense", "sensor", "list"],
                          capture_output=True, text=True, timeout=120)  # fmt: skip
    assert done.returncode == 0, done.stderr
    assert "pad16" in done.stdout and "dome12" in done.stdout
