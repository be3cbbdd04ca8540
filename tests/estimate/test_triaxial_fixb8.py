"""Trial 8's slip-label and threshold defects (r8-fixb8): a dead band between stick and
partial, a stick row's c/a, one --threshold rule on a three-axis pad, and locate's
summary when nothing was touched."""

from __future__ import annotations

import numpy as np
import pytest
from typer.testing import CliRunner

from tactsense.estimate.triaxial.slip import PARTIAL_RATIO, STICK_RATIO, SlipMonitor


def _states(ratios, friction):
    monitor = SlipMonitor(0.01, friction=friction)
    n = len(ratios)
    zeros = np.zeros(n)
    return monitor.update(np.arange(n), np.zeros(n, int), np.asarray(ratios, float), zeros,
                          zeros, zeros, np.full(n, 0.5))  # fmt: skip


@pytest.mark.parametrize("friction", [1.0, None], ids=["mu given", "mu found"])
def test_noise_about_the_stick_ratio_does_not_flip_the_state(friction):
    # the trial's ratios: 0.032 then 0.025 flipped partial -> stick; inside the dead
    # band [STICK_RATIO, PARTIAL_RATIO) a contact keeps its state
    assert 0.025 < STICK_RATIO < 0.032 < 0.045 < PARTIAL_RATIO
    out = _states([0.0, 0.032, 0.045, 0.06, 0.032, 0.045, 0.025, 0.045], friction)
    assert list(out["slip_state"]) == [
        "stick", "stick", "stick", "partial", "partial", "partial", "stick", "stick",
    ]  # fmt: skip


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_a_press_alone_sticks(seed):
    # a press with no tangential force: the uncalibrated ratio's noise (up to 0.035 on
    # the twin, straddling STICK_RATIO) labelled most rows `partial` or flipped them
    import tactsense as ts
    from tactsense.estimate.triaxial.locate import ShearPipeline
    from tactsense.flat_scenarios import press

    spec = ts.preset("mag4x4")
    recording = ts.simulate(spec, press(spec), rng=seed)
    pipeline = ShearPipeline(spec, np.median(recording.frames[:5].astype(float), axis=0))
    table, _ = pipeline(recording.frames)
    held = table.force_n > 0.2  # the press, not its last (lift) frame
    assert held.sum() > 30
    assert (table.extra["slip_state"][held] == "stick").all()
    np.testing.assert_array_equal(table.extra["stick_ratio"][held], 1.0)


@pytest.mark.parametrize("friction", [1.0, None], ids=["mu given", "mu found"])
def test_a_stick_rows_stick_ratio_is_one(friction):
    # stick = no tangential load: no slip annulus, c/a = 1 (the trial saw 0.991)
    out = _states([0.0, 0.01, 0.02, 0.2], friction)
    stick = out["slip_state"] == "stick"
    assert stick.sum() == 3
    np.testing.assert_array_equal(out["stick_ratio"][stick], 1.0)
    if friction is not None:  # partial: Cattaneo-Mindlin's c/a (Johnson 1985, eq. 7.40)
        np.testing.assert_allclose(out["stick_ratio"][3], (1 - 0.2 / friction) ** (1 / 3))


def _recording(tmp_path):
    import tactsense as ts

    spec = ts.preset("mag4x4")
    rec = tmp_path / "fixb8_rest.h5"
    ts.write_recording(rec, ts.simulate(spec, ts.Scenario((ts.Step((), 0.2),)), rng=0))
    return spec, rec


def test_locate_says_no_contact_not_nan(tmp_path):
    from tactsense.cli import app

    _, rec = _recording(tmp_path)
    out = tmp_path / "fixb8_rest.csv"
    result = CliRunner().invoke(app, ["locate", str(rec), "-o", str(out), "--threshold", "0.01"])
    text = " ".join(result.output.split())
    assert result.exit_code == 0, text
    assert "nan" not in text
    assert "no contact found (threshold 0.01 of full scale = 655 counts" in text


def test_live_takes_locates_threshold_on_a_three_axis_pad(tmp_path):
    # one rule: --threshold is a fraction of the converter's full scale on locate,
    # export, live and view alike
    from tactsense.cli._live_sources import _locator_for
    from tactsense.estimate.triaxial.locate import threshold_counts_of

    spec, _ = _recording(tmp_path)
    locator = _locator_for(spec, None, 5, 0.01, keep_deflection=False, contact_options=None)
    assert locator._options["threshold_counts"] == pytest.approx(0.01 * 65535)
    assert threshold_counts_of(spec, 0.01) == pytest.approx(0.01 * 65535)
    assert threshold_counts_of(spec, None) is None


def test_live_method_message_has_no_doubled_quote(tmp_path):
    # the trial saw `'mag4x4''s` in `live --method cop`'s refusal
    from tactsense._validation import TactsenseInputError
    from tactsense.cli._live_sources import _locator_for

    spec, _ = _recording(tmp_path)
    with pytest.raises(TactsenseInputError) as error:
        _locator_for(spec, None, 5, None, keep_deflection=False, contact_options={"method": "cop"})
    assert "''" not in str(error.value) and "the contacts of 'mag4x4'" in str(error.value)


def test_locate_help_states_the_three_axis_threshold_rule():
    from tactsense.cli import app

    result = CliRunner().invoke(app, ["locate", "--help"], terminal_width=200)
    text = " ".join(result.output.replace("│", " ").split())
    assert "Three-axis taxels (the same rule in locate, export, live and view)" in text
    assert "read_noise_counts times sqrt(3), at least 10 counts" in text
