"""The pads' inverse crime: contacts found on a true pad whose habits the description
leaves out (issue 32).

Every pad accuracy figure elsewhere estimates frames made by the description the
estimator is given. Here the frames come from a *true* pad that differs from it by one
habit of real arrays at a time (:func:`perturbations`): a 20 % gain spread, read noise of
2 % of full scale, the FSR's hysteresis and drift under load
(:mod:`tactsense.physics.piezo`), and the ghosting of a passive row/column scan
(:mod:`tactsense.physics.crosstalk`); then all together. The estimator,
:func:`tactsense.estimate.contacts.find_contacts`, is given the description as it is,
and the baseline of the first untouched frames.

The load is the one that shows ghosting: three spheres pressed together on three corners
of an axis-aligned rectangle (a three-finger grasp whose fingers line up with the rows
and columns), each placement held ``hold_s`` and released before the next. A passive
matrix then reads the fourth corner too. Each placement's last frame is scored: whether
exactly three contacts were found, the ghosts (contacts more than a pitch from every
probe), the probes missed, the position error of each found probe [taxel] and its force
error [%].
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from tactsense.estimate.contacts import find_contacts
from tactsense.estimate.finger.deflection import baseline_from
from tactsense.physics.indenters import SphereProbe
from tactsense.sensor import PadSpec
from tactsense.simulate import Scenario, Step, simulate

FLAWS = ["noise", "quantization"]
"""Flaws of every true pad: its read noise and quantization (no creep, no jitter: the
habits alone)."""

PIEZO_ONLY = ("hysteresis", "drift")
"""Habits of piezoresistive cells (no effect on a linear resistive or capacitive pad)."""


def perturbations(spec: PadSpec) -> dict[str, tuple[dict, list[str]]]:
    """The true pads: name -> (``PadSpec.replace`` arguments, flaws switched on)."""
    full = 2**spec.electronics.adc_bits - 1
    habits = {
        "gain spread 20 %": ({"flaws__gain_spread_sd": 0.2}, ["gain_spread"]),
        "read noise 2 % of full scale": ({"flaws__read_noise_counts": 0.02 * full}, []),
        "hysteresis 0.2": ({"flaws__hysteresis": 0.2}, ["hysteresis"]),
        "drift 5 % per decade": ({"flaws__drift_per_decade": 0.05}, ["drift"]),
        "passive-matrix crosstalk": ({"flaws__crosstalk": 1.0}, ["crosstalk"]),
    }
    if spec.transduction.kind != "piezoresistive":
        habits = {k: v for k, v in habits.items() if not set(v[1]) & set(PIEZO_ONLY)}
    table = {"as described": ({}, list(FLAWS))}
    every: dict = {}
    every_flaws = list(FLAWS)
    for name, (change, flaws) in habits.items():
        table[name] = (change, FLAWS + flaws)
        every.update(change)
        every_flaws += flaws
    table["every habit"] = (every, every_flaws)
    return table


@dataclass(frozen=True)
class Row:
    """One true pad's scores over the placements."""

    pad: str
    habit: str
    exact_pct: float
    """Placements whose last frame has exactly three contacts [%]."""
    ghosts: float
    """Contacts more than a pitch from every probe, per placement [-]."""
    missed: float
    """Probes with no contact within a pitch, per placement [-]."""
    position_taxel: float
    """Mean position error of the probes found [taxel]."""
    force_pct: float
    """Median |force error| of the probes found whose force is given [%] (a contact on a
    saturated taxel has its force withheld)."""


def _placements(spec: PadSpec, n: int, rng) -> list[tuple[tuple[int, int], ...]]:
    """Three corners (row, col) of random rectangles, sides >= 3 pitches, off the edges."""
    rows, cols = spec.shape
    out = []
    for _ in range(n):
        r0, r1 = sorted(rng.choice(np.arange(1, rows - 1), 2, replace=False))
        while r1 - r0 < 3:
            r0, r1 = sorted(rng.choice(np.arange(1, rows - 1), 2, replace=False))
        c0, c1 = sorted(rng.choice(np.arange(1, cols - 1), 2, replace=False))
        while c1 - c0 < 3:
            c0, c1 = sorted(rng.choice(np.arange(1, cols - 1), 2, replace=False))
        corners = [(r0, c0), (r0, c1), (r1, c1), (r1, c0)]
        skip = int(rng.integers(4))
        out.append(tuple(c for k, c in enumerate(corners) if k != skip))
    return out


