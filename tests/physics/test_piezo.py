"""Piezoresistive cells (tactsense.physics.piezo), each habit against an independent
evaluation: the divider from its resistors, the power law from a log-log fit, the
hysteresis loop's area from the model's definition against a numerical loading and
unloading run, the drift from its formula, and the simulator against the elastic model
read through the closed-form divider."""

from __future__ import annotations

import numpy as np
import pytest

import tactsense as ts
from tactsense.physics.indenters import SphereProbe
from tactsense.physics.pad_response import pad_strain
from tactsense.physics.piezo import (
    conductance_ratio,
    divider_conductance,
    divider_counts,
    hysteresis,
    hysteresis_loop_area,
    load_drift,
    temperature_factor,
)
from tactsense.simulate import Scenario, Step

FULL = 4095.0


@pytest.mark.parametrize("r_fsr_ohm", [1e7, 1e5, 1e4, 3.3e3, 1e3, 250.0])
def test_divider_counts_is_the_voltage_divider_of_the_integration_guide(r_fsr_ohm):
    """V_out = V+ R_M / (R_M + R_FSR), read ratiometrically (reference V+): computed from
    the two resistances, not from the conductance ratio."""
    r_m, v_plus = 10e3, 3.3
    v_out = v_plus * r_m / (r_m + r_fsr_ohm)
    expected = v_out / v_plus * FULL
    assert divider_counts(r_m / r_fsr_ohm, 0.0, FULL) == pytest.approx(expected, rel=1e-12)


def test_divider_reads_rest_half_span_and_saturates():
    assert divider_counts(0.0, 12.0, FULL) == 12.0
    assert divider_counts(1.0, 12.0, FULL) == pytest.approx(12.0 + (FULL - 12.0) / 2)
    # the reading never reaches the full scale, and each equal step of conductance
    # gains less than the one before (saturation)
    readings = divider_counts(np.linspace(0.0, 1000.0, 21), 0.0, FULL)
    assert np.all(readings < FULL) and np.all(np.diff(np.diff(readings)) < 0)
    g = np.array([0.0, 0.3, 1.0, 7.0])
    np.testing.assert_allclose(divider_conductance(divider_counts(g, 5.0, FULL), 5.0, FULL), g)
    assert np.isnan(divider_conductance(FULL, 0.0, FULL))


@pytest.mark.parametrize("exponent", [0.7, 1.0, 1.6])
def test_conductance_is_a_power_of_the_strain_and_zero_in_tension(exponent):
    strain = np.logspace(-3, -0.5, 12)
    g = conductance_ratio(strain, 0.05, exponent)
    slope, _ = np.polyfit(np.log(strain), np.log(g), 1)
    assert slope == pytest.approx(exponent, rel=1e-9)
    assert conductance_ratio(0.05, 0.05, exponent) == pytest.approx(1.0)
    np.testing.assert_array_equal(conductance_ratio([-0.1, 0.0], 0.05, exponent), [0.0, 0.0])


@pytest.mark.parametrize("amount", [0.1, 0.2, 0.5])
def test_hysteresis_loop_area_matches_its_definition(amount):
    """Load 0 -> P -> 0 in fine steps through the model, integrate the loop numerically
    (trapezoids of unloading minus loading over g), against h P^2 / 6 from the
    definition's integral."""
    peak = 0.8
    up = np.linspace(0.0, peak, 4001)
    path = np.concatenate([up, up[::-1][1:]])
    read, after = hysteresis(path[:, None], amount)
    read = read[:, 0]
    loading, unloading = read[: len(up)], read[len(up) - 1 :][::-1]
    np.testing.assert_allclose(loading, up)  # the virgin curve is the plain response
    area = np.trapezoid(unloading - loading, up)
    assert area == pytest.approx(amount * peak**2 / 6.0, rel=1e-6)
    assert hysteresis_loop_area(peak, amount) == pytest.approx(area, rel=1e-6)
    # the mean excess of the unloading branch over the loading one is h / 2 (how the
    # FSR data sheet's "+10 % average" reads as h = 0.2)
    excess = (unloading[1:] - loading[1:]) / loading[1:]
    assert np.trapezoid(excess, up[1:]) / (peak - up[1]) == pytest.approx(amount / 2, rel=1e-3)
    assert after[0] == 0.0  # back at rest: the memory is cleared


def test_hysteresis_memory_carries_across_blocks_and_resets_at_rest():
    rng = np.random.default_rng(3)
    g = np.abs(rng.normal(0.5, 0.3, (60, 2, 3)))
    g[20] = 0.0  # every taxel rests once
    whole, peak_whole = hysteresis(g, 0.3)
    first, peak = hysteresis(g[:37], 0.3)
    second, peak_split = hysteresis(g[37:], 0.3, peak)
    np.testing.assert_allclose(np.concatenate([first, second]), whole)
    np.testing.assert_allclose(peak_split, peak_whole)
    # after the rest the peak is the largest g since it
    np.testing.assert_allclose(peak_whole, g[20:].max(axis=0))


def test_load_drift_follows_the_log_time_law_and_restarts_after_a_rest():
    times = np.arange(0.0, 200.0, 0.5)
    g = np.full((len(times), 1), 0.4)
    g[:10] = 0.0  # loaded from t = 5 s
    read, _ = load_drift(g, times, 0.05)
    t_on = np.clip(times - 5.0, 0.0, None)
    expected = np.where(times >= 5.0, 0.4 * (1 + 0.05 * np.log10(1 + t_on)), 0.0)
    np.testing.assert_allclose(read[:, 0], expected)
    # split in two blocks: the same
    a, start = load_drift(g[:123], times[:123], 0.05)
    b, _ = load_drift(g[123:], times[123:], 0.05, start)
    np.testing.assert_allclose(np.concatenate([a, b]), read)


