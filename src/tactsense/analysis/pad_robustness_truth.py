"""Pad robustness against a truth the estimator does not share (issue 34 item 4).

:mod:`tactsense.analysis.pad_robustness` (issue 32) makes its frames with the
simulator the estimator's response table comes from: an inverse crime. Here every
frame's strain comes from :mod:`tactsense.analysis.layer_truth` (Love's strain function
per wavenumber and the load's exact Hankel transform: no FFT grid, no table), and the
true pad differs from the description the estimator is given by one thing at a time
(:func:`cases`): the indenter's shape, size or load; the layer's thickness (+-15 %, the
sensing depth in proportion); Poisson's ratio (0.45 against the described 0.5); the
gain spread of the twin (``physics.flaws.draw_gains``, the preset's spread); read noise
of 1-2 % of full scale; the crosstalk of a passive resistive matrix with floating lines
(``physics.crosstalk.scan_conductance``, resistive pads only); then several together.
The transducer is the twin's (``physics.transduction.deflection_to_counts`` for a
capacitive pad, ``physics.pad_response.resistive_counts`` for a resistive one), then
noise, rounding to counts and the converter's range.

Each case is estimated twice, by ``find_contacts`` with ``method="fit"`` (the response
of the scenarios' 1.6-mm sphere) and ``"joint"`` (each contact's size fitted too):

* **before** calibration: the description as given, the baseline of untouched frames;
* **after**: the lab's calibration made on the true pad itself, as tactsense offers
  it: the calibration probe (the 1.6-mm sphere, 50 g) pressed on every taxel in turn
  (``calibrate_array(..., method="sweep")``: gains and baseline), then presses logged
  by a load cell (:data:`CAL_LOADS_N`, the same probe, at random positions) against
  which a model-force
  curve is fitted (``weight_curve.force_curve`` of the estimator's own forces against
  the known loads, the curve ``tactsense calibrate --force-log`` fits). The calibration
  probe is the described one: the test indenter is not.

Scores per case and estimator, over ``n_positions`` random positions in the pad's
interior: the share of frames with exactly one contact, the position error [pitch]
(mean and worst) and the force error [%] (median and worst of the absolute value) of
the frames with one contact.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from tactsense.analysis.layer_truth import TrueLayer, taxel_strain
from tactsense.estimate.contacts import find_contacts
from tactsense.estimate.contacts.calibrate_array import calibrate_array
from tactsense.estimate.contacts.weight_curve import force_curve
from tactsense.physics.crosstalk import scan_conductance
from tactsense.physics.flaws import draw_gains
from tactsense.physics.pad_response import resistive_counts
from tactsense.physics.transduction import deflection_to_counts

METHODS = ("fit", "joint")
"""The pad estimators compared."""

MAX_CONTACTS = 3
"""Contacts kept per frame [-]: one is pressed, so a frame with more has failed
whichever they are (fewer to fit jointly keeps the noisy rows' cost bounded)."""

PROBE_MM, PROBE_N = 1.6, 0.49
"""The described probe (the scenarios' sphere [mm]) and the reference load [N]."""

CAL_LOADS_N = tuple(np.geomspace(0.098, 2.94, 48))
"""Loads of the calibration presses as a load cell logs them [N]: 48, spread evenly in
log over 10-300 g (the force curve's 8 bins of 6 presses, as ``tactsense calibrate``
bins a force log). Not a few discrete weights: the curve's knots are medians per bin,
and a bin holding one weight only makes a flat step that snaps every estimate near it
to that weight (a test at that load would then read no error at all)."""


@dataclass(frozen=True)
class Case:
    """A true pad and its load: what differs from the description."""

    name: str
    shape: str = "sphere"
    """Indenter: "sphere" (Hertz), "disc" (uniform), "punch" (rigid flat)."""
    radius_mm: float = PROBE_MM
    """Sphere radius, or the disc's or punch's radius [mm]."""
    force_n: float = PROBE_N
    """Load [N]."""
    thickness_factor: float = 1.0
    """True layer thickness (and sensing depth) over the described [-]."""
    poisson_ratio: float | None = None
    """True Poisson's ratio [-] (None: the described)."""
    gain_spread: bool = False
    """The twin's per-taxel gains (the preset's spread)."""
    noise_fs: float | None = None
    """Read noise as a share of full scale [-] (None: the preset's)."""
    crosstalk: bool = False
    """Passive-matrix crosstalk, every unscanned line floating (resistive pads)."""
    group: str = "load"
    """Which table the case belongs to."""
    layer: TrueLayer | None = field(default=None, compare=False)


def cases(spec) -> list[Case]:
    """The cases of the study for a pad: the truth as described, then one change at a
    time, then several together."""
    pitch = spec.grid.row_pitch_mm
    resistive = spec.transduction.kind != "capacitive"
    out = [
        Case("as described (1.6-mm sphere, 50 g)", group="described"),
        Case("sphere 1.6 mm, 20 g", force_n=0.196),
        Case("sphere 1.6 mm, 200 g", force_n=1.96),
        Case("sphere 5 mm, 50 g", radius_mm=5.0),
        Case("sphere 10 mm, 200 g", radius_mm=10.0, force_n=1.96),
        Case("flat disc 1 pitch across, 100 g", "disc", pitch / 2, 0.98),
        Case("flat disc 2 pitches across, 200 g", "disc", pitch, 1.96),
        Case("rigid punch 1 pitch across, 100 g", "punch", pitch / 2, 0.98),
        Case("layer 15 % thicker", thickness_factor=1.15, group="pad"),
        Case("layer 15 % thinner", thickness_factor=0.85, group="pad"),
        Case("nu 0.45 (described 0.5)", poisson_ratio=0.45, group="pad"),
        Case("gain spread (twin's)", gain_spread=True, group="pad"),
        Case("noise 1 % of full scale", noise_fs=0.01, group="pad"),
        Case("noise 2 % of full scale", noise_fs=0.02, group="pad"),
    ]
    if resistive:
        out.append(Case("passive-matrix crosstalk", crosstalk=True, group="pad"))
    out.append(
        Case(
            "all: 5-mm sphere 100 g, layer +15 %, nu 0.45, gains, 1 % noise"
            + (", crosstalk" if resistive else ""),
            radius_mm=5.0,
            force_n=0.98,
            thickness_factor=1.15,
            poisson_ratio=0.45,
            gain_spread=True,
            noise_fs=0.01,
            crosstalk=resistive,
            group="pad",
        )
    )
    return out


def true_layer(spec, case: Case) -> TrueLayer:
    """The true pad's layer for ``case``."""
    lay = TrueLayer.of(spec)
    nu = lay.poisson_ratio if case.poisson_ratio is None else case.poisson_ratio
    f = case.thickness_factor
    return TrueLayer(lay.thickness_mm * f, lay.sensing_depth_mm * f, lay.youngs_modulus_pa, nu)


def transduced_counts(spec, strain, case: Case, gains=1.0) -> np.ndarray:
    """The true pad's noiseless, unrounded readings [counts] for compressive strains
    ``strain`` (..., rows, cols) [-]: gains, the twin's transducer (and crosstalk)."""
    sampled = np.asarray(strain, dtype=float) * gains
    if spec.transduction.kind == "capacitive":
        # plates held apart at 0.95 of the gap, as the twin's chain holds them
        deflection = np.minimum(spec.transduction.strain_gain * sampled, 0.95)
        return deflection_to_counts(spec, deflection, quantize=False)
    if case.crosstalk:
        sampled = scan_conductance(np.maximum(sampled, 0.0), 1.0)
    return resistive_counts(spec, sampled)


def read_noise_counts(spec, case: Case) -> float:
    """The true pad's read noise [counts RMS]: the preset's, or ``case.noise_fs`` of the
    converter's full scale."""
    full = 2**spec.electronics.adc_bits - 1
    return spec.flaws.read_noise_counts if case.noise_fs is None else case.noise_fs * full


def true_counts(spec, strain, case: Case, gains, rng) -> np.ndarray:
    """Readings [counts] of the true pad for compressive strains ``strain`` (N, rows,
    cols) [-]: :func:`transduced_counts`, read noise, rounding, the converter's range."""
    full = 2**spec.electronics.adc_bits - 1
    counts = transduced_counts(spec, strain, case, gains)
    counts = counts + read_noise_counts(spec, case) * rng.standard_normal(counts.shape)
    return np.clip(np.rint(counts), 0, full)


def _interior(spec, n, rng) -> np.ndarray:
    """``n`` positions (x, y) [mm] uniform over the pad's interior (half a pitch in from
    the outer taxels' centres, at least the middle pitch)."""
    g = spec.grid
    lo = np.array([0.5 * g.row_pitch_mm, 0.5 * g.col_pitch_mm])
    hi = np.array([(g.rows - 1.5) * g.row_pitch_mm, (g.cols - 1.5) * g.col_pitch_mm])
    return lo + (hi - lo) * rng.uniform(size=(n, 2))


@dataclass(frozen=True)
class Score:
    """One case, one estimator, before or after calibration."""

    found_pct: float
    """Frames with exactly one contact [%]."""
    position_mean: float
    """Mean position error of those frames [pitch]."""
    position_worst: float
    """Largest position error [pitch]."""
    force_median: float
    """Median |force error| [%] (a withheld force, NaN, counts as 100 %)."""
    force_worst: float
    """Largest |force error| [%]."""
    position_rms: float = np.nan
    """Root mean square position error (x and y together) [pitch]."""
    force_rms: float = np.nan
    """Root mean square force error [%] (a withheld force counts as 100 %)."""


@dataclass(frozen=True)
class Row:
    """A case's scores per estimator, before and after calibration."""

    pad: str
    case: Case
    before: dict[str, Score]
    after: dict[str, Score]
    bound: tuple[float, float] | None = None
    """The Cramer-Rao bound of the case's frames where one applies (a sphere on the
    described layer, no gain spread or crosstalk): RMS over the positions of position
    [pitch] and force [%] (``scripts/pad_robustness_truth_numbers.py`` sets it)."""


def _score(table, n, positions, force_n, pitch) -> Score:
    counts = np.bincount(table.frame, minlength=n)
    alone = np.flatnonzero(counts == 1)
    if len(alone) == 0:
        return Score(0.0, np.nan, np.nan, np.nan, np.nan)
    row = {int(f): i for i, f in enumerate(table.frame) if counts[f] == 1}
    idx = np.array([row[int(f)] for f in alone])
    dx = table.x_mm[idx] - positions[alone, 0]
    dy = table.y_mm[idx] - positions[alone, 1]
    position = np.hypot(dx, dy) / pitch
    force = np.abs(100.0 * (table.force_n[idx] / force_n - 1.0))
    force = np.where(np.isfinite(force), force, 100.0)
    return Score(
        100.0 * len(alone) / n,
        float(position.mean()),
        float(position.max()),
        float(np.median(force)),
        float(force.max()),
        float(np.sqrt(np.mean(position**2))),
        float(np.sqrt(np.mean(force**2))),
    )


def _calibrations(spec, case, layer, gains, rng, methods=METHODS):
    """The lab's calibration of the true pad, per estimator: the sweep's gains and
    baseline, then a model-force curve from presses of known loads."""
    g = spec.grid
    baseline_frames = true_counts(spec, np.zeros((5, *spec.shape)), case, gains, rng)
    centres = [(r * g.row_pitch_mm, c * g.col_pitch_mm) for r in range(g.rows)
               for c in range(g.cols)]  # fmt: skip
    sweep = np.stack([taxel_strain(spec, x, y, PROBE_N, PROBE_MM, layer=layer)
                      for x, y in centres])  # fmt: skip
    frames = np.concatenate([baseline_frames, true_counts(spec, sweep, case, gains, rng)])
    base = calibrate_array(frames, spec, method="sweep", partial=True)
    loads = np.array(CAL_LOADS_N)
    where = _interior(spec, len(loads), rng)
    presses = np.stack([taxel_strain(spec, x, y, f, PROBE_MM, layer=layer)
                        for (x, y), f in zip(where, loads, strict=True)])  # fmt: skip
    press_counts = true_counts(spec, presses, case, gains, rng)
    out = {}
    for method in methods:
        found = find_contacts(
            press_counts, spec, calibration=base, method=method, max_contacts=MAX_CONTACTS
        )
        estimated = np.zeros(len(loads))
        np.add.at(estimated, found.frame, np.nan_to_num(found.force_n))
        keep = estimated > 0
        calibration = calibrate_array(frames, spec, method="sweep", partial=True)
        calibration.force_curve = force_curve(estimated[keep], loads[keep])
        out[method] = calibration
    return out


def run_case(spec, case: Case, *, n_positions: int = 24, seed: int = 0, methods=METHODS) -> Row:
    """One case of the study (``methods``: some of :data:`METHODS`); see the module."""
    rng = np.random.default_rng(seed)
    layer = true_layer(spec, case)
    gains = (
        draw_gains(spec, np.random.default_rng(seed + 1))
        if case.gain_spread
        else np.ones(spec.shape)
    )
    positions = _interior(spec, n_positions, np.random.default_rng(seed + 2))
    strain = np.stack(
        [taxel_strain(spec, x, y, case.force_n, case.radius_mm, shape=case.shape, layer=layer)
         for x, y in positions]
    )  # fmt: skip
    untouched = true_counts(spec, np.zeros((5, *spec.shape)), case, gains, rng)
    frames = true_counts(spec, strain, case, gains, rng)
    baseline = np.median(untouched, axis=0)
    pitch = spec.grid.row_pitch_mm
    calibrations = _calibrations(spec, case, layer, gains, rng, methods)
    before, after = {}, {}
    for method in methods:
        found = find_contacts(
            frames, spec, baseline=baseline, method=method, max_contacts=MAX_CONTACTS
        )
        before[method] = _score(found, n_positions, positions, case.force_n, pitch)
        found = find_contacts(
            frames,
            spec,
            calibration=calibrations[method],
            method=method,
            max_contacts=MAX_CONTACTS,
        )
        after[method] = _score(found, n_positions, positions, case.force_n, pitch)
    return Row(spec.name, case, before, after)


def pad_robustness_truth_study(
    spec,
    *,
    n_positions: int = 24,
    seed: int = 0,
    names: list[str] | None = None,
    progress: Callable[[str], None] | None = None,
) -> list[Row]:
    """Every case of :func:`cases` (or those named) for ``spec``; see the module.

    Parameters
    ----------
    spec : PadSpec
        The description the estimator is given.
    n_positions : int
        Random interior positions per case [-].
    seed : int
        Seeds the positions, gains and noise (each case draws the same positions).
    names : list of str, optional
        Case names to run (default all).
    """
    out = []
    for case in cases(spec):
        if names is not None and case.name not in names:
            continue
        if progress is not None:
            progress(case.name)
        out.append(run_case(spec, case, n_positions=n_positions, seed=seed))
    return out


def _cell(s: Score) -> str:
    if not np.isfinite(s.position_mean):
        return f"{s.found_pct:.0f} % | - | -"
    return (
        f"{s.found_pct:.0f} % | {s.position_mean:.3f} / {s.position_worst:.3f} "
        f"| {s.force_median:.1f} / {s.force_worst:.0f}"
    )


def bound_applies(case: Case) -> bool:
    """Whether the bound of :mod:`tactsense.analysis.pad_efficiency` describes the
    case's frames: a sphere on the described layer, without gain spread or crosstalk."""
    return (
        case.shape == "sphere"
        and case.thickness_factor == 1.0
        and case.poisson_ratio is None
        and not case.gain_spread
        and not case.crosstalk
    )


def _efficiency(s: Score, bound) -> str:
    if bound is None:
        return "-"
    if not np.all(np.isfinite(bound)):
        return "singular"
    if not np.isfinite(s.position_rms) or not np.isfinite(s.force_rms):
        return "n/a"
    return f"{s.position_rms / bound[0]:.2g} / {s.force_rms / bound[1]:.2g}"


def markdown_table(rows: list[Row]) -> str:
    """The study as a Markdown table: per case and estimator, before -> after; with an
    efficiency column (RMS error over the bound, before and after) when any row has a
    bound."""
    with_bound = any(r.bound is not None for r in rows)
    head = (
        "| pad | true pad and load | estimator | one contact found | position, mean / worst "
        "[pitch] | force, median / worst [%] | after calibration: found | position "
        "| force |"
    )
    rule = "|---|---|---|---|---|---|---|---|---|"
    if with_bound:
        head += " efficiency vs bound: position / force, before; after |"
        rule += "---|"
    lines = [head, rule]
    for r in rows:
        for method in r.before:
            line = (
                f"| {r.pad} | {r.case.name} | {method} | {_cell(r.before[method])} "
                f"| {_cell(r.after[method])} |"
            )
            if with_bound:
                line += (
                    f" {_efficiency(r.before[method], r.bound)}; "
                    f"{_efficiency(r.after[method], r.bound)} |"
                )
            lines.append(line)
    return "\n".join(lines)
