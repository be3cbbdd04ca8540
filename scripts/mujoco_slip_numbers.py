"""Slip onset, normal force and centroid from MuJoCo on a three-axis pad (issue 38 item 2).

Runs the three-axis example (``mujoco_slip.xml``: the ``mag4x4`` pad pressed on a 2-mm
ball and dragged until it slips, twice), records the pad's frames with every per-frame
flaw (``record_mujoco``), runs the three-axis estimator on them (the response for the
kind's default probe, as round 8; the response for the ball; the ball's bench calibration
with it), with ``mu`` given (``--friction 0.5``) and found, and compares with MuJoCo's
contacts (``compare``), over several noise seeds. Checks first that the bench
calibration is unbiased noise-free (every gain 1) when judged against the ball's own
response. Times the recording (MuJoCo stepping and the frames), MuJoCo's stepping alone
and the estimator. Writes the marked block of docs/mujoco.md.

    PYTHONPATH=src python scripts/mujoco_slip_numbers.py
"""

from __future__ import annotations

import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "scripts"))

from docblock import replace_block  # noqa: E402

from tactsense.estimate.triaxial import calibrate_triaxial, find_shear_contacts  # noqa: E402
from tactsense.estimate.triaxial.calibration import TriaxialCalibration  # noqa: E402
from tactsense.estimate.triaxial.locate import ShearPipeline  # noqa: E402
from tactsense.estimate.triaxial.response import _table  # noqa: E402
from tactsense.interop.mujoco import (  # noqa: E402
    MujocoSensor,
    _mujoco,
    load_model,
    read_controls,
    record_mujoco,
)
from tactsense.interop.mujoco_shear import (  # noqa: E402
    EXAMPLE_BALL_RADIUS_MM,
    EXAMPLE_FRICTION,
    _sweep,
    ball_calibration,
    compare,
    slip_controls_path,
    slip_model_path,
)
from tactsense.io.recording import read_recording  # noqa: E402
from tactsense.sensor import preset  # noqa: E402

SECONDS = 8.0
SEED = 7
SEEDS = tuple(range(SEED, SEED + 5))
LINEAR_MIN_N = 0.25
"""Frames pressed with at least this normal force [N] (half the press) are the force
check's: touch-down and lift, a few read noises of force, are left out."""
BEGIN = "<!-- begin mujoco slip numbers -->"
END = "<!-- end mujoco slip numbers -->"


def step_alone(model, controls, seconds: float) -> float:
    """MuJoCo's stepping alone over the example's motion [s of wall time]."""
    mujoco = _mujoco()
    data = mujoco.MjData(model)
    n = round(seconds / model.opt.timestep)
    start = time.perf_counter()
    for _ in range(n):
        data.ctrl[:] = controls.at(data.time)
        mujoco.mj_step(model, data)
    return time.perf_counter() - start


def record(spec, model, controls, seed: int, flaws: str = "all"):
    """The example's recording (frames with ``flaws``, noise seed ``seed``) and the
    wall time of making it [s]."""
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "slip.h5"
        start = time.perf_counter()
        record_mujoco(path, MujocoSensor(model, spec, geom="pad"), seconds=SECONDS,
                      controls=controls, rng=seed, flaws=flaws,
                      model_path=slip_model_path())  # fmt: skip
        took = time.perf_counter() - start
        return read_recording(path), took


def gains_noise_free(spec) -> dict:
    """The bench calibration's diagonal gains [-] from noise-free ball sweeps, judged
    against the ball's own response and (the loads' radius withheld) against the
    default probe's: {label: (rows, cols, 3)}."""
    out = {}
    out["the ball's response (2 mm)"] = np.diagonal(
        ball_calibration(spec, flaws="none").matrices, axis1=-2, axis2=-1
    )
    sweeps = []
    for k, (ratio, angle) in enumerate(((0.0, 0.0), (0.3, 0.0), (0.3, 90.0))):
        frames, steps, contacts = _sweep(spec, EXAMPLE_BALL_RADIUS_MM, 0.5, ratio, angle, k,
                                         2, [])  # fmt: skip
        withheld = [[{k_: v for k_, v in c.items() if k_ != "radius_mm"} for c in step]
                    for step in contacts]  # fmt: skip
        sweeps.append((frames, steps, withheld))
    out["the default probe's (1.6 mm, round 8)"] = np.diagonal(
        calibrate_triaxial(sweeps, spec).matrices, axis1=-2, axis2=-1
    )
    return out


