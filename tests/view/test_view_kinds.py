"""The view asks the sensor's kind how to draw it and what estimates its contacts
(Kind.view_drawing, contact_estimation, multi_contact): no table keyed by kind names."""

from __future__ import annotations

import dataclasses

import pytest

import tactsense.kinds.registry as registry
from tactsense._validation import TactsenseInputError
from tactsense.kinds import Kind
from tactsense.sensor import PadSpec, preset
from tactsense.stream.live import LiveContacts, LiveLocator
from tactsense.view import DeflectionOnly, feed, layout_message, locators, view_locator


@dataclasses.dataclass(frozen=True)
class ToySpec(PadSpec):
    kind = "toyview"


class ToyKind(Kind):
    name = "toyview"
    spec_class = ToySpec
    contact_estimation = False


@pytest.fixture
def toy(monkeypatch):
    every = dict(registry.kinds())
    every["toyview"] = ToyKind()
    monkeypatch.setattr(registry, "kinds", lambda: every)
    pad = preset("pad4")
    return ToySpec(**{f.name: getattr(pad, f.name) for f in dataclasses.fields(PadSpec)})


def test_a_kind_without_contact_estimation_shows_its_deflection_as_dots(toy):
    message = layout_message(toy, {})
    assert message["kind"] == "toyview"
    assert message["geometry"] == "plane" and message["surface"] is None  # the dots
    assert message["estimation"] == "contact estimation: not yet for toyviews"
    assert message["multi_contact"] is False
    assert isinstance(view_locator(toy), DeflectionOnly)
    with pytest.raises(TactsenseInputError, match="not to toyviews"):
        view_locator(toy, calibration=object())


def test_the_built_in_kinds_are_drawn_and_estimated_as_before():
    assert layout_message(preset("initial"), {})["geometry"] == "finger"
    pad = layout_message(preset("pad16"), {})
    assert pad["geometry"] == "plane" and pad["surface"] is not None
    dots = layout_message(preset("dome12"), {})
    assert dots["geometry"] == "plane" and dots["surface"] is None
    expected = {"finger": LiveLocator, "pad": LiveContacts, "points": LiveContacts}
    assert {k: v for k, v in feed.LOCATORS.items() if k in expected} == expected
    assert locators.PLURAL["points"] == "point sets" and feed.PLURAL["finger"] == "fingers"
