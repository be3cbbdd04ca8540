"""Sections 3.5-3.6, the array around the finger and under the tip: Figs. 13-14."""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np

import tactsense as ts
from tactsense.reproduce._common import (
    MEASURED,
    Context,
    recording_deflection,
)


def fig13_around(ctx: Context) -> None:
    spec = ctx.spec
    increment = 3.0 if not ctx.quick else 9.0
    scene = ts.probe_sweep(
        spec,
        along="around",
        row=4,
        start=-90,
        stop=135,
        increment=increment,
        dwell_s=0.5,
        lift_s=0.3,
    )
    rec = ts.simulate(spec, scene, flaws=MEASURED, rng=6)
    d = recording_deflection(rec)
    fig, ax = plt.subplots(figsize=(7, 4), constrained_layout=True)
    for col in (0, 1, 2):
        last, last_step = rec.last_loaded_frames(4, col)
        ax.plot(
            rec.truth["step_angle_deg"][last_step],
            100 * d[last, 4, col],
            ".-",
            label=f"col {col} ({spec.col_angle_deg[col]:.0f} deg)",
        )
    ax.set_xlabel("probe angle around the finger [deg]")
    ax.set_ylabel("fractional deflection [%]")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    ctx.save(
        fig,
        13,
        "response around the circumference for a moving probe",
        "A probe applied normally at 3-deg intervals around the 45-deg finger; three cells.",
        "The same on row 4 of the simulated finger.",
        "Each cell's response falls to zero about one strip (45 deg) away, the ring "
        "spreading of docs/model.md; neighbours overlap less than along the finger.",
    )


def fig14_tip(ctx: Context) -> None:
    spec = ctx.spec
    start = -np.pi * spec.radius_mm / 2 + 0.5
    increment = 0.6 if not ctx.quick else 1.5
    scene = ts.probe_sweep(
        spec,
        along="axial",
        col=0,
        start=start,
        stop=6.0,
        increment=increment,
        dwell_s=0.5,
        lift_s=0.3,
    )
    rec = ts.simulate(spec, scene, flaws=MEASURED, rng=7)
    d = recording_deflection(rec)
    fig, ax = plt.subplots(figsize=(7, 4), constrained_layout=True)
    for row in (0, 1):
        last, last_step = rec.last_loaded_frames(row, 0)
        ax.plot(
            rec.truth["step_axial_mm"][last_step],
            100 * d[last, row, 0],
            ".-",
            label=f"row {row}" + (" (tip)" if row == 0 else ""),
        )
    ax.axvline(0, color="0.5", lw=0.8)
    ax.set_xlabel("probe arc position from the cylinder junction [mm] (negative: tip)")
    ax.set_ylabel("fractional deflection [%]")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    ctx.save(
        fig,
        14,
        "responses for a probe moved normal to the tip",
        "A probe normal to the hemispherical tip, two elements.",
        "A probe stepped along a meridian from the apex onto the cylinder; tip row and "
        "first ring. The tip model is crude (docs/model.md): an effective depth of 6 mm.",
        "The tip row responds under the hemisphere and the first ring near the junction; "
        "the paper gives no numbers to compare.",
    )
