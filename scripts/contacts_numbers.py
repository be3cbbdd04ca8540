"""The numbers and the figure of docs/contacts.md: the two-contact resolution limit of every
pad preset and the paper's finger, position and force errors against separation beside
the Cramer-Rao bound, and single-contact accuracy of the three position methods.

Run: ``python scripts/contacts_numbers.py`` prints the Markdown blocks that
docs/contacts.md and docs/accuracy.md hold (``tests/estimate/test_contacts_doc.py``
checks that they do) and writes ``docs/images/contacts_resolution.png``;
``python scripts/contacts_numbers.py --accuracy`` writes docs/accuracy.md's block.

How the numbers are made (all seeded, so a run repeats them):

* **Frames**: the twin (``tactsense.simulate``) with read noise and quantization only
  (``FLAWS``): no gain spread (a calibrated array), no creep, no jitter, so the errors
  are those of the estimators at the noise limit. Each placement is held three scans
  and the last is used (a scan samples the taxels in turn).
* **Two contacts**: two equal 1.6-mm spheres of 50 g each, ``s`` apart along the
  columns (y; along the finger's axis for the finger), their midpoint at
  ``RESOLUTION_PHASES`` sub-taxel offsets from the middle of the array, evenly spread
  over one pitch and including the middle itself (the pair symmetric about a line
  between two taxels, the hardest to part). Placements seen as one contact give the
  merged contact's force against the pair's summed force. A frame *resolves* them when
  :func:`~tactsense.estimate.contacts.find_contacts` reports exactly two contacts; the
  resolution limit is the smallest separation from which on at least 90 % of
  placements do. Errors: each true contact matched to the nearer estimate.
* **Cramer-Rao bound** (two contacts): the Fisher information of the noise-free
  response ``F1 k(p1) + F2 k(p2)`` (six parameters: two positions, two forces) under
  independent Gaussian noise of the readings (read noise and quantization, in the
  signal's units), with ``k`` the twin's response to one sphere (central differences of
  noise-free simulations, step 0.05 mm); the bound on one contact's y position.
* **One contact**: 100 random positions inside the array (a taxel from the edge), 50 g;
  errors of the windowed-sinc interpolation, the centre of pressure and the
  model-based fit (pads), in taxels and percent of force.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

import tactsense as ts
from tactsense.analysis.pad_bound import rank_test
from tactsense.estimate.contacts import find_contacts
from tactsense.physics.contact import grams_force
from tactsense.physics.indenters import SphereProbe
from tactsense.simulate import Scenario, Step

FLAWS = ["noise", "quantization"]
PADS = ("pad4", "pad16", "pad12x32")
PHASES = 6
RESOLUTION_PHASES = 24
SEPARATIONS_TAXEL = np.round(np.arange(0.6, 4.01, 0.2), 2)
FORCE_N = grams_force(50.0)
ROOT = Path(__file__).resolve().parents[1]


def _pitch(spec) -> float:
    """Spacing along the separation [mm]: columns (y) on a pad, rings on the finger."""
    return spec.grid.col_pitch_mm if spec.kind == "pad" else float(np.diff(spec.row_axial_mm)[1])


def _probe(spec, along_mm: float, across_mm: float, force_n: float = FORCE_N):
    if spec.kind == "pad":
        return SphereProbe(across_mm, along_mm, force_n)
    return ts.Probe(along_mm, across_mm, force_n)


def _middle(spec) -> tuple[float, float]:
    if spec.kind == "pad":
        g = spec.grid
        return 0.5 * (g.cols - 1) * g.col_pitch_mm, 0.5 * (g.rows - 1) * g.row_pitch_mm
    # the finger: the middle of the cylinder's rings, between two columns' angles
    rings = spec.row_axial_mm[1:]  # row 0 is the tip's
    return float(np.mean(rings)), 0.5 * float(spec.col_angle_deg[0] + spec.col_angle_deg[1])


def _frames(spec, placements, rng):
    """The last of three scans of each placement (a tuple of probes; a scan samples the
    taxels one after another, so the first scan of a placement mixes it with the one
    before), after half a second untouched."""
    period = spec.scan_period_s
    steps = [Step((), 0.5, "baseline")]
    steps += [Step(tuple(p), 3 * period, "") for p in placements]
    rec = ts.simulate(spec, Scenario(tuple(steps)), flaws=FLAWS, rng=rng)
    step = rec.truth["frame_step"]
    last = np.flatnonzero((step > 0) & np.r_[step[1:] != step[:-1], True])
    base = np.median(rec.frames[: int(0.4 / period)].astype(float), axis=0)
    return rec.frames[last], base


def _noise_sigma(spec) -> float:
    """Standard deviation of one reading in the signal's units [-]: read noise and
    quantization [counts] over counts per unit strain (resistive) or over the untouched
    reading (capacitive: eq. 4 at small deflection)."""
    counts = float(np.sqrt(spec.flaws.read_noise_counts**2 + 1.0 / 12.0))
    if spec.kind == "pad" and spec.transduction.kind == "resistive":
        return counts / spec.transduction.counts_per_strain
    return counts / spec.electronics.nominal_counts


def _signal(spec, probes) -> np.ndarray:
    """Noise-free, unquantized signal of one placement [-]: the physics alone (the
    layer's strain on a pad, eqs. 1-2 on the finger), no converter."""
    if spec.kind == "pad":
        from tactsense.physics.pad_response import pad_strain

        strain = pad_strain(spec, list(probes))
        if spec.transduction.kind == "resistive":
            return np.maximum(strain, 0.0)  # a resistive taxel reads compression only
        return spec.transduction.strain_gain * strain
    from tactsense.physics.array_response import tactel_deflection

    return tactel_deflection(spec, list(probes))


def two_contact_bound(spec, separation_mm: float, centre_offset_mm: float = 0.0) -> float:
    """Cramer-Rao bound on one contact's position along the separation [mm], for the pair
    centred ``centre_offset_mm`` from the middle of the array (inf where the readings do
    not change with it: a probe on a taxel's centre that moves no neighbour)."""
    mid_a, mid_c = _middle(spec)
    centre = mid_a + centre_offset_mm
    a1, a2 = centre - separation_mm / 2, centre + separation_mm / 2
    h = 0.05
    columns = []
    for k, a in enumerate((a1, a2)):
        other = [_probe(spec, a2 if k == 0 else a1, mid_c)]
        plus = _signal(spec, [_probe(spec, a + h, mid_c), *other])
        minus = _signal(spec, [_probe(spec, a - h, mid_c), *other])
        columns.append(((plus - minus) / (2 * h)).ravel())
        up = _signal(spec, [_probe(spec, a, mid_c + h), *other])
        down = _signal(spec, [_probe(spec, a, mid_c - h), *other])
        columns.append(((up - down) / (2 * h)).ravel())
        f_up = _signal(spec, [_probe(spec, a, mid_c, FORCE_N * 1.01), *other])
        f_down = _signal(spec, [_probe(spec, a, mid_c, FORCE_N * 0.99), *other])
        columns.append(((f_up - f_down) / (0.02 * FORCE_N)).ravel())
    jac = np.column_stack(columns) / _noise_sigma(spec)
    fisher = jac.T @ jac
    # a pitch and the load on a pad; the finger's columns (mm, deg, N) at their own size
    scales = (_pitch(spec), _pitch(spec), FORCE_N) * 2
    if spec.kind != "pad":
        scales = 1.0 / np.linalg.norm(jac, axis=0)
    if rank_test(jac, scales)["singular"]:  # tolerance 1e-6 (pad_bound.rank_test)
        return float("inf")
    return float(np.sqrt(max(np.linalg.inv(fisher)[0, 0], 0.0)))


def bounds(spec, separations=(1.0, 2.0, 3.0)) -> dict:
    """Median over the placements' sub-taxel offsets of the two-contact bound [mm], and
    the share of offsets where it is finite, per separation [taxel]."""
    pitch = _pitch(spec)
    offsets = ((np.arange(PHASES) + 0.5) / PHASES - 0.5) * pitch
    out = {}
    for s in separations:
        values = np.array([two_contact_bound(spec, s * pitch, o) for o in offsets])
        out[s] = (float(np.median(values)), float(np.mean(np.isfinite(values))))
    return out


def resolution(spec, rng):
    """Per separation [taxel]: share resolved, RMS position error [mm], mean |force
    error| [%] over the placements resolved as two, and mean |error| of the merged
    contact's force against the pair's sum [%] over the placements seen as one."""
    pitch = _pitch(spec)
    mid_a, mid_c = _middle(spec)
    offsets = np.arange(RESOLUTION_PHASES) / RESOLUTION_PHASES - 0.5
    placements, truths = [], []
    n_along = spec.shape[1] if spec.kind == "pad" else spec.shape[0] - 1
    fits = [s for s in SEPARATIONS_TAXEL if s + 1.0 <= n_along - 1]  # both on the array
    for s in fits:
        for o in offsets:
            centre = mid_a + o * pitch
            a1, a2 = centre - s * pitch / 2, centre + s * pitch / 2
            placements.append((_probe(spec, a1, mid_c), _probe(spec, a2, mid_c)))
            truths.append((a1, a2))
    frames, base = _frames(spec, placements, rng)
    method = "fit" if spec.kind == "pad" else "interpolate"
    table = find_contacts(frames, spec, baseline=base, method=method, max_contacts=4)
    along = table.y_mm if spec.kind == "pad" else table.extra["axial_mm"]
    n = table.per_frame_counts()
    out = []
    for i, s in enumerate(fits):
        sel = range(i * RESOLUTION_PHASES, (i + 1) * RESOLUTION_PHASES)
        two = [k for k in sel if n[k] == 2]
        one = [k for k in sel if n[k] == 1]
        merged = [table.force_n[table.frame == k][0] / (2 * FORCE_N) - 1 for k in one]
        errors, forces = [], []
        for k in two:
            rows = np.flatnonzero(table.frame == k)
            est = along[rows]
            for t in truths[k]:
                j = int(np.argmin(np.abs(est - t)))
                errors.append(est[j] - t)
                forces.append(table.force_n[rows[j]] / FORCE_N - 1)
        out.append(
            (
                float(s),
                len(two) / RESOLUTION_PHASES,
                float(np.sqrt(np.mean(np.square(errors)))) if errors else float("nan"),
                float(100 * np.nanmean(np.abs(forces)))
                if np.isfinite(forces).any()
                else float("nan"),
                float(100 * np.nanmean(np.abs(merged)))
                if np.isfinite(merged).any()
                else float("nan"),
            )
        )
    return out


def limit(rows) -> float:
    """Smallest separation [taxel] from which on at least 90 % of placements resolve."""
    ok = [r[1] >= 0.9 for r in rows]
    for k in range(len(rows)):
        if all(ok[k:]):
            return rows[k][0]
    return float("nan")


def single(spec, rng, n=100):
    """Mean / worst |position error| [taxel] and |force error| [%] per method (pads)."""
    g = spec.grid
    r = np.random.default_rng(rng)
    xs = r.uniform(1.0, g.rows - 2.0, n) * g.row_pitch_mm
    ys = r.uniform(1.0, g.cols - 2.0, n) * g.col_pitch_mm
    placements = [(SphereProbe(x, y, FORCE_N),) for x, y in zip(xs, ys, strict=True)]
    frames, base = _frames(spec, placements, rng)
    out = {}
    for method in ("interpolate", "cop", "fit"):
        t = find_contacts(frames, spec, baseline=base, method=method, max_contacts=1)
        k = t.frame
        dx = (t.x_mm - xs[k]) / g.row_pitch_mm
        dy = (t.y_mm - ys[k]) / g.col_pitch_mm
        pos = np.hypot(dx, dy)
        force = 100 * np.abs(t.force_n / FORCE_N - 1)  # NaN where a taxel saturated
        finite = np.isfinite(force)
        out[method] = (
            float(np.mean(pos)), float(np.max(pos)),
            float(np.mean(force[finite])) if finite.any() else float("nan"),
            float(np.max(force[finite])) if finite.any() else float("nan"),
            len(t) / n, float(np.mean(~finite)),
        )  # fmt: skip
    return out


def compute(rng: int = 0):
    results = {}
    for name in (*PADS, "initial"):
        spec = ts.preset(name)
        rows = resolution(spec, rng)
        pitch = _pitch(spec)
        results[name] = {"rows": rows, "pitch": pitch, "bounds": bounds(spec),
                         "single": single(spec, rng) if spec.kind == "pad" else None}  # fmt: skip
    return results


def _bound_cell(bound) -> str:
    """The median bound, with the share of offsets where it is finite when not all."""
    median, finite = bound
    text = "inf" if not np.isfinite(median) else f"{median:.3g}"
    return text if finite == 1.0 else f"{text} ({round(finite * PHASES)}/{PHASES} finite)"


def block(results=None) -> str:
    results = compute() if results is None else results
    lines = [
        "<!-- generated by scripts/contacts_numbers.py: do not edit by hand -->",
        "",
        "| sensor | pitch [mm] | resolved from [taxel] | seen as two at 1.6 / 1.8 / 2 "
        "taxels [%] | RMS position error at 1 / 2 / 3 taxels [mm] | CRB at 1 / 2 / 3 "
        "taxels [mm] | mean force error at 2 / 3 taxels [%] | one contact's force against "
        "the pair's at 1 / 1.4 / 1.8 taxels, mean error [%] |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for name, r in results.items():
        by = {row[0]: row for row in r["rows"]}

        def cell(s, k, fmt, by=by):
            row = by.get(s)
            return "–" if row is None or not np.isfinite(row[k]) else format(row[k], fmt)

        def share(s, by=by):
            row = by.get(s)
            return "–" if row is None else format(100 * row[1], ".0f")

        lim = limit(r["rows"])
        lines.append(
            f"| {name} | {r['pitch']:.3g} | {'–' if not np.isfinite(lim) else f'{lim:.1f}'} | "
            f"{share(1.6)} / {share(1.8)} / {share(2.0)} | "
            f"{cell(1.0, 2, '.2f')} / {cell(2.0, 2, '.2f')} / {cell(3.0, 2, '.2f')} | "
            + " / ".join(_bound_cell(r["bounds"][s]) for s in (1.0, 2.0, 3.0))
            + f" | {cell(2.0, 3, '.0f')} / {cell(3.0, 3, '.0f')} | "
            f"{cell(1.0, 4, '.0f')} / {cell(1.4, 4, '.0f')} / {cell(1.8, 4, '.0f')} |"
        )
    lines += [
        "",
        "| pad | method | position mean / worst [taxel] | force mean / worst [%] | found "
        "| saturated (force NaN) |",
        "|---|---|---|---|---|---|",
    ]
    for name, r in results.items():
        if r["single"] is None:
            continue
        for method, (pm, pw, fm, fw, found, saturated) in r["single"].items():
            force = "–" if not np.isfinite(fm) else f"{fm:.1f} / {fw:.1f}"
            lines.append(
                f"| {name} | {method} | {pm:.3f} / {pw:.3f} | {force} | "
                f"{100 * found:.0f} % | {100 * saturated:.0f} % |"
            )
    return "\n".join(lines) + "\n"


def figure(results, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 3, figsize=(13, 3.8))
    for name, r in results.items():
        rows = np.array(r["rows"])
        axes[0].plot(rows[:, 0], 100 * rows[:, 1], marker="o", ms=3, label=name)
        line = axes[1].plot(rows[:, 0], rows[:, 2] / r["pitch"], marker="o", ms=3, label=name)
        seps = sorted(r["bounds"])
        axes[1].plot(seps, [r["bounds"][s][0] / r["pitch"] for s in seps], ls="--",
                     color=line[0].get_color())  # fmt: skip
        axes[2].plot(rows[:, 0], rows[:, 3], marker="o", ms=3, label=name)
    axes[0].set(xlabel="separation [taxel pitches]", ylabel="placements seen as two [%]",
                title="two equal 50-g probes")  # fmt: skip
    axes[0].axhline(90, color="grey", lw=0.8)
    axes[1].set(xlabel="separation [taxel pitches]", ylabel="RMS position error [taxel]",
                title="position (dashed: Cramer-Rao bound)", yscale="log")  # fmt: skip
    axes[2].set(xlabel="separation [taxel pitches]", ylabel="mean |force error| [%]",
                title="force", yscale="log")  # fmt: skip
    axes[0].legend()
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)


# ---- single contacts on the pads: docs/accuracy.md ----------------------------------

LOADS_G = (20.0, 50.0, 100.0)
OFFSETS_TAXEL = (0.0, 0.1, 0.2, 0.3, 0.4, 0.5)


def one_contact_bound(spec, x_mm: float, y_mm: float, force_n: float) -> float:
    """Cramer-Rao bound on the position of one sphere [mm] (the larger axis' standard
    deviation), with x, y and force unknown; inf where the readings do not move with it."""
    cov = one_contact_covariance(spec, x_mm, y_mm, force_n)
    return float(np.sqrt(max(cov[0, 0], cov[1, 1], 0.0)))


def one_contact_covariance(spec, x_mm: float, y_mm: float, force_n: float) -> np.ndarray:
    """The Cramer-Rao bound's covariance of (x [mm], y [mm], force [N]) of one sphere,
    (3, 3); every entry inf where the Fisher matrix is singular (rank test)."""
    h = 0.05
    columns = []
    for dx, dy in ((h, 0.0), (0.0, h)):
        plus = _signal(spec, [SphereProbe(x_mm + dx, y_mm + dy, force_n)])
        minus = _signal(spec, [SphereProbe(x_mm - dx, y_mm - dy, force_n)])
        columns.append(((plus - minus) / (2 * h)).ravel())
    up = _signal(spec, [SphereProbe(x_mm, y_mm, force_n * 1.01)])
    down = _signal(spec, [SphereProbe(x_mm, y_mm, force_n * 0.99)])
    columns.append(((up - down) / (0.02 * force_n)).ravel())
    jac = np.column_stack(columns) / _noise_sigma(spec)
    fisher = jac.T @ jac
    scales = (_pitch(spec), _pitch(spec), force_n)  # a pitch, the load
    if rank_test(jac, scales)["singular"]:  # tolerance 1e-6 (pad_bound.rank_test)
        return np.full((3, 3), np.inf)
    return np.linalg.inv(fisher)


def efficiency(spec, xs, ys, force_n, errors) -> tuple[float, float, int]:
    """The model-based fit's RMS error over the bound's RMS, at the same placements:
    position (|error|, x and y together, against ``sqrt(var_x + var_y)``) and force;
    and how many placements have a singular bound (left out of both RMS)."""
    pitch = spec.grid.col_pitch_mm
    cov = np.array(
        [one_contact_covariance(spec, x, y, force_n) for x, y in zip(xs, ys, strict=True)]
    )
    pos, force = errors["fit"]
    finite = np.isfinite(cov[:, 0, 0])
    use = finite & np.isfinite(pos) & np.isfinite(force)
    if not use.any():
        return np.nan, np.nan, int(np.sum(~finite))
    bound_pos = np.sqrt(np.mean(cov[use, 0, 0] + cov[use, 1, 1])) / pitch
    bound_force = 100.0 * np.sqrt(np.mean(cov[use, 2, 2])) / force_n
    return (
        float(np.sqrt(np.mean(pos[use] ** 2)) / bound_pos),
        float(np.sqrt(np.mean(force[use] ** 2)) / bound_force),
        int(np.sum(~finite)),
    )


def _errors(spec, xs, ys, force_n, rng):
    """Per method: |position error| [taxel] and |force error| [%] of one sphere at each
    (x, y), NaN force where a taxel saturated."""
    g = spec.grid
    placements = [(SphereProbe(x, y, force_n),) for x, y in zip(xs, ys, strict=True)]
    frames, base = _frames(spec, placements, rng)
    out = {}
    for method in ("interpolate", "cop", "fit"):
        t = find_contacts(frames, spec, baseline=base, method=method, max_contacts=1)
        pos = np.full(len(xs), np.nan)
        force = np.full(len(xs), np.nan)
        k = t.frame
        pos[k] = np.hypot((t.x_mm - xs[k]) / g.row_pitch_mm, (t.y_mm - ys[k]) / g.col_pitch_mm)
        force[k] = 100 * np.abs(t.force_n / force_n - 1)
        out[method] = (pos, force)
    return out


def _cell(values, fmt=".3f"):
    finite = np.asarray(values)[np.isfinite(values)]
    if not len(finite):
        return "–"
    return f"{np.mean(finite):{fmt}} / {np.max(finite):{fmt}}"


def accuracy(rng: int = 0, n: int = 60):
    """Per pad: rows against load (random interior positions) and against the offset
    from a taxel's centre along y (x on a row line), with the one-contact bound."""
    results = {}
    for name in PADS:
        spec = ts.preset(name)
        g = spec.grid
        r = np.random.default_rng(rng)
        xs = r.uniform(1.0, g.rows - 2.0, n) * g.row_pitch_mm
        ys = r.uniform(1.0, g.cols - 2.0, n) * g.col_pitch_mm
        by_load = []
        for grams in LOADS_G:
            f = grams_force(grams)
            errors = _errors(spec, xs, ys, f, rng)
            bound = np.median(
                [one_contact_bound(spec, x, y, f) for x, y in zip(xs[:12], ys[:12], strict=True)]
            )
            by_load.append(
                (grams, errors, bound / g.col_pitch_mm, efficiency(spec, xs, ys, f, errors))
            )
        by_offset = []
        row0, col0 = g.rows // 2, g.cols // 2
        for off in OFFSETS_TAXEL:
            # 12 placements at this offset along y, at random offsets across (x)
            x = (row0 + r.uniform(-0.5, 0.5, 12)) * g.row_pitch_mm
            y = np.full(12, (col0 + off) * g.col_pitch_mm)
            errors = _errors(spec, x, y, FORCE_N, rng)
            bound = one_contact_bound(spec, row0 * g.row_pitch_mm, y[0], FORCE_N)
            eff = efficiency(spec, x, y, FORCE_N, errors)
            by_offset.append((off, errors, bound / g.col_pitch_mm, eff))
        results[name] = (by_load, by_offset)
    return results


def accuracy_block(results=None) -> str:
    results = accuracy() if results is None else results
    lines = [
        "<!-- generated by scripts/contacts_numbers.py: do not edit by hand -->",
        "",
        "Against load (60 random interior positions; mean / worst |error|; position in "
        "taxels, force in percent; bound: the median Cramer-Rao bound on position over 12 "
        "of the positions, in taxels; the model-based fit's efficiency: its RMS error over "
        "the bound's RMS at the same placements, position (x and y together) and force, "
        "where the bound is finite at every placement (one frame a placement: an "
        "efficiency from 60 is good to about 10 %; on the resistive pads the bound of "
        "these frames is singular over much of a taxel, and its finite values near the "
        "clip's kink mean nothing, as said below):",
        "",
        "| pad | load [g] | interpolate: position / force | centre of pressure | "
        "model-based fit | bound [taxel] | fit's efficiency: position / force |",
        "|---|---|---|---|---|---|---|",
    ]

    def bound_text(b):
        return "inf" if not np.isfinite(b) else f"{b:.4f}"

    def eff_text(eff, n):
        pos, force, singular = eff
        if singular:
            return f"- (bound singular at {singular} of {n})"
        return f"{pos:.2f} / {force:.2f}"

    for name, (by_load, _) in results.items():
        for grams, errors, bound, eff in by_load:
            cells = [f"{_cell(errors[m][0])}; {_cell(errors[m][1], '.0f')} %"
                     for m in ("interpolate", "cop", "fit")]  # fmt: skip
            n = len(errors["fit"][0])
            lines.append(
                f"| {name} | {grams:g} | " + " | ".join(cells) + f" | {bound_text(bound)} "
                f"| {eff_text(eff, n)} |"
            )
    lines += [
        "",
        "Against the position within a taxel (50 g; the probe's offset from a taxel's "
        "centre along y, 12 placements at random offsets across; mean / worst |position "
        "error| in taxels; bound at the offset, x on the taxel's row; efficiency as "
        "above, over the 12 placements, good to about 20 %):",
        "",
        "| pad | offset [taxel] | interpolate | centre of pressure | model-based fit "
        "| bound [taxel] | fit's efficiency: position / force |",
        "|---|---|---|---|---|---|---|",
    ]
    for name, (_, by_offset) in results.items():
        for off, errors, bound, eff in by_offset:
            cells = [_cell(errors[m][0]) for m in ("interpolate", "cop", "fit")]
            n = len(errors["fit"][0])
            lines.append(
                f"| {name} | {off:.1f} | " + " | ".join(cells) + f" | {bound_text(bound)} "
                f"| {eff_text(eff, n)} |"
            )
    lines += ["", ACCURACY_END]
    return "\n".join(lines) + "\n"


ACCURACY_BEGIN = "<!-- generated by scripts/contacts_numbers.py: do not edit by hand -->"
ACCURACY_END = "<!-- end of scripts/contacts_numbers.py (accuracy) -->"


def write_accuracy() -> None:
    """Put the single-contact tables in docs/accuracy.md (``--accuracy``)."""
    sys.path.insert(0, str(ROOT / "scripts"))
    from docblock import replace_block

    text = accuracy_block().rstrip("\n")
    replace_block(ROOT / "docs" / "accuracy.md", ACCURACY_BEGIN, ACCURACY_END, text)
    sys.stdout.write(text + "\n")


def main() -> None:
    if sys.argv[1:] == ["--accuracy"]:
        write_accuracy()
        return
    results = compute()
    sys.stdout.write(block(results))
    sys.stdout.write("\n---- docs/accuracy.md ----\n\n")
    sys.stdout.write(accuracy_block())
    figure(results, ROOT / "docs" / "images" / "contacts_resolution.png")


if __name__ == "__main__":
    main()
