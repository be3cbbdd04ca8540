"""The registry of the paper's experiments, in the paper's order.

Each experiment is a function of a :class:`~tactsense.reproduce._common.Context`: it
simulates (or evaluates) what the paper measured (or computed), saves its figure and
appends the claims it can check. A new experiment is a function in the module of its
section of the paper and a line here.
"""

from __future__ import annotations

from collections.abc import Callable

from tactsense.reproduce._common import Context
from tactsense.reproduce.angle import fig27_28_angle
from tactsense.reproduce.array import fig13_around, fig14_tip
from tactsense.reproduce.force import fig26_force
from tactsense.reproduce.halfplane import fig16_fit
from tactsense.reproduce.localization import fig23_24_25_localization
from tactsense.reproduce.robustness import robustness
from tactsense.reproduce.sampling import fig19_20_aliasing, fig21_22_surface
from tactsense.reproduce.strip import fig17_strip_gain, fig18_strip_impulse
from tactsense.reproduce.transduction import (
    fig06_nonlinearity,
    fig07_08_calibration,
    fig09_superposition,
    fig10_11_jitter,
    fig12_creep,
)

EXPERIMENTS: list[tuple[str, Callable[[Context], None]]] = [
    ("Fig. 6: nonlinearity", fig06_nonlinearity),
    ("Figs. 7-8: calibration", fig07_08_calibration),
    ("Fig. 9: superposition", fig09_superposition),
    ("Figs. 10-11: jitter", fig10_11_jitter),
    ("Fig. 12: creep", fig12_creep),
    ("Fig. 13: around the finger", fig13_around),
    ("Fig. 14: tip", fig14_tip),
    ("Fig. 16: plane-stress fit", fig16_fit),
    ("Fig. 17: strip gain", fig17_strip_gain),
    ("Fig. 18: strip impulse response", fig18_strip_impulse),
    ("Figs. 19-20: aliasing", fig19_20_aliasing),
    ("Figs. 21-22: surface and contours", fig21_22_surface),
    ("Figs. 23-25: localization", fig23_24_25_localization),
    ("Fig. 26: total force", fig26_force),
    ("Figs. 27-28: force angle", fig27_28_angle),
    ("Beyond the paper: a finger unlike its description", robustness),
]
