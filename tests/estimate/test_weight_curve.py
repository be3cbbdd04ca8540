"""Force from known weights alone (issue 32, item 4): the weight curve against laws
evaluated independently here, its saturation, leave-one-out, hysteresis and
temperature, the presses found in a recording, and the curve applied by find_contacts."""

import numpy as np
import pytest

import tactsense as ts
from tactsense import flat_scenarios as fs
from tactsense.estimate.contacts import find_contacts, signal_from_counts
from tactsense.estimate.contacts.array_calibration import (
    ArrayCalibration,
    ArrayCalibrationError,
    Presses,
    hysteresis,
    read_weights_log,
    segment_presses,
    temperature_coefficient,
    weight_curve,
)
from tactsense.estimate.finger.deflection import Flag

G = 9.80665e-3  # N per gram-force


def _presses(force, total, saturated=None, temperature=None):
    n = len(force)
    return Presses(np.arange(n) * 100, np.arange(n) * 100 + 50, np.asarray(total, float),
                   np.asarray(force, float),
                   np.zeros(n, bool) if saturated is None else np.asarray(saturated),
                   None if temperature is None else np.asarray(temperature, float))  # fmt: skip


def test_the_curve_is_the_inverse_of_a_known_piecewise_linear_law():
    """A law with kinks at weights and a flat top from 1.0 N (saturation without a rail):
    the curve reads the law's inverse exactly between weights, the range ends at 1.0 N,
    and a total above it has no force (NaN, beyond)."""
    law_f = [0.0, 0.2, 0.5, 1.0, 2.0]
    law_t = [0.0, 0.04, 0.08, 0.11, 0.11]
    weights = np.round(np.arange(0.1, 1.51, 0.1), 3)
    curve = weight_curve(_presses(weights, np.interp(weights, law_f, law_t)))
    assert curve["saturation"]["from_n"] == pytest.approx(1.1)
    assert "stopped growing" in curve["saturation"]["reason"]
    assert curve["force_n"][-1] == pytest.approx(1.0)
    cal = ArrayCalibration("", np.zeros(1), np.ones(1), np.zeros(1, bool),
                           (curve["signal_total"], curve["force_n"]),
                           curve_input="signal_total",
                           curve_top=curve["signal_total_max"])  # fmt: skip
    between = np.array([0.05, 0.25, 0.45, 0.65, 0.95])  # loads no weight had
    force, beyond = cal.force_of_total(np.interp(between, law_f, law_t))
    np.testing.assert_allclose(force, between, rtol=1e-9)
    assert not beyond.any()
    force, beyond = cal.force_of_total(np.array([0.1101, 0.5]))
    assert np.all(np.isnan(force)) and beyond.all()


def test_leave_one_out_is_the_chord_of_the_neighbours():
    """T = sqrt(F): a weight held out is read on the chord between its neighbours, the
    lightest on the chord from the origin; both computed here in closed form."""
    f = np.array([0.1, 0.2, 0.3, 0.4, 0.5, 0.6])
    t = np.sqrt(f)
    curve = weight_curve(_presses(f, t))
    for k, w in enumerate(curve["weights"]):
        if k == len(f) - 1:
            assert w["loo_n"] is None and "not extrapolated" in w["loo_note"]
            continue
        lo_f, lo_t = (0.0, 0.0) if k == 0 else (f[k - 1], t[k - 1])
        chord = lo_f + (f[k + 1] - lo_f) * (t[k] - lo_t) / (t[k + 1] - lo_t)
        assert w["loo_n"] == pytest.approx(chord, rel=1e-12)
        assert w["loo_between"] == (k > 0)
    inner = [abs(chord_error) for chord_error in
             (100 * (w["loo_n"] / w["force_n"] - 1) for w in curve["weights"][1:-1])]  # fmt: skip
    assert curve["loo_max_error_percent"] == pytest.approx(max(inner))


