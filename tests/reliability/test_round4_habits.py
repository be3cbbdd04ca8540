"""Round 4 (issue 32, item 2), the twin's habits of real arrays: bad input to the
piezoresistive transduction, hysteresis, drift and crosstalk says what was wrong (in the
library and at the CLI, exit 2); the new presets simulate and are located through the CLI.
"""

from __future__ import annotations

import csv

import numpy as np
import pytest
from typer.testing import CliRunner

import tactsense as ts
from tactsense._validation import TactsenseInputError
from tactsense.cli import app
from tactsense.physics.crosstalk import effective_conductance, scan_conductance
from tactsense.physics.indenters import SphereProbe
from tactsense.physics.piezo import conductance_ratio, divider_counts, hysteresis, load_drift
from tactsense.sensor import SensorSpecError
from tactsense.sensor.registry import sensor_from_dict
from tactsense.simulate import Scenario, Step

runner = CliRunner()

BAD_DESCRIPTIONS = [
    ({"transduction": {"exponent": -1.0}}, "[transduction] exponent must be positive"),
    ({"transduction": {"exponent": 0.0}}, "[transduction] exponent must be positive"),
    ({"transduction": {"exponent": 12.0}}, "exponent = 12 is outside 0.2..5"),
    ({"transduction": {"kind": "piezo"}}, "'piezoresistive'"),
    ({"flaws": {"crosstalk": 1.5}}, "[flaws] crosstalk must lie in [0, 1]"),
    ({"flaws": {"crosstalk": -0.1}}, "[flaws] crosstalk must lie in [0, 1]"),
    ({"flaws": {"hysteresis": -0.2}}, "[flaws] hysteresis must lie in [0, 1]"),
    ({"flaws": {"hysteresis": 2.0}}, "[flaws] hysteresis must lie in [0, 1]"),
    ({"flaws": {"drift_per_decade": 1.5}}, "[flaws] drift_per_decade must lie in [0, 1]"),
    ({"flaws": {"temperature_coefficient_per_k": 0.5}}, "more than 10 % per kelvin"),
    ({"flaws": {"crosstalk": "yes"}}, "[flaws] crosstalk = 'yes': expected a number"),
    ({"transduction": {"exponent": True}}, "[transduction] exponent = True: expected a number"),
]


@pytest.mark.parametrize(("change", "message"), BAD_DESCRIPTIONS)
def test_bad_habit_descriptions_say_what_is_wrong(change, message):
    with pytest.raises(SensorSpecError) as error:
        sensor_from_dict({"kind": "pad", "extends": "fsr16", **change})
    assert message in str(error.value)


@pytest.mark.parametrize("value", [float("nan"), float("inf")])
def test_non_finite_temperature_figures_are_refused(value):
    with pytest.raises(SensorSpecError, match="temperature_rate_k_per_s must be a finite"):
        ts.preset("fsr16").replace(flaws__temperature_rate_k_per_s=value)


def test_bad_crosstalk_at_the_cli_is_one_line_and_exit_2(tmp_path):
    path = tmp_path / "bad.toml"
    path.write_text('kind = "pad"\nextends = "fsr16"\n[flaws]\ncrosstalk = 2.0\n')
    result = runner.invoke(app, ["sensor", "check", str(path)])
    assert result.exit_code == 2, result.output
    assert "crosstalk must lie in [0, 1]" in result.output
    assert "Traceback" not in result.output


def test_a_description_written_before_the_habits_still_loads(tmp_path):
    """A complete pad description without the new keys (exponent, the habits' flaws)
    loads, with them off."""
    data = ts.preset("pad16").to_dict()
    for key in ("exponent", "polarity"):
        data["transduction"].pop(key)
    for key in ("hysteresis", "drift_per_decade", "temperature_coefficient_per_k",
                "temperature_rate_k_per_s", "crosstalk"):  # fmt: skip
        data["flaws"].pop(key)
    assert sensor_from_dict(data) == ts.preset("pad16")


