"""Sections 6-7, sampling, aliasing and the interpolated surface: Figs. 19-22."""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np
from scipy.integrate import quad
from scipy.optimize import minimize_scalar

import tactsense as ts
from tactsense.analysis import aliasing as al
from tactsense.estimate.finger.contours import track_contour
from tactsense.estimate.finger.interpolate import surface
from tactsense.geometry import tactel_to_surface
from tactsense.reproduce._common import (
    Claim,
    Context,
    on_array,
)


def fig19_20_aliasing(ctx: Context) -> None:
    d, b = 3.8, 3.8
    s = np.linspace(0, 0.5, 501)
    response = al.normalized_response(s, d, 0.5)
    aliased = al.aliased_spectrum(s, d, b, 0.5)
    best = minimize_scalar(
        lambda f: -al.normalized_response(f, d, 0.5),
        bounds=(0.0, 0.2),
        method="bounded",
        options={"xatol": 1e-9},
    )
    peak = float(best.x)
    xi = float(al.reconstruction_error(d, b, 0.5))
    # the other readings of the printed 0.20 (errata 15): eq. 41 itself instead of its
    # square, and both folded images against the band kept
    above = quad(lambda f: al.normalized_response(f, d, 0.5), 1 / (2 * b), np.inf)[0]
    total = quad(lambda f: al.normalized_response(f, d, 0.5), 0.0, np.inf)[0]
    xi_amplitude = above / total
    xi_folded = float(np.sqrt(2 * xi / (1 - xi)))
    fig, ax = plt.subplots(figsize=(7, 4), constrained_layout=True)
    ax.plot(s, response, label="H(s) / H(0)")
    ax.plot(s, aliased, label="A(s) / H(0)")
    ax.axvline(1 / (2 * b), color="0.5", ls=":", label="1 / 2b")
    ax.set_xlabel("spatial frequency [cycles/mm]")
    ax.set_ylabel("normalized response")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    ctx.save(
        fig,
        19,
        "frequency response H(s) and aliased response A(s)",
        "Eqs. 41 and 44 for d = 3.8 mm.",
        "The same, nu = 0.5.",
        f"H(s) peaks at {peak:.4f} cycles/mm; eq. 45 gives xi = {xi:.3f} (sqrt {np.sqrt(xi):.2f}).",
    )
    positions = np.linspace(-0.5, 0.5, 41)
    pos_err, amp_err = al.interpolation_errors(positions, d, b, 0.5)
    fig, axes = plt.subplots(1, 2, figsize=(10, 4), constrained_layout=True)
    axes[0].plot(positions, pos_err)
    axes[0].set_ylabel("peak position error [tactel]")
    axes[1].plot(positions, 100 * amp_err)
    axes[1].set_ylabel("peak amplitude error [%]")
    for ax in axes:
        ax.set_xlabel("line-load position from a sensor [tactel]")
        ax.grid(alpha=0.3)
    ctx.save(
        fig,
        20,
        "reconstruction error caused by aliasing (b = 3.8 mm)",
        "Windowed-sinc interpolation of seven samples of the plane-stress response to a "
        "point force, against the continuous response.",
        "Eqs. 46-47 on seven samples of eq. 38, nu = 0.5, d = b = 3.8 mm.",
        f"Up to {np.abs(pos_err).max():.2f} tactel in position and "
        f"{100 * np.abs(amp_err).max():.0f} % in amplitude, zero above a sensor.",
    )
    ctx.claims += [
        Claim(
            "frequency_peak_per_mm",
            "the maximum of H(s) occurs at s = 1/(3 pi d)",
            1 / (3 * np.pi * d),
            peak,
            "cycles/mm",
            0.01,
            "Eq. 41 checked against the numerical transform of eq. 38; general form "
            "nu / (pi d (1 + nu)).",
        ),
        Claim(
            "aliasing_xi",
            "eq. 45 evaluated for 3.8-mm depth and spacing: xi ~ 0.20",
            0.20,
            xi,
            "1",
            0.25,
            f"Eq. 45 (an energy ratio) gives {xi:.4f}. Which quantity the printed 0.20 "
            f"is remains a conjecture (errata 15): the square root {np.sqrt(xi):.3f} (RMS "
            f"amplitude ratio), the ratio of the amplitude integrals {xi_amplitude:.3f}, "
            f"or the folded-over RMS against the in-band one {xi_folded:.3f}; none is 0.20.",
        ),
    ]


