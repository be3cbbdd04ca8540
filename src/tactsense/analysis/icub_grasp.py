"""Contacts on real fingertips: the iCub grasp dataset through tactsense's own estimators.

The dataset (Soh, Su and Demiris, IROS 2012; :mod:`tactsense.interop.icub_grasp`) has
about 20 grasps of each of ten objects and 22 grasps of nothing (the hand closing on
air). Its trials start with the hand already closing, so no trial has an untouched
first frame to take a baseline from; the grasps of nothing give it instead.

The rule, fixed before any grasp of an object was looked at, and never tuned on the
grasps it judges:

* **Baseline** of every taxel [counts]: the mean, over the grasps of nothing used, of
  each grasp's mean reading (each grasp weighs the same, however many slices it has).
* **Threshold** [-]: the largest signal of any taxel in any slice of the grasps of
  nothing used, each of them judged against the baseline of the *others*
  (leave-one-grasp-out inside the grasps used): the largest excursion an untouched
  fingertip showed against a baseline it did not make.
* A fingertip is **in contact** in a grasp when :func:`~tactsense.estimate.contacts.
  find_contacts`, given that baseline and threshold, finds a contact on it in any slice
  (every fingertip imported as its own recording by :func:`~tactsense.interop.
  icub_grasp.trial_recording`, the ``icub_fingertip`` preset, readings falling under load).
* A grasp of an object is judged with the baseline and threshold of all 22 grasps of
  nothing; a grasp of nothing with those of the other 21 (its false-positive rate is
  therefore out of sample).

Run ``python scripts/icub_grasp_numbers.py`` for the table of ``docs/contacts.md``.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from tactsense.interop.icub_grasp import FINGERS, GraspTrial, read_dataset, trial_recording

NOTHING = "none"
"""The grasps of nothing."""
RIGID = (
    "book",
    "lotion",
    "empty_coke",
    "med_coke",
    "empty_vitamin_water",
    "med_vitamin_water",
    "full_vitamin_water",
)
"""The rigid objects: the goal is a contact in at least 95 % of their grasps."""
SOFT = ("blue_bear", "monkey_toy")
"""The soft toys: reported as measured."""
UNRELIABLE = ("full_coke",)
"""Marked unreliable by the dataset's author ("problems during data collection")."""
GOAL_RIGID = 0.95
"""Smallest share of the rigid objects' grasps with a contact [-]."""
GOAL_NOTHING = 0.05
"""Largest share of the grasps of nothing with a contact [-]."""


@dataclass
class GraspResult:
    """One grasp judged: which fingertips were in contact, and how much signal."""

    obj: str
    trial: int
    fingertips: tuple[bool, ...]
    """In contact in any slice, per fingertip (:data:`~tactsense.interop.icub_grasp.FINGERS`)."""
    total_signal: float
    """The largest, over the slices, of the summed signal of every contact on every
    fingertip [-] (the signal: fractional plate deflection, about counts / 245 here)."""
    threshold: float
    """The threshold it was judged with [-]."""
    largest: float = 0.0
    """The largest signal of any taxel in any slice [-] (contact where above the threshold)."""

    @property
    def contact(self) -> bool:
        return any(self.fingertips)


@dataclass
class ObjectRow:
    """One object's line of the table."""

    obj: str
    grasps: int
    with_contact: int
    fingertips_mean: float
    """Fingertips in contact per grasp, mean [-]."""
    per_finger: tuple[int, ...]
    """Grasps with a contact on each fingertip [-]."""
    total_signal_median: float
    """Median over the grasps of :attr:`GraspResult.total_signal` [-]."""
    largest_median: float = 0.0
    """Median over the grasps of :attr:`GraspResult.largest` [-]."""

    @property
    def share(self) -> float:
        return self.with_contact / self.grasps if self.grasps else float("nan")


