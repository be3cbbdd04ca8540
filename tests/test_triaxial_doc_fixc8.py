"""docs/triaxial.md's claims about reading files back, against the tool (trial 8, defect
7; r8-fixc8)."""

import re
from pathlib import Path

from typer.testing import CliRunner

from tactsense.cli import app

DOC = Path(__file__).resolve().parents[1] / "docs" / "triaxial.md"
runner = CliRunner()


def _text() -> str:
    return " ".join(DOC.read_text().split())


def test_the_doc_says_an_rrd_does_not_import_and_import_refuses_it(tmp_path):
    text = _text()
    assert "A Rerun `.rrd` does not import" in text
    assert "each form reads back" not in text  # the old claim, which took in the .rrd
    quoted = re.search(r'`import` refuses it, "([^"]+)"', text).group(1)
    rrd = tmp_path / "fixc8.rrd"
    rrd.write_bytes(b"RRF2")
    result = runner.invoke(app, ["import", str(rrd), "-o", str(tmp_path / "x.h5")])
    message = " ".join(result.output.split())
    assert result.exit_code == 2 and quoted in message, message


def test_every_form_the_doc_says_imports_is_in_import_help():
    text = _text()
    listed = re.search(r"`import --help`: ([^)]+)\)", text).group(1)
    help_text = " ".join(runner.invoke(app, ["import", "--help"]).output.split())
    for form, word in (("MCAP", "MCAP"), ("rosbag2", "rosbag2"), ("XDF", "XDF"),
                       ("CSV", "CSV"), ("LeRobot", "LeRobot")):  # fmt: skip
        assert form in listed
        assert word in help_text, word
    assert ".rrd" not in help_text and "Rerun" not in help_text
