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


def _block(name: str) -> str:
    text = DOC.read_text()
    return text[text.index(f"<!-- {name} -->") : text.index(f"<!-- /{name} -->")]


def test_the_calibration_sweeps_recipe_runs_as_written(tmp_path, monkeypatch):
    """docs/triaxial.md's recipe (trial 8 defect 4): every line runs as written, the x and
    y sweeps push every taxel along x and y at Q/P 0.3, and the calibration it makes
    gives the sheared contact's direction within 3 deg."""
    import csv
    import json

    import numpy as np

    from tactsense.io.recording import read_recording

    block = _block("r8-fixc8")
    lines = [line for line in block.splitlines() if line.startswith("tactsense ")]
    assert len(lines) == 6
    monkeypatch.chdir(tmp_path)
    for line in lines:
        result = runner.invoke(app, line.split()[1:])
        assert result.exit_code == 0, (line, result.output)
    for name, (ux, uy) in (("sweep_x.h5", (1, 0)), ("sweep_y.h5", (0, 1))):
        recording = read_recording(tmp_path / name)
        steps = json.loads(recording.truth["step_contacts_json"])  # a list per step
        pressed = [step[0] for step in steps if step]
        spec = recording.sensor
        assert len({(c["x_mm"], c["y_mm"]) for c in pressed}) == spec.n_taxels
        for c in pressed:  # a push of 0.3 times the press along the axis, on every taxel
            q = np.array([c.get("shear_x_n", 0.0), c.get("shear_y_n", 0.0)])
            np.testing.assert_allclose(q, 0.3 * c["force_n"] * np.array([ux, uy]), atol=1e-12)
    with open(tmp_path / "contacts.csv") as f:
        rows = list(csv.DictReader(f))
    top = max(rows, key=lambda r: float(r["shear_n"]))
    assert abs(float(top["shear_angle_deg"]) - 30.0) < 3.0, top
