"""Section 8, total force: Fig. 26."""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np

import tactsense as ts
from tactsense.estimate.interpolate import surface
from tactsense.reproduce._common import (
    G50,
    MEASURED,
    Claim,
    Context,
    calibration_of,
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
    worst = float(np.abs(errors).max())
    ctx.save(
        fig,
        26,
        "contacts and total contact load",
        "Interpolated profiles for three contact lengths, each 50 g; the integrals "
        "(eqs. 55-56) do not disagree much.",
        "Three soft contacts (3, 8, 16 mm long) on the calibrated simulated finger; "
        "force from the integral of the deflection (docs/estimation.md).",
        f"Force errors {', '.join(f'{e:+.0f} %' for e in errors)}.",
    )
    ctx.claims.append(
        Claim(
            "force_error_pct",
            "pressure (total force) estimation within 20 %",
            20.0,
            worst,
            "%",
            0.15,
            "Worst of the three contact lengths of Fig. 26; the integral is exact for the "
            "linear model, the error is the finite array and the 45-deg sampling.",
            kind="within",
        )
    )
