"""The viscoelastic memories read where they are sampled equal the tick-by-tick filter."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tactsense.physics.viscoelastic import (
    sampled_viscoelastic_response,
    viscoelastic_response,
)

CONSTANTS = dict(
    delayed_fraction=0.538,
    delayed_time_constant_s=0.0422,
    creep_fraction=1.14,
    creep_time_constant_s=20.0,
)


@settings(max_examples=30, deadline=None)
@given(
    st.integers(1, 6),  # taxels per frame side
    st.lists(st.integers(1, 40), min_size=1, max_size=12),  # ticks each step lasts
    st.integers(0, 2**31 - 1),
)
def test_sampled_memories_equal_the_tick_by_tick_filter(side, durations, seed):
    """Reference: scipy's lfilter over every tick for every taxel (the scan as it is),
    then each taxel read at its own tick; the closed form must agree to rounding, carried
    across two blocks through the returned state."""
    rng = np.random.default_rng(seed)
    n = side * side
    values = rng.uniform(0.0, 0.3, (len(durations), n))
    tick_step = np.repeat(np.arange(len(durations)), durations)
    frames = len(tick_step) // n
    if frames == 0:
        return
    tick_step = tick_step[: frames * n]
    dt = 1e-3
    reference, _ = viscoelastic_response(values[tick_step], dt, **CONSTANTS)
    expected = reference.reshape(frames, n, n)[:, np.arange(n), np.arange(n)]
    ticks = np.arange(frames)[:, None] * n + np.arange(n)[None, :]
    half = (frames // 2) * n  # two blocks, the memories carried between them
    if half == 0:
        got, _ = sampled_viscoelastic_response(values, tick_step, ticks, dt, **CONSTANTS)
    else:
        first, state = sampled_viscoelastic_response(
            values, tick_step[:half], ticks[: half // n], dt, **CONSTANTS
        )
        second, _ = sampled_viscoelastic_response(
            values, tick_step[half:], ticks[half // n :] - half, dt, **CONSTANTS, state=state
        )
        got = np.concatenate([first, second])
    np.testing.assert_allclose(got, expected, rtol=1e-12, atol=1e-15)


def test_a_held_load_decays_as_the_memories_say():
    """A step held long enough: the reading tends to (1 + a_c (1 - e^-t/tau_c)) u, the
    delayed part having settled (closed form of the two first-order lags)."""
    values = np.array([[0.1]])
    ticks = 2000
    sampled, _ = sampled_viscoelastic_response(
        values, np.zeros(ticks, int), np.array([[ticks - 1]]), 1e-3, **CONSTANTS
    )
    t = ticks * 1e-3
    delayed = 1 - np.exp(-t / CONSTANTS["delayed_time_constant_s"])
    creep = 1 - np.exp(-t / CONSTANTS["creep_time_constant_s"])
    expected = 0.1 * ((1 - 0.538) + 0.538 * delayed + 1.14 * creep)
    assert sampled[0, 0] == pytest.approx(expected, rel=1e-9)
