"""Section 8, total force: Fig. 26."""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np

import tactsense as ts
from tactsense.estimate.finger.interpolate import surface
from tactsense.reproduce._common import (
    G50,
    MEASURED,
    Claim,
    Context,
    calibration_of,
    centre_col,
)


def fig26_force(ctx: Context) -> None:
    spec = ctx.spec
    calibration = calibration_of(ctx)
    lengths = (3.0, 8.0, 16.0)
    fig, ax = plt.subplots(figsize=(7, 4), constrained_layout=True)
    errors = []
    x = np.linspace(1, spec.shape[0] - 1, 200)
    axial = np.interp(x, np.arange(spec.shape[0]), spec.row_axial_mm)
    for k, length in enumerate(lengths):
        contact = ts.soft_object(spec.row_axial_mm[4], 10.0, G50, length_mm=length, width_mm=6.0)
        rec = ts.simulate(spec, ts.static([contact], 1.0), flaws=MEASURED, rng=30 + k)
        est = ts.locate(rec.frames[-1:], spec, calibration=calibration)
        deflection, _ = calibration.apply(rec.frames[-1:], spec)
        errors.append(100 * (float(est.force_n[0]) / rec.truth["step_force_n"][1] - 1))
        profile = surface(deflection[0], x, est.col[0], periodic=spec.closes_circumference)
        ax.plot(axial, 100 * profile, label=f"{length:.0f} mm: force {est.force_n[0]:.3f} N")
    ax.set_xlabel("position along the finger [mm]")
    ax.set_ylabel("interpolated deflection [%]")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, title="contact length (50 g)")
    # the same contacts at angles across one column spacing: the force error depends on
    # where the contact falls between strips (docs/accuracy.md)
    spacing = spec.array.spacing_angle_deg
    offsets = np.linspace(0.0, spacing, ctx.n(9, 4))
    start = spec.col_angle_deg[centre_col(spec)]
    spread = np.zeros((len(lengths), offsets.size))
    for k, length in enumerate(lengths):
        for j, offset in enumerate(offsets):
            contact = ts.soft_object(
                spec.row_axial_mm[4], start + offset, G50, length_mm=length, width_mm=6.0
            )
            rec = ts.simulate(spec, ts.static([contact], 1.0), flaws=MEASURED, rng=40 + j)
            est = ts.locate(rec.frames[-1:], spec, calibration=calibration)
            spread[k, j] = 100 * (float(est.force_n[0]) / rec.truth["step_force_n"][1] - 1)
    inset = ax.inset_axes([0.08, 0.5, 0.27, 0.4])
    for k in range(len(lengths)):
        inset.plot(offsets / spacing, spread[k], ".-", lw=0.8)
    inset.axhline(0, color="k", lw=0.5)
    inset.set_xlabel("angle from a strip [spacing]", fontsize=6)
    inset.set_ylabel("force error [%]", fontsize=6)
    inset.tick_params(labelsize=6)
    worst = float(max(np.abs(errors).max(), np.abs(spread).max()))
    ctx.save(
        fig,
        26,
        "contacts and total contact load",
        "Interpolated profiles for three contact lengths, each 50 g; the integrals "
        "(eqs. 55-56) do not disagree much.",
        "Three soft contacts (3, 8, 16 mm long) on the calibrated simulated finger; "
        "force from the integral of the deflection (docs/estimation.md).",
        f"Force errors {', '.join(f'{e:+.0f} %' for e in errors)} at 10 deg; over angles "
        f"across one strip spacing (inset) from {spread.min():+.0f} to {spread.max():+.0f} %.",
    )
    ctx.claims.append(
        Claim(
            "force_error_pct",
            "pressure (total force) estimation within 20 %",
            20.0,
            worst,
            "%",
            0.15,
            "Worst over the three contact lengths of Fig. 26 and over contact angles across "
            "one strip spacing; the integral is exact for the linear model, the error is the "
            "finite array and the sampling around the finger. The force conversion (force "
            "per summed deflection) is calibrated on the twin's own model "
            "(estimate.force.force_per_deflection), so a finger unlike the twin would add "
            "its model error (robustness study).",
            kind="within",
        )
    )
