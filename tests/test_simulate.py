import numpy as np
import pytest

import tactsense as ts
from tactsense.physics.transduction import deflection_to_counts, fractional_deflection

G50 = ts.grams_force(50)


def test_flawless_simulation_is_the_forward_model(initial):
    probe = ts.Probe(10.0, 15.0, G50)
    rec = ts.simulate(initial, ts.static(probe, 1.0, settle_s=0.5), flaws="none")
    assert rec.frames.dtype == np.float64  # no quantization: ideal readings
    held = rec.frames[-1]
    want = deflection_to_counts(initial, ts.tactel_deflection(initial, probe), quantize=False)
    np.testing.assert_allclose(held, want, rtol=1e-12)
    np.testing.assert_allclose(rec.frames[0], 2000.0)


def test_frames_timestamps_and_truth(initial):
    scene = ts.probe_sweep(initial, along="axial", col=0, start=5.0, stop=8.0, dwell_s=0.5)
    rec = ts.simulate(initial, scene, rng=1)
    assert rec.frames.dtype == np.uint16 and rec.frames.shape[1:] == (8, 8)
    assert len(rec) == int(scene.duration_s * 7 + 1e-9)
    np.testing.assert_allclose(np.diff(rec.time_s), 1 / 7)
    positions = rec.truth["step_axial_mm"][rec.truth["frame_step"]]
    touched = ~np.isnan(positions)
    assert np.all(np.abs(positions[touched] - np.clip(positions[touched], 5, 8)) < 0.3)
    assert rec.baseline_frames.size >= 6  # the 1-s settle time at 7 Hz


def test_same_seed_same_recording(initial):
    scene = ts.repeated_load(initial, repeats=3, on_s=0.5, off_s=0.5)
    a = ts.simulate(initial, scene, rng=5)
    b = ts.simulate(initial, scene, rng=5)
    c = ts.simulate(initial, scene, rng=6)
    np.testing.assert_array_equal(a.frames, b.frames)
    assert not np.array_equal(a.frames, c.frames)


def test_dead_tactels_read_zero(initial):
    spec = initial.replace(flaws__dead_tactels=((3, 0), (5, 6)))
    rec = ts.simulate(spec, ts.static(ts.Probe(8.7, 0.0, G50)), flaws="all", rng=0)
    assert np.all(rec.frames[:, 3, 0] == 0) and np.all(rec.frames[:, 5, 6] == 0)
    assert np.all(rec.frames[:, 4, 0] > 0)


def test_each_tactel_sampled_at_its_own_instant(initial):
    # a load that starts mid-frame is seen by the tactels scanned after it only
    probe = ts.Probe(initial.row_axial_mm[3], 0.0, G50)
    start = 1.0 + 0.5 / 7  # halfway through frame 7's scan
    scene = ts.Scenario((ts.Step((), start), ts.Step((probe,), 1.0)))
    rec = ts.simulate(initial, scene, flaws="none")
    frame = rec.frames[7]
    half = rec.sample_offset_s < 0.5 / 7
    assert np.all(frame[half] == 2000.0)
    assert frame[3, 0] == 2000.0 and frame[4, 0] > 2000.0  # (3, 0) sampled before, (4, 0) after


def test_jitter_is_about_one_gram(initial):
    # Figs. 10-11: 100 applications of 50 g; the standard deviation under the probe is
    # equivalent to about a 1-g variation
    scene = ts.repeated_load(initial, row=4, col=0, repeats=100, on_s=1.0, off_s=1.0)
    rec = ts.simulate(initial, scene, flaws=["jitter", "noise", "quantization"], rng=2)
    step = rec.truth["frame_step"]
    on = rec.truth["step_n_contacts"][step] > 0
    last_of_each = np.flatnonzero(on[:-1] & ~on[1:])  # the last frame of every application
    readings = rec.frames[last_of_each, 4, 0].astype(float)
    per_gram = (readings.mean() - 2000) / 50
    assert readings.std() / per_gram == pytest.approx(1.0, rel=0.35)


def test_sweep_reads_like_fig7(initial):
    # the swept tactels overlap: between two rings both respond
    scene = ts.probe_sweep(initial, along="axial", col=0)
    rec = ts.simulate(initial, scene, flaws="none")
    baseline = rec.frames[rec.baseline_frames].mean(axis=0)
    step = rec.truth["frame_step"]
    position = rec.truth["step_axial_mm"][step]
    between = np.flatnonzero(np.abs(position - (initial.row_axial_mm[3] + 1.9)) < 0.31)[-1]
    d = fractional_deflection(rec.frames[between], baseline)
    assert d[3, 0] > 0.01 and d[4, 0] > 0.01


def test_bad_arguments_are_reported(initial):
    scene = ts.static(ts.Probe(8.7, 0.0, G50))
    with pytest.raises(ValueError, match="unknown flaw"):
        ts.simulate(initial, scene, flaws="gremlins")
    with pytest.raises(ValueError, match="gains has shape"):
        ts.simulate(initial, scene, gains=np.ones((3, 3)))
    with pytest.raises(ValueError, match="outside the 8x8 array"):
        ts.probe_sweep(initial, along="around", row=9)
    with pytest.raises(ValueError, match="outside the 8x8 array"):
        ts.knife_edge_sweep(initial, col=8)
    with pytest.raises(ValueError, match="outside the 8x8 array"):
        ts.load_series(initial, row=-1)
    with pytest.raises(ValueError, match="at least one step"):
        ts.Scenario(())
    with pytest.raises(ValueError, match="SensorSpec"):
        ts.simulate("initial", scene)


def test_scenario_round_trips_through_dict(initial):
    scene = ts.Scenario((ts.Step((ts.rod(10, 0, 1.0), ts.Probe(3, 40, 0.2)), 0.5, "x"),))
    assert ts.Scenario.from_dict(scene.to_dict()) == scene


def test_superposition_with_the_nonlinearity_below_100_g(initial):
    # Fig. 9: two probes applied apart and together; with the stiffening law on, the sum
    # of the single responses still matches the joint response to within 5 % of its peak
    # (the loads stay below 100 g, where the paper found superposition valid)
    p1 = ts.Probe(initial.row_axial_mm[3], 0.0, G50)
    p2 = ts.Probe(initial.row_axial_mm[3] + 5.0, 0.0, G50)

    def held(contacts):
        rec = ts.simulate(initial, ts.static(contacts, 1.0, settle_s=0.5), flaws=["nonlinearity"])
        return fractional_deflection(rec.frames[-1], rec.frames[0])

    joint, single = held([p1, p2]), held([p1]) + held([p2])
    error = np.abs(joint - single).max() / joint.max()
    assert 0 < error < 0.05
