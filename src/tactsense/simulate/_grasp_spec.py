"""What a simulated grasp is (:class:`Grasp`): the object, joint state, forces, load,
time course, flaws and seed, checked on construction."""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

from tactsense.simulate._grasp_geometry import GraspError, GraspObject
from tactsense.simulate._grasp_timing import Timing
from tactsense.simulate.contact_frames import named_left_out_flaws, resolve_flaws


@dataclass(frozen=True)
class Grasp:
    """A grasp to simulate.

    Attributes
    ----------
    object : GraspObject
    joints : mapping of str -> float
        Position of each movable joint [rad or m]; those left out at rest (0 clipped
        into their limits, :func:`joint_state`).
    force_n : float, mapping of str -> float, or None
        The commanded force [N] > 0: one number for every finger the object touches, or
        by finger or patch name; None: the penetration-stiffness rule.
    stiffness_n_per_mm : float
        The penetration-stiffness rule's spring [N/mm] > 0.
    load_n : (3,) tuple or None
        A force on the object the contacts carry, in the base frame [N] (its weight:
        ``(0, 0, -m g)``): each touched patch takes a share in proportion to its normal
        force, and the part of it tangent to the skin at its contact is the tangential
        force the object applies there (following the time course as the normal forces
        do). None: no tangential forces.
    timing : Timing
    flaws : str
        The per-frame flaws (as ``frames_from_contacts`` takes them: "all", "none" or a
        comma list); a flaw with memory or jitter named is refused.
    seed : int
        Seed of the read noise [-] (each patch draws from its own stream of it).
    """

    object: GraspObject
    joints: Mapping[str, float] = field(default_factory=dict)
    force_n: float | Mapping[str, float] | None = None
    stiffness_n_per_mm: float = 1.0
    load_n: tuple[float, float, float] | None = None
    timing: Timing = field(default_factory=Timing)
    flaws: str = "all"
    seed: int = 0

    def __post_init__(self) -> None:
        if not isinstance(self.object, GraspObject):
            raise GraspError(f"object must be a GraspObject; got {type(self.object).__name__}")
        if not isinstance(self.timing, Timing):
            raise GraspError(f"timing must be a Timing; got {type(self.timing).__name__}")
        object.__setattr__(self, "joints", dict(self.joints))
        force = self.force_n
        if isinstance(force, Mapping):
            force = {str(k): _positive(f"force for {k!r}", v, "N", 1e4) for k, v in force.items()}
            if not force:
                raise GraspError("force_n names no finger or patch; give at least one")
        elif force is not None:
            force = _positive("force_n", force, "N", 1e4)
        object.__setattr__(self, "force_n", force)
        _positive("stiffness_n_per_mm", self.stiffness_n_per_mm, "N/mm", 1e6)
        if self.load_n is not None:
            try:
                load = tuple(float(v) for v in self.load_n)
            except (TypeError, ValueError):
                load = ()
            if len(load) != 3 or not all(math.isfinite(v) and abs(v) <= 1e4 for v in load):
                raise GraspError(
                    f"load_n = {self.load_n!r}: expected three finite numbers, each at most "
                    "10,000 in size [N]"
                )
            object.__setattr__(self, "load_n", load)
        resolve_flaws(self.flaws)
        left_out = named_left_out_flaws(self.flaws)
        if left_out:
            raise GraspError(
                f"flaws {', '.join(left_out)} need a frame sequence (memory or jitter); a "
                "simulated grasp applies the per-frame flaws only"
            )
        if not (isinstance(self.seed, int) and self.seed >= 0):
            raise GraspError(f"seed {self.seed!r}: expected a whole number >= 0")


def _positive(name: str, value: Any, unit: str, most: float) -> float:
    try:
        number = float(value)
    except (TypeError, ValueError):
        raise GraspError(f"{name} = {value!r}: expected a number [{unit}]") from None
    if not (math.isfinite(number) and 0.0 < number <= most):
        raise GraspError(f"{name} = {value!r}: expected more than 0 and at most {most:g} [{unit}]")
    return number
