"""Bad input to the contact estimation of ``locate`` (pads, point sets, ``--contacts``):
exit status 2, one line naming what was wrong, no traceback, nothing written."""

import pytest
from typer.testing import CliRunner

import tactsense as ts
from tactsense import flat_scenarios as fs
from tactsense.cli import app
from tactsense.sensor.registry import load_sensor

runner = CliRunner()


@pytest.fixture(scope="module")
def workspace(tmp_path_factory):
    folder = tmp_path_factory.mktemp("contacts_matrix")
    pad = load_sensor("pad16")
    ts.write_recording(folder / "pad.h5", ts.simulate(pad, fs.two_probes(pad), rng=0))
    finger = ts.fearing1990_initial()
    ts.write_recording(folder / "rec.h5", ts.simulate(finger, ts.probe_sweep(finger), rng=0))
    (folder / "cal.json").write_text("{}")
    return folder


BAD = [
    ("locate PAD --method bogus --out OUT", "--method 'bogus'"),
    ("locate PAD --max-contacts 0 --out OUT", "--max-contacts"),
    ("locate PAD --max-contacts 65 --out OUT", "--max-contacts"),
    ("locate PAD --threshold nan --out OUT", "--threshold"),
    ("locate PAD --threshold 0 --out OUT", "--threshold"),
    ("locate PAD --out OUT.txt", "use the extension .csv, .parquet or .h5"),
    ("locate PAD --out PAD", "an output never replaces an input"),
    ("locate REC --contacts --method fit --out OUT", "method 'fit' works on pads"),
    ("locate PAD --calibration DIR/cal.json --out OUT", "is not a tactsense calibration"),
    ("locate PAD --drift-s -1 --out OUT", "--drift-s"),
    ("locate REC --method cop --out OUT", "--method apply to the long table of contacts"),
    ("locate REC --max-contacts 2 --out OUT", "--max-contacts apply to the long table"),
    ("locate PAD --drift-s nan --out OUT", "--drift-s"),
    ("locate PAD --drift-s inf --out OUT", "--drift-s"),
]


@pytest.mark.parametrize("line, names", BAD, ids=[line for line, _ in BAD])
def test_bad_contact_options(workspace, line, names):
    out = workspace / "never_written.parquet"
    args = (
        line.replace("PAD", str(workspace / "pad.h5"))
        .replace("REC", str(workspace / "rec.h5"))
        .replace("OUT", str(out))
        .replace("DIR", str(workspace))
        .split()
    )
    result = runner.invoke(app, args)
    message = result.output
    assert result.exit_code == 2, message
    assert "Traceback" not in message
    assert names.replace("PAD", str(workspace / "pad.h5")) in " ".join(message.split()), message
    assert not out.exists()
    assert not (workspace / "never_written.events.csv").exists()
    assert (workspace / "pad.h5").stat().st_size > 0
