"""What estimation asks a sensor's kind (issue 33): the response a fit uses comes from the
kind, and the estimators branch on the kind's answers, never on its name."""

from __future__ import annotations

import numpy as np
import pytest

from tactsense.estimate.contacts import find_contacts, pad_force_kernel, points_force_kernel
from tactsense.kinds import Kind, KindNotSupported, kind_of
from tactsense.sensor.registry import load_sensor


def test_the_fitted_response_is_the_kinds():
    pad = load_sensor("pad16")
    kernel, step, half = pad_force_kernel(pad)
    np.testing.assert_array_equal(kernel, kind_of(pad).contact_response(pad, half=half))
    assert step == 1 / 8 and kernel.shape == (9, 9, 2 * half + 1, 2 * half + 1)
    dome = load_sensor("dome12")
    response = kind_of(dome).contact_response(dome)
    assert response.shape == (dome.shape[1], dome.shape[1])
    np.testing.assert_array_equal(points_force_kernel(dome), response)


def test_a_kind_without_a_response_says_so_in_one_line():
    finger = load_sensor("initial")
    with pytest.raises(KindNotSupported, match="a contact response does not apply to"):
        kind_of(finger).contact_response(finger)
    assert Kind.contact_response is kind_of(finger).contact_response.__func__


def test_the_kinds_answers():
    finger, pad, dome = (kind_of(load_sensor(n)) for n in ("initial", "pad16", "dome12"))
    assert not finger.array_calibration and pad.array_calibration and dome.array_calibration
    assert pad.response_fit and not finger.response_fit and not dome.response_fit


def test_fit_on_a_kind_without_a_response_table():
    dome = load_sensor("dome12")
    finger = load_sensor("initial")
    with pytest.raises(
        ValueError, match="method 'fit' works on pads; 'fearing1990_initial' is a finger"
    ):
        find_contacts(np.zeros((1, *finger.shape)), finger, counts=False, method="fit")
    table = find_contacts(np.zeros((1, *dome.shape)), dome, counts=False)
    assert len(table) == 0