def fig21_22_surface(ctx: Context) -> None:
    spec = ctx.spec
    soft = ts.soft_object(12.0, 20.0, ts.grams_force(100), length_mm=12.0, width_mm=15.0)
    frame = ts.tactel_deflection(spec, soft)
    first = 1 if spec.array.tip_row else 0
    x = np.linspace(first, spec.shape[0] - 1, 71)
    if spec.closes_circumference:
        # unwrapped around the contact, so that it is one blob and the seam lies opposite
        centre = float(np.argmax(frame.max(axis=0)))
        y = np.linspace(centre - spec.shape[1] / 2, centre + spec.shape[1] / 2, 81)
    else:
        y = np.linspace(0, spec.shape[1] - 1, 81)
    # the cylinder alone is interpolated (uniform rings); the tip row lies 11 mm before
    # row 1, not one spacing, so it is drawn as its samples at their true position
    cylinder = frame.copy()
    cylinder[:first] = 0.0
    values = surface(cylinder, x[:, None], y[None, :], periodic=spec.closes_circumference)
    grid_x, grid_y = np.meshgrid(x, y, indexing="ij")
    axial, _ = tactel_to_surface(spec, grid_x, np.zeros_like(grid_y))
    around = spec.col_angle_deg[0] + spec.array.spacing_angle_deg * grid_y
    fig = plt.figure(figsize=(7, 5))
    ax = fig.add_subplot(projection="3d")
    ax.plot_surface(around, axial, 100 * values, cmap="viridis", linewidth=0)
    if first:
        cols = np.arange(spec.shape[1], dtype=float)
        if spec.closes_circumference:
            cols = np.where(cols < y[0], cols + spec.shape[1], cols)
            cols = np.where(cols > y[-1], cols - spec.shape[1], cols)
        tip_angle = spec.col_angle_deg[0] + spec.array.spacing_angle_deg * cols
        tip_axial = np.full(cols.shape, float(spec.row_axial_mm[0]))
        for a, b, h in zip(tip_angle, tip_axial, 100 * frame[0], strict=True):
            ax.plot([a, a], [b, b], [0, h], color="C3", lw=1)
        ax.scatter(tip_angle, tip_axial, 100 * frame[0], color="C3", s=8, label="tip row")
        ax.legend(fontsize=7)
    ax.set_xlabel("angle around the finger [deg]")
    ax.set_ylabel("along the finger [mm]")
    ax.set_zlabel("deflection [%]")
    gap = float(spec.row_axial_mm[1] - spec.row_axial_mm[0]) if first else 0.0
    ctx.save(
        fig,
        21,
        "interpolated deflection surface",
        "Eq. 48 for a contact with a large soft object (another finger), cylinder and "
        "tip unwrapped onto a plane.",
        "A 100-g soft object 12 x 15 mm on the simulated finger, eq. 48 on the cylinder's "
        "tactels, drawn at the rows' true surface positions"
        + (
            f"; the tip row (red) lies {gap:.1f} mm before row 1, not one "
            f"{spec.array.spacing_axial_mm:g}-mm spacing, and is shown as its samples"
            if first
            else ""
        )
        + ".",
        "A smooth single-peaked surface; the low-pass response keeps it well behaved.",
    )
    rod = ts.rod(12.0, on_array(spec, 90.0), ts.grams_force(100), orientation_deg=45.0)
    frame = ts.tactel_deflection(spec, rod)
    est = ts.locate(frame, spec, counts=False)
    fig, ax = plt.subplots(figsize=(6, 5), constrained_layout=True)
    lines = []
    branches = 0
    for k, share in enumerate((0.2, 0.4, 0.6, 0.8)):
        # an open contour may have a second branch on the other side of the peak (the
        # two edges of a rod across the array): track from both sides, keep both
        found = []
        for toward in (1.0, -1.0):
            try:
                line = track_contour(
                    frame,
                    share * float(est.peak_deflection),
                    est.row,
                    est.col,
                    sensor=spec,
                    periodic=spec.closes_circumference,
                    toward=toward,
                )
            except ValueError:
                continue
            if found and (found[0].closed or _same_line(found[0], line, spec)):
                continue
            found.append(line)
        if not found:
            continue
        lines.append(found[0])
        branches += len(found) - 1
        for j, line in enumerate(found):
            ax.plot(
                line.angle_deg,
                line.axial_mm,
                ".",
                ms=1.5,
                color=f"C{k}",
                label=f"{100 * share:.0f} % of peak" if j == 0 else None,
            )
    ax.plot(est.angle_deg, est.axial_mm, "k+", ms=10, label="peak")
    open_levels = ", ".join(
        f"{100 * line.level / float(est.peak_deflection):.0f} %"
        for line in lines
        if not line.closed
    )
    ax.set_xlabel("angle around the finger [deg]")
    ax.set_ylabel("position along the finger [mm]")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    ctx.save(
        fig,
        22,
        "deflection contours on the 8 x 8 array",
        "Contour tracking (eqs. 49-51) for a rod at 45 deg to the cylinder axis on the "
        "45-deg, 3.8-mm finger.",
        "A 100-g rod at 45 deg on the simulated finger; contours tracked at four levels.",
        f"{sum(line.closed for line in lines)} of {len(lines)} contours close "
        f"({open_levels or 'none'} open: they leave the array"
        + (f"; {branches} of them in two separate branches, both drawn" if branches else "")
        + "); they are elongated along "
        "the rod, and around the "
        "finger the strips resolve the rod's tilt only coarsely, as the paper found.",
    )


def _same_line(first, second, spec) -> bool:
    """Whether two tracked open contours are the same line (the middle point of the
    second lies on the first, within 0.1 tactel)."""
    cols = spec.shape[1]
    mid = len(second.row) // 2
    d_col = first.col - second.col[mid]
    if spec.closes_circumference:
        d_col = (d_col + cols / 2) % cols - cols / 2
    return bool(np.min(np.hypot(first.row - second.row[mid], d_col)) < 0.1)
