"""Three-axis scenarios of the estimator's tests and measurements (r8-triest), built from
``Scenario``/``Step`` with sheared indenters: a press, then a tangential force ramped in a
direction, frame by frame, to a ratio below or past the friction coefficient.

The truth of every step is the indenter's (``step_contacts_json``): its normal force,
tangential force and friction; :func:`slip_truth` gives the slip of each step from them
(Cattaneo-Mindlin: 0 no tangential force, 1 partial slip for ``0 < Q < mu P``, 2 gross
slip at ``Q >= mu P``) and the stick ratio ``c/a = (1 - Q / (mu P))^(1/3)``.
"""

from __future__ import annotations

import json
import math

import numpy as np

from tactsense.physics.indenters import SphereProbe
from tactsense.simulate.scenario import Scenario, Step


def shear_ramp(
    spec,
    *,
    x_mm: float,
    y_mm: float,
    force_n: float = 0.49,
    angle_deg: float = 0.0,
    ratio_max: float = 0.6,
    friction: float = 1.0,
    ramp_frames: int = 40,
    hold_frames: int = 10,
    settle_frames: int = 10,
    press_frames: int = 10,
    size_mm: float = 1.6,
    slide_mm_s: float = 10.0,
) -> Scenario:
    """Untouched, a press of ``force_n`` [N] at (x, y) [mm], then the tangential force
    ramped linearly in ``ramp_frames`` frames to ``ratio_max`` times the normal force
    along ``angle_deg`` (from +x toward +y) [deg], held ``hold_frames``, released,
    lifted. One step a frame while it ramps and holds. Where the tangential force
    reaches ``friction`` times the normal force the contact slides along it at
    ``slide_mm_s`` [mm/s] (gross slip: it moves, its tangential force stays at mu P)."""
    period = spec.scan_period_s
    steps = [Step((), settle_frames * period, "untouched")]
    along = (math.cos(math.radians(angle_deg)), math.sin(math.radians(angle_deg)))
    slid = [0.0]

    def probe(ratio: float) -> SphereProbe:
        q = ratio * force_n
        return SphereProbe(
            x_mm + slid[0] * along[0], y_mm + slid[0] * along[1], force_n,
            radius_mm=size_mm, friction=friction,
            shear_x_n=q * along[0], shear_y_n=q * along[1],
        )  # fmt: skip

    steps.append(Step((probe(0.0),), press_frames * period, "pressed"))
    ratios = [ratio_max * k / ramp_frames for k in range(1, ramp_frames + 1)]
    for ratio in ratios + [ratio_max] * hold_frames:
        if ratio >= friction:
            slid[0] += slide_mm_s * period
        steps.append(Step((probe(ratio),), period, "ramp" if ratio < ratio_max else "held"))
    steps.append(Step((probe(0.0),), press_frames * period, "released"))
    steps.append(Step((), settle_frames * period, "lifted"))
    return Scenario(
        tuple(steps),
        "shear-ramp",
        "press, tangential ramp, hold, release",
        {"ratio_max": ratio_max, "angle_deg": angle_deg, "friction": friction},
    )


def step_loads(truth: dict) -> list[list[dict]]:
    """The contacts of every step, from the recording's truth."""
    return json.loads(truth["step_contacts_json"])


def slip_truth(truth: dict) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Per step: normal force [N], tangential force (x, y) [N] as applied to the skin
    (capped at mu P: the contact slides at mu P), slip (0, 1, 2) and stick ratio c/a."""
    steps = step_loads(truth)
    n = len(steps)
    normal, shear = np.zeros(n), np.zeros((n, 2))
    slip, stick = np.zeros(n, int), np.full(n, np.nan)
    for k, contacts in enumerate(steps):
        if len(contacts) != 1:
            continue
        c = contacts[0]
        p, mu = c["force_n"], c.get("friction", 1.0)
        qx, qy = c.get("shear_x_n", 0.0), c.get("shear_y_n", 0.0)
        q = math.hypot(qx, qy)
        normal[k] = p
        scale = min(1.0, mu * p / q) if q > 0 else 1.0
        shear[k] = (qx * scale, qy * scale)
        if q <= 0:
            slip[k], stick[k] = 0, 1.0
        elif q < mu * p:
            slip[k], stick[k] = 1, (1.0 - q / (mu * p)) ** (1.0 / 3.0)
        else:
            slip[k], stick[k] = 2, 0.0
    return normal, shear, slip, stick
