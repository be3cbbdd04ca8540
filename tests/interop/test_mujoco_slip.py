"""MuJoCo in, three-axis frames out: the slip example (issue 38 item 2) against MuJoCo.

The example ``mujoco_slip.xml`` presses a ``mag4x4`` pad on a ball and drags it until
friction gives way; the three-axis estimator on its frames is set against MuJoCo's own
contacts (``tactsense.interop.mujoco_shear.compare``). Bounds are the measured figures
of docs/mujoco.md's slip block with a margin: noise-free frames (flaws 'none') test the
chain (contacts -> frames -> estimate); one noise draw with every per-frame flaw and the
ball's bench calibration tests issue 38's goals (the doc's block has five draws)."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("mujoco")

from tactsense.estimate.triaxial import TriaxialCalibration, find_shear_contacts
from tactsense.estimate.triaxial.locate import ShearPipeline
from tactsense.interop.mujoco import (
    MujocoSensor,
    load_model,
    read_controls,
    record_mujoco,
)
from tactsense.interop.mujoco_shear import (
    EXAMPLE_BALL_RADIUS_MM,
    EXAMPLE_FRICTION,
    ball_calibration,
    compare,
    ramp_onsets,
    slip_controls_path,
    slip_model_path,
)
from tactsense.io.recording import read_recording
from tactsense.sensor import preset


def _record(folder, flaws):
    spec = preset("mag4x4")
    model = load_model(slip_model_path())
    controls = read_controls(slip_controls_path(), model)
    path = folder / f"mjslip_example_{flaws}.h5"
    record_mujoco(path, MujocoSensor(model, spec, geom="pad"), seconds=4.0, controls=controls,
                  flaws=flaws, rng=0)  # fmt: skip
    return spec, read_recording(path)


def _run(folder, flaws, friction):
    """The example's first press, estimated with the response for its 2-mm ball."""
    spec, recording = _record(folder, flaws)
    baseline = np.median(recording.frames[:5].astype(float), axis=0)
    table, _ = ShearPipeline(spec, baseline, friction=friction,
                             radius_mm=EXAMPLE_BALL_RADIUS_MM)(recording.frames)  # fmt: skip
    return spec, recording, table


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    spec, recording, table = _run(tmp_path_factory.mktemp("mjslip"), "none", EXAMPLE_FRICTION)
    return spec, recording, compare(recording.truth, table, spec.scan_period_s), table


def test_the_example_presses_drags_and_slips_in_mujoco(run):
    """The example does what its docs say: three-axis frames, one press, MuJoCo's friction
    reaching mu times the normal force (the cone's limit) partway through the drag."""
    spec, recording, result, _ = run
    assert recording.frames.shape[1:] == spec.frame_shape == (4, 4, 3)
    truth = recording.truth
    (press,) = result.presses
    onset = press["mujoco_onset"]
    assert onset is not None and press["first"] + 30 < onset < press["last"] - 30
    ratio = np.hypot(*truth["mujoco_tangential_force_n"].T) / np.maximum(
        truth["step_force_n"], 1e-9
    )
    assert ratio[onset + 5] == pytest.approx(EXAMPLE_FRICTION, rel=0.01)
    assert ratio[onset - 20] < 0.8 * EXAMPLE_FRICTION  # stick before: the ratio still rising
    assert np.all(truth["mujoco_slip"][press["first"] : onset] == 0)


def test_the_frames_give_the_slip_onset_within_a_frame_of_mujocos(run):
    """Causal onset from the frames (mu given) against MuJoCo's transition: within one
    frame (issue 38's goal; measured -1: the ramp's line crossed with mu, its ratio
    reading about 1 % high). Round 8's rule (the first frame within 4 % of mu) was 2
    frames early."""
    (press,) = run[2].presses
    assert press["delay"] is not None
    assert abs(press["delay"]) <= 1


def test_the_frames_give_mujocos_normal_force_and_contact_point(run):
    """Noise-free, the kind's response for the ball alone: normal force within 1.5 % of
    MuJoCo's sum in every frame pressed with more than 0.25 N, sticking or sliding
    (measured: largest -1.2 %, sliding); the contact within a quarter pitch of MuJoCo's
    contact point in every pressed frame."""
    spec, _, result, _ = run
    assert np.isfinite(result.force_error).all()
    stick = result.force_error[~result.sliding & (result.mujoco_force_n > 0.25)]
    slide = result.force_error[result.sliding & (result.mujoco_force_n > 0.25)]
    assert len(stick) > 30 and len(slide) > 30
    assert np.max(np.abs(stick)) < 0.015
    assert np.max(np.abs(slide)) < 0.015
    assert np.max(result.centroid_error_mm) < 0.25 * spec.grid.row_pitch_mm


def test_the_ramp_onset_is_within_a_frame_of_mujocos(run):
    """The ramp of Q/P crossed with its sliding plateau (``ramp_onsets``): within one
    frame of MuJoCo's transition (measured 0 noise-free), and a fractional frame between
    the estimator's flag and its early call."""
    spec, recording, _, table = run
    (press,) = compare(recording.truth, table, spec.scan_period_s, ramp=True).presses
    assert abs(press["delay"]) <= 1
    (onset,) = ramp_onsets(table).values()
    assert press["mujoco_onset"] - 2 < onset < press["mujoco_onset"] + 1