@dataclass
class GraspReport:
    """Every grasp judged, the baseline and threshold of all the grasps of nothing."""

    results: list[GraspResult]
    baseline_counts: np.ndarray
    """(5, 12) baseline from all the grasps of nothing [counts]."""
    threshold: float
    """Threshold from all the grasps of nothing [-] (the one the objects are judged with)."""
    nothing_thresholds: list[float] = field(default_factory=list)
    """Threshold each grasp of nothing was judged with (from the other grasps) [-]."""
    default_threshold: float = float("nan")
    """The estimators' default threshold for the sensor [-]
    (:func:`~tactsense.estimate.contacts.default_threshold`)."""
    default_nothing: int = 0
    """Grasps of nothing with a contact at the default threshold (each against the
    baseline of the others) [-]."""
    untouched: dict = field(default_factory=dict)
    """The grasps of nothing's readings [counts]: ``low``, ``high`` (the range of the
    taxels' grasp means), ``between`` (the largest range of one taxel's grasp means over
    the grasps), ``within`` (the scatter within a grasp: standard deviation over its
    slices, mean over taxels and grasps)."""

    def rows(self) -> list[ObjectRow]:
        """One row per object, in the order rigid, soft, unreliable, nothing."""
        order = [*RIGID, *SOFT, *UNRELIABLE, NOTHING]
        seen = {r.obj for r in self.results}
        order += sorted(seen - set(order))
        out = []
        for obj in order:
            mine = [r for r in self.results if r.obj == obj]
            if not mine:
                continue
            touched = np.array([r.fingertips for r in mine])
            out.append(
                ObjectRow(
                    obj=obj,
                    grasps=len(mine),
                    with_contact=sum(r.contact for r in mine),
                    fingertips_mean=float(touched.sum(axis=1).mean()),
                    per_finger=tuple(int(v) for v in touched.sum(axis=0)),
                    total_signal_median=float(np.median([r.total_signal for r in mine])),
                    largest_median=float(np.median([r.largest for r in mine])),
                )
            )
        return out

    def share(self, objects) -> float:
        """Share of the grasps of ``objects`` with a contact [-]."""
        mine = [r for r in self.results if r.obj in objects]
        return sum(r.contact for r in mine) / len(mine) if mine else float("nan")


def hand(trial: GraspTrial, sensor=None) -> tuple:
    """The five fingertips of a trial as recordings (thumb to little), imported by
    :func:`~tactsense.interop.icub_grasp.trial_recording`."""
    return tuple(trial_recording(trial, finger, sensor=sensor) for finger in FINGERS)


def baseline_of(hands: list[tuple]) -> np.ndarray:
    """Baseline of every taxel of every fingertip from grasps of nothing, (5, 12) [counts]:
    the mean of each grasp's mean reading."""
    if not hands:
        raise ValueError("a baseline needs at least one grasp of nothing")
    return np.mean(
        [[rec.frames[:, 0, :].astype(float).mean(axis=0) for rec in h] for h in hands], axis=0
    )


def _signal(h: tuple, baseline: np.ndarray) -> np.ndarray:
    """Signal of every slice, fingertip and taxel of a grasp, (T, 5, 12) [-], by
    :func:`~tactsense.estimate.contacts.signal_from_counts`."""
    from tactsense.estimate.contacts import signal_from_counts

    out = []
    for k, rec in enumerate(h):
        signal, _ = signal_from_counts(rec.frames, baseline[k][np.newaxis, :], rec.sensor)
        out.append(signal[:, 0, :])
    return np.stack(out, axis=1)


def threshold_of(hands: list[tuple]) -> float:
    """Contact threshold from grasps of nothing [-]: the largest signal of any taxel in any
    slice of each grasp against the baseline of the others (at least two grasps)."""
    if len(hands) < 2:
        raise ValueError("a leave-one-out threshold needs at least two grasps of nothing")
    largest = 0.0
    for i, h in enumerate(hands):
        others = baseline_of(hands[:i] + hands[i + 1 :])
        largest = max(largest, float(_signal(h, others).max()))
    return largest


def judge(
    h: tuple, baseline: np.ndarray, threshold: float, *, obj: str, number: int
) -> GraspResult:
    """Which fingertips of a grasp are in contact (:func:`~tactsense.estimate.contacts.
    find_contacts` on each fingertip's recording), and its total signal."""
    from tactsense.estimate.contacts import find_contacts

    touched = []
    total = np.zeros(len(h[0]))
    signal = _signal(h, baseline)
    for k, rec in enumerate(h):
        base = baseline[k][np.newaxis, :]
        table = find_contacts(rec.frames, rec.sensor, baseline=base, threshold=threshold)
        touched.append(len(table) > 0)
        if len(table):
            s = signal[:, k, :]
            total += np.where(s > threshold, s, 0.0).sum(axis=1)
    return GraspResult(
        obj, number, tuple(touched), float(total.max()), float(threshold), float(signal.max())
    )


