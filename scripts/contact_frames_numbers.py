"""Regenerate the measured blocks of docs/batch-frames.md and docs/performance.md.

Run from the repository root: ``python scripts/contact_frames_numbers.py [--frames N]``.
Throughput from ``benchmarks/bench_contact_frames.py`` (this run); accuracy of the fast
path and of today's path against the layer's exact solution (the Hankel quadrature of
``tests/simulate/test_contact_frames.py``) on random frames of one to three contacts;
a figure of one frame (``docs/figures/batch_frames.png``).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path[:0] = [str(ROOT), str(ROOT / "benchmarks"), str(ROOT / "scripts")]

from docblock import replace_block, save_figure  # noqa: E402
from tests.simulate.test_contact_frames import _exact_frame  # noqa: E402

from bench_contact_frames import measure  # noqa: E402
from tactsense.kinds import kind_of  # noqa: E402
from tactsense.physics.indenters import DiscProbe, SphereProbe  # noqa: E402
from tactsense.sensor.registry import pad12x32, pad16  # noqa: E402
from tactsense.simulate import ContactBatch  # noqa: E402

DOC = ROOT / "docs" / "batch-frames.md"
PERFORMANCE = ROOT / "docs" / "performance.md"
FIGURE = ROOT / "docs" / "figures" / "batch_frames.png"


def accuracy_cases(make, shape: str, n: int = 6, seed: int = 7):
    """(spec, batch, fast strain, today's strain, exact strain), each (n, rows, cols)."""
    spec = make()
    g = spec.grid
    rng = np.random.default_rng(seed)
    extent = np.array([(g.rows - 1) * g.row_pitch_mm, (g.cols - 1) * g.col_pitch_mm])
    position = rng.uniform(0.0, 1.0, (n, 3, 2)) * extent
    force = rng.uniform(0.05, 3.0, (n, 3))
    missing = rng.random((n, 3)) < 1.0 / 3.0
    missing[:, 0] = False
    force[missing] = 0.0
    radius = rng.uniform(1.0, 3.0, (n, 3)) if shape == "disc" else 1.6
    batch = ContactBatch(position, force, radius_mm=radius, shape=shape)
    kind = kind_of(spec)
    fast = kind.contact_forward(spec).prepare(batch)(0, n).reshape(n, g.rows, g.cols)
    layer = spec.layer
    a = batch.pressure_radius_mm(layer.youngs_modulus_pa / (1 - layer.poisson_ratio**2))
    exact = np.empty_like(fast)
    today = np.empty_like(fast)
    cls = SphereProbe if shape == "sphere" else DiscProbe
    for i in range(n):
        on = force[i] > 0
        contacts = zip(position[i, on, 0], position[i, on, 1], force[i, on], a[i, on], strict=True)
        exact[i] = _exact_frame(spec, contacts, shape)
        r = np.broadcast_to(np.asarray(radius, dtype=float), (n, 3))
        today[i] = kind.layer_strain(
            spec,
            [
                cls(x, y, f, radius_mm=rr)
                for (x, y), f, rr in zip(position[i, on], force[i, on], r[i, on], strict=True)
            ],
        )
    return spec, batch, fast, today, exact


def relative_errors(estimate, exact) -> np.ndarray:
    """Largest error of each frame over the exact frame's peak [-]."""
    peak = np.abs(exact).max(axis=(1, 2))
    return np.abs(estimate - exact).max(axis=(1, 2)) / peak


def accuracy_block() -> tuple[str, tuple]:
    lines = [
        "| sensor | contacts | frames | fast path: largest error / exact peak | "
        "today's path (`layer_strain`, 0.5-mm pressure grid) |",
        "|---|---|---|---|---|",
    ]
    shown = None
    for make, shape in ((pad16, "sphere"), (pad16, "disc"), (pad12x32, "sphere")):
        spec, _, fast, today, exact = accuracy_cases(make, shape)
        e_fast, e_today = relative_errors(fast, exact), relative_errors(today, exact)
        what = "1-3 spheres of 1.6 mm, 0.05-3 N (Hertz radius)" if shape == "sphere" else (
            "1-3 discs of radius 1-3 mm, 0.05-3 N")  # fmt: skip
        lines.append(
            f"| {spec.name} | {what} | {len(fast)} | max {e_fast.max():.1e} "
            f"(median {np.median(e_fast):.1e}) | max {e_today.max():.1e} "
            f"(median {np.median(e_today):.1e}) |"
        )
        if shown is None:
            shown = (spec, fast[0], today[0], exact[0])
    return "\n".join(lines), shown


def figure(shown) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    spec, fast, today, exact = shown
    fig, axes = plt.subplots(1, 4, figsize=(13, 3.2), constrained_layout=True)
    peak = np.abs(exact).max()
    panels = [
        (exact, "exact layer (Hankel) [-]", "viridis"),
        (fast, "frames_from_contacts [-]", "viridis"),
        ((fast - exact) / peak, "fast - exact [peak]", "coolwarm"),
        ((today - exact) / peak, "today's layer_strain - exact [peak]", "coolwarm"),
    ]
    for ax, (image, title, cmap) in zip(axes, panels, strict=True):
        limit = np.abs(image).max() if cmap == "coolwarm" else None
        shown_image = ax.imshow(image, cmap=cmap, vmin=-limit if limit else None, vmax=limit)
        ax.set_title(title, fontsize=9)
        ax.set_xlabel("column")
        ax.set_ylabel("row")
        fig.colorbar(shown_image, ax=ax, shrink=0.8)
    fig.suptitle(f"{spec.name}: compressive strain of one frame (contacts of the first case)")
    save_figure(fig, FIGURE)


def table_block() -> str:
    """What the one-off table of each built-in pad is: steps, reach, terms, build time."""
    import os
    import tempfile
    import time

    from bench_contact_frames import pad32
    from tactsense.physics._hertz_table import cached_response_table, layer_response_table

    lines = [
        "| sensor | shape | offset step [mm] | radius step [mm] | radii tabulated [mm] | "
        "reach [mm] | terms | factoring error / peak | build [s, CPU] |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    folder = tempfile.TemporaryDirectory()  # a cold cache: every table built
    os.environ["TACTSENSE_CACHE_DIR"] = folder.name
    for make in (pad16, pad32, pad12x32):
        spec = make()
        forward = kind_of(spec).contact_forward(spec)
        for shape in ("sphere", "disc"):
            cached_response_table.cache_clear()
            layer_response_table.cache_clear()
            on_disk = len(os.listdir(folder.name))
            start = time.process_time()
            table = forward.table(shape, 1.6)
            build = f"{time.process_time() - start:.1f}"
            if len(os.listdir(folder.name)) == on_disk:  # the same layer and electrode
                build = f"{build} (read: the table above)"
            _, n_x, terms = table.x_factors.shape
            lines.append(
                f"| {spec.name} | {shape} | {table.step_mm:g} | {table.a_step_mm:g} | "
                f"0-{table.a_top_mm:g} | {table.step_mm * n_x:.1f} | {terms} | "
                f"{table.rank_error:.1e} | {build} |"
            )
    cached_response_table.cache_clear()
    del os.environ["TACTSENSE_CACHE_DIR"]
    folder.cleanup()
    return "\n".join(lines)


# ---- every contact size; the table's build and cache; wide contacts (r9-fastpath) ----
SIZE_SPHERE_MM = 20.0
"""The 40-mm sphere of round 7's finding on hand4's palm pad [mm]."""


def size_cases(spec):
    """(pressure radius a [mm], place, shape) for a from 0.3 mm to the pad's width."""
    g = spec.grid
    width = (g.rows - 1) * g.row_pitch_mm
    places = {"centre": (width / 2 + 0.3, width / 2 - 0.7), "edge": (0.0, width / 3)}
    radii = (0.3, 1.0, 2.5, 4.9, 6.0, 10.0, width / 2, width)
    return [(a, place, places[place], shape) for a in radii for place in places
            for shape in ("sphere", "disc")]  # fmt: skip


def size_block() -> tuple[str, dict]:
    """The fast path and today's path against the exact layer, one contact a frame, for
    pressure radii from 0.3 mm to the pad's width: the largest error over the frame's
    taxels / the exact peak, per radius (worst of centre/edge and sphere/disc)."""
    from tactsense.physics._hertz_table import A_TOP_LIMIT_MM
    from tactsense.robot.presets import _hand4_pad

    lines = [
        "| sensor | pressure radius a [mm] | fast path's route | fast path: error / exact "
        "peak | today's path (0.5-mm pressure grid, a margin of 4 mm) |",
        "|---|---|---|---|---|",
    ]
    worst = {"fast": 0.0, "today": 0.0}
    for spec in (_hand4_pad(18, 18), pad16()):
        kind = kind_of(spec)
        forward = kind.contact_forward(spec)
        layer = spec.layer
        modulus = layer.youngs_modulus_pa / (1 - layer.poisson_ratio**2)
        cases = size_cases(spec)
        rows = {}
        for a, _place, p, shape in cases:
            sphere = max(SIZE_SPHERE_MM, 2.0 * a)
            force = (
                4.0 * modulus * (a * 1e-3) ** 3 / (3.0 * sphere * 1e-3)
                if shape == "sphere"
                else 1.0
            )
            radius = sphere if shape == "sphere" else a
            batch = ContactBatch(
                np.array([[p]]), np.array([[force]]), radius_mm=radius, shape=shape
            )
            g = spec.grid
            fast = forward.prepare(batch)(0, 1).reshape(g.rows, g.cols)
            today = kind.elastic_batch(spec, [kind.contact_state(spec, batch.frame(0))])
            exact = _exact_frame(spec, [(p[0], p[1], force, a)], shape)
            peak = np.abs(exact).max()
            e_fast = np.abs(fast - exact).max() / peak
            e_today = np.abs(today.reshape(g.rows, g.cols) - exact).max() / peak
            old = rows.get(a, (0.0, 0.0))
            rows[a] = (max(old[0], e_fast), max(old[1], e_today))
        for a, (e_fast, e_today) in rows.items():
            route = "table" if a <= A_TOP_LIMIT_MM else "spectral sum"
            lines.append(f"| {spec.name} | {a:g} | {route} | {e_fast:.1e} | {e_today:.1e} |")
            worst["fast"] = max(worst["fast"], e_fast)
            worst["today"] = max(worst["today"], e_today)
    return "\n".join(lines), worst


def builds_block() -> str:
    """The table's one-off build, the disk cache, and wide contacts (the benchmark)."""
    from bench_contact_frames import measure_builds, measure_wide

    lines = [
        "| sensor, 200 frames of a 40-mm sphere (0.05-2.5 N: a 1.3-4.8 mm) | first call, "
        "table built [s] | first call of a new process, table on disk [s] | later calls "
        "[s] | today's path [s] |",
        "|---|---|---|---|---|",
    ]
    for r in measure_builds():
        lines.append(
            f"| {r['sensor']} | {r['cold'][0]:.2f} (wall {r['cold'][1]:.2f}) | "
            f"{r['disk'][0]:.3f} (wall {r['disk'][1]:.3f}) | {r['memory'][0]:.4f} | "
            f"{r['today'][0]:.2f} (wall {r['today'][1]:.2f}) |"
        )
    wide = measure_wide()
    lines.append("")
    lines.append(
        f"Contacts wider than the tables (pad16, {wide['frames']} frames of one disc of "
        f"radius 6-18 mm, 0.5-5 N, every per-frame flaw): **{wide['frames_per_s']:,.0f}** "
        f"frames/s (CPU; wall {wide['wall_frames_per_s']:,.0f}) on the spectral sum, "
        f"today's path {wide['reference_frames_per_s']:,.0f} frames/s in the same run "
        f"({wide['ratio']:.1f}x)."
    )
    return "\n".join(lines)


def components_line(n: int = 100_000) -> str:
    """pad16 per frame: the superposition alone and the noise alone [us], best of 3."""
    import time

    from bench_contact_frames import random_contacts

    spec = pad16()
    batch = random_contacts(spec, n)
    block = kind_of(spec).contact_forward(spec).prepare(batch)
    rng = np.random.default_rng(0)

    def best(function):
        times = []
        for _ in range(3):
            start = time.process_time()
            function()
            times.append(time.process_time() - start)
        return 1e6 * min(times) / n

    superposition = best(lambda: [block(lo, min(n, lo + 1024)) for lo in range(0, n, 1024)])
    noise = best(lambda: [rng.standard_normal((1024, 256), dtype=np.float32)
                          for _ in range(0, n, 1024)])  # fmt: skip
    return (
        f"Of a pad16 frame (this run, CPU time, best of three): the superposition of its "
        f"contacts {superposition:.2f} us, its 256 float32 normals for the read noise "
        f"{noise:.2f} us."
    )


def throughput_block(rows) -> str:
    lines = [
        "| sensor | taxels | flaws | frames/s (CPU time, one core) | readings/s | "
        "today's path (`simulate`, one step per frame) | ratio |",
        "|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        path = "" if r["fast_path"] else " (no fast forward: the reference)"
        lines.append(
            f"| {r['sensor']}{path} | {r['taxels']} | {r['flaws']} | "
            f"**{r['frames_per_s']:,.0f}** (wall {r['wall_frames_per_s']:,.0f}) | "
            f"{r['readings_per_s']:,.0f} | {r['reference_frames_per_s']:,.0f} frames/s | "
            f"{r['ratio']:,.0f}x |"
        )
    return "\n".join(lines)


def _write(path, name: str, text: str) -> None:
    replace_block(
        path,
        f"<!-- begin contact-frames {name} -->",
        f"<!-- end contact-frames {name} -->",
        f"<!-- begin contact-frames {name} -->\n{text}\n<!-- end contact-frames {name} -->",
    )
    print(text)


def _throughput(frames: int) -> None:
    table = throughput_block(measure(frames))
    _write(DOC, "throughput", table)
    _write(PERFORMANCE, "throughput", table)


def _accuracy() -> None:
    accuracy, shown = accuracy_block()
    figure(shown)
    _write(DOC, "accuracy", accuracy)


def _sizes() -> None:
    sizes, worst = size_block()
    _write(DOC, "sizes", sizes)
    print(f"worst: fast {worst['fast']:.1e}, today {worst['today']:.1e}")


def _builds() -> None:
    builds = builds_block()
    _write(DOC, "builds", builds)
    _write(PERFORMANCE, "builds", builds)


BLOCKS = ("throughput", "components", "tables", "accuracy", "sizes", "builds")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--frames", type=int, default=200_000, help="frames per run [-]")
    parser.add_argument(
        "--only",
        default=",".join(BLOCKS),
        help=f"comma-separated blocks to regenerate (default all: {', '.join(BLOCKS)})",
    )
    args = parser.parse_args()
    chosen = [b.strip() for b in args.only.split(",") if b.strip()]
    unknown = sorted(set(chosen) - set(BLOCKS))
    if unknown:
        parser.error(f"unknown block(s) {', '.join(unknown)}; expected {', '.join(BLOCKS)}")
    run = {
        "throughput": lambda: _throughput(args.frames),
        "components": lambda: _write(DOC, "components", components_line()),
        "tables": lambda: _write(DOC, "tables", table_block()),
        "accuracy": _accuracy,
        "sizes": _sizes,
        "builds": _builds,
    }
    for name in BLOCKS:
        if name in chosen:
            run[name]()


if __name__ == "__main__":
    main()