def traction_check(spec, radius: float) -> dict:
    """Largest normal-force error [%] of the fit of the ball's response to frames of the
    kind's forward model (no flaws) under a sliding ball (0.528 N, Q/P 0.5 along x) at
    five places along the first drag, with mu 1 and 0.5: {mu: error}."""
    from tactsense.physics.indenters import SphereProbe
    from tactsense.physics.triaxial import dipole_field_t, field_counts, magnet_displacement

    rest = field_counts(spec, dipole_field_t(spec, np.zeros((*spec.shape, 3))))
    out = {}
    for mu in (1.0, 0.5):
        errors = []
        for x in np.linspace(7.05, 10.3, 5):
            probe = SphereProbe(float(x), 7.05, 0.528, radius_mm=radius, shear_x_n=0.264,
                                friction=mu)  # fmt: skip
            frame = field_counts(spec, dipole_field_t(spec, magnet_displacement(spec, [probe])))
            table = find_shear_contacts(frame, spec, baseline=rest, radius_mm=radius,
                                        threshold_counts=10.0)  # fmt: skip
            errors.append(100 * (table.force_n[0] / 0.528 - 1))
        out[mu] = errors[int(np.argmax(np.abs(errors)))]
    return out


def first_gross(table, comparison) -> list:
    """The ``friction`` column [-] at each press's first gross-slip row (mu found)."""
    frame = np.asarray(table.frame)
    gross = np.asarray(table.extra["slip_state"]) == "gross"
    out = []
    for p in comparison.presses:
        inside = np.flatnonzero((frame >= p["first"]) & (frame < p["last"]) & gross)
        out.append(float(table.extra["friction"][inside[0]]) if len(inside) else np.nan)
    return out


def pair(v) -> str:
    v = np.asarray(v)[np.isfinite(v)]
    return f"{np.median(v):+.2f} / {v[np.argmax(np.abs(v))]:+.2f}" if len(v) else "-"


def delays(c) -> str:
    out = [p["delay"] for p in c.presses if p["mujoco_onset"] is not None]
    return " / ".join("missed" if d is None else f"{d:+d}" for d in out)


