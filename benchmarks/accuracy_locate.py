"""Accuracy of tactsense.locate against the paper's figures (docs/accuracy.md).

Run: ``python benchmarks/accuracy_locate.py``. For both finger designs a 3-mm probe is
placed at 200 random positions in the interior of the cylinder (rows 2-6) and, for the
position table, stepped through one tactel in 0.1-tactel increments; each placement is
held for 3 frames at 7 Hz with quantization, read noise and the balance-beam jitter of
Figs. 10-11 switched on (no gain spread: calibration is a separate step). Errors are
against the load actually applied (jitter included), on the last frame of each hold.
"""

from __future__ import annotations

import numpy as np

import tactsense as ts
from tactsense.geometry import wrap_angle_deg

FLAWS = ["noise", "quantization", "jitter"]


def run(spec, positions, grams, rng=0):
    force = ts.grams_force(grams)
    steps = [ts.Step((), 1.0, "baseline")]
    steps += [ts.Step((ts.Probe(a, b, force),), 3 / 7, "") for a, b in positions]
    rec = ts.simulate(spec, ts.Scenario(tuple(steps)), flaws=FLAWS, rng=rng)
    est = ts.locate(rec.frames, spec, baseline=ts.baseline_from(rec.frames, 5), threshold=0.002)
    step = rec.truth["frame_step"]
    last = np.flatnonzero((step > 0) & np.r_[step[1:] != step[:-1], True])
    s = step[last]
    d_axial = est.axial_mm[last] - rec.truth["step_axial_mm"][s]
    d_angle = wrap_angle_deg(est.angle_deg[last] - rec.truth["step_angle_deg"][s])
    d_force = est.force_n[last] / rec.truth["step_force_n"][s] - 1
    return d_axial, d_angle, d_force, est.iterations[last]


def stats(values):
    values = np.abs(values)
    return f"{np.nanmean(values):.3g} / {np.nanmax(values):.3g}"


def main() -> None:
    rng = np.random.default_rng(0)
    print("## Against load (200 random interior positions; mean / worst |error|)\n")
    print(
        "| finger | load | along [mm] | along [tactel] | around [deg] | around [tactel] "
        "| force [%] | Newton steps (median) |"
    )
    print("|---|---|---|---|---|---|---|---|")
    for name in ("initial", "improved"):
        spec = ts.preset(name)
        axial = rng.uniform(spec.row_axial_mm[2], spec.row_axial_mm[6], 200)
        if spec.closes_circumference:
            angle = rng.uniform(-180, 180, 200)
        else:
            angle = rng.uniform(spec.col_angle_deg[1], spec.col_angle_deg[-2], 200)
        positions = list(zip(axial, angle, strict=True))
        for grams in (10, 50, 100, 200):
            da, dg, df, it = run(spec, positions, grams)
            b, phi = spec.array.spacing_axial_mm, spec.array.spacing_angle_deg
            print(
                f"| {name} | {grams} g | {stats(da)} | {stats(da / b)} | {stats(dg)} "
                f"| {stats(dg / phi)} | {stats(100 * df)} | {np.median(it):.0f} |"
            )
    print("\n## Against position within a tactel (50 g; worst |error| over the other axis)\n")
    print("| finger | offset [tactel] | along [mm] | around [deg] | force [%] |")
    print("|---|---|---|---|---|")
    for name in ("initial", "improved"):
        spec = ts.preset(name)
        b, phi = spec.array.spacing_axial_mm, spec.array.spacing_angle_deg
        centre_col = spec.col_angle_deg[spec.shape[1] // 2 - 1]
        for frac in np.arange(0, 1.01, 0.25):
            others = np.linspace(0, 1, 5, endpoint=False)
            along = [(spec.row_axial_mm[4] + frac * b, centre_col + o * phi) for o in others]
            around = [(spec.row_axial_mm[4] + o * b, centre_col + frac * phi) for o in others]
            da, _, df_a, _ = run(spec, along, 50)
            _, dg, df_g, _ = run(spec, around, 50)
            print(
                f"| {name} | {frac:.2f} | {np.abs(da).max():.3g} | {np.abs(dg).max():.3g} "
                f"| {100 * np.abs(np.r_[df_a, df_g]).max():.3g} |"
            )


if __name__ == "__main__":
    main()
