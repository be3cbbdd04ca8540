"""What every experiment shares: the claim and figure records, the run context, and the
finger calibration that several figures use."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import matplotlib
import numpy as np

matplotlib.use("Agg")
import matplotlib.pyplot as plt

import tactsense as ts
from tactsense.estimate.finger import calibrate as cal
from tactsense.physics.transduction import fractional_deflection
from tactsense.reproduce.basis import BY_CONSTRUCTION, FITTED, RESTATED, basis_of

G50 = ts.grams_force(50)


def centre_col(spec) -> int:
    """The column the experiments load: column 0 (0 deg) on a finger whose columns close
    the circumference, as in the paper; else the wired column nearest the middle of the
    array, so that every contact lies on the tactels whatever the layout."""
    if spec.closes_circumference:
        return 0
    angles = np.asarray(spec.col_angle_deg, dtype=float)
    return int(np.argmin(np.abs(angles - angles.mean())))


def centre_angle(spec) -> float:
    """The angle of :func:`centre_col` [deg]."""
    return float(spec.col_angle_deg[centre_col(spec)])


def on_array(spec, angle_deg: float) -> float:
    """``angle_deg`` if it lies on the array, else the angle of :func:`centre_col` [deg]."""
    if spec.closes_circumference:
        return float(angle_deg)
    angles = np.asarray(spec.col_angle_deg, dtype=float)
    half = 0.5 * spec.array.spacing_angle_deg
    inside = angles.min() - half <= angle_deg <= angles.max() + half
    return float(angle_deg) if inside else centre_angle(spec)


MEASURED = ["gain_spread", "noise", "quantization", "jitter", "nonlinearity"]


@dataclass
class Claim:
    """One quantitative statement of the paper against what the model computes."""

    id: str
    statement: str
    paper: float | None
    computed: float
    unit: str
    tolerance: float
    """Relative difference within which the claim agrees (for 'within' claims: computed
    may be up to paper * (1 + tolerance))."""
    note: str
    kind: str = "value"  # "value", "within" (paper is a bound), "qualitative"
    restates: Claim | None = None
    """For a ``restated`` claim: the claim whose measurement it states in other units.
    Its verdict is that claim's: a measurement that differs in millimetres does not
    agree because the paper's restatement in tactels is looser."""

    @property
    def relative_difference(self) -> float | None:
        if self.paper in (None, 0):
            return None
        return (self.computed - self.paper) / abs(self.paper)

    @property
    def basis(self) -> str:
        """``predicted``, ``fitted``, ``by construction`` or ``arithmetic``."""
        return basis_of(self.id)[0]

    @property
    def basis_note(self) -> str:
        """How the computed value was obtained (for a fit: the constant set from it)."""
        return basis_of(self.id)[1]

    @property
    def within_tolerance(self) -> bool:
        if self.kind == "qualitative" or self.paper is None:
            return self.tolerance >= abs(self.computed)
        if self.kind == "within":
            return abs(self.computed) <= abs(self.paper) * (1 + self.tolerance)
        return abs(self.relative_difference) <= self.tolerance

    @property
    def verdict(self) -> str:
        """``agrees`` or ``differs`` for predictions and arithmetic; a fitted or
        by-construction claim within tolerance is ``consistent`` (an echo of what the
        twin was set to, not evidence); a restated claim carries the verdict of the claim
        it restates (:attr:`restates`), whatever its own tolerance says."""
        if self.basis == RESTATED and self.restates is not None:
            return self.restates.verdict
        if not self.within_tolerance:
            return "differs"
        return "consistent" if self.basis in (FITTED, BY_CONSTRUCTION) else "agrees"

    def to_dict(self) -> dict:
        return {
            "statement": self.statement,
            "paper": self.paper,
            "computed": self.computed,
            "unit": self.unit,
            "tolerance": self.tolerance,
            "kind": self.kind,
            "relative_difference": self.relative_difference,
            "basis": self.basis,
            "basis_note": self.basis_note,
            "verdict": self.verdict,
            "restates": None if self.restates is None else self.restates.id,
            "note": self.note,
        }


@dataclass
class Figure:
    """One reproduced figure and its text."""

    number: int
    title: str
    paper_did: str
    simulated: str
    came_out: str
    path: Path
    label: str = ""
    """How the report names it: ``Fig. N`` for the paper's figures; the studies that go
    beyond the paper have their own label (and a number after the paper's last)."""
    table: str = ""
    """A Markdown table printed under the figure (studies beyond the paper)."""

    @property
    def name(self) -> str:
        return self.label or f"Fig. {self.number}"


@dataclass
class Context:
    out: Path
    quick: bool
    spec: ts.SensorSpec
    figures: list[Figure] = field(default_factory=list)
    claims: list[Claim] = field(default_factory=list)
    cache: dict = field(default_factory=dict)

    def n(self, full: int, quick: int) -> int:
        return quick if self.quick else full

    def save(
        self,
        fig,
        number: int,
        title: str,
        paper_did: str,
        simulated: str,
        came_out: str,
        *,
        label: str = "",
        stem: str = "",
        table: str = "",
    ) -> None:
        path = self.out / f"{stem or f'fig{number:02d}'}.png"
        fig.suptitle(f"{label or f'Fig. {number}'}: {title}", fontsize=11)
        fig.savefig(path, dpi=100)
        plt.close(fig)
        self.figures.append(
            Figure(number, title, paper_did, simulated, came_out, path, label, table)
        )


def recording_deflection(rec):
    """Fractional deflection of a recording against the median of its first 5 frames."""
    return fractional_deflection(rec.frames.astype(float), ts.baseline_from(rec.frames, 5))


def calibration_of(ctx: Context):
    """The finger's gain calibration from a section 3.1 sweep (shared by several figures)."""
    if "calibration" not in ctx.cache:
        spec = ctx.spec
        increment = 0.6 if not ctx.quick else 1.2
        sweep = ts.simulate(
            spec, ts.calibration_sweep(spec, increment=increment), flaws=MEASURED, rng=11
        )
        ctx.cache["calibration"] = cal.calibrate_sweep(sweep.frames, spec)
        ctx.cache["sweep"] = sweep
    return ctx.cache["calibration"]
