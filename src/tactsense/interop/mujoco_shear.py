"""Slip onset, force and centroid from MuJoCo on a three-axis pad, against MuJoCo.

The example (``mujoco_slip.xml`` and its motion ``mujoco_slip.csv``, shipped with
tactsense): a finger carrying the ``mag4x4`` magnetic three-axis pad (4 x 4 taxels at
4.7 mm) presses on a fixed ball of 2 mm radius with about 0.5 N, then its x servo drags
it 4 mm along -x until friction (mu = 0.5, MuJoCo's elliptic cone) gives way and the
ball slides across the pad along +x (the pad's coordinates); it lifts, presses again
and drags along the pad's -y. :func:`compare` sets the three-axis estimator's contacts
(``locate`` on the recording) against the recording's truth (MuJoCo's contacts at each
frame's instant): the slip onset per press (the first frame MuJoCo's friction force is
at the cone's limit against the estimator's ``slip_onset_s``), the normal force and the
contact centroid per frame. :func:`ball_calibration` makes the sensor's calibration as a
lab would on the bench: the same ball pressed on every taxel and between them, then
pressed and pushed along x and along y (simulated sweeps, the loads known), each taxel's
3x3 matrix by ``calibrate_triaxial`` judged against the kind's response to that ball
(r9-mjslip2: against the default probe's, the gains came out 6 % high on z). The
estimator is then run with the ball's radius (``ShearPipeline(..., radius_mm=2.0)``).
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from importlib import resources
from pathlib import Path

import numpy as np

__all__ = [
    "EXAMPLE_BALL_RADIUS_MM",
    "EXAMPLE_FRICTION",
    "SlipComparison",
    "ball_calibration",
    "compare",
    "force_curve",
    "ramp_onsets",
    "slip_controls_path",
    "slip_model_path",
]

EXAMPLE_BALL_RADIUS_MM = 2.0
"""Radius of the example's fixed ball [mm] (``mujoco_slip.xml``)."""

EXAMPLE_FRICTION = 0.5
"""Friction coefficient of the example's ball and pad [-] (``mujoco_slip.xml``)."""


def slip_model_path() -> Path:
    """The three-axis example: a finger with a ``mag4x4`` pad pressing on a ball and
    dragged across it until it slips (``mujoco_slip.xml``)."""
    return Path(str(resources.files("tactsense.interop") / "data" / "mujoco_slip.xml"))


def slip_controls_path() -> Path:
    """The three-axis example's motion: ``time_s`` [s] and the three servos' targets
    [m] (``mujoco_slip.csv``)."""
    return Path(str(resources.files("tactsense.interop") / "data" / "mujoco_slip.csv"))


def _sweep(spec, radius_mm: float, force_n: float, ratio: float, angle_deg: float, seed,
           step: int = 1, flaws="all"):  # fmt: skip
    """A simulated bench sweep: the ball pressed on every taxel (and ``step - 1`` places
    between neighbours) with ``force_n`` [N] and dragged with a tangential force
    ``ratio`` times it along ``angle_deg`` [deg] (gross slip: friction ``ratio``, so that
    the tangential force is known, as triest's sweeps); (frames, frame_step, step
    contacts) as ``calibrate_triaxial`` takes them."""
    from tactsense.kinds import kind_of
    from tactsense.physics.indenters import SphereProbe
    from tactsense.simulate.run import simulate
    from tactsense.simulate.scenario import Scenario, Step

    (x_pitch, rows), (y_pitch, cols) = kind_of(spec).surface_grid(spec)
    qx = ratio * force_n * math.cos(math.radians(angle_deg))
    qy = ratio * force_n * math.sin(math.radians(angle_deg))
    period = spec.scan_period_s
    steps = [Step((), 10 * period, "untouched")]
    for r in range(step * (rows - 1) + 1):
        for c in range(step * (cols - 1) + 1):
            probe = SphereProbe(
                r * x_pitch / step, c * y_pitch / step, force_n, radius_mm=radius_mm,
                shear_x_n=qx, shear_y_n=qy, friction=max(ratio, 0.05),
            )  # fmt: skip
            steps += [Step((probe,), 6 * period, "pressed"), Step((), 3 * period, "lifted")]
    recording = simulate(spec, Scenario(tuple(steps), "bench sweep"), rng=seed, flaws=flaws)
    truth = recording.truth
    return recording.frames, truth["frame_step"], json.loads(truth["step_contacts_json"])