def test_with_the_pads_flaws_and_mu_unknown_the_ramp_onset_holds(tmp_path):
    """Noise, gain spread, quantization and the rest of the per-frame flaws, ``mu`` not
    given (the estimator finds it at the plateau, flagging late): the ramp onset still
    within one frame of MuJoCo's; the flag itself comes after MuJoCo's onset."""
    spec, recording, table = _run(tmp_path, "all", None)
    (ramp,) = compare(recording.truth, table, spec.scan_period_s, ramp=True).presses
    (flag,) = compare(recording.truth, table, spec.scan_period_s).presses
    assert abs(ramp["delay"]) <= 1
    assert flag["detected"] > flag["mujoco_onset"]


@pytest.fixture(scope="module")
def calibrated(tmp_path_factory):
    """Every per-frame flaw (gain spread, offsets, noise, quantization), the ball's bench
    calibration (simulated sweeps with the same flaws, judged against the ball's own
    response), mu given and found."""
    spec, recording = _record(tmp_path_factory.mktemp("mjslip_cal"), "all")
    baseline = np.median(recording.frames[:5].astype(float), axis=0)
    bench = ball_calibration(spec)
    options = {"calibration": TriaxialCalibration(spec.name, baseline, bench.matrices),
               "radius_mm": EXAMPLE_BALL_RADIUS_MM}  # fmt: skip
    found = find_shear_contacts(recording.frames, spec, baseline=baseline, **options)
    out = {}
    for mu in (EXAMPLE_FRICTION, None):
        table, _ = ShearPipeline(spec, baseline, friction=mu, **options).track(found)
        out[mu] = (compare(recording.truth, table, spec.scan_period_s), table)
    return spec, out


def test_with_the_flaws_and_the_ball_calibration_the_force_is_within_2_percent(calibrated):
    """Issue 38's goal on this example: the normal force read from the frames (with the
    sensor's calibration) within 2 % of MuJoCo's normal force sum in every frame pressed
    with at least 0.25 N, sticking or sliding (this draw: 274 frames, median -0.41 %,
    largest -1.59 %; over the doc's five draws 2,737 of 2,740 frames, the other three at
    touch-down or sliding: docs/mujoco.md); median within 1 %; the centroid within 0.25
    pitch."""
    spec, out = calibrated
    result, _ = out[EXAMPLE_FRICTION]
    linear = result.mujoco_force_n >= 0.25
    errors = result.force_error[linear]
    assert np.isfinite(errors).all() and len(errors) > 150
    assert np.max(np.abs(errors)) <= 0.02
    assert abs(np.median(errors)) < 0.01
    assert np.nanmax(result.centroid_error_mm) < 0.25 * spec.grid.row_pitch_mm


@pytest.mark.parametrize("friction", [EXAMPLE_FRICTION, None])
def test_with_the_flaws_the_causal_onset_is_within_a_frame(calibrated, friction):
    """Causal onset (``slip_onset_s`` at the first gross row) within one frame of
    MuJoCo's, mu given and found; found, mu within 3 % of the model's 0.5."""
    _, out = calibrated
    result, table = out[friction]
    (press,) = result.presses
    assert press["delay"] is not None and abs(press["delay"]) <= 1
    if friction is None:
        gross = np.asarray(table.extra["slip_state"]) == "gross"
        assert table.extra["friction"][np.argmax(gross)] == pytest.approx(0.5, rel=0.03)


def test_locate_takes_the_indenters_radius(tmp_path):
    """``tactsense locate --indenter-radius 2 --friction 0.5`` on the example's recording
    writes the forces and onset of ``ShearPipeline(..., radius_mm=2.0)`` (the same numbers,
    to the CSV's printing), and they differ from the default probe's (the option acts)."""
    import csv

    from typer.testing import CliRunner

    from tactsense.cli import app

    spec, recording = _record(tmp_path, "none")
    baseline = np.median(recording.frames[:5].astype(float), axis=0)
    want, _ = ShearPipeline(spec, baseline, friction=EXAMPLE_FRICTION,
                            radius_mm=EXAMPLE_BALL_RADIUS_MM)(recording.frames)  # fmt: skip
    source = tmp_path / "mjslip_example_none.h5"
    out = tmp_path / "mjslip2_locate.csv"
    args = ["locate", str(source), "--friction", "0.5", "--indenter-radius", "2", "-o", str(out)]
    result = CliRunner().invoke(app, args)
    assert result.exit_code == 0, result.output
    with out.open() as handle:
        rows = list(csv.DictReader(handle))
    forces = np.array([float(r["force_n"]) for r in rows])
    np.testing.assert_allclose(forces, want.force_n, rtol=1e-6, atol=1e-9)
    default, _ = ShearPipeline(spec, baseline, friction=EXAMPLE_FRICTION)(recording.frames)
    assert np.max(np.abs(default.force_n - want.force_n)) > 1e-3
