"""A contact's friction coefficient in ``ContactBatch`` reaches a three-axis pad's
Cattaneo-Mindlin traction (the MuJoCo adapter passes MuJoCo's mu, and mu = Q/P for a
contact MuJoCo reports sliding)."""

import numpy as np
import pytest

from tactsense.sensor import load_sensor
from tactsense.simulate import ContactBatch, ContactBatchError, frames_from_contacts


def _frames(friction):
    spec = load_sensor("mag4x4")
    batch = ContactBatch(
        position_mm=[[[7.05, 7.05]]],
        normal_force_n=[[0.5]],
        tangential_force_n=[[[0.25, 0.0]]],  # Q/P = 0.5
        radius_mm=2.0,
        friction=friction,
    )
    return frames_from_contacts(spec, batch, flaws="none").astype(float)


def test_friction_sets_the_slip_state():
    # Q/P = 0.5: with mu 0.5 the contact slides whole (gross slip), as it does with any
    # mu below 0.5 (a tangential force above mu P is gross slip, mu = Q/P); with mu
    # unknown (None, or 0) the force is carried with a stick zone (mu = max(1, Q/P)).
    at_limit, below = _frames(0.5), _frames(0.3)
    unknown, zero = _frames(None), _frames(0.0)
    np.testing.assert_array_equal(at_limit, below)
    np.testing.assert_array_equal(unknown, zero)
    # partial slip moves the traction's centre: the frames differ, by more than rounding
    assert np.abs(at_limit - unknown).max() >= 1.0
    # and mu 1 given is the same as unknown (the default is mu = 1)
    np.testing.assert_array_equal(_frames(1.0), unknown)


@pytest.mark.parametrize(
    "friction, message",
    [(-0.1, ">= 0"), (np.ones((2, 3)), "friction has shape"), (np.nan, "finite")],
)
def test_bad_friction_is_refused(friction, message):
    with pytest.raises(ContactBatchError, match=message):
        ContactBatch(position_mm=[[[0.0, 0.0]]], normal_force_n=[[0.5]], friction=friction)
