"""Simulating a three-axis pad (issue 35 items 2 and 5): the shear scenarios and their
truth per step, the chain's flaws, and frames_from_contacts with tangential forces."""

import dataclasses
import math

import numpy as np
import pytest

from tactsense._validation import TactsenseInputError
from tactsense.flat_scenarios import FIFTY_GRAMS, shear, slide_to_slip
from tactsense.kinds import kind_of
from tactsense.physics import triaxial as tri
from tactsense.sensor import preset
from tactsense.simulate import ContactBatch, Scenario, Step, frames_from_contacts, simulate


@pytest.fixture(scope="module")
def spec():
    return preset("mag4x4")


def per_frame(recording, key):
    return recording.truth[key][recording.truth["frame_step"]]


def test_shear_ramps_holds_and_releases_below_friction(spec):
    """Truth: the tangential force rises to Q/P x P along the angle, the contact partly
    slips (c/a = (1 - Q/(mu P))^(1/3)), and returns to a stuck press."""
    scene = shear(spec, shear_ratio=0.4, angle_deg=30.0, friction=0.8)
    rec = simulate(spec, scene, flaws="none", rng=0)
    qx, qy = per_frame(rec, "step_shear_x_n"), per_frame(rec, "step_shear_y_n")
    q = np.hypot(qx, qy)
    assert q.max() == pytest.approx(0.4 * FIFTY_GRAMS, rel=1e-12)
    touched = q > 0
    np.testing.assert_allclose(np.degrees(np.arctan2(qy, qx))[touched], 30.0, atol=1e-9)
    slip, stick = per_frame(rec, "step_slip"), per_frame(rec, "step_stick_ratio")
    assert set(np.unique(slip)) == {0, 1}
    np.testing.assert_allclose(
        stick[touched], (1 - q[touched] / (0.8 * FIFTY_GRAMS)) ** (1 / 3), rtol=1e-12
    )
    # a frame at the held shear reads the field's x and y change along the push
    frames = rec.frames.astype(float)
    rest = frames[0]
    held = np.argmax(q)
    pressed = np.flatnonzero((per_frame(rec, "step_force_n") > 0) & ~touched)[0]
    change = frames[held] - frames[pressed]
    i, j = 1, 1  # the taxel nearest the pad's middle, (7.05, 7.05) mm, on its -x -y side
    assert change[i, j, 0] > 0 and change[i, j, 1] > 0
    assert change[i, j, 1] < change[i, j, 0]  # 30 deg: more along x than along y
    assert np.all(rest.shape == (4, 4, 3))


def test_slide_to_slip_onset_is_where_the_force_reaches_mu_p(spec):
    """Partial slip grows (c/a falls) until Q = mu P, at the scenario's slip_onset_s; from
    then the force passed is mu P and the contact slides at the speed asked."""
    mu = 0.7
    scene = slide_to_slip(spec, shear_ratio=1.4, friction=mu, ramp_s=1.0, speed_mm_s=2.0,
                          angle_deg=90.0)  # fmt: skip
    rec = simulate(spec, scene, flaws="none", rng=0)
    onset = scene.parameters["slip_onset_s"]
    slip = per_frame(rec, "step_slip")
    first_gross = int(np.argmax(slip == 2))
    period = spec.scan_period_s
    # the frame's step is the one held mid-scan: the onset falls within that frame
    assert first_gross * period <= onset + 0.5 * period < (first_gross + 1) * period + 1e-12
    assert onset == pytest.approx(0.2 + 0.2 + 0.5, abs=period + 1e-9)  # settle, press, mu/ratio
    stick = per_frame(rec, "step_stick_ratio")
    partial = slip == 1
    assert np.all(np.diff(stick[partial]) <= 1e-12)  # the stick zone shrinks
    assert np.all(stick[slip == 2] == 0.0)
    q = np.hypot(per_frame(rec, "step_shear_x_n"), per_frame(rec, "step_shear_y_n"))
    np.testing.assert_allclose(q[slip == 2], mu * FIFTY_GRAMS, rtol=1e-12)
    y = per_frame(rec, "step_y_mm")
    moving = np.flatnonzero(slip == 2)
    speed = (y[moving[-1]] - y[moving[0]]) / ((moving[-1] - moving[0]) * period)
    assert speed == pytest.approx(2.0, rel=0.02)


