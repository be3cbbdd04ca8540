"""docs/accuracy.md's pad bounds table and docs/sensors.md's tension sentence hold what
scripts/pad_bounds_numbers.py computes (one row recomputed: pad16 at 1 % of full scale)."""

import importlib.util
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def _script():
    spec = importlib.util.spec_from_file_location(
        "pad_bounds_numbers", ROOT / "scripts" / "pad_bounds_numbers.py"
    )
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_accuracy_doc_holds_the_pad16_row():
    script = _script()
    doc = (ROOT / "docs" / "accuracy.md").read_text()
    assert script.row("pad16", 1.0) in doc


def test_sensors_doc_holds_the_tension_sentence():
    script = _script()
    doc = (ROOT / "docs" / "sensors.md").read_text()
    sentence = script.tension()
    assert sentence in doc
    assert "(-206 counts' worth" in sentence
