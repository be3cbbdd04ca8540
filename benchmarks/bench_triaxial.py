"""Throughput of the three-axis pad's forward model (``mag4x4``, issue 35).

Run: ``PYTHONPATH=src python benchmarks/bench_triaxial.py [--write]`` (about a minute).
``frames_from_contacts`` (the reference path: ``simulate``'s scan, one step per frame)
on 200 frames of one sheared sphere each, and ``simulate`` of the default
``slide-to-slip`` scenario, with every flaw; each against the straightforward
implementation in the same run: the tractions evaluated on the whole grid for every
contact (``traction_maps(..., window=False)``) instead of on the cells the contact
reaches. ``--write`` replaces the block between ``<!-- begin bench_triaxial -->`` and
``<!-- end bench_triaxial -->`` in docs/performance.md.
"""

from __future__ import annotations

import argparse
import functools
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "scripts"))
from docblock import replace_block  # noqa: E402

from tactsense.flat_scenarios import slide_to_slip  # noqa: E402
from tactsense.physics import triaxial as tri  # noqa: E402
from tactsense.sensor import preset  # noqa: E402
from tactsense.simulate import ContactBatch, frames_from_contacts, simulate  # noqa: E402

DOC = ROOT / "docs" / "performance.md"
BEGIN, END = "<!-- begin bench_triaxial -->", "<!-- end bench_triaxial -->"


def best_time(fn, repeats: int = 3) -> float:
    best = np.inf
    for _ in range(repeats):
        start = time.process_time()
        fn()
        best = min(best, time.process_time() - start)
    return best


def straightforward():
    """The whole-grid tractions in place of the windowed ones, for a ``with`` block."""
    windowed = tri.traction_maps

    class Swap:
        def __enter__(self):
            tri.traction_maps = functools.partial(windowed, window=False)

        def __exit__(self, *exc):
            tri.traction_maps = windowed

    return Swap()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--write", action="store_true", help="replace the block in the doc")
    args = parser.parse_args()
    spec = preset("mag4x4")
    rng = np.random.default_rng(0)
    n = 200
    batch = ContactBatch(
        rng.uniform(0, 14.1, (n, 1, 2)),
        rng.uniform(0.1, 1.0, (n, 1)),
        tangential_force_n=rng.uniform(-0.3, 0.3, (n, 1, 2)),
        radius_mm=1.6,
    )
    scene = slide_to_slip(spec)
    frames = round(scene.duration_s / spec.scan_period_s)
    rows = []
    for label, run, count in (
        (f"`frames_from_contacts`, {n} frames of a sheared sphere",
         lambda: frames_from_contacts(spec, batch, flaws="all", rng=1), n),
        (f"`simulate`, the default `slide-to-slip` ({frames} frames, {len(scene.steps)} "
         "steps)", lambda: simulate(spec, scene, flaws="all", rng=1), frames),
    ):  # fmt: skip
        run()
        fast = best_time(run)
        with straightforward():
            slow = best_time(run)
        rows.append(
            f"| {label} | **{count / fast:,.0f}** | {count / slow:,.0f} | {slow / fast:.1f}x |"
        )
    with straightforward():
        whole = frames_from_contacts(spec, batch, flaws="none")
    same = np.max(np.abs(frames_from_contacts(spec, batch, flaws="none") - whole))
    text = "\n".join(
        [
            BEGIN,
            "| run (mag4x4, 4 x 4 x 3, all flaws) | frames/s (CPU time, one core) | "
            "tractions on the whole grid (the straightforward way) | ratio |",
            "|---|---|---|---|",
            *rows,
            "",
            f"The two ways' frames differ by at most {same:.2g} counts (flaws off).",
            END,
        ]
    )
    print(text)
    if args.write:
        replace_block(DOC, BEGIN, END, text)


if __name__ == "__main__":
    main()
