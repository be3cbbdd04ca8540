"""Slip onset, normal force and centroid from MuJoCo on a three-axis pad (issue 38 item 2).

Runs the three-axis example (``mujoco_slip.xml``: the ``mag4x4`` pad pressed on a ball
and dragged until it slips, twice), records the pad's frames with every per-frame flaw
(``record_mujoco``), runs the three-axis estimator on them with the ball's calibration
(``ball_calibration``) and without it, with ``mu`` given (``--friction 0.5``) and found,
and compares with MuJoCo's contacts (``compare``). Times the recording (MuJoCo stepping
and the frames), MuJoCo's stepping alone, and the estimator. Writes the marked block of
docs/mujoco.md.

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

from tactsense.estimate.triaxial.calibration import TriaxialCalibration  # noqa: E402
from tactsense.estimate.triaxial.locate import ShearPipeline  # noqa: E402
from tactsense.interop.mujoco import (  # noqa: E402
    MujocoSensor,
    _mujoco,
    load_model,
    read_controls,
    record_mujoco,
)
from tactsense.interop.mujoco_shear import (  # noqa: E402
    EXAMPLE_FRICTION,
    ball_calibration,
    compare,
    force_curve,
    slip_controls_path,
    slip_model_path,
)
from tactsense.io.recording import read_recording  # noqa: E402
from tactsense.sensor import preset  # noqa: E402

SECONDS = 8.0
SEED = 7
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


def main() -> None:
    spec = preset("mag4x4")
    model = load_model(slip_model_path())
    controls = read_controls(slip_controls_path(), model)
    pitch = spec.grid.row_pitch_mm
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "slip.h5"
        start = time.perf_counter()
        n = record_mujoco(path, MujocoSensor(model, spec, geom="pad"), seconds=SECONDS,
                          controls=controls, rng=SEED, model_path=slip_model_path())  # fmt: skip
        record_s = time.perf_counter() - start
        recording = read_recording(path)
    stepping_s = min(step_alone(model, controls, SECONDS) for _ in range(2))
    frames, truth, period = recording.frames, recording.truth, spec.scan_period_s
    baseline = np.median(frames[:5].astype(float), axis=0)
    start = time.perf_counter()
    bench = ball_calibration(spec)
    calibration_s = time.perf_counter() - start
    calibration = TriaxialCalibration(spec.name, baseline, bench.matrices)
    curve, bench_residual = force_curve(spec)
    configs = {
        "the kind's response alone": (None, None),
        "3x3 bench calibration (ball)": (calibration, None),
        "response + force curve (ball)": (None, curve),
    }
    results, locate_s = {}, {}
    for label, (cal, use_curve) in configs.items():
        for mu_label, mu in (("given", EXAMPLE_FRICTION), ("found", None)):
            pipeline = ShearPipeline(spec, baseline, calibration=cal, friction=mu)
            start = time.perf_counter()
            table, _ = pipeline(frames)
            locate_s[(label, mu_label)] = time.perf_counter() - start
            results[(label, mu_label)] = (
                compare(truth, table, period, curve=use_curve),
                compare(truth, table, period, curve=use_curve, ramp=True),
            )
    lines = [
        f"`mag4x4` on `mujoco_slip.xml`, {n} frames at {1 / period:g} Hz with every per-frame "
        f"flaw (noise seed {SEED}); MuJoCo {_mujoco().__version__}. Two presses of about "
        f"{np.median(truth['step_force_n'][truth['step_force_n'] > 0.4]):.3f} N, each "
        "dragged until friction (mu 0.5) gives way: along the pad's +x, then -y. "
        "Onset delay: the frames' onset minus MuJoCo's (the first frame with the friction "
        "force at the cone's limit), press 1 / press 2; 'estimator': `locate`'s "
        "`slip_onset_s`; 'ramp': the ramp of Q/P fitted and crossed with its sliding "
        "plateau (`ramp_onsets`, offline). Force and centroid over the frames with "
        "MuJoCo's normal force >= 0.05 N (`python scripts/mujoco_slip_numbers.py`).",
        "",
        "| normal force from | mu | onset delay, estimator [frames] | onset delay, ramp "
        "[frames] | flagged after MuJoCo's onset [frames] | force error, stick: median / "
        "largest [%] | force error, sliding: median / largest [%] | centroid error: median "
        "/ largest [mm] (pitch) |",
        "|---|---|---|---|---|---|---|---|",
    ]

    def pair(v):
        v = v[np.isfinite(v)]
        return f"{np.median(v):+.2f} / {v[np.argmax(np.abs(v))]:+.2f}" if len(v) else "-"

    def delays(c):
        out = [p["delay"] for p in c.presses if p["mujoco_onset"] is not None]
        return " / ".join("missed" if d is None else f"{d:+d}" for d in out)

    for (label, mu_label), (c, r) in results.items():
        detected = [p["detected"] - p["mujoco_onset"] for p in c.presses
                    if p["detected"] is not None and p["mujoco_onset"] is not None]  # fmt: skip
        stick = 100 * c.force_error[~c.sliding]
        slide = 100 * c.force_error[c.sliding]
        cen = c.centroid_error_mm[np.isfinite(c.centroid_error_mm)]
        lines.append(
            f"| {label} | {mu_label} | {delays(c)} | {delays(r)} | "
            f"{', '.join(f'{d:+d}' for d in detected) or '-'} | {pair(stick)} | "
            f"{pair(slide)} | {np.median(cen):.3f} / {cen.max():.3f} "
            f"({np.median(cen) / pitch:.2f} / {cen.max() / pitch:.2f}) |"
        )
    seeds = []
    for seed in range(SEED + 1, SEED + 6):
        with tempfile.TemporaryDirectory() as folder:
            path = Path(folder) / "slip.h5"
            record_mujoco(path, MujocoSensor(model, spec, geom="pad"), seconds=SECONDS,
                          controls=controls, rng=seed)  # fmt: skip
            again = read_recording(path)
        rest = np.median(again.frames[:5].astype(float), axis=0)
        table, _ = ShearPipeline(spec, rest)(again.frames)
        c = compare(again.truth, table, period, ramp=True, curve=curve)
        seeds += [p["delay"] for p in c.presses]
        seeds_force = 100 * np.nanmedian(c.force_error[~c.sliding])
        seeds.append(f"{seeds_force:+.2f} %")
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "slip.h5"
        record_mujoco(path, MujocoSensor(model, spec, geom="pad"), seconds=SECONDS,
                      controls=controls, rng=SEED, flaws="none")  # fmt: skip
        clean = read_recording(path)
    rest = np.median(clean.frames[:5].astype(float), axis=0)
    table, _ = ShearPipeline(spec, rest, friction=EXAMPLE_FRICTION)(clean.frames)
    clean_c = compare(clean.truth, table, period)
    clean_r = compare(clean.truth, table, period, ramp=True)
    c0 = results[("the kind's response alone", "given")][0]
    onsets = [p["mujoco_onset"] for p in c0.presses]
    missing = np.isnan(c0.force_error).sum()
    total_locate = locate_s[("the kind's response alone", "given")]
    lo, hi = np.percentile(100 * bench_residual, [5, 95])
    lines += [
        "",
        f"* MuJoCo's onsets (friction at the cone's limit): frames {onsets}; pressed frames "
        f"without an estimated contact: {missing} of {len(c0.frames)}.",
        f"* The force curve (`force_curve`: the ball pressed with 0.2, 0.5, 0.8 N on a grid "
        f"a half pitch apart): true = {curve[0]:.4f} e {curve[1]:+.4f} e^2 [N]; the bench's "
        f"own presses scatter {lo:+.1f} % to {hi:+.1f} % (5-95 %) about it, with the place "
        "of the press.",
        "* Noise-free frames (flaws 'none'), the kind's response alone, mu given: onset "
        f"delay, estimator {delays(clean_c)}, ramp {delays(clean_r)} [frames]; force "
        f"error, stick {pair(100 * clean_c.force_error[~clean_c.sliding])} %, sliding "
        f"{pair(100 * clean_c.force_error[clean_c.sliding])} % (median / largest).",
        "* Other noise seeds (response + force curve, mu found, ramp onset): "
        + "; ".join(
            f"seed {SEED + 1 + k}: delays {seeds[3 * k]:+d} / {seeds[3 * k + 1]:+d}, "
            f"stick force {seeds[3 * k + 2]}"
            for k in range(5)
        )
        + ".",
        f"* Throughput (one core): recording {n} frames with MuJoCo stepping "
        f"({round(SECONDS / model.opt.timestep)} steps of 1 ms) took {record_s:.2f} s "
        f"({n / record_s:.0f} frames/s); MuJoCo's stepping alone {stepping_s:.2f} s "
        f"({stepping_s / record_s:.0%} of it); the estimator (response alone, mu given) "
        f"{total_locate:.2f} s ({n / total_locate:.0f} frames/s, its response table "
        f"included); the bench calibration (three simulated sweeps) {calibration_s:.1f} s, "
        "once.",
    ]
    text = "\n".join([BEGIN, *lines, END])
    print(text)
    replace_block(ROOT / "docs" / "mujoco.md", BEGIN, END, text)


if __name__ == "__main__":
    main()