@pytest.mark.parametrize(
    ("builder", "kwargs", "said"),
    [
        (shear, {"shear_ratio": 1.0, "friction": 1.0}, "at or above the friction"),
        (slide_to_slip, {"shear_ratio": 0.5, "friction": 1.0}, "never slip"),
        (shear, {"ramp_s": 0.0}, "ramp_s"),
        (slide_to_slip, {"speed_mm_s": 40.0, "ramp_s": 2.0}, "off the 4x4"),
    ],
)
def test_bad_shear_scenarios_say_why(spec, builder, kwargs, said):
    with pytest.raises(TactsenseInputError, match=said):
        builder(spec, **kwargs)


def test_frames_are_deterministic_for_a_seed_and_flaws_act(spec):
    scene = shear(spec, ramp_s=0.1, dwell_s=0.1)
    a = simulate(spec, scene, flaws="all", rng=7).frames
    b = simulate(spec, scene, flaws="all", rng=7).frames
    np.testing.assert_array_equal(a, b)
    clean = simulate(spec, scene, flaws="none", rng=7).frames
    noisy = simulate(spec, scene, flaws="noise", rng=7).frames
    sd = np.std(noisy - clean)
    assert sd == pytest.approx(spec.flaws.read_noise_counts, rel=0.1)
    # gain_spread: the skin's own offsets and gains, the same whatever the rng
    g1 = simulate(spec, scene, flaws="gain_spread", rng=1).frames
    g2 = simulate(spec, scene, flaws="gain_spread", rng=2).frames
    np.testing.assert_array_equal(g1, g2)
    assert np.std(g1[0] - clean[0]) > 5.0  # counts: 20 uT offsets and 5 % gains
    dead = dataclasses.replace(spec, flaws=dataclasses.replace(spec.flaws, dead_tactels=((2, 3),)))
    frames = simulate(dead, scene, flaws="dead", rng=0).frames
    assert np.all(frames[:, 2, 3, :] == 0) and np.all(frames[:, 2, 2, :] > 0)


def test_viscoelastic_memory_delays_the_displacement(spec):
    """After a press, the layer's delayed part (10 %, 50 ms) brings the reading to its
    elastic value over some 0.2 s: the first pressed frame is short of the last."""
    centre = (7.05, 7.05)
    from tactsense.physics.indenters import SphereProbe

    probe = SphereProbe(*centre, FIFTY_GRAMS, radius_mm=1.6)
    scene = Scenario((Step((), 0.1), Step((probe,), 0.5)))
    elastic = simulate(spec, scene, flaws="none", rng=0).frames.astype(float)
    memory = simulate(spec, scene, flaws="viscoelastic", rng=0).frames.astype(float)
    rise = elastic[-1, 1, 1, 2] - elastic[0, 1, 1, 2]
    first = 11  # the first frame read wholly under the press
    short = (elastic[first, 1, 1, 2] - memory[first, 1, 1, 2]) / rise
    assert 0.02 < short < 0.15
    late = (elastic[-1, 1, 1, 2] - memory[-1, 1, 1, 2]) / rise
    assert abs(late) < abs(short) / 2


