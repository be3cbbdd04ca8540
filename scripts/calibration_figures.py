"""Figures and numbers of docs/calibration.md.

Run: ``python scripts/calibration_figures.py`` (writes docs/images/calibration_*.png and
prints the numbers quoted in the doc).
"""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

import tactsense as ts
from tactsense.estimate.finger import calibrate as cal
from tactsense.physics.flaws import draw_gains
from tactsense.physics.transduction import fractional_deflection

OUT = Path(__file__).resolve().parents[1] / "docs" / "images"
FLAWS = ["noise", "quantization", "gain_spread"]


def gains_figure(spec):
    sweep = ts.simulate(spec, ts.calibration_sweep(spec), flaws=FLAWS, rng=1)
    calibration = cal.calibrate_sweep(sweep.frames, spec)
    truth = draw_gains(spec)
    error = np.abs(calibration.gains[1:] / truth[1:] - 1)
    print(
        f"gains: true spread {truth[1:].max() / truth[1:].min():.2f}:1, recovered within "
        f"{100 * error.max():.1f} % (mean {100 * error.mean():.1f} %)"
    )
    scene = ts.probe_sweep(spec, along="axial", col=2)
    rec = ts.simulate(spec, scene, flaws=FLAWS, rng=2)
    base = ts.baseline_from(rec.frames, 5)
    raw = fractional_deflection(rec.frames.astype(float), base)
    fixed, _ = calibration.apply(rec.frames, spec)
    step = rec.truth["frame_step"]
    touched = rec.truth["step_n_contacts"][step] > 0
    position = rec.truth["step_axial_mm"][step][touched]
    fig, axes = plt.subplots(1, 2, figsize=(10, 4), sharey=True, constrained_layout=True)
    for ax, data, title in ((axes[0], raw, "before"), (axes[1], fixed, "after")):
        for r in range(1, 8):
            ax.plot(position, 100 * data[touched, r, 2], lw=1, label=f"row {r}")
        ax.set_title(f"{title} gain calibration")
        ax.set_xlabel("probe position along the finger [mm]")
        ax.grid(alpha=0.3)
    axes[0].set_ylabel("fractional deflection [%]")
    axes[1].legend(fontsize=7, ncol=2)
    fig.suptitle("50-g probe swept along column 2 of the initial finger (cf. Fig. 7)")
    fig.savefig(OUT / "calibration_gains.png", dpi=110)
    plt.close(fig)
    peaks = [raw[touched, r, 2].max() for r in range(1, 8)]
    peaks_fixed = [fixed[touched, r, 2].max() for r in range(1, 8)]
    print(
        f"row peaks: spread {max(peaks) / min(peaks):.2f}:1 before, "
        f"{max(peaks_fixed) / min(peaks_fixed):.2f}:1 after"
    )
    return calibration


def thresholds_figure(calibration):
    measured = calibration.threshold_g[1:].ravel()
    fig, ax = plt.subplots(figsize=(6, 3.5), constrained_layout=True)
    ax.hist(measured, bins=np.arange(0.1, 1.0, 0.05), color="C0", edgecolor="k")
    ax.set_xlabel("force for one A/D unit [g]")
    ax.set_ylabel("tactels")
    ax.set_title("Sensitivity of the 56 cylinder tactels (cf. Fig. 8)")
    fig.savefig(OUT / "calibration_thresholds.png", dpi=110)
    plt.close(fig)
    print(
        f"thresholds: mean {measured.mean():.2f} g, min {measured.min():.2f} g, "
        f"max {measured.max():.2f} g, cells at <= 0.25 g: {(measured <= 0.25).sum()}"
    )


