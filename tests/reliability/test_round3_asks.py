"""Bad input to what a lab asked for first (issue 31, item 14): ``sensor list``,
``two-probes --x-mm/--y-mm``, the ``loads`` scenario's ``--forces-g``, ``simulate
--force-log``, ``design bound`` on pads and ``sensor check --probe-g``. Each line ends
with exit status 2, one line naming what was wrong, no traceback, and nothing written."""

import pytest
from typer.testing import CliRunner

from tactsense.cli import app

runner = CliRunner()


@pytest.fixture(scope="module")
def workspace(tmp_path_factory):
    folder = tmp_path_factory.mktemp("asks")
    (folder / "taken.csv").write_text("x")
    (folder / "pad16.toml").write_text('name = "pad16"\nextends = "pad16"\n')
    (folder / "initial.toml").write_text('name = "initial"\nextends = "initial"\n')
    return folder


SIM = "simulate --sensor pad4 --out OUT.h5"
BAD = [
    # (command line, what the message must say)
    (f"{SIM} --scenario two-probes --x-mm 40", "--x-mm 40 is off the 4x4 pad 'pad4'"),
    (f"{SIM} --scenario two-probes --y-mm -9", "--y-mm -9 is off the 4x4 pad 'pad4'"),
    (f"{SIM} --scenario loads --x-mm 99", "--x-mm 99 is off the 4x4 pad"),
    (f"{SIM} --scenario loads --forces-g 0", "--forces-g '0': expected grams-force"),
    (f"{SIM} --scenario loads --forces-g 10,-5", "--forces-g '10,-5': expected grams-force"),
    (f"{SIM} --scenario loads --forces-g 10,nan", "--forces-g '10,nan': expected grams-force"),
    (f"{SIM} --scenario loads --forces-g 1e9", "--forces-g '1e9': expected grams-force"),
    (f"{SIM} --scenario loads --forces-g heavy", "--forces-g 'heavy': expected grams-force"),
    (f"{SIM} --scenario loads --forces-g 10:100:0", "--forces-g '10:100:0': expected"),
    (f"{SIM} --scenario loads --forces-g 10:100", "--forces-g '10:100': expected"),
    (f"{SIM} --scenario loads --force-g 50", "--force-g does not apply to --scenario loads"),
    (f"{SIM} --scenario loads --angle-deg 10", "--angle-deg does not apply to --scenario loads"),
    (f"{SIM} --scenario press --forces-g 10,20", "--forces-g does not apply to --scenario press"),
    ("simulate --sensor initial --out OUT.h5 --forces-g 10",
     "--forces-g does not apply to --scenario sweep-axial"),
    (f"{SIM} --scenario loads --force-log OUT.txt", "use the extension .csv"),
    (f"{SIM} --scenario loads --force-log OUT.h5", "is the same file as --out"),
    (f"{SIM} --scenario loads --force-log DIR/taken.csv", "taken.csv exists; pass --force"),
    (f"{SIM} --scenario loads --force-log DIR/nowhere/log.csv", "folder"),
    ("emulate --sensor pad4 --scenario loads --forces-g 0 --port 0",
     "--forces-g '0': expected grams-force"),
    ("design bound --sensor pad4 --x-mm 40", "--x-mm 40 is off the 4x4 pad 'pad4'"),
    ("design bound --sensor pad4 --y-mm -10", "--y-mm -10 is off the 4x4 pad 'pad4'"),
    ("design bound --sensor pad4 --axial 3", "--axial is for fingers; 'pad4' is a pad"),
    ("design bound --sensor pad4 --angle 3", "--angle is for fingers; 'pad4' is a pad"),
    ("design bound --sensor initial --x-mm 3", "--x-mm is for pads"),
    ("design bound --sensor initial --y-mm 3", "--y-mm is for pads"),
    ("design bound --sensor pad4 --x-mm nan", "'--x-mm': NaN is not a number"),
    ("sensor check DIR/pad16.toml --probe-g 0", "Invalid value for '--probe-g'"),
    ("sensor check DIR/pad16.toml --probe-g nan", "'--probe-g': NaN is not a number"),
    ("sensor check DIR/initial.toml --probe-g 50", "--probe-g maps the blind spots of a pad"),
    ("sensor list --sensor pad4", "No such option: --sensor"),
]  # fmt: skip


@pytest.mark.parametrize("line, says", BAD, ids=[line for line, _ in BAD])
def test_bad_input_is_one_line_and_writes_nothing(workspace, line, says):
    out = workspace / "out"
    args = line.replace("OUT", str(out)).replace("DIR", str(workspace)).split()
    result = runner.invoke(app, args)
    message = " ".join(result.output.split())  # rich wraps long lines at the terminal width
    assert result.exit_code == 2, message
    assert "Traceback" not in message
    assert says in message, message
    assert len([line for line in result.output.splitlines() if "error" in line]) == 1
    assert not list(workspace.glob("out*")), "something was written"
    assert (workspace / "taken.csv").read_text() == "x"
    assert not [p for p in workspace.iterdir() if ".partial" in p.name]
