"""frames_from_contacts: the batch call from arrays of contacts to frames.

The reference path (``fast=False``) is :func:`simulate`'s own scan loop, one step per
frame: checked here against :func:`simulate` run on the same contacts as a scenario.
"""

import dataclasses
import warnings

import numpy as np
import pytest

from tactsense._validation import TactsenseInputError
from tactsense.kinds import kind_of
from tactsense.sensor.registry import dome12, fearing1990_improved, pad16
from tactsense.simulate import ContactBatch, Scenario, Step, frames_from_contacts, simulate
from tactsense.simulate.contact_frames import (
    LEFT_OUT_FLAWS,
    ContactBatchError,
    ShearIgnoredWarning,
)


def _pad(rate_hz=64.0):
    """pad16 with a scan rate whose period is exact in binary (frame starts exact)."""
    spec = pad16()
    electronics = dataclasses.replace(spec.electronics, scan_rate_hz=rate_hz)
    return dataclasses.replace(spec, electronics=electronics)


def _random_batch(n, k=3, extent_mm=37.5, seed=0, max_n=3.0):
    rng = np.random.default_rng(seed)
    position = rng.uniform(0.0, extent_mm, (n, k, 2))
    force = rng.uniform(0.05, max_n, (n, k))
    force[rng.random((n, k)) < 0.3] = 0.0  # missing contacts
    radius = rng.uniform(1.0, 5.0, (n, k))
    return ContactBatch(position, force, radius_mm=radius)


@pytest.mark.parametrize("flaws", ["none", "gain_spread,noise,quantization,nonlinearity,dead"])
def test_reference_is_simulate_with_one_step_per_frame(flaws):
    spec = _pad()
    spec = dataclasses.replace(spec, flaws=dataclasses.replace(spec.flaws, dead_tactels=((3, 4),)))
    batch = _random_batch(12)
    steps = [
        Step(kind_of(spec).contact_state(spec, batch.frame(i)), spec.scan_period_s)
        for i in range(batch.n_frames)
    ]
    expected = simulate(spec, Scenario(steps), flaws=flaws, rng=5).frames
    got = frames_from_contacts(spec, batch, flaws=flaws, rng=5, fast=False)
    assert got.shape == (12, 256)
    np.testing.assert_array_equal(got, expected.reshape(12, -1).astype(float))


def test_flaws_with_memory_and_jitter_are_left_out():
    spec = _pad()
    batch = _random_batch(6)
    plain = frames_from_contacts(spec, batch, flaws="none", fast=False)
    for flaw in LEFT_OUT_FLAWS:
        np.testing.assert_array_equal(
            frames_from_contacts(spec, batch, flaws=flaw, rng=1, fast=False), plain
        )


def test_a_frame_without_contacts_reads_the_rest_value():
    spec = _pad()
    batch = ContactBatch(np.zeros((2, 1, 2)), np.zeros((2, 1)))
    frames = frames_from_contacts(spec, batch, flaws="none", fast=False)
    np.testing.assert_array_equal(frames, spec.electronics.nominal_counts)


@pytest.mark.parametrize("make", [dome12, fearing1990_improved])
def test_every_kind_answers_through_its_elastic_batch(make):
    spec = make()
    batch = ContactBatch(np.array([[[0.0, 0.0]], [[1.0, 0.5]]]), np.array([[0.5], [0.0]]))
    frames = frames_from_contacts(spec, batch, flaws="none", fast=False)
    assert frames.shape == (2, spec.n_taxels)
    rest = frames[1]
    assert np.ptp(rest) == 0.0  # nothing touches: every taxel at rest
    assert np.abs(frames[0] - rest).max() > 1.0  # the contact reads


def test_tangential_forces_on_a_pad_are_ignored_and_said_so():
    spec = _pad()
    batch = _random_batch(3, k=1)
    sheared = dataclasses.replace(batch, tangential_force_n=np.full((3, 1, 2), 0.2))
    with pytest.warns(ShearIgnoredWarning, match="tangential forces ignored"):
        got = frames_from_contacts(spec, sheared, flaws="none", fast=False)
    np.testing.assert_array_equal(got, frames_from_contacts(spec, batch, flaws="none"))


def test_the_finger_takes_the_axial_tangential_force_without_warning():
    spec = fearing1990_improved()
    position = np.array([[[10.0, 0.0]]])
    plain = ContactBatch(position, np.array([[0.5]]))
    sheared = ContactBatch(position, np.array([[0.5]]), np.array([[[0.3, 0.0]]]))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        a = frames_from_contacts(spec, plain, flaws="none", fast=False)
        b = frames_from_contacts(spec, sheared, flaws="none", fast=False)
    assert np.abs(a - b).max() > 1.0


@pytest.mark.parametrize(
    ("arguments", "message"),
    [
        ((np.zeros((2, 3, 2)), np.zeros((2, 2))), "position_mm has shape"),
        ((np.zeros((2, 1, 2)), -np.ones((2, 1))), "must be >= 0"),
        ((np.full((2, 1, 2), np.nan), np.ones((2, 1))), "finite"),
        ((np.zeros((2, 1, 2)), np.ones(2)), "expected \\(N frames, k contacts\\)"),
        ((np.zeros((1, 1, 2)), np.ones((1, 1)), None, 0.0), "radius_mm must be > 0"),
        ((np.zeros((1, 1, 2)), np.ones((1, 1)), None, np.ones(3)), "radius_mm has shape"),
        ((np.zeros((1, 1, 2)), np.ones((1, 1)), None, 1.0, "cube"), "unknown contact shape"),
        ((np.zeros((1, 1, 2)), np.ones((1, 1)), np.zeros((1, 2, 2))), "tangential_force_n"),
    ],
)
def test_a_bad_batch_is_one_line_error(arguments, message):
    with pytest.raises(ContactBatchError, match=message):
        ContactBatch(*arguments)


def test_bad_call_arguments_are_one_line_errors():
    batch = _random_batch(2)
    with pytest.raises(TactsenseInputError, match="sensor description"):
        frames_from_contacts("pad16", batch)
    with pytest.raises(TactsenseInputError, match="ContactBatch"):
        frames_from_contacts(_pad(), np.zeros((2, 3)))
    with pytest.raises(TactsenseInputError, match="gains has shape"):
        frames_from_contacts(_pad(), batch, gains=np.ones((4, 4)))
    with pytest.raises(TactsenseInputError, match="unknown flaw"):
        frames_from_contacts(_pad(), batch, flaws="warp")
