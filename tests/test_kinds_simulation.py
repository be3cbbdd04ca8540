"""What the simulator, the scenarios and the design commands ask a sensor's kind (issue 33)."""

import numpy as np
import pytest

from tactsense.cli._scenario import ScenarioKind, resolve_scenario
from tactsense.flat_scenarios import centre_mm
from tactsense.kinds import KindNotSupported, kind_of
from tactsense.physics.array_response import deflection_batch
from tactsense.physics.contact import Probe
from tactsense.physics.indenters import SphereProbe
from tactsense.physics.pad_response import (
    deflection_batch_flat,
    pad_strain,
    points_strain,
)
from tactsense.sensor import load_sensor


@pytest.fixture(scope="module")
def sensors():
    return {name: load_sensor(name) for name in ("initial", "pad4", "dome12")}


def test_the_elastic_model_is_the_kinds(sensors):
    finger, pad, dome = sensors["initial"], sensors["pad4"], sensors["dome12"]
    probes = [(Probe(12.5, 0.0, 0.5),), ()]
    got = kind_of(finger).elastic_batch(finger, probes)
    assert np.array_equal(got, deflection_batch(finger, probes))
    presses = [(SphereProbe(7.5, 7.5, 0.5, radius_mm=1.6),)]
    got = kind_of(pad).elastic_batch(pad, presses)
    assert np.array_equal(got, deflection_batch_flat(pad, presses, pad_strain))
    presses = [(SphereProbe(0.0, 0.0, 0.5, radius_mm=1.6, at_taxel=0),)]
    got = kind_of(dome).elastic_batch(dome, presses)
    assert np.array_equal(got, deflection_batch_flat(dome, presses, points_strain))


def test_a_window_of_probes_takes_the_path_of_the_whole(sensors):
    finger = sensors["initial"]
    kind = kind_of(finger)
    alone = [(Probe(10.0, 0.0, 0.5),), (Probe(12.0, 0.0, 0.5),)]
    assert kind.elastic_window_alone(alone)
    assert not kind.elastic_window_alone([*alone, ()])
    whole = kind.elastic_batch(finger, alone, alone=False)
    assert np.allclose(whole, deflection_batch(finger, [*alone, ()])[:-1])


def test_forward_models_a_kind_lacks_are_one_line_errors(sensors):
    assert kind_of(sensors["initial"]).check_forward(sensors["initial"], "finger3d") == "finger3d"
    with pytest.raises(KindNotSupported, match="'pad4' is a pad \\(its layer model"):
        kind_of(sensors["pad4"]).check_forward(sensors["pad4"], "finger3d")


def test_scenarios_and_their_surface(sensors):
    assert resolve_scenario(sensors["initial"], None) is ScenarioKind.sweep_axial
    assert resolve_scenario(sensors["pad4"], None) is ScenarioKind.press
    assert kind_of(sensors["pad4"]).surface_grid(sensors["pad4"]) == ((5.0, 4), (5.0, 4))
    assert kind_of(sensors["dome12"]).surface_grid(sensors["dome12"]) is None
    assert centre_mm(sensors["pad4"]) == (7.5, 7.5)
    assert not kind_of(sensors["initial"]).surface_scenarios


def test_what_the_kinds_answer_for_the_commands(sensors):
    finger, pad, dome = (kind_of(sensors[n]) for n in ("initial", "pad4", "dome12"))
    assert (finger.design_model, pad.design_model, dome.design_model) == ("paper", "layer", None)
    assert finger.position_names == ("axial_mm", "angle_deg")
    assert finger.frame_axes.startswith("time, row (along the finger")
    assert pad.frame_axes == dome.frame_axes == "time, row, col"
    assert finger.size_text(sensors["initial"]) == ("8 x 8 tactels", "3.8 mm x 45 deg")
    assert pad.size_text(sensors["pad4"]) == ("4 x 4 taxels", "5 x 5 mm")
    assert dome.size_text(sensors["dome12"])[0] == "12 taxels"