def creep_figure(spec):
    fast = spec.replace(electronics__scan_rate_hz=50.0)
    rec = ts.simulate(
        fast,
        ts.force_steps(fast, repeats=5, on_s=3, off_s=3),
        flaws=["viscoelastic", "noise", "quantization"],
        rng=0,
    )
    model, _, rms = cal.fit_viscoelastic_recording(rec, 4, 0)
    print(
        f"creep fit: {model}, RMS {100 * rms:.2f} % (truth {spec.flaws.delayed_fraction}, "
        f"{spec.flaws.delayed_time_constant_s}, {spec.flaws.creep_fraction}, "
        f"{spec.flaws.creep_time_constant_s})"
    )
    fig, axes = plt.subplots(2, 1, figsize=(9, 6), constrained_layout=True)
    for ax, rate in zip(axes, (7.0, 25.0), strict=True):
        slow = spec.replace(electronics__scan_rate_hz=rate)
        scene = ts.force_steps(slow, repeats=4)
        y = ts.simulate(slow, scene, flaws=["viscoelastic", "noise", "quantization"], rng=1)
        x = ts.simulate(slow, scene, flaws=["noise", "quantization"], rng=1)
        dy = fractional_deflection(y.frames.astype(float), ts.baseline_from(y.frames, 5))[:, 4, 0]
        dx = fractional_deflection(x.frames.astype(float), ts.baseline_from(x.frames, 5))[:, 4, 0]
        fixed = cal.compensate_viscoelastic(dy, slow.scan_period_s, model)
        for data, label in ((dx, "elastic (no creep)"), (dy, "reading"), (fixed, "compensated")):
            ax.step(y.time_s, 100 * data, where="post", label=label, lw=1.2)
        before = np.abs(dy - dx)
        after = np.abs(fixed - dx)
        peak = dx.max()
        print(
            f"{rate:g} Hz: error max {100 * before.max() / peak:.1f} % -> "
            f"{100 * after.max() / peak:.1f} %, RMS {100 * np.sqrt(np.mean(before**2)) / peak:.1f}"
            f" % -> {100 * np.sqrt(np.mean(after**2)) / peak:.1f} % of the step"
        )
        ax.set_title(f"50-g steps read at {rate:g} Hz (cf. Fig. 12)")
        ax.set_xlabel("time [s]")
        ax.set_ylabel("deflection [%]")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    fig.savefig(OUT / "calibration_creep.png", dpi=110)
    plt.close(fig)


def fit_figure(spec):
    rec = ts.simulate(
        spec, ts.knife_edge_sweep(spec), flaws=["noise", "quantization", "jitter"], rng=3
    )
    d = fractional_deflection(rec.frames.astype(float), ts.baseline_from(rec.frames, 5))[:, 4, 0]
    last, steps = rec.last_loaded_frames(4, 0)
    x = rec.truth["step_axial_mm"][steps]
    fit = cal.fit_plane_stress(x, d[last])
    print(f"knife-edge fit: {fit}")
    fine = np.linspace(x.min(), x.max(), 300)
    h = -ts.physics.halfplane.impulse_response(
        (fine - fit.centre_mm) * 1e-3,
        fit.depth_mm * 1e-3,
        youngs_modulus=2.5e5,
        poisson_ratio=fit.poisson_ratio,
    )
    fig, ax = plt.subplots(figsize=(6.5, 4), constrained_layout=True)
    ax.plot(x - fit.centre_mm, 100 * d[last], "o", label="simulated tactel (0.5-N knife edge)")
    ax.plot(
        fine - fit.centre_mm,
        100 * fit.amplitude * h / h.max(),
        "-",
        label=f"plane stress, d = {fit.depth_mm:.2f} mm, nu = {fit.poisson_ratio:.2f}",
    )
    ax.set_xlabel("knife-edge position from the tactel [mm]")
    ax.set_ylabel("fractional deflection [%]")
    ax.set_title(f"Section 4.1 fit (cf. Fig. 16): RMS {fit.rms_percent:.2f} % of full scale")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    fig.savefig(OUT / "calibration_fit.png", dpi=110)
    plt.close(fig)


def nonlinearity_figure(spec):
    forces = np.linspace(0.1, 1.0, 10)
    rec = ts.simulate(spec, ts.load_series(spec, forces_n=forces), flaws=["nonlinearity"])
    d = fractional_deflection(rec.frames, ts.baseline_from(rec.frames, 5))[:, 4, 0]
    last, _ = rec.last_loaded_frames(4, 0)
    knots = cal.nonlinearity_table(forces, d[last], linear_below=0.5)
    linear = cal.apply_nonlinearity(d[last], *knots)
    print(
        f"nonlinearity: 1 N is {100 * (1 - d[last][-1] / (2 * d[last][4])):.1f} % below the "
        f"line; after the table {100 * (1 - linear[-1] / (2 * linear[4])):.2f} %"
    )
    fig, ax = plt.subplots(figsize=(6, 4), constrained_layout=True)
    ax.plot(forces, 100 * d[last], "o-", label="measured")
    ax.plot(forces, 100 * linear, "s--", label="after the lookup table")
    ax.plot([0, 1], [0, 200 * d[last][4]], "k:", label="line through the 0.5-N response")
    ax.set_xlabel("load [N]")
    ax.set_ylabel("fractional deflection [%]")
    ax.set_title("Force-deflection nonlinearity (cf. Fig. 6)")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    fig.savefig(OUT / "calibration_nonlinearity.png", dpi=110)
    plt.close(fig)


def main() -> None:
    OUT.mkdir(parents=True, exist_ok=True)
    spec = ts.fearing1990_initial()
    calibration = gains_figure(spec)
    thresholds_figure(calibration)
    creep_figure(spec)
    fit_figure(spec)
    nonlinearity_figure(spec)


if __name__ == "__main__":
    main()
