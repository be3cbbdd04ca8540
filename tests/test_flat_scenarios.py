"""Pad and point-set scenarios fit the sensor they are given and refuse what does not."""

import pytest

import tactsense as ts
from tactsense._validation import TactsenseInputError
from tactsense.flat_scenarios import SCENARIOS, centre_mm, press, slide, two_probes
from tactsense.physics.indenters import SphereProbe
from tactsense.simulate import Scenario


@pytest.mark.parametrize("name", list(SCENARIOS))
@pytest.mark.parametrize("sensor", ["pad4", "pad16", "pad12x32", "dome12"])
def test_every_scenario_fits_every_flat_sensor_and_round_trips(name, sensor):
    spec = ts.preset(sensor)
    scenario = SCENARIOS[name](spec)
    assert Scenario.from_dict(scenario.to_dict()) == scenario
    assert scenario.steps[0].contacts == ()  # an untouched start for the baseline


def test_press_defaults_to_the_middle_of_the_pad():
    spec = ts.preset("pad12x32")  # 12 rows at 2 mm, 32 columns at 2 mm
    assert centre_mm(spec) == (11.0, 31.0)
    (contact,) = press(spec).steps[1].contacts
    assert (contact.x_mm, contact.y_mm) == (11.0, 31.0)


def test_two_probes_are_separated_as_asked():
    first, second = two_probes(ts.preset("pad16"), separation_mm=6.0).steps[1].contacts
    assert isinstance(first, SphereProbe)
    assert abs((second.y_mm - first.y_mm) - 6.0) < 1e-12 and abs(second.x_mm - first.x_mm) < 1e-12


@pytest.mark.parametrize(
    "build, message",
    [
        (lambda s: press(s, x_mm=100.0), "off the 16x16 pad"),
        (lambda s: press(s, dwell_s=0.0), "dwell_s must be a finite positive"),
        (lambda s: press(s, repeats=0), "repeats must be at least 1"),
        (lambda s: press(s, indenter="hammer"), "unknown indenter 'hammer'"),
        (lambda s: two_probes(s, separation_mm=80.0), "off the 16x16 pad"),
        (lambda s: slide(s, speed_mm_s=0.0), "speed_mm_s must be a finite positive"),
        (lambda s: press(s, force_n=-1.0), "force_n must be >= 0"),
    ],
)
def test_bad_scenarios_say_what_is_wrong(build, message):
    with pytest.raises(TactsenseInputError, match=message):
        build(ts.preset("pad16"))
