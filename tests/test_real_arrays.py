"""Issue 32, done when: a zero-at-rest piezoresistive matrix and an inverted capacitive
fingertip are described, imported, located and calibrated in newtons from weights alone,
end to end through the command line (``scripts/real_arrays_example.py``, the worked
examples of docs/devices.md, "Describing your array")."""

from __future__ import annotations

import importlib.util
import math
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


def _script():
    spec = importlib.util.spec_from_file_location(
        "real_arrays_example", ROOT / "scripts" / "real_arrays_example.py"
    )
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # its dataclass looks its module up
    spec.loader.exec_module(module)
    return module


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    script = _script()
    folder = tmp_path_factory.mktemp("arrays")
    return script, {name: script.run_array(name, folder / name) for name in script.ARRAYS}


# Tolerance of a load inside the calibrated range, between two weights: the curve is
# piecewise linear between knots 40 g (FSR) or 20 g (fingertip) apart, and the FSR's
# divider bends most below its second weight, where the lightest load lies (its
# leave-one-out error there is the table's largest); elsewhere the goal of issue 32
# (held-out weights within 5 % in the linear range) holds.
LIGHTEST_TOLERANCE = 0.10
TOLERANCE = 0.05


@pytest.mark.parametrize("name", ["lab_fsr", "lab_tip"])
def test_newtons_from_weights_alone(run, name):
    script, outcomes = run
    outcome = outcomes[name]
    assert outcome.presses_found == len(script.ARRAYS[name]["weights_g"])
    inside = [row for row in outcome.rows if row[0] < outcome.range_n / script.GRAM]
    beyond = [row for row in outcome.rows if row[0] > outcome.range_n / script.GRAM * 1.05]
    assert len(inside) == 4 and len(beyond) == 1
    for k, (applied, read, flagged) in enumerate(inside):
        tolerance = LIGHTEST_TOLERANCE if k == 0 else TOLERANCE
        assert abs(read / applied - 1) < tolerance, (applied, read)
        assert flagged == 0.0
    applied, read, flagged = beyond[0]
    assert math.isinf(read), "a load beyond the heaviest weight was extrapolated"
    assert flagged > 0.9


def test_the_docs_table_is_the_scripts(run):
    script, outcomes = run
    text = (ROOT / "docs" / "devices.md").read_text()
    generated = script.block([outcomes[name] for name in script.ARRAYS])
    assert generated in text, "run: python scripts/real_arrays_example.py --write"