def test_noise_is_made_monotone_and_replicates_pooled():
    """Two presses per weight; one pair out of order by noise: the knots still rise (the
    isotonic fit), and each weight is one knot at its presses' median."""
    f = np.repeat([0.1, 0.2, 0.3, 0.4], 2)
    t = 0.1 * f + np.array([0, 0.0002, 0.0001, 0.0003, 0.0, 0.0, 0.0, 0.0])
    t[4:6] = 0.0295  # the 0.3-N weight reads a hair under the 0.2-N one
    curve = weight_curve(_presses(f, t))
    assert np.all(np.diff(curve["signal_total"]) > 0)
    assert [w["presses"] for w in curve["weights"]] == [2, 2, 2, 2]


def test_hysteresis_of_a_known_unloading_branch():
    """Unloading reads 10 % more than loading at every load: the loading branch gives an
    unloading press of load F the force 1.1 F; the largest difference is 0.1 times the
    heaviest unloading press within the loading branch's range, over full scale."""
    up = np.array([0.1, 0.2, 0.3, 0.4, 0.5])
    down = up[::-1][1:]
    force = np.r_[up, down]
    total = np.r_[0.1 * up, 0.11 * down]
    presses = _presses(force, total)
    curve = weight_curve(presses)
    h = hysteresis(presses, curve)
    assert h["measured"]
    within = down[0.11 * down <= 0.1 * up[-1]]
    assert h["max_difference_n"] == pytest.approx(0.1 * within.max(), rel=1e-9)
    assert h["percent_of_full_scale"] == pytest.approx(100 * 0.1 * within.max() / 0.5)
    assert not hysteresis(_presses(up, 0.1 * up), weight_curve(_presses(up, 0.1 * up)))["measured"]


def test_temperature_coefficient_of_a_known_drift():
    f = np.tile([0.1, 0.2, 0.3, 0.4, 0.5], 3)
    temp = np.repeat([20.0, 25.0, 30.0], 5)
    total = 0.1 * f * (1 + 0.004 * (temp - 25.0))
    presses = _presses(f, total, temperature=temp)
    found = temperature_coefficient(presses, weight_curve(presses))
    assert found["calibrated"]
    assert found["coefficient_per_c"] == pytest.approx(0.004, rel=0.02)
    assert found["reference_c"] == 25.0
    flat = _presses(f, total, temperature=np.full(15, 22.0))
    assert not temperature_coefficient(flat, weight_curve(flat))["calibrated"]
    assert "no temperature_c" in temperature_coefficient(
        _presses(f, total), weight_curve(_presses(f, total)))["why"]  # fmt: skip


def test_presses_are_found_in_a_series_with_creep_tails_and_noise():
    """Six weights held 60 frames, lifted 40; after each lift a tail of a third of the
    press decays with a 10-frame time constant (creep), over noise of 0.5 % of the
    heaviest: six presses, each starting within 2 frames of the placement."""
    rng = np.random.default_rng(0)
    loads = [0.2, 0.5, 0.3, 0.9, 0.6, 1.0]
    series, starts = [np.zeros(20)], []
    for load in loads:
        starts.append(sum(map(len, series)))
        series.append(np.full(60, load))
        series.append(load / 3 * np.exp(-np.arange(40) / 10.0))
    total = np.concatenate(series) + rng.normal(0, 0.005, sum(map(len, series)))
    found = segment_presses(np.maximum(total, 0))
    assert len(found) == len(loads)
    assert np.all(np.abs(np.array([a for a, _, _ in found]) - starts) <= 2)


def test_units_in_the_header(tmp_path):
    rows = "1,100\n2,200\n"
    for column, factor in [("mass_g", G), ("mass_kg", 1000 * G), ("force_n", 1.0),
                           ("force_mn", 1e-3)]:  # fmt: skip
        path = tmp_path / f"{column}.csv"
        path.write_text(f"press,{column}\n{rows}")
        log = read_weights_log(path)
        np.testing.assert_allclose(log.force_n, [100 * factor, 200 * factor])
        assert log.time_s is None and log.column == column


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("press,mass\n1,10\n", "column 'mass' has no unit"),
        ("press,mass_g\n1,10\n2,-5\n", "line 3: mass_g is -5"),
        ("press,mass_g,force_n\n1,10,0.1\n", "are both loads"),
        ("press,mass_g\n1,10\n2,\n", "line 3: mass_g is blank"),
        ("press,mass_g,temperature\n1,10,20\n", "temperature_c"),
        ("time_s,mass_g\n0,1\n", "at least 2 rows"),
    ],
)
def test_a_bad_weights_log_is_one_line(tmp_path, text, message):
    path = tmp_path / "w.csv"
    path.write_text(text)
    with pytest.raises(ArrayCalibrationError, match=message):
        read_weights_log(path)


