"""The sensor's flaws reproduce the numbers of section 3 of the paper."""

import numpy as np
import pytest

import tactsense as ts
from tactsense.physics.flaws import draw_gains, stiffening
from tactsense.physics.viscoelastic import first_order_memory, viscoelastic_response


def test_gain_spread_statistics(initial):
    gains = np.concatenate([draw_gains(initial, seed).ravel() for seed in range(200)])
    threshold = 1 / gains
    # Fig. 8: mean threshold 0.4 g, best 0.2 g, worst 0.8 g (relative: 1, 0.5, 2)
    assert threshold.mean() == pytest.approx(1.0, abs=0.02)
    assert threshold.min() == pytest.approx(0.5) and threshold.max() <= 2.0
    # "five cells [of 56] were very sensitive": the share clipped at 0.5 is 5/56 within 3 cells
    assert 2 / 56 < np.mean(threshold <= 0.5 + 1e-12) < 8 / 56


def test_gains_repeat_with_the_same_rng(initial):
    np.testing.assert_array_equal(draw_gains(initial, 3), draw_gains(initial, 3))
    assert not np.array_equal(draw_gains(initial, 3), draw_gains(initial, 4))


def test_nonlinearity_six_percent_below_the_line(initial):
    # section 3: "the tactel response to a 1-N load is 6% less than the straight line
    # from the origin through the strain for a 0.5-N load"
    def reading(force):
        lin = ts.tactel_deflection(initial, ts.Probe(initial.row_axial_mm[3], 0.0, force))[3, 0]
        return stiffening(lin, initial.flaws.nonlinear_saturation)

    drop = 1 - reading(1.0) / (2 * reading(0.5))
    assert drop == pytest.approx(0.06, abs=0.002)


def test_stiffening_is_monotonic_and_linear_at_small_deflection():
    d = np.linspace(-0.3, 0.6, 200)
    y = stiffening(d, 0.7)
    assert np.all(np.diff(y) >= 0)
    assert stiffening(1e-6, 0.7) == pytest.approx(1e-6, rel=1e-5)


def test_first_order_memory_matches_exponential():
    dt, tau = 1e-3, 0.05
    t = np.arange(1, 501) * dt
    m, _ = first_order_memory(np.ones(500), dt, tau)
    np.testing.assert_allclose(m, 1 - np.exp(-t / tau), rtol=1e-10)
    # chunked evaluation equals one pass
    m1, s1 = first_order_memory(np.ones(200), dt, tau)
    m2, _ = first_order_memory(np.ones(300), dt, tau, state=s1)
    np.testing.assert_allclose(np.concatenate([m1, m2]), m, rtol=1e-12)


def test_viscoelastic_preset_reproduces_fig12(initial):
    # section 3.4 after a 1-s step: 10 % of peak at 0.1 s, ~5 % residual, and 25 % at
    # 40 ms ("beyond a 25-Hz scan rate ... a 25% sensor output error")
    f = initial.flaws
    dt = 1e-4
    u = np.concatenate([np.ones(10000), np.zeros(20000)])
    y, _ = viscoelastic_response(
        u,
        dt,
        delayed_fraction=f.delayed_fraction,
        delayed_time_constant_s=f.delayed_time_constant_s,
        creep_fraction=f.creep_fraction,
        creep_time_constant_s=f.creep_time_constant_s,
    )
    peak = y[9999]
    after = lambda seconds: y[9999 + round(seconds / dt)] / peak  # noqa: E731
    assert after(0.1) == pytest.approx(0.10, abs=0.01)
    assert after(0.04) == pytest.approx(0.25, abs=0.02)
    assert after(1.0) == pytest.approx(0.05, abs=0.01)