def test_frames_from_contacts_takes_the_tangential_force(spec):
    """The reference path is simulate's scan with one step per frame; a tangential force
    changes the x, y components (the old skeleton said non-shear kinds ignore it: this
    kind does not)."""
    n = 4
    position = np.tile([[[7.05, 7.05]]], (n, 1, 1))
    force = np.full((n, 1), FIFTY_GRAMS)
    tangential = np.zeros((n, 1, 2))
    tangential[1, 0] = (0.2, 0.0)
    tangential[2, 0] = (0.0, 0.2)
    tangential[3, 0] = (0.6, 0.0)  # beyond P: passed whole (friction taken as Q/P)
    batch = ContactBatch(position, force, tangential_force_n=tangential, radius_mm=1.6)
    frames = frames_from_contacts(spec, batch, flaws="none")
    assert frames.shape == (n, 16, 3)
    kind = kind_of(spec)
    steps = [Step(kind.contact_state(spec, batch.frame(i)), spec.scan_period_s)
             for i in range(n)]  # fmt: skip
    expected = simulate(spec, Scenario(tuple(steps)), flaws="none", rng=0).frames
    np.testing.assert_array_equal(frames, expected.reshape(n, 16, 3))
    taxel = 1 * 4 + 1
    assert frames[1, taxel, 0] > frames[0, taxel, 0]
    assert frames[2, taxel, 1] > frames[0, taxel, 1]
    applied = kind.contact_state(spec, batch.frame(3))[0]
    assert tri.transmitted_shear_n(applied) == pytest.approx((0.6, 0.0))
    assert math.isclose(applied.friction, 0.6 / FIFTY_GRAMS)


def test_simulate_command_writes_the_shear_truth(tmp_path):
    """``tactsense simulate --scenario slide-to-slip`` with its options: the recording's
    truth holds the shear (in N), the slip states and the stick ratio per step, and the
    scenario's parameters the onset."""
    import h5py
    from typer.testing import CliRunner

    from tactsense.cli import app
    from tactsense.io.recording import read_recording

    out = tmp_path / "triphys_slip.h5"
    args = ["simulate", "--sensor", "magtip", "--scenario", "slide-to-slip", "--shear-ratio",
            "1.2", "--friction", "0.9", "--ramp-s", "0.4", "--shear-angle-deg", "-90",
            "--flaws", "none", "-o", str(out)]  # fmt: skip
    result = CliRunner().invoke(app, args)
    assert result.exit_code == 0, result.output
    rec = read_recording(out)
    assert rec.frames.shape[1:] == (6, 4, 3)
    slip = rec.truth["step_slip"]
    assert set(np.unique(slip)) == {0, 1, 2}
    with h5py.File(out) as h5:
        assert h5["truth/step_shear_y_n"].attrs["units"] == "N"
    q = np.hypot(rec.truth["step_shear_x_n"], rec.truth["step_shear_y_n"])
    np.testing.assert_allclose(q[slip == 2], 0.9 * FIFTY_GRAMS, rtol=1e-12)
    assert np.all(rec.truth["step_shear_y_n"] <= 1e-12)  # -90 deg: along -y
    onset = rec.scenario["parameters"]["slip_onset_s"]
    assert onset == pytest.approx(0.2 + 0.2 + 0.4 * 0.9 / 1.2, abs=spec_period("magtip") + 1e-9)


def spec_period(name):
    return preset(name).scan_period_s


def test_a_slide_drags_a_three_axis_skin_but_not_a_pads_contacts(spec):
    """'slide' on a kind that senses shear: friction mu P (mu = 1) along the motion, gross
    slip in every touching step; on a pad the contacts stay pure presses."""
    from tactsense.flat_scenarios import slide

    rec = simulate(spec, slide(spec), flaws="none", rng=0)
    touching = rec.truth["step_n_contacts"] > 0
    assert np.all(rec.truth["step_slip"][touching] == 2)
    np.testing.assert_allclose(rec.truth["step_shear_y_n"][touching], FIFTY_GRAMS, rtol=1e-12)
    np.testing.assert_allclose(rec.truth["step_shear_x_n"][touching], 0.0, atol=1e-15)
    pad = preset("pad16")
    assert all(c.shear_n == 0 for step in slide(pad).steps for c in step.contacts)