@pytest.mark.parametrize(
    ("force", "total", "saturated", "message"),
    [
        ([0.1, 0.2], [0.01, 0.02], None, "a curve needs at least 3"),
        ([0.5, 0.5, 0.52], [0.05, 0.05, 0.05], None, "holds one load"),
        ([0.1, 0.2, 0.3, 0.4], [0.04, 0.03, 0.02, 0.01], None, "does not rise with the load"),
        ([0.1, 0.2, 0.3], [0.1, 0.1, 0.1], [True] * 3, "every weight saturated"),
        ([0.1, 0.2, 0.3, 0.4], [0.01, 0.02, 0.03, 0.03], [False, False, True, True],
         "2 weights below saturation"),
    ],
)  # fmt: skip
def test_a_series_that_cannot_make_a_curve_is_refused(force, total, saturated, message):
    with pytest.raises(ArrayCalibrationError, match=message):
        weight_curve(_presses(force, total, saturated))


def test_find_contacts_reads_the_curve_at_the_contact_total():
    """One press on pad16: the contact's force is the curve at the sum of its taxels'
    signal above the threshold (summed here from the signal), and above the curve's top
    it is NaN and flagged."""
    pad = ts.preset("pad16")
    rec = ts.simulate(pad, fs.press(pad, force_n=30 * G), rng=0, flaws="none")
    base = rec.frames[0].astype(float)
    signal, _ = signal_from_counts(rec.frames, base, pad)
    threshold = 0.0005
    k = int(np.argmax(signal.sum(axis=(1, 2))))
    total = signal[k][signal[k] > threshold].sum()
    curve = ([0.0, 1.0], [0.0, 2.0])  # 2 N per unit of total signal
    cal = ArrayCalibration(pad.to_toml_string(), base, np.ones(pad.shape),
                           np.zeros(pad.shape, bool), curve, notes={"threshold": threshold},
                           curve_input="signal_total", curve_top=1.0)  # fmt: skip
    table = find_contacts(rec.frames[k], pad, calibration=cal)
    assert len(table) == 1
    assert table.force_n[0] == pytest.approx(2 * total, rel=1e-9)
    low = ArrayCalibration(pad.to_toml_string(), base, np.ones(pad.shape),
                           np.zeros(pad.shape, bool), ([0.0, total / 2], [0.0, 1.0]),
                           notes={"threshold": threshold}, curve_input="signal_total",
                           curve_top=total / 2)  # fmt: skip
    table = find_contacts(rec.frames[k], pad, calibration=low)
    assert np.isnan(table.force_n[0]) and table.flags[0] & int(Flag.BEYOND_CALIBRATION)


def test_the_weight_curve_survives_its_json(tmp_path):
    from tactsense.estimate.contacts.array_calibration import load_calibration

    pad = ts.preset("pad16")
    cal = ArrayCalibration(pad.to_toml_string(), np.full(pad.shape, 100.0), np.ones(pad.shape),
                           np.zeros(pad.shape, bool), ([0.0, 0.1, 0.2], [0.0, 0.5, 0.8]),
                           notes={"threshold": 0.01}, curve_input="signal_total",
                           curve_top=0.204)  # fmt: skip
    back = load_calibration(cal.save(tmp_path / "c.json"), pad)
    assert back.curve_input == "signal_total" and back.curve_top == 0.204
    assert back.force_curve == cal.force_curve and back.contact_threshold == 0.01
