"""The main job: the paper's experiments on the digital twin, and the claims table."""

from __future__ import annotations

import time
from collections.abc import Callable
from pathlib import Path

from tactsense._version import __version__
from tactsense.reproduce._common import Claim, Context, Figure
from tactsense.reproduce.basis import RESTATED
from tactsense.reproduce.registry import EXPERIMENTS
from tactsense.reproduce.report import write_html, write_markdown, write_results
from tactsense.sensor import SensorSpec, fearing1990_initial

__all__ = ["Claim", "Figure", "reproduce"]


def reproduce(
    out: str | Path,
    *,
    quick: bool = False,
    force: bool = False,
    sensor: SensorSpec | None = None,
    progress: Callable[[str, int, int], None] | None = None,
) -> dict:
    """Run the paper's experiments and write figures, report.md, report.html, results.json.

    Parameters
    ----------
    out : path
        A new directory for the report; an existing one is refused unless ``force``
        (then its report files are replaced; nothing else in it is touched).
    quick : bool
        Fewer positions and repetitions: for tests and a first look (seconds, not minutes).
    sensor : SensorSpec, optional
        The finger; default the paper's initial finger (3.8 mm x 45 deg).
    progress : callable(name, done, total), optional
        Called before each experiment.

    Returns
    -------
    dict
        ``claims`` (id -> Claim), ``figures`` (list of Figure), ``paths``.
    """
    out = Path(out)
    if out.exists() and not force:
        raise FileExistsError(f"{out} exists; pass force=True (--force) to write into it")
    out.mkdir(parents=True, exist_ok=True)
    ctx = Context(out=out, quick=quick, spec=sensor or fearing1990_initial())
    start = time.perf_counter()
    for k, (name, experiment) in enumerate(EXPERIMENTS):
        if progress is not None:
            progress(name, k, len(EXPERIMENTS))
        experiment(ctx)
    unlinked = [c.id for c in ctx.claims if c.basis == RESTATED and c.restates is None]
    if unlinked:  # a restated claim carries the verdict of what it restates
        raise RuntimeError(f"restated claims without the claim they restate: {unlinked}")
    if progress is not None:
        progress("report", len(EXPERIMENTS), len(EXPERIMENTS))
    meta = {
        "sensor": ctx.spec.name,
        "mode": "quick" if quick else "full",
        "version": __version__,
        "seconds": time.perf_counter() - start,
    }
    paths = [
        write_results(out, ctx.claims, ctx.figures, meta),
        write_markdown(out, ctx.claims, ctx.figures, meta),
        write_html(out, ctx.claims, ctx.figures, meta),
    ]
    return {
        "claims": {c.id: c for c in ctx.claims},
        "figures": ctx.figures,
        "paths": paths,
        "meta": meta,
    }
