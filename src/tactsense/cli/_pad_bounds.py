"""``design bound`` on a pad: the classic, censored and unclipped point bounds and the
Bayesian bound over the taxel cell, at the preset's noise and a realistic one."""

from __future__ import annotations

import math

from rich.markup import escape
from rich.table import Table

from tactsense.analysis.pad_censored import (
    MODELS,
    RANK_TOLERANCE,
    bayesian_bound,
    noise_from_full_scale,
    point_bound,
)


def _taxel_of(spec, x_mm: float, y_mm: float) -> tuple[int, int]:
    g = spec.grid
    return (
        min(max(round(x_mm / g.row_pitch_mm), 0), g.rows - 1),
        min(max(round(y_mm / g.col_pitch_mm), 0), g.cols - 1),
    )


def pad_bound_rows(spec, x_mm, y_mm, force_n, radius_mm, noise_fs_pct) -> list[dict]:
    """One row per (noise, bound): ``noise`` ("preset" or "N % FS"), ``noise_counts``,
    ``bound`` (classic / censored / unclipped at the point, bayesian over the cell of the
    nearest taxel), the standard deviations and, for point bounds, the rank test."""
    rows = []
    for label, noise in (
        ("preset", None),
        (f"{noise_fs_pct:g} % FS", noise_from_full_scale(spec, noise_fs_pct)),
    ):
        counts = spec.flaws.read_noise_counts if noise is None else noise
        for model in MODELS:
            b = point_bound(
                spec, x_mm, y_mm, force_n, model=model, noise_counts=noise, radius_mm=radius_mm
            )
            rows.append({"noise": label, "noise_counts": counts, "bound": model, **b})
        b = bayesian_bound(
            spec, force_n, taxel=_taxel_of(spec, x_mm, y_mm), noise_counts=noise,
            radius_mm=radius_mm,
        )  # fmt: skip
        rows.append({"noise": label, "noise_counts": counts, "bound": "bayesian", **b})
    return rows


def _um(value: float) -> str:
    return "singular" if not math.isfinite(value) else f"{1e3 * value:.3g}"


def bounds_table(rows: list[dict], name: str) -> Table:
    """The rows of :func:`pad_bound_rows` as a table."""
    table = Table(
        title=f"Bounds on {name}: classic (noise after the clip), censored (noise before "
        "it), unclipped (a two-sided transducer), bayesian (hybrid Van Trees, cos^2 prior "
        f"over the taxel cell); singular: rank test, tolerance {RANK_TOLERANCE:g} on the "
        "singular values in units of a pitch and the load"
    )
    for column in ("noise", "read noise [counts]", "bound", "x [um]", "y [um]", "force [%]"):
        table.add_column(escape(column), no_wrap=True)
    for r in rows:
        force = "singular" if not math.isfinite(r["force_relative"]) else (
            f"{100 * r['force_relative']:.3g}")  # fmt: skip
        table.add_row(r["noise"], f"{r['noise_counts']:.3g}", r["bound"], _um(r["x_mm"]),
                      _um(r["y_mm"]), force)  # fmt: skip
    return table
