"""Issue 34 items 1 and 3: the joint pad fit's efficiency against the bound, with noise
(``tactsense.analysis.pad_efficiency``); writes the block ``<!-- pad-efficiency
(r9-padbounds) -->`` of docs/accuracy.md. ``tests/analysis/test_pad_efficiency.py``
checks that the block's verdicts are its numbers'.

    PYTHONPATH=src python scripts/pad_efficiency_numbers.py            # all, write
    PYTHONPATH=src python scripts/pad_efficiency_numbers.py --frames 20 --no-write

How: per pad (pad4, pad16, pad12x32, and pad16 under a 6-mm layer read 4 mm deep),
per read noise (the preset's, 1 and 2 % of the converter's full scale) and per
placement (a 50-g, 3.2-mm sphere a quarter and a half pitch off the middle taxel along
both axes), ``FRAMES`` frames from the Hankel truth with fresh noise each, estimated by
``find_contacts(method="joint")`` as it is in this tree. A few minutes on one core.
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "scripts"))

import numpy as np  # noqa: E402
from docblock import replace_block  # noqa: E402
from scipy import special  # noqa: E402

from tactsense.analysis import pad_censored as pc  # noqa: E402
from tactsense.analysis import pad_efficiency as pe  # noqa: E402
from tactsense.kinds import kind_of  # noqa: E402
from tactsense.physics.contact import grams_force  # noqa: E402
from tactsense.sensor.registry import load_sensor  # noqa: E402

ZBEGIN = "<!-- pad-zivzakai (r9-padbounds) -->"
ZEND = "<!-- /pad-zivzakai (r9-padbounds) -->"
ZZ_CASES = (("pad16", 1.0), ("pad16", 2.0), ("pad12x32", 1.0))
ZZ_DRAWS = 1500
MBEGIN = "<!-- pad-mlthreshold (r9-padbounds) -->"
MEND = "<!-- /pad-mlthreshold (r9-padbounds) -->"
ML_NOISE = 50.0
ML_FRAMES = (1, 4, 16, 64)
ML_DRAWS = 400
BEGIN = "<!-- pad-efficiency (r9-padbounds) -->"
END = "<!-- /pad-efficiency (r9-padbounds) -->"
FRAMES = 100
NOISES = (None, 0.01, 0.02)
OFFSETS = (0.25, 0.5)
THICK = "pad16, 6-mm layer"
FORCE_N = grams_force(50.0)


def pads():
    """(label, spec) of the pads measured."""
    out = [(name, load_sensor(name)) for name in ("pad4", "pad16", "pad12x32")]
    thick = load_sensor("pad16").replace(layer__thickness_mm=6.0, layer__sensing_depth_mm=4.0)
    out.append((THICK, thick))
    return out


def _num(value: float, scale: float = 1.0, fmt: str = ".3g") -> str:
    if not math.isfinite(value):
        return "singular" if value == math.inf else "-"
    return f"{scale * value:{fmt}}"


def row_line(r: pe.EfficiencyRow) -> str:
    verdict = "met" if r.met else "missed"
    mark = "" if r.sized_bound_finite else " (known)"
    return (
        f"| {r.pad} | {r.noise_label} ({r.noise_counts:.3g}) | {r.offset_pitch:g} "
        f"| {r.found_pct:.0f} % | {_num(r.position_rms_mm, 1e3)} "
        f"| {_num(r.bound_position_mm, 1e3)} / {_num(r.sized_position_mm, 1e3)} "
        f"| **{_num(r.position_efficiency, fmt='.2f')}**{mark} "
        f"| {_num(r.force_rms, 100)} | {_num(r.bound_force, 100)} / {_num(r.sized_force, 100)} "
        f"| **{_num(r.force_efficiency, fmt='.2f')}**{mark} "
        f"| {_num(r.position_bias, fmt='.2f')} / {_num(r.force_bias, fmt='.2f')} "
        f"| {_num(r.censored_ratio, fmt='.3f')} | {verdict} |"
    )


def table(rows) -> str:
    header = (
        "| pad | noise [counts] | offset [pitch] | one contact found | position RMS [um] "
        "| bound: indenter known / size unknown [um] | efficiency | force RMS [%] "
        "| bound: known / size unknown [%] | efficiency "
        "| bias: position / force [bound] | censored / classic | goal |\n|" + "---|" * 13
    )
    met = sum(r.met for r in rows)
    noisy = [r for r in rows if r.noise_label != "preset"]
    found = [r.found_pct for r in noisy]
    lines = [header, *(row_line(r) for r in rows), ""]
    lines.append(
        f"Goal (one contact in at least {pe.FOUND_GOAL_PCT:g} % of frames, position and "
        f"force RMS within {pe.EFFICIENCY_GOAL:g}x the bound) met in **{met} of "
        f"{len(rows)} rows** ({sum(r.met for r in noisy)} of {len(noisy)} with 1-2 % of "
        f"full scale); with 1-2 % of full scale one contact is found in "
        f"{min(found):.0f}-{max(found):.0f} % of frames. {rows[0].frames} frames a "
        f"row: an RMS is good to about {100 / (2 * rows[0].frames) ** 0.5:.0f} %."
    )
    return "\n".join(lines)


def posterior_mean_mse(spec, noise, draws=ZZ_DRAWS, seed=5) -> float:
    """Mean square error [mm^2] of the posterior mean of x (the sphere random over the
    middle taxel's cell, cos^2 prior, y and the force known) over ``draws`` censored
    frames, the posterior by direct numerical integration on the Ziv-Zakai bound's
    grid of positions."""
    g = spec.grid
    r, c = g.rows // 2, g.cols // 2
    sigma = np.sqrt(pc.noise_variance(spec, noise))
    rest, _, _ = pc.rest_and_slope(spec)
    u = np.linspace(-0.5, 0.5, pc.ZZ_POINTS) * g.row_pitch_mm
    mus = np.array(
        [pc._latent(spec, ((r * g.row_pitch_mm) + v, c * g.col_pitch_mm, FORCE_N), 1.6)
         for v in u]
    )  # fmt: skip
    prior = np.cos(np.pi * u / g.row_pitch_mm) ** 2
    prior /= prior.sum()
    rng = np.random.default_rng(seed)
    errors = np.empty(draws)
    for n in range(draws):
        k = rng.choice(u.size, p=prior)
        y = np.maximum(mus[k] + sigma * rng.standard_normal(mus.shape[1]), rest)
        loglik = np.where(
            y <= rest, special.log_ndtr((rest - mus) / sigma), -0.5 * ((y - mus) / sigma) ** 2
        ).sum(axis=1)
        post = prior * np.exp(loglik - loglik.max())
        errors[n] = np.sum(post * u) / post.sum() - u[k]
    return float(np.mean(errors**2))


def van_trees_x(spec, noise, nodes=16) -> float:
    """Van Trees bound on x alone [mm^2]: ``1 / (E[J_xx] + J_prior)``, the prior mean by
    Gauss-Legendre over the cell (y and the force known)."""
    g = spec.grid
    r, c = g.rows // 2, g.cols // 2
    u, w = np.polynomial.legendre.leggauss(nodes)
    w = w * np.cos(0.5 * np.pi * u) ** 2
    w /= w.sum()
    jxx = 0.0
    for ui, wi in zip(u, w, strict=True):
        a = pc.whitened_jacobian(
            spec, (r + 0.5 * ui) * g.row_pitch_mm, c * g.col_pitch_mm, FORCE_N,
            noise_counts=noise,
        )  # fmt: skip
        jxx += wi * float(a[:, 0] @ a[:, 0])
    return 1.0 / (jxx + pc.cell_prior_information(g.row_pitch_mm))


def zz_table() -> str:
    lines = [
        "| pad | noise [counts] | prior RMS [um] | Van Trees [um] | Ziv-Zakai [um] "
        "| posterior mean RMS error [um] | error / Van Trees | error / Ziv-Zakai |",
        "|---|---|---|---|---|---|---|---|",
    ]
    ratios_vt, ratios_zz = [], []
    for name, pct in ZZ_CASES:
        spec = load_sensor(name)
        noise = pc.noise_from_full_scale(spec, pct)
        zz = pc.ziv_zakai_bound(spec, FORCE_N, noise_counts=noise)
        vt = van_trees_x(spec, noise)
        mse = posterior_mean_mse(spec, noise)
        lines.append(
            f"| {name} | {pct:g} % FS ({noise:.3g}) | {1e3 * zz['prior_rms_mm']:.0f} "
            f"| {1e3 * vt**0.5:.1f} | {1e3 * zz['rms_mm']:.1f} | {1e3 * mse**0.5:.1f} "
            f"| {(mse / vt) ** 0.5:.2f} ({mse / vt:.1f} in MSE) "
            f"| {(mse / zz['mse_mm2']) ** 0.5:.2f} ({mse / zz['mse_mm2']:.1f} in MSE) |"
        )
        print(lines[-1], flush=True)
        ratios_vt.append((mse / vt) ** 0.5)
        ratios_zz.append((mse / zz["mse_mm2"]) ** 0.5)
    lines += [
        "",
        f"The best estimator's RMS error lies {min(ratios_zz):.1f}-{max(ratios_zz):.1f} "
        f"times above the Ziv-Zakai bound, and {min(ratios_vt):.1f}-{max(ratios_vt):.1f} "
        "times above Van Trees'.",
    ]
    return "\n".join(lines)


def ml_threshold(seed: int = 2) -> str:
    """The censored maximum-likelihood fit of x alone (y and the force known) on pad16,
    50 g a tenth of a pitch off the middle taxel, 50 counts, from K frames: its spread,
    bias and RMS over the bound (``J_xx^-1/2 / sqrt(K)``), the share of fits on the far
    side of the taxel's centre, and how far the mirror position's frames lie from the
    true ones in noise units (``sqrt(-8 K ln rho)``, ``rho`` the Bhattacharyya
    coefficient of one censored frame's distributions: ``sqrt(K) |mu - mu'| / sigma``
    for Gaussian frames). ML on a 501-point
    grid of x over one pitch (exact censored likelihood), refined by a parabola."""
    spec = load_sensor("pad16")
    g = spec.grid
    r, c = g.rows // 2, g.cols // 2
    x0, y0 = (r + 0.1) * g.row_pitch_mm, c * g.col_pitch_mm
    sigma = np.sqrt(pc.noise_variance(spec, ML_NOISE))
    rest, _, _ = pc.rest_and_slope(spec)
    grid = x0 + np.linspace(-0.5, 0.5, 501) * g.row_pitch_mm
    mus = np.array([pc._latent(spec, (x, y0, FORCE_N), 1.6) for x in grid])
    mu0 = mus[250]
    a = pc.whitened_jacobian(spec, x0, y0, FORCE_N, noise_counts=ML_NOISE)
    bound = 1.0 / np.sqrt(a[:, 0] @ a[:, 0])
    centre = r * g.row_pitch_mm
    mirror = pc._latent(spec, (2 * centre - x0, y0, FORCE_N), 1.6)
    # the Bhattacharyya distance of the two censored frames' distributions, as a length
    # in noise units (sqrt(-8 ln rho): the means' distance over sigma for Gaussians)
    mirror_d = float(np.sqrt(-8.0 * pc._log_bhattacharyya(mu0, mirror, rest, sigma, True)))
    rng = np.random.default_rng(seed)
    lines = [
        "| frames K | bound / sqrt(K) [um] | ML spread / bound | bias / bound | RMS / bound "
        "| fits past the taxel's centre | mirror distance [noise units] |",
        "|---|---|---|---|---|---|---|",
    ]
    h = grid[1] - grid[0]
    for k in ML_FRAMES:
        est = np.empty(ML_DRAWS)
        for n in range(ML_DRAWS):
            frames = np.maximum(mu0 + sigma * rng.standard_normal((k, mu0.size)), rest)
            ll = np.zeros(grid.size)
            for f in frames:
                ll += np.where(
                    f <= rest,
                    special.log_ndtr((rest - mus) / sigma),
                    -0.5 * ((f - mus) / sigma) ** 2,
                ).sum(axis=1)
            i = int(np.clip(np.argmax(ll), 1, grid.size - 2))
            curv = ll[i - 1] - 2 * ll[i] + ll[i + 1]
            step = 0.5 * (ll[i - 1] - ll[i + 1]) / curv if curv < 0 else 0.0
            est[n] = grid[i] + step * h - x0
        b = bound / np.sqrt(k)
        lines.append(
            f"| {k} | {1e3 * b:.1f} | {est.std(ddof=1) / b:.2f} | {est.mean() / b:.2f} "
            f"| {np.sqrt(np.mean(est**2)) / b:.2f} | {100 * np.mean(est + x0 < centre):.0f} % "
            f"| {np.sqrt(k) * mirror_d:.1f} |"
        )
        print(lines[-1], flush=True)
    return "\n".join(lines)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--frames", type=int, default=FRAMES, help="frames per row (>= 2)")
    parser.add_argument("--no-write", action="store_true", help="print, do not write the doc")
    parser.add_argument(
        "--only", choices=("efficiency", "zivzakai", "mlthreshold"), help="one block only"
    )
    args = parser.parse_args()
    if args.frames < 2:
        raise SystemExit("--frames must be at least 2")
    if args.only in (None, "mlthreshold"):
        mblock = (
            f"{MBEGIN}\n<!-- generated by scripts/pad_efficiency_numbers.py: do not edit by "
            f"hand -->\n{ml_threshold()}\n{MEND}"
        )
        print(mblock)
        if not args.no_write:
            replace_block(ROOT / "docs" / "accuracy.md", MBEGIN, MEND, mblock)
    if args.only == "mlthreshold":
        return
    if args.only != "efficiency":
        zblock = (
            f"{ZBEGIN}\n<!-- generated by scripts/pad_efficiency_numbers.py: do not edit by "
            f"hand -->\n{zz_table()}\n{ZEND}"
        )
        print(zblock)
        if not args.no_write:
            replace_block(ROOT / "docs" / "accuracy.md", ZBEGIN, ZEND, zblock)
    if args.only == "zivzakai":
        return
    rows = []
    for label, spec in pads():
        kind_of(spec).contact_model(spec)  # the fit's table, built once
        for noise in NOISES:
            for offset in OFFSETS:
                t0 = time.perf_counter()
                r = pe.efficiency_row(
                    spec, noise_fs=noise, offset_pitch=offset, n_frames=args.frames,
                    seed=34, label=label,
                )  # fmt: skip
                rows.append(r)
                print(row_line(r), f"{time.perf_counter() - t0:.0f} s", flush=True)
    block = (
        f"{BEGIN}\n<!-- generated by scripts/pad_efficiency_numbers.py: do not edit by "
        f"hand -->\n{table(rows)}\n{END}"
    )
    print(block)
    if not args.no_write:
        replace_block(ROOT / "docs" / "accuracy.md", BEGIN, END, block)


if __name__ == "__main__":
    main()