def analyse(folder: str | Path, *, sensor=None) -> GraspReport:
    """Every grasp of the dataset in ``folder`` judged by the rule of this module."""
    data = read_dataset(folder)
    if NOTHING not in data or len(data[NOTHING]) < 3:
        raise ValueError(f"{folder}: the rule needs at least three grasps of nothing (none_N.txt)")
    hands = {obj: {n: hand(t, sensor) for n, t in trials.items()} for obj, trials in data.items()}
    nothing = hands[NOTHING]
    keys = list(nothing)
    baseline = baseline_of(list(nothing.values()))
    threshold = threshold_of(list(nothing.values()))
    from tactsense.estimate.contacts import default_threshold

    usual = default_threshold(nothing[keys[0]][0].sensor)
    results, thresholds, at_default = [], [], 0
    for key in keys:  # each grasp of nothing against the others only
        others = [nothing[k] for k in keys if k != key]
        own = threshold_of(others)
        thresholds.append(own)
        base = baseline_of(others)
        results.append(judge(nothing[key], base, own, obj=NOTHING, number=key))
        at_default += judge(nothing[key], base, usual, obj=NOTHING, number=key).contact
    for obj, grasps in hands.items():
        if obj == NOTHING:
            continue
        for number, h in grasps.items():
            results.append(judge(h, baseline, threshold, obj=obj, number=number))
    means = np.array([[r.frames[:, 0, :].mean(axis=0) for r in h] for h in nothing.values()])
    scatter = [np.mean([r.frames[:, 0, :].std(axis=0) for r in h]) for h in nothing.values()]
    untouched = {
        "low": float(means.min()),
        "high": float(means.max()),
        "between": float((means.max(axis=0) - means.min(axis=0)).max()),
        "within": float(np.mean(scatter)),
    }
    return GraspReport(results, baseline, threshold, thresholds, usual, at_default, untouched)


def markdown(report: GraspReport) -> str:
    """The table of ``docs/contacts.md`` and the figures around it."""
    kinds = {**dict.fromkeys(RIGID, "rigid"), **dict.fromkeys(SOFT, "soft toy")}
    kinds |= {**dict.fromkeys(UNRELIABLE, "unreliable upstream"), NOTHING: "nothing"}
    u = report.untouched
    lines = [
        f"Untouched (the grasps of nothing): the taxels' mean readings lie between "
        f"{u['low']:.1f} and {u['high']:.1f} counts; a taxel's mean moves by up to "
        f"{u['between']:.1f} counts from one grasp to another, while within a grasp its "
        f"readings scatter by {u['within']:.2f} counts (standard deviation).",
        "",
        "| object | kind | grasps | with a contact | fingertips in contact per grasp "
        "(mean) | grasps touching thumb / index / middle / ring / little | largest taxel "
        "signal (median) [-] | total signal (median) [-] |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for row in report.rows():
        lines.append(
            f"| {row.obj} | {kinds.get(row.obj, '')} | {row.grasps} | {row.with_contact} "
            f"({100 * row.share:.0f} %) | {row.fingertips_mean:.2f} | "
            + " / ".join(str(v) for v in row.per_finger)
            + f" | {row.largest_median:.4f} | {row.total_signal_median:.3f} |"
        )
    low, high = min(report.nothing_thresholds), max(report.nothing_thresholds)
    rigid, nothing = report.share(RIGID), report.share([NOTHING])
    weakest = min((r for r in report.results if r.obj in RIGID), key=lambda r: r.largest)
    closest = max(
        (r for r in report.results if r.obj == NOTHING), key=lambda r: r.largest / r.threshold
    )
    lines += [
        "",
        f"Rigid objects: {100 * rigid:.1f} % of their grasps with a contact (goal >= "
        f"{100 * GOAL_RIGID:.0f} %); grasps of nothing: {100 * nothing:.1f} % (goal <= "
        f"{100 * GOAL_NOTHING:.0f} %). Threshold from all {len(report.nothing_thresholds)} "
        f"grasps of nothing: {report.threshold:.4f} (about "
        f"{_counts(report, report.threshold):.1f} counts below the baseline); each grasp of "
        f"nothing was judged with the threshold of the others, {low:.4f} to {high:.4f}. "
        "Closest calls: the rigid grasp with the least signal "
        f"({weakest.obj}_{weakest.trial}) reached "
        f"{weakest.largest / weakest.threshold:.1f} times the threshold; the grasp of nothing "
        f"nearest to its own (none_{closest.trial}), {closest.largest / closest.threshold:.2f} "
        "times.",
        "",
        f"At the estimators' default threshold ({report.default_threshold:.4f}, about "
        f"{_counts(report, report.default_threshold):.1f} counts at this rest reading) "
        f"{report.default_nothing} of the {len(report.nothing_thresholds)} grasps of nothing "
        "show a contact: on this fingertip the threshold has to come from untouched data.",
    ]
    return "\n".join(lines) + "\n"


def _counts(report: GraspReport, threshold: float, sensor=None) -> float:
    """A threshold [-] as a drop below the mean baseline [counts]: the drop whose signal,
    through :func:`~tactsense.estimate.contacts.signal_from_counts`, is the threshold."""
    from tactsense.estimate.contacts import signal_from_counts
    from tactsense.sensor import load_sensor

    spec = load_sensor("icub_fingertip" if sensor is None else sensor)
    rest = float(np.mean(report.baseline_counts))
    drops = np.linspace(0.0, 0.5 * rest, 2001)
    frames = (rest - drops)[:, np.newaxis, np.newaxis] * np.ones((1, *spec.shape))
    signal, _ = signal_from_counts(frames, np.full(spec.shape, rest), spec)
    return float(np.interp(threshold, signal[:, 0, 0], drops))
