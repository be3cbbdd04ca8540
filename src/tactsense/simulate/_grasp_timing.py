"""The time course of a simulated grasp: approach, squeeze, hold, release."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from tactsense.simulate._grasp_geometry import GraspError

PHASES = ("approach", "squeeze", "hold", "release")
"""The phases of a grasp's time course, in order."""

MAX_PHASE_S = 600.0
"""Longest phase [s] (the frames of every patch are held in memory until written)."""


@dataclass(frozen=True)
class Timing:
    """Durations of the grasp's phases [s], each 0 to :data:`MAX_PHASE_S`, more than 0
    in all."""

    approach_s: float = 0.2
    squeeze_s: float = 0.3
    hold_s: float = 0.5
    release_s: float = 0.3

    def __post_init__(self) -> None:
        durations = self.durations_s
        for name, value in zip(PHASES, durations, strict=True):
            if not (math.isfinite(value) and 0.0 <= value <= MAX_PHASE_S):
                raise GraspError(f"{name} duration {value!r}: expected 0 to {MAX_PHASE_S:g} [s]")
        if sum(durations) <= 0:
            raise GraspError("the grasp's phases last 0 s in all; give a duration > 0 [s]")

    @property
    def durations_s(self) -> tuple[float, float, float, float]:
        """(approach, squeeze, hold, release) [s]."""
        return (
            float(self.approach_s),
            float(self.squeeze_s),
            float(self.hold_s),
            float(self.release_s),
        )

    @property
    def total_s(self) -> float:
        """The whole course [s]."""
        return float(sum(self.durations_s))

    def phase(self, time_s: np.ndarray) -> np.ndarray:
        """The phase (index into :data:`PHASES`) at each time [s]: a time on a boundary
        (to a nanosecond: the decimal durations' rounding) starts the next phase; the end
        belongs to the release."""
        bounds = np.cumsum(self.durations_s) - 1e-9
        return np.minimum(np.searchsorted(bounds, np.asarray(time_s), side="right"), 3)

    def scale(self, time_s: np.ndarray) -> np.ndarray:
        """The fraction of the full force at each time [s] (0 to 1): 0 in the approach,
        a linear ramp up in the squeeze, 1 in the hold, a linear ramp down in the
        release (0 after it)."""
        approach, squeeze, hold, release = self.durations_s
        t = np.asarray(time_s, float)
        phase = self.phase(t)
        up = np.clip((t - approach) / squeeze, 0.0, 1.0) if squeeze > 0 else np.ones_like(t)
        end_hold = approach + squeeze + hold
        down = np.clip(1.0 - (t - end_hold) / release, 0.0, 1.0) if release > 0 else 0.0 * t
        return np.select([phase == 0, phase == 1, phase == 2], [0.0 * t, up, 1.0 + 0.0 * t], down)
