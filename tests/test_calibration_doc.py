"""docs/calibration.md quotes, for its own command lines, the numbers a run of them gives
(issue 21, item 10: it quoted depth 3.76 mm, nu 0.377 and RMS 1.00 % where the commands
gave 4.07 mm, 0.228 and 3.59 %)."""

import importlib.util
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


def _script():
    spec = importlib.util.spec_from_file_location(
        "calibration_numbers", ROOT / "scripts" / "calibration_numbers.py"
    )
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_the_doc_holds_what_its_commands_give():
    script = _script()
    doc = (ROOT / "docs" / "calibration.md").read_text(encoding="utf-8")
    # the commands the script runs are the ones the document shows
    for line in script.COMMANDS[:4]:
        words = " ".join(line.split()[:4])
        assert words in " ".join(doc.replace("\\\n", " ").split()), line
    assert script.block() in doc


def test_creep_compensation_brings_the_knife_fit_to_the_twin():
    """The twin's skin is 3.8 mm deep with nu 0.4: with --steps the fit is within
    0.2 mm and 0.06 of them (the tolerance of the noise-free fit's test); without it,
    it is not (creep bends the fit)."""
    import tempfile

    with tempfile.TemporaryDirectory() as folder:
        cals = _script().run(Path(folder))
    fit, alone = cals["calibration.json"].model_fit, cals["knife_alone.json"].model_fit
    assert abs(fit.depth_mm - 3.8) < 0.2 and abs(fit.poisson_ratio - 0.4) < 0.06
    assert abs(alone.poisson_ratio - 0.4) > 0.06
    assert fit.rms_percent < alone.rms_percent / 2


def _weights_script():
    spec = importlib.util.spec_from_file_location(
        "weights_calibration", ROOT / "scripts" / "weights_calibration.py"
    )
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.fixture(scope="module")
def weights_run():
    script = _weights_script()
    return script, script.measure(list(script.SENSORS))


def test_the_doc_holds_what_the_weights_give(weights_run):
    """docs/calibration.md's table of the calibration from weights is the script's."""
    script, results = weights_run
    doc = (ROOT / "docs" / "calibration.md").read_text(encoding="utf-8")
    assert script.block(results) in doc
    calibrate = " ".join(script.COMMANDS[1].split()[:4])  # the command the section shows
    assert calibrate == "calibrate weights.h5 --force-log weights.csv"
    assert f"tactsense {calibrate}" in doc


def test_weights_alone_meet_the_goal_on_the_twin(weights_run):
    """Issue 32, item 4, on pad16 and fsr16 with their gain spread and 1 % of full scale
    of noise: held-out weights (a second series between the first's, another seed)
    located within 5 % (the issue's goal) where calibrated; saturation found; the presses
    beyond the range never read more than their load, and those at or past the first
    saturated weight flagged in every settled frame (no force); the leave-one-out error
    above 5 % for at most one weight (where the response bends most, which the command
    points out)."""
    script, results = weights_run
    assert [r["sensor"].name for r in results] == list(script.SENSORS)
    for result in results:
        assert "refused" not in result, result.get("refused")
        s = script.summary(result)
        assert s["saturation"] is not None
        assert s["check_within"] >= 6 and s["check_error"] < 5.0, s
        beyond = [c for c in result["check"] if not c["within"]]
        assert beyond and all(c["located_n"] < c["force_n"] for c in beyond)
        saturated = [c for c in beyond if c["force_n"] >= s["saturation"]["from_n"]]
        assert all(c["flagged_share"] == 1.0 for c in saturated)
        assert len(s["loo_off"]) <= 1