def ball_calibration(spec, *, radius_mm: float = EXAMPLE_BALL_RADIUS_MM, force_n: float = 0.5,
                     ratio: float = 0.3, seed: int = 0, step: int = 2,
                     flaws="all"):  # fmt: skip
    """The sensor's three-axis calibration made with the example's ball: a normal sweep
    and two tangential sweeps (``ratio`` of ``force_n`` [N] along x, then y) on a grid
    ``step`` places per pitch (2: on every taxel and half-way between neighbours),
    simulated with the per-frame flaws ``flaws`` (as :func:`record_mujoco` takes them:
    "all" the per-frame ones, the same skin's gains and offsets as its frames; "none"
    noise-free); each taxel's matrix judged against the kind's response to a sphere of
    ``radius_mm`` [mm] (:func:`calibrate_triaxial`)."""
    from tactsense.estimate.triaxial import calibrate_triaxial
    from tactsense.interop.mujoco import active_flaws

    active = list(active_flaws(flaws))
    sweeps = [
        _sweep(spec, radius_mm, force_n, 0.0, 0.0, seed, step, active),
        _sweep(spec, radius_mm, force_n, ratio, 0.0, seed + 1, step, active),
        _sweep(spec, radius_mm, force_n, ratio, 90.0, seed + 2, step, active),
    ]
    return calibrate_triaxial(sweeps, spec, radius_mm=radius_mm)


def force_curve(spec, *, radius_mm: float = EXAMPLE_BALL_RADIUS_MM,
                forces_n=(0.2, 0.5, 0.8), calibration=None, seed: int = 11,
                flaws="all"):  # fmt: skip
    """A normal-force curve, as a lab makes one on the bench: the ball pressed with each
    of ``forces_n`` [N] at every point of a grid a half pitch apart over the pad's
    interior (simulated with the per-frame flaws ``flaws``, as :func:`ball_calibration`;
    the estimator with the ball's radius), the estimator's normal force against
    the known one; returns ``(a, b)`` of ``true = a e + b e^2`` (``e`` the estimate
    [N]), least squares over the settled frames, and the bench's relative residuals
    (true over the curve's value, minus 1) [-]."""
    from tactsense.estimate.triaxial.locate import ShearPipeline
    from tactsense.interop.mujoco import active_flaws
    from tactsense.kinds import kind_of
    from tactsense.physics.indenters import SphereProbe
    from tactsense.simulate.run import simulate
    from tactsense.simulate.scenario import Scenario, Step

    (x_pitch, rows), (y_pitch, cols) = kind_of(spec).surface_grid(spec)
    period = spec.scan_period_s
    steps = [Step((), 10 * period, "untouched")]
    for x in np.arange(1, 2 * rows - 2) * x_pitch / 2:
        for y in np.arange(1, 2 * cols - 2) * y_pitch / 2:
            for force in forces_n:
                probe = SphereProbe(float(x), float(y), float(force), radius_mm=radius_mm)
                steps += [Step((probe,), 6 * period, "pressed"), Step((), 3 * period, "lifted")]
    recording = simulate(spec, Scenario(tuple(steps), "force curve"), rng=seed,
                         flaws=list(active_flaws(flaws)))  # fmt: skip
    step = np.asarray(recording.truth["frame_step"])
    true = np.asarray(recording.truth["step_force_n"], float)[step]
    baseline = np.median(recording.frames[:5].astype(float), axis=0)
    if calibration is not None:
        baseline = calibration.baseline
    table, _ = ShearPipeline(spec, baseline, calibration=calibration,
                             radius_mm=radius_mm)(recording.frames)  # fmt: skip
    estimate = np.zeros(len(step))
    np.add.at(estimate, np.asarray(table.frame), np.asarray(table.force_n))
    settled = (true > 0) & (np.r_[-1, -1, step[:-2]] == step) & (estimate > 0)
    e, t = estimate[settled], true[settled]
    (a, b), *_ = np.linalg.lstsq(np.column_stack([e, e * e]), t, rcond=None)
    return (float(a), float(b)), t / (a * e + b * e * e) - 1.0


@dataclass(frozen=True)
class SlipComparison:
    """The estimator's contacts against MuJoCo's, per press and per frame.

    Attributes
    ----------
    presses : list of dict
        One per press (a run of frames with MuJoCo contact): ``first``, ``last`` (frames),
        ``mujoco_onset`` (first frame at the friction cone's limit, or None),
        ``onset`` (the estimator's onset frame, or None), ``delay`` (frames, onset minus
        MuJoCo's), ``detected`` (frame the estimator flagged it).
    force_error : ndarray
        Per pressed frame with one estimated contact: estimated normal force over
        MuJoCo's normal force sum, minus 1 [-] (NaN where none was found).
    centroid_error_mm : ndarray
        Per pressed frame: distance from the estimated contact to MuJoCo's
        force-weighted contact point [mm] (NaN where none was found).
    sliding : ndarray of bool
        Per pressed frame: whether MuJoCo's contact is at the cone's limit.
    mujoco_force_n : ndarray
        Per pressed frame: MuJoCo's normal force sum [N].
    frames : ndarray of int
        The pressed frames' indices.
    """

    presses: list
    force_error: np.ndarray
    centroid_error_mm: np.ndarray
    sliding: np.ndarray
    mujoco_force_n: np.ndarray
    frames: np.ndarray


def _runs(mask: np.ndarray) -> list[tuple[int, int]]:
    edges = np.diff(np.concatenate([[0], mask.astype(int), [0]]))
    return list(zip(np.flatnonzero(edges == 1), np.flatnonzero(edges == -1), strict=True))


