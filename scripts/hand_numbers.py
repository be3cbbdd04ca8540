"""Regenerate the measured block of docs/performance.md for the whole hand's estimator
(issue 36, item 7) from ``benchmarks/bench_hand.py``, run here.

Run from the repository root: ``python scripts/hand_numbers.py [--frames N] [--live-s S]``.
The live part needs ``tactsense.stream.robot`` (r7-capture); without it the block says
so.
"""

from __future__ import annotations

import argparse
import os
import platform
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path[:0] = [str(ROOT), str(ROOT / "benchmarks"), str(ROOT / "scripts")]

from docblock import replace_block  # noqa: E402

from bench_hand import live, measure, pads4000  # noqa: E402
from tactsense.robot import skin_preset  # noqa: E402

PERFORMANCE = ROOT / "docs" / "performance.md"
BEGIN, END = "<!-- begin bench_hand -->", "<!-- end bench_hand -->"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--frames", type=int, default=20_000)
    parser.add_argument("--live-s", type=float, default=20.0)
    parser.add_argument("--live-reference-s", type=float, default=3.0)
    args = parser.parse_args()
    load_before = os.getloadavg()[0]
    rows = [measure("hand4", skin_preset("hand4"), args.frames),
            measure("pads4000", pads4000(), args.frames)]  # fmt: skip
    live_rows = live(args.live_s, args.live_reference_s) if args.live_s > 0 else None
    load_after = os.getloadavg()[0]
    lines = [BEGIN, ""]
    lines.append(
        f"This run: {args.frames:,} hand frames per skin, {platform.python_version()}, NumPy "
        f"{np.__version__}, one core; load average {load_before:.1f} before and "
        f"{load_after:.1f} after (2 cores, shared with the other jobs of the machine)."
    )
    lines += ["", "| skin | patches | taxels | `HandLocator.locate`, blocks of 1,000 | one call "
              "per hand frame (median, p99) | straightforward loop (`LiveContacts` per patch) "
              "| ratio (blocks, one call) |", "|---|---|---|---|---|---|---|"]  # fmt: skip
    for r in rows:
        lines.append(
            f"| {r['skin']} ({r['sensors']}) | {r['patches']} | {r['taxels']:,} | "
            f"**{r['block_rate']:,.0f} hand frames/s** ({r['contacts_per_frame']:.1f} contacts "
            f"a frame) | {r['one_rate']:,.0f} frames/s ({r['one_median_ms']:.2f} ms, "
            f"{r['one_p99_ms']:.2f} ms) | {r['reference_rate']:,.0f} hand frames/s "
            f"({r['reference_frames']} frames) | {r['block_rate'] / r['reference_rate']:,.0f}x, "
            f"{r['one_rate'] / r['reference_rate']:,.0f}x |"
        )
    lines.append("")
    for r in rows:
        lines.append(
            f"- {r['skin']}: against `find_contacts` per patch on the same frames, "
            f"{'the same' if r['same'] else 'NOT the same'} {r['contacts']:,} contacts; "
            f"largest difference {r['dx_mm']:.1e} mm (base frame) and {r['df_n']:.1e} N."
        )
    lines.append("")
    if live_rows is None:
        lines.append("Live: not measured in this run (`tactsense.stream.robot` absent).")
    else:
        lines += ["| live, 4 devices x 5 pads at 250 Hz (4,000 taxels) | device frames/s "
                  "handled | last byte to contacts: median | p99 | max | lost |",
                  "|---|---|---|---|---|---|"]  # fmt: skip
        for what, r in live_rows.items():
            lines.append(
                f"| {what} ({r['seconds']:.0f} s) | {r['rate']:,.0f} | {r['median_ms']:.2f} ms "
                f"| **{r['p99_ms']:.2f} ms** | {r['max_ms']:.1f} ms | {r['lost']} |"
            )
    lines += ["", END]
    replace_block(PERFORMANCE, BEGIN, END, "\n".join(lines))
    print("\n".join(lines))


if __name__ == "__main__":
    main()