def main() -> None:
    spec = preset("mag4x4")
    model = load_model(slip_model_path())
    controls = read_controls(slip_controls_path(), model)
    pitch = spec.grid.row_pitch_mm
    period = spec.scan_period_s
    radius = EXAMPLE_BALL_RADIUS_MM
    gains = gains_noise_free(spec)
    start = time.perf_counter()
    bench = ball_calibration(spec)
    calibration_s = time.perf_counter() - start
    recordings = {}
    for seed in SEEDS:
        recordings[seed], took = record(spec, model, controls, seed)
        if seed == SEED:
            record_s = took
    stepping_s = min(step_alone(model, controls, SECONDS) for _ in range(2))
    recording = recordings[SEED]
    frames, truth = recording.frames, recording.truth
    n = len(frames)

    fitted: dict = {}

    def run(rec, config: str, mu):
        """The estimator's tracked table on ``rec`` and its comparisons (causal, ramp):
        the fit made once per recording and configuration, followed with each ``mu``."""
        rest = np.median(rec.frames[:5].astype(float), axis=0)
        options = {
            "default probe": {},
            "ball": {"radius_mm": radius},
            "ball + calibration": {
                "radius_mm": radius,
                "calibration": TriaxialCalibration(spec.name, rest, bench.matrices),
            },
        }[config]
        key = (id(rec), config)
        if key not in fitted:
            fitted[key] = find_shear_contacts(rec.frames, spec, baseline=rest, **options)
        table, _ = ShearPipeline(spec, rest, friction=mu, **options).track(fitted[key])
        return table, compare(rec.truth, table, period), compare(rec.truth, table, period,
                                                                  ramp=True)  # fmt: skip

    configs = {
        "response for the default probe (1.6 mm), uncalibrated (round 8)": "default probe",
        "response for the ball (2 mm), uncalibrated": "ball",
        "response for the ball + its 3x3 bench calibration": "ball + calibration",
    }
    lines = [
        f"`mag4x4` on `mujoco_slip.xml`, {n} frames at {1 / period:g} Hz with every per-frame "
        f"flaw (gain spread, offsets, noise, quantization; noise seed {SEED} in the first "
        f"table); MuJoCo {_mujoco().__version__}. Two presses of about "
        f"{np.median(truth['step_force_n'][truth['step_force_n'] > 0.4]):.3f} N by a "
        f"{radius:g}-mm ball, each dragged until friction (mu 0.5) gives way: along the "
        "pad's +x, then -y. Onset delay: the frames' onset minus MuJoCo's (the first frame "
        "with the friction force at the cone's limit), press 1 / press 2; 'causal': "
        "`locate`'s `slip_onset_s` at its first gross row (frames up to then only); "
        "'ramp': offline (`ramp_onsets`, the whole record). Force error over the frames "
        f"pressed with at least {LINEAR_MIN_N:g} N, centroid over those with 0.05 N "
        "(`python scripts/mujoco_slip_numbers.py`).",
        "",
        "| estimator | mu | onset delay, causal [frames] | onset delay, ramp [frames] | "
        "flagged after MuJoCo's onset [frames] | mu found [-] | force error, stick: median "
        "/ largest [%] | force error, sliding: median / largest [%] | centroid error: "
        "median / largest [mm] (pitch) |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    _table.cache_clear()  # the estimator's time with its table for the ball
    start = time.perf_counter()
    ShearPipeline(spec, np.median(frames[:5].astype(float), axis=0), friction=EXAMPLE_FRICTION,
                  radius_mm=radius)(frames)  # fmt: skip
    locate_s = time.perf_counter() - start
    for label, config in configs.items():
        for mu_label, mu in (("given", EXAMPLE_FRICTION), ("found", None)):
            table, c, r = run(recording, config, mu)
            detected = [p["detected"] - p["mujoco_onset"] for p in c.presses
                        if p["detected"] is not None and p["mujoco_onset"] is not None]  # fmt: skip
            linear = c.mujoco_force_n >= LINEAR_MIN_N
            cen = c.centroid_error_mm[np.isfinite(c.centroid_error_mm)]
            found = " / ".join(f"{m:.3f}" for m in first_gross(table, c)) if mu is None else "-"
            lines.append(
                f"| {label} | {mu_label} | {delays(c)} | {delays(r)} | "
                f"{', '.join(f'{d:+d}' for d in detected) or '-'} | {found} | "
                f"{pair(100 * c.force_error[linear & ~c.sliding])} | "
                f"{pair(100 * c.force_error[linear & c.sliding])} | "
                f"{np.median(cen):.3f} / {cen.max():.3f} "
                f"({np.median(cen) / pitch:.2f} / {cen.max() / pitch:.2f}) |"
            )
    lines += [
        "",
        "The response for the ball with its bench calibration, every noise seed (the "
        "calibration made once, seed 0 of the bench):",
        "",
        "| noise seed | onset delay, causal, mu given [frames] | onset delay, causal, mu found "
        "[frames] | mu found [-] | force error, stick: median / largest [%] | force "
        "error, sliding: median / largest [%] | frames within 2 % | centroid largest "
        "[pitch] |",
        "|---|---|---|---|---|---|---|---|",
    ]
    pooled, all_delays, within_total, linear_total, outside = [], [], 0, 0, []
    for seed in SEEDS:
        _, given, _ = run(recordings[seed], "ball + calibration", EXAMPLE_FRICTION)
        table, found, _ = run(recordings[seed], "ball + calibration", None)
        linear = given.mujoco_force_n >= LINEAR_MIN_N
        errors = 100 * given.force_error[linear]
        pooled.append(errors)
        within = int(np.sum(np.abs(errors) <= 2.0))
        for i in np.flatnonzero(linear)[np.abs(errors) > 2.0]:
            state = "sliding" if given.sliding[i] else "sticking"
            outside.append(
                f"seed {seed} frame {given.frames[i]} ({state}, MuJoCo "
                f"{given.mujoco_force_n[i]:.3f} N): {100 * given.force_error[i]:+.2f} %"
            )
        within_total += within
        linear_total += len(errors)
        all_delays += [p["delay"] for p in given.presses + found.presses]
        lines.append(
            f"| {seed} | {delays(given)} | {delays(found)} | "
            + " / ".join(f"{m:.3f}" for m in first_gross(table, found))
            + f" | {pair(100 * given.force_error[linear & ~given.sliding])} | "
            f"{pair(100 * given.force_error[linear & given.sliding])} | {within} of "
            f"{len(errors)} | {np.nanmax(given.centroid_error_mm) / pitch:.3f} |"
        )
    pooled = np.concatenate(pooled)
    clean, _ = record(spec, model, controls, SEED, flaws="none")
    _, clean_c, clean_r = run(clean, "ball", EXAMPLE_FRICTION)
    clean_linear = clean_c.mujoco_force_n >= LINEAR_MIN_N
    onsets = [p["mujoco_onset"] for p in run(recording, "ball", EXAMPLE_FRICTION)[1].presses]
    light = []  # noise-free, the first touch-down's frames
    for i in range(len(clean_c.frames)):
        if clean_c.frames[i] < onsets[0] and clean_c.mujoco_force_n[i] < 0.46:
            light.append(f"{clean_c.mujoco_force_n[i]:.2f} N {100 * clean_c.force_error[i]:+.1f} %")
    traction = traction_check(spec, radius)
    ball_gains, probe_gains = gains.values()
    worst = [d for d in all_delays if d is not None]
    lines += [
        "",
        f"* Over the {len(SEEDS)} seeds: force error in the pressed frames (>= "
        f"{LINEAR_MIN_N:g} N) median {np.median(pooled):+.2f} %, largest "
        f"{pooled[np.argmax(np.abs(pooled))]:+.2f} %, {within_total} of {linear_total} "
        f"frames ({within_total / linear_total:.1%}) within 2 %; causal onset delays "
        f"(mu given and found, both presses) from {min(worst):+d} to {max(worst):+d} "
        "frames.",
        "* The bench calibration, noise-free ball sweeps (the ball pressed with 0.5 N on "
        "every taxel and half-way between, then pushed with 0.3 of it along x and y), "
        "diagonal gains x / y / z, mean (largest distance from 1): judged against the "
        "ball's own response "
        + ", ".join(f"{ball_gains[..., a].mean():.4f}" for a in range(3))
        + f" ({np.abs(ball_gains - 1).max():.2%}); against the default probe's "
        + ", ".join(f"{probe_gains[..., a].mean():.4f}" for a in range(3))
        + f" ({np.abs(probe_gains - 1).max():.2%}).",
        f"* MuJoCo's onsets (friction at the cone's limit): frames {onsets}.",
        "* Frames pressed with 0.25 N or more outside 2 %: " + ("; ".join(outside) or "none") + ".",
        "* Noise-free, the response for the ball, the first touch-down's frames (MuJoCo's "
        "force, error): " + ", ".join(light) + ".",
        "* The traction a sliding contact's frames are made with (the kind's forward model "
        "alone, a 2-mm ball with 0.528 N and Q/P 0.5 at five places from the pad's centre "
        "to over a magnet, fitted with the response for the ball), largest force error: "
        f"with mu taken as 1 (`contact_state`'s for contacts given as forces: "
        f"Cattaneo-Mindlin's partial slip) {traction[1.0]:+.2f} %; with mu 0.5 (gross "
        f"slip, as MuJoCo reports) {traction[0.5]:+.2f} %.",
        "* Noise-free frames (flaws 'none'), the response for the ball alone, mu given: "
        f"onset delay, causal {delays(clean_c)}, ramp {delays(clean_r)} [frames]; force "
        f"error, stick {pair(100 * clean_c.force_error[clean_linear & ~clean_c.sliding])} %, "
        f"sliding {pair(100 * clean_c.force_error[clean_linear & clean_c.sliding])} % "
        "(median / largest).",
        f"* Throughput (one core): recording {n} frames with MuJoCo stepping "
        f"({round(SECONDS / model.opt.timestep)} steps of 1 ms) took {record_s:.2f} s "
        f"({n / record_s:.0f} frames/s); MuJoCo's stepping alone {stepping_s:.2f} s "
        f"({stepping_s / record_s:.0%} of it); the estimator (response for the ball, mu "
        f"given) {locate_s:.2f} s ({n / locate_s:.0f} frames/s, its response table for the "
        f"ball included); the bench calibration (three simulated sweeps of 49 presses) "
        f"{calibration_s:.1f} s, once.",
    ]
    text = "\n".join([BEGIN, *lines, END])
    print(text)
    replace_block(ROOT / "docs" / "mujoco.md", BEGIN, END, text)


if __name__ == "__main__":
    main()
