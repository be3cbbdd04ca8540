"""The sensor's flaws that are not dynamics: gain spread and stiffening (section 3).

Random flaws draw from an explicit ``rng`` (``numpy.random.Generator``).
Viscoelastic creep lives in :mod:`tactsense.physics.viscoelastic`;
jitter, noise and dead tactels are applied by the simulator.
"""

from __future__ import annotations

import numpy as np

from tactsense.sensor import SensorSpec

FLAW_NAMES = (
    "gain_spread",
    "jitter",
    "noise",
    "quantization",
    "nonlinearity",
    "viscoelastic",
    "dead",
    "hysteresis",
    "drift",
    "crosstalk",
)
"""Flaws a simulation can switch on. The last three are the habits of resistive arrays
(issue 32): their parameters in ``[flaws]`` default to off, so ``"all"`` reads every
earlier sensor as before (:mod:`tactsense.physics.piezo`,
:mod:`tactsense.physics.crosstalk`)."""


def draw_gains(spec: SensorSpec, rng=None) -> np.ndarray:
    """Per-tactel gain multipliers, shape (rows, cols) [-].

    Without ``rng`` the draw uses the finger's own ``flaws.gain_seed``, so
    every simulation of one finger sees the same gains, as a real finger
    would; pass an ``rng`` to draw another finger.

    The force threshold for one A/D unit (Fig. 8) relative to the mean is
    drawn normal with standard deviation ``gain_spread_sd`` and clipped to
    ``[1 / gain_max, 1 / gain_min]``; the gain is its inverse. With the
    preset (sd 0.35, gains 0.5-2) about 5 of 56 cells sit at half the mean
    threshold, as in Fig. 8.
    """
    rng = np.random.default_rng(spec.flaws.gain_seed if rng is None else rng)
    flaws = spec.flaws
    threshold = rng.normal(1.0, flaws.gain_spread_sd, spec.shape)
    threshold = np.clip(threshold, 1.0 / flaws.gain_max, 1.0 / flaws.gain_min)
    return 1.0 / threshold


def stiffening(deflection, saturation):
    """Force-deflection nonlinearity of Fig. 6: ``d / (1 + d / c)`` [-].

    The rubber stiffens as it is compressed; ``c`` (``nonlinear_saturation``)
    sets how fast. Tension (negative deflection) is limited to ``-c / 2``
    to keep the law monotonic.
    """
    deflection = np.maximum(np.asarray(deflection, dtype=float), -0.5 * saturation)
    return deflection / (1.0 + deflection / saturation)
