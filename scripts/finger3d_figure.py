"""3-D finger (FEM) against the paper's 2-D plane-stress model: figure and numbers.

Run: ``PYTHONPATH=src python scripts/finger3d_figure.py [--level 1]``. Writes
``docs/images/finger3d_vs_2d.png`` and prints the numbers quoted in docs/model.md.
"""

from __future__ import annotations

import argparse
import json

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
from scipy.optimize import least_squares

from tactsense.physics import finger3d, halfplane

E = finger3d.YOUNGS_PA


def shape_2d(x, depth, nu):
    """Plane-stress line-load profile normalised to its peak (eq. 7 of the paper)."""
    h = halfplane.impulse_response(x, depth, youngs_modulus=E, poisson_ratio=nu)
    return h / np.abs(h).max()


def shape_free(x, depth, nu):
    """The same shape, z (z^2 - nu x^2) / (x^2 + z^2)^2, for any nu (the fit's range).

    Plane stress with nu* = nu / (1 - nu) is plane strain with nu, so a 3-D skin of
    nu = 0.49 may look like plane stress with nu* up to 0.96: the fit allows nu < 1.
    """
    h = -depth * (depth**2 - nu * x**2) / (x**2 + depth**2) ** 2
    return h / np.abs(h).max()


def fit_2d(x, profile):
    """Least-squares depth [m] and nu after amplitude normalisation (section 4.1)."""
    target = profile / np.abs(profile).max()

    def resid(p):
        return shape_free(x, p[0] * 1e-3, p[1]) - target

    grid = [(d, n) for d in np.linspace(1.0, 8.0, 29) for n in np.linspace(-0.5, 0.95, 30)]
    start = min(grid, key=lambda p: float(np.sum(resid(p) ** 2)))
    fit = least_squares(resid, start, bounds=([0.5, -0.99], [12.0, 0.99]))
    rms = float(np.sqrt(np.mean(fit.fun**2)))
    return fit.x[0] * 1e-3, float(fit.x[1]), rms


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--level", type=int, default=1, help="mesh level of finger3d.LEVELS")
    parser.add_argument("--out", default="docs/images/finger3d_vs_2d.png")
    parser.add_argument("--poisson-study", action="store_true", help="also nu 0.45/0.48/0.49")
    args = parser.parse_args(argv)
    spec = finger3d.LEVELS[args.level]

    xs = np.linspace(0.0, 12e-3, 49)
    x_full = np.concatenate([-xs[:0:-1], xs])
    knife = finger3d.solve_load(finger3d.knife_edge(), 0.5, spec=spec)
    along = knife.radial_strain(xs, 0 * xs)
    along_full = np.concatenate([along[:0:-1], along])
    depth, nu, rms = fit_2d(x_full, along_full)
    preset = shape_2d(x_full, 3.8e-3, 0.4)
    target = along_full / np.abs(along_full).max()
    rms_preset = float(np.sqrt(np.mean((preset - target) ** 2)))
    ring = shape_2d(x_full, 3.2e-3, 0.5)
    rms_ring = float(np.sqrt(np.mean((ring - target) ** 2)))
    band = finger3d.solve_load(
        finger3d.knife_edge(half_arc_m=np.pi / 2 * finger3d.OUTER_M), 0.5, spec=spec
    )
    along_band = band.radial_strain(xs, 0 * xs)
    band_full = np.concatenate([along_band[:0:-1], along_band])
    depth_b, nu_b, rms_b = fit_2d(x_full, band_full)
    rms_preset_b = float(np.sqrt(np.mean((preset - band_full / np.abs(band_full).max()) ** 2)))

    probe_p, contact = finger3d.hertz_probe()
    probe = finger3d.solve_load(probe_p, 0.05 * 9.80665, spec=spec)
    thetas = np.linspace(0.0, np.pi / 2, 46)
    around = probe.radial_strain(0 * thetas, thetas)
    probe_along = probe.radial_strain(xs, 0 * xs)
    arc = (finger3d.OUTER_M - finger3d.RING_DEPTH_M) * thetas

    def half_width(x, y):
        y = np.abs(y) / np.abs(y).max()
        return float(np.interp(0.5, y[::-1], x[::-1]))

    numbers = {
        "level": args.level,
        "knife_peak_strain": float(along[0]),
        "fit_depth_mm": depth * 1e3,
        "fit_nu": nu,
        "fit_rms_pct_of_peak": 100 * rms,
        "preset_3p8mm_nu0p4_rms_pct_of_peak": 100 * rms_preset,
        "ring_depth_3p2mm_nu0p5_rms_pct_of_peak": 100 * rms_ring,
        "band_peak_strain": float(along_band[0]),
        "band_fit_depth_mm": depth_b * 1e3,
        "band_fit_nu": nu_b,
        "band_fit_rms_pct_of_peak": 100 * rms_b,
        "band_preset_rms_pct_of_peak": 100 * rms_preset_b,
        "probe_peak_strain": float(probe_along[0]),
        "probe_half_width_along_mm": 1e3 * half_width(xs, probe_along),
        "probe_half_width_around_mm_at_ring": 1e3 * half_width(arc, around),
        "probe_contact_radius_mm": contact * 1e3,
    }
    if args.poisson_study:
        for nu_3d in (0.45, 0.48, 0.49):
            sol = finger3d.solve_load(probe_p, 0.05 * 9.80665, spec=spec, poisson_ratio=nu_3d)
            numbers[f"probe_peak_strain_nu{nu_3d}"] = float(sol.radial_strain(0.0, 0.0))
    print(json.dumps(numbers, indent=1))

    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(10, 4))
    ax1.plot(x_full * 1e3, target, "k.", label="3-D FEM, knife edge 0.5 N")
    ax1.plot(x_full * 1e3, preset, "b-", label="2-D plane stress d=3.8 mm, nu=0.4")
    ax1.plot(
        x_full * 1e3,
        shape_free(x_full, depth, nu),
        "r--",
        label=f"2-D fit d={depth * 1e3:.2f} mm, nu={nu:.2f}",
    )
    ax1.plot(x_full * 1e3, ring, "g:", label="2-D plane stress d=3.2 mm, nu=0.5")
    ax1.plot(
        x_full * 1e3,
        band_full / np.abs(band_full).max(),
        "m.",
        ms=3,
        label=f"3-D, load band over the upper half (fit d={depth_b * 1e3:.2f}, nu={nu_b:.2f})",
    )
    ax1.set_xlabel("load offset along the finger [mm]")
    ax1.set_ylabel("radial strain at 3.2 mm depth / peak")
    ax1.legend(fontsize=7)
    ax2.plot(xs * 1e3, probe_along / np.abs(probe_along).max(), "k-", label="along (x)")
    ax2.plot(arc * 1e3, around / np.abs(around).max(), "r-", label="around (arc at ring radius)")
    ax2.set_xlabel("distance from the 50 g probe [mm]")
    ax2.set_ylabel("radial strain / peak")
    ax2.legend(fontsize=7)
    ax2.set_title("3-D FEM, probe: along vs around")
    fig.tight_layout()
    fig.savefig(args.out, dpi=110)


if __name__ == "__main__":
    main()