def pad_robustness_study(
    spec: PadSpec,
    *,
    n_placements: int = 24,
    force_n: float = 0.5,
    hold_s: float = 2.0,
    seed: int = 0,
    habits: list[str] | None = None,
    progress: Callable[[str], None] | None = None,
) -> list[Row]:
    """Contacts found on true pads that differ from ``spec`` by one habit; see the module.

    Parameters
    ----------
    spec : PadSpec
        The description the estimator is given (the true pad's starting point).
    n_placements : int
        Three-probe placements [-].
    force_n : float
        Load of each probe [N].
    hold_s : float
        How long each placement is held before its last frame is scored [s].
    habits : list of str, optional
        Names from :func:`perturbations` (default all).

    Returns
    -------
    list of Row
    """
    rng = np.random.default_rng(seed)
    pitch = spec.grid.row_pitch_mm, spec.grid.col_pitch_mm
    placements = _placements(spec, n_placements, rng)
    jitter = rng.uniform(-0.3, 0.3, (n_placements, 3, 2))
    steps = [Step((), 0.5, "baseline")]
    truth = []
    for k, corners in enumerate(placements):
        where = [((r + jitter[k, i, 0]) * pitch[0], (c + jitter[k, i, 1]) * pitch[1])
                 for i, (r, c) in enumerate(corners)]  # fmt: skip
        truth.append(np.array(where))
        probes = tuple(SphereProbe(x, y, force_n) for x, y in where)
        steps += [Step(probes, hold_s, f"placement {k}"), Step((), 0.5, "release")]
    scenario = Scenario(tuple(steps), name="pad robustness")
    table = perturbations(spec)
    out: list[Row] = []
    for name in habits or list(table):
        if progress is not None:
            progress(name)
        change, flaws = table[name]
        true_pad = spec.replace(**change)
        rec = simulate(true_pad, scenario, flaws=flaws, rng=seed + 7)
        step = rec.truth["frame_step"]
        last = np.flatnonzero(np.r_[step[1:] != step[:-1], True] & (step % 2 == 1))
        baseline = baseline_from(rec.frames, 5)
        found = find_contacts(rec.frames[last], spec, baseline=baseline, max_contacts=8)
        exact = ghosts = missed = 0
        errors, forces = [], []
        for j in range(len(last)):
            mine = found.frame == j
            xy = np.column_stack([found.x_mm[mine], found.y_mm[mine]])
            probes = truth[(int(step[last[j]]) - 1) // 2]
            exact += int(mine.sum() == 3)
            if len(xy) == 0:
                missed += 3
                continue
            scale = np.array(pitch)
            distance = np.linalg.norm((xy[:, None, :] - probes[None]) / scale, axis=-1)
            ghosts += int(np.sum(distance.min(axis=1) > 1.0))
            nearest = distance.argmin(axis=0)
            hit = distance.min(axis=0) <= 1.0
            missed += int(np.sum(~hit))
            errors += distance.min(axis=0)[hit].tolist()
            forces += (100 * np.abs(found.force_n[mine][nearest[hit]] / force_n - 1)).tolist()
        n = len(last)
        out.append(
            Row(
                spec.name,
                name,
                100.0 * exact / n,
                ghosts / n,
                missed / n,
                float(np.mean(errors)) if errors else float("nan"),
                float(np.nanmedian(forces)) if np.isfinite(forces).any() else float("nan"),
            )
        )
    return out


def markdown_table(rows: list[Row]) -> str:
    """The study as a Markdown table."""
    lines = [
        "| pad | true pad (habit left out of the description) | exactly 3 contacts [%] "
        "| ghosts per placement | probes missed per placement | position error [taxel] "
        "| force error, median [%] |",
        "|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        lines.append(
            f"| {r.pad} | {r.habit} | {r.exact_pct:.0f} | {r.ghosts:.2f} | {r.missed:.2f} "
            f"| {r.position_taxel:.3f} | {r.force_pct:.0f} |"
        )
    return "\n".join(lines)