RAMP_BAND = (0.3, 0.85)
"""The share of the sliding plateau's ratio between which :func:`ramp_onsets` fits the
ramp's line [-]: above the press's own ratio, below the rounding into the plateau."""


def ramp_onsets(table, *, min_points: int = 4) -> dict[int, float]:
    """Each gross-slipping contact's onset [frames, fractional] from the whole record,
    where the tangential-to-normal ratio's ramp reaches the plateau it slides at.

    For a contact (a track id of ``table``) the estimator called in gross slip: the
    plateau is the median of its ``shear_ratio`` from that call on (frames loaded with
    at least 0.8 times its median normal force: not the lift); the ramp is the frames
    before the call whose ratio is within :data:`RAMP_BAND` of the plateau; a straight
    line fitted to the ramp (least squares) crosses the plateau at the onset. Offline:
    it needs frames after the onset (a recording's analysis; ``live`` has the
    estimator's own onset). A contact with fewer than ``min_points`` ramp frames (a
    jerk into slip) gets the estimator's onset frame.
    """
    ratio = np.asarray(table.extra["shear_ratio"], float)
    gross = np.asarray(table.extra["slip_state"]) == "gross"
    frame, ids, force = np.asarray(table.frame), np.asarray(table.id), np.asarray(table.force_n)
    onsets = {}
    for i in np.unique(ids[gross]):
        mine = np.flatnonzero(ids == i)
        f, q, g = frame[mine], ratio[mine], gross[mine]
        loaded = force[mine] >= 0.8 * np.median(force[mine])
        called = np.argmax(g)
        after = (np.arange(len(q)) >= called) & loaded & np.isfinite(q)
        plateau = float(np.median(q[after])) if after.any() else np.nan
        low, high = RAMP_BAND
        ramp = (np.arange(len(q)) < called) & loaded & (q > low * plateau) & (q < high * plateau)
        if np.isfinite(plateau) and ramp.sum() >= min_points:
            slope, intercept = np.polyfit(f[ramp], q[ramp], 1)
            if slope > 0:
                onsets[int(i)] = float((plateau - intercept) / slope)
                continue
        onsets[int(i)] = float(f[called])
    return onsets


def compare(truth: dict, table, period_s: float, *, min_force_n: float = 0.05,
            ramp: bool = False, curve=None) -> SlipComparison:  # fmt: skip
    """Set the estimator's ``table`` (a ``ContactTable`` with the three-axis columns)
    against ``truth`` (the recording's: ``step_force_n``, ``step_x_mm``, ``step_y_mm``,
    ``mujoco_slip``; one entry per frame). Frames with MuJoCo's normal force below
    ``min_force_n`` [N] (touching down, lifting) are left out of the force and centroid
    errors; ``period_s`` [s] turns the estimator's onset times into frames. ``ramp``:
    the onsets of :func:`ramp_onsets` (the first frame at or after the ramp's crossing)
    instead of the estimator's ``slip_onset_s``. ``curve``: ``(a, b)`` of
    :func:`force_curve`, applied to the estimated normal force."""
    force = np.asarray(truth["step_force_n"], float)
    x, y = np.asarray(truth["step_x_mm"], float), np.asarray(truth["step_y_mm"], float)
    slip = np.asarray(truth["mujoco_slip"], bool)
    frame = np.asarray(table.frame)
    onset_s = np.asarray(table.extra["slip_onset_s"], float)
    gross = np.asarray(table.extra["slip_state"]) == "gross"
    refined = ramp_onsets(table) if ramp else {}
    ids = np.asarray(table.id)
    presses = []
    for first, last in _runs(force > 0):
        mujoco = np.flatnonzero(slip[first:last])
        inside = (frame >= first) & (frame < last) & gross
        press = {"first": int(first), "last": int(last), "mujoco_onset": None, "onset": None,
                 "delay": None, "detected": None}  # fmt: skip
        if len(mujoco):
            press["mujoco_onset"] = int(first + mujoco[0])
        if inside.any():
            k = np.flatnonzero(inside)[0]
            if ramp:
                press["onset"] = math.ceil(refined[int(ids[k])] - 1e-9)
            else:
                press["onset"] = round(onset_s[k] / period_s)
            press["detected"] = int(frame[k])
        if press["onset"] is not None and press["mujoco_onset"] is not None:
            press["delay"] = press["onset"] - press["mujoco_onset"]
        presses.append(press)
    pressed = np.flatnonzero(force >= min_force_n)
    f_err = np.full(len(pressed), np.nan)
    c_err = np.full(len(pressed), np.nan)
    for i, j in enumerate(pressed):
        rows = np.flatnonzero(frame == j)
        if len(rows) == 0:
            continue
        estimate = float(np.sum(table.force_n[rows]))
        if curve is not None:
            estimate = curve[0] * estimate + curve[1] * estimate**2
        f_err[i] = estimate / force[j] - 1.0
        k = rows[np.argmax(table.force_n[rows])]
        c_err[i] = math.hypot(table.x_mm[k] - x[j], table.y_mm[k] - y[j])
    return SlipComparison(presses, f_err, c_err, slip[pressed], force[pressed], pressed)