@pytest.mark.parametrize(
    ("call", "message"),
    [
        (lambda: scan_conductance(np.ones((3, 3)), 1.5), "crosstalk must lie in [0, 1]"),
        (lambda: scan_conductance(np.ones((3, 3)), float("nan")), "crosstalk must lie"),
        (lambda: effective_conductance(np.ones(4)), "shape (..., rows, cols)"),
        (lambda: effective_conductance(-np.ones((2, 2))), "non-negative"),
        (lambda: effective_conductance(np.full((2, 2), np.nan)), "finite"),
        (lambda: conductance_ratio([0.1], 0.0), "half_scale_strain must be a positive"),
        (lambda: conductance_ratio([0.1], 0.1, -1.0), "exponent must be a positive"),
        (lambda: divider_counts([-0.5], 0.0, 4095.0), "never negative"),
        (lambda: hysteresis(np.ones((3, 2)), 1.5), "hysteresis must lie in [0, 1]"),
        (lambda: hysteresis(np.ones((0, 2)), 0.2), "time axis"),
        (lambda: load_drift(np.ones((3, 2)), [0.0, 1.0], 0.05), "2 values for 3 frames"),
        (lambda: load_drift(np.ones((3, 2)), [0.0, 1.0, 2.0], -0.1), "must lie in [0, 1]"),
    ],
)
def test_bad_arguments_to_the_habits_say_what_is_wrong(call, message):
    with pytest.raises(TactsenseInputError) as error:
        call()
    assert message in str(error.value)


def test_a_temperature_drift_that_would_make_a_cell_negative_is_refused():
    spec = ts.preset("fsr16").replace(
        flaws__temperature_coefficient_per_k=-0.05, flaws__temperature_rate_k_per_s=1.0
    )
    probe = SphereProbe(20.0, 20.0, 1.0)
    scenario = Scenario((Step((), 0.1, "rest"), Step((probe,), 30.0, "hold")))
    with pytest.raises(TactsenseInputError, match="conductance negative"):
        ts.simulate(spec, scenario, flaws=["drift"])


def test_unknown_flaw_names_list_the_new_ones():
    with pytest.raises(TactsenseInputError, match="hysteresis, drift, crosstalk"):
        ts.simulate(ts.preset("fsr16"), Scenario((Step((), 0.1, "rest"),)), flaws=["ghosts"])


@pytest.mark.parametrize("name", ["fsr16", "dsa9205"])
def test_new_presets_simulate_and_locate_through_the_cli(name, tmp_path):
    """``tactsense simulate --sensor NAME`` then ``locate``: one press, one contact id,
    found in at least 90 % of its loaded frames (the probe's 50 g is near the FSR's
    0.1-0.2 N actuation force; read noise is 1 % of full scale)."""
    rec, out = tmp_path / f"{name}.h5", tmp_path / f"{name}.csv"
    result = runner.invoke(app, ["simulate", "--sensor", name, "--scenario", "press",
                                 "-o", str(rec)])  # fmt: skip
    assert result.exit_code == 0, result.output
    frames = ts.read_recording(rec)
    assert frames.sensor == ts.preset(name)
    assert np.median(frames.frames[:10]) == 0.0  # untouched it reads 0
    result = runner.invoke(app, ["locate", str(rec), "-o", str(out)])
    assert result.exit_code == 0, result.output
    rows = list(csv.DictReader(out.open()))
    loaded = np.flatnonzero(frames.truth["frame_step"] == 1)
    during = [r for r in rows if int(r["frame"]) in set(loaded.tolist())]
    assert len({r["frame"] for r in during}) >= 0.9 * len(loaded)
    assert len({r["id"] for r in during}) == 1


def test_the_fsr_example_of_docs_sensors_is_valid():
    """docs/sensors.md's FSR matrix of one's own loads, with the habits it names."""
    from pathlib import Path

    text = (Path(__file__).resolve().parents[2] / "docs" / "sensors.md").read_text()
    block = text.split("An FSR matrix of your own", 1)[1].split("```toml\n", 1)[1]
    spec = ts.sensor.SpecBase.from_toml_string(block.split("```", 1)[0])
    assert spec.shape == (8, 8) and spec.transduction.kind == "piezoresistive"
    assert (spec.flaws.crosstalk, spec.flaws.hysteresis) == (1.0, 0.2)