def test_temperature_factor_is_the_coefficient_times_the_warming():
    np.testing.assert_allclose(temperature_factor([0.0, 100.0], 0.003, 0.1), [1.0, 1.03])


def _press(spec, force_n, hold_s=0.3):
    g = spec.grid
    probe = SphereProbe(5 * g.row_pitch_mm, 3 * g.col_pitch_mm, force_n)
    return Scenario((Step((), 0.2, "rest"), Step((probe,), hold_s, "press"))), probe


@pytest.mark.parametrize("name", ["fsr16", "dsa9205"])
@pytest.mark.parametrize("force_n", [0.5, 2.0, 20.0])
def test_simulated_readings_are_the_elastic_strain_through_the_divider(name, force_n):
    """Without flaws the simulator's reading is the layer model's strain read through
    the divider written out here; untouched, it reads exactly 0."""
    spec = ts.preset(name)
    scenario, probe = _press(spec, force_n)
    rec = ts.simulate(spec, scenario, flaws="none")
    assert np.all(rec.frames[0] == 0.0)
    strain = pad_strain(spec, [probe])
    full = 2**spec.electronics.adc_bits - 1
    x = (np.maximum(strain, 0) * spec.transduction.counts_per_strain / full) ** (
        spec.transduction.exponent
    )
    np.testing.assert_allclose(rec.frames[-1], full * x / (1 + x), rtol=1e-9, atol=1e-9)
    assert rec.frames[-1].max() < full


def test_fsr16_saturates_where_a_linear_cell_would_not():
    spec = ts.preset("fsr16")
    peaks = [ts.simulate(spec, _press(spec, f)[0], flaws="none").frames[-1].max()
             for f in (1.0, 10.0, 40.0)]  # fmt: skip
    # ten times the load gives less than ten times the reading; forty gives little more
    assert peaks[1] < 2.0 * peaks[0] and peaks[2] - peaks[1] < 0.1 * 4095


def test_hysteresis_and_drift_in_the_simulator():
    """A press held then eased: with the flaws the eased reading lies above the loading
    one at the same load (hysteresis) and the held reading rises (drift)."""
    spec = ts.preset("fsr16")
    g = spec.grid
    at = (5 * g.row_pitch_mm, 3 * g.col_pitch_mm)
    steps = [Step((), 0.2, "rest"), Step((SphereProbe(*at, 1.0),), 0.2, "load 1 N")]
    steps += [Step((SphereProbe(*at, 4.0),), 5.0, "hold 4 N")]
    steps += [Step((SphereProbe(*at, 1.0),), 0.2, "ease to 1 N")]
    scenario = Scenario(tuple(steps))
    plain = ts.simulate(spec, scenario, flaws="none").frames[:, 5, 3]
    habits = ts.simulate(spec, scenario, flaws=["hysteresis", "drift"]).frames[:, 5, 3]
    loaded, held_early, held_late, eased = 35, 45, 535, -1
    assert plain[loaded] == pytest.approx(plain[eased])
    assert habits[eased] > habits[loaded] * 1.05
    assert habits[held_late] > habits[held_early] and plain[held_late] == plain[held_early]


@pytest.mark.parametrize("name", ["pad4", "pad16", "dome12"])
def test_the_new_flaws_leave_earlier_sensors_as_they_were(name):
    """'all' now includes hysteresis, drift and crosstalk; their parameters default to
    off, so an earlier preset's frames are identical with and without them."""
    spec = ts.preset(name)
    rows, cols = spec.shape
    if spec.kind == "pad":
        probe = SphereProbe(spec.x_mm[rows // 2], spec.y_mm[cols // 2], 0.49)
    else:
        probe = SphereProbe(0.0, 0.0, 0.49)
    scenario = Scenario((Step((), 0.1, "rest"), Step((probe,), 0.2, "press")))
    every = ts.simulate(spec, scenario, flaws="all", rng=5).frames
    before = [f for f in ts.simulate(spec, scenario, flaws="all", rng=5).flaws
              if f not in ("hysteresis", "drift", "crosstalk")]  # fmt: skip
    assert len(before) == 7
    np.testing.assert_array_equal(every, ts.simulate(spec, scenario, flaws=before, rng=5).frames)


def test_the_simulator_carries_the_habits_across_its_blocks_of_frames():
    """The simulator computes frames 128 at a time; its hysteresis and drift equal the
    habits applied to the whole flawless series at once (from the flawless readings
    through the inverse divider)."""
    spec = ts.preset("dsa9205")  # 30 Hz: 20 s is 600 frames, five blocks
    g = spec.grid
    at = (5 * g.row_pitch_mm, 3 * g.col_pitch_mm)
    steps = [Step((), 0.5, "rest")]
    for force, hold in ((3.0, 6.0), (1.0, 3.0), (0.0, 1.0), (2.0, 9.5)):
        steps.append(Step((SphereProbe(*at, force),) if force else (), hold, f"{force} N"))
    scenario = Scenario(tuple(steps))
    plain = ts.simulate(spec, scenario, flaws="none")
    habits = ts.simulate(spec, scenario, flaws=["hysteresis", "drift"])
    assert len(plain.frames) > 4 * 128
    full = 2**spec.electronics.adc_bits - 1
    conductance = divider_conductance(plain.frames, 0.0, full)
    conductance, _ = hysteresis(conductance, spec.flaws.hysteresis)
    conductance, _ = load_drift(conductance, plain.time_s, spec.flaws.drift_per_decade)
    np.testing.assert_allclose(habits.frames, divider_counts(conductance, 0.0, full),
                               rtol=1e-9, atol=1e-9)  # fmt: skip
