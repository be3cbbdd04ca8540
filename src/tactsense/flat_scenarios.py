"""Scenarios for pads and point sets: what presses where, and for how long.

Each builder returns a :class:`tactsense.simulate.Scenario` of indenters
(:mod:`tactsense.physics.indenters`) that fits the sensor it is given: positions default
to the middle of the array and are checked against it. Positions are in the pad's axes
(x along rows, y along columns, ``docs/nomenclature.md``); on a point set, ``(x, y)``
are in the tangent plane of a taxel (``at_taxel``, default the first).
"""

from __future__ import annotations

import math

import numpy as np

from tactsense._validation import TactsenseInputError, check_positive
from tactsense.kinds import kind_of
from tactsense.physics.contact import grams_force
from tactsense.physics.indenters import (
    INDENTERS,
    CylinderProbe,
    FlatPunch,
    Indenter,
    KnifeEdge,
    SphereProbe,
    SquareStamp,
)
from tactsense.simulate import Scenario, Step

FIFTY_GRAMS = grams_force(50.0)
"""The default load of every scenario: the paper's 50-g probe [N]."""


def _settle(settle_s: float) -> list[Step]:
    return [Step((), settle_s, "baseline")] if settle_s > 0 else []


def centre_mm(spec) -> tuple[float, float]:
    """The middle of a pad's grid, or of a point set's first taxel's tangent plane [mm]."""
    grid = kind_of(spec).surface_grid(spec)
    if grid is not None:
        (row_pitch, rows), (col_pitch, cols) = grid
        return (0.5 * (rows - 1) * row_pitch, 0.5 * (cols - 1) * col_pitch)
    return (0.0, 0.0)


def _check_on(spec, x_mm: float, y_mm: float, what: str) -> None:
    kind = kind_of(spec)
    grid = kind.surface_grid(spec)
    if grid is None:  # no grid to fall off: a place in a taxel's tangent plane
        return
    (row_pitch, rows), (col_pitch, cols) = grid
    low_x, high_x = -0.5 * row_pitch, (rows - 0.5) * row_pitch
    low_y, high_y = -0.5 * col_pitch, (cols - 0.5) * col_pitch
    if not (low_x <= x_mm <= high_x and low_y <= y_mm <= high_y):
        raise TactsenseInputError(
            f"{what} at ({x_mm:g}, {y_mm:g}) mm is off the {rows}x{cols} {kind.label} "
            f"{spec.name!r} (x in [{low_x:g}, {high_x:g}], y in [{low_y:g}, {high_y:g}] mm)"
        )


def make_indenter(
    kind: str, x_mm: float, y_mm: float, force_n: float, size_mm: float, **extra
) -> Indenter:
    """An indenter by kind: ``sphere`` (radius), ``disc`` (radius), ``punch`` (radius),
    ``knife`` (length), ``square`` (a flat stamp's side) or ``cylinder`` (a cylinder
    lying on the surface: its length; ``radius_mm`` in ``extra``, default 5); ``angle_deg``
    in ``extra`` for the last three (their axis from the x axis [deg])."""
    if kind not in INDENTERS:
        raise TactsenseInputError(f"unknown indenter {kind!r}; expected {', '.join(INDENTERS)}")
    if "angle_deg" in extra and kind not in ANGLED:
        if extra["angle_deg"] != 0.0:
            raise TactsenseInputError(
                f"angle_deg applies to {', '.join(ANGLED)}; a {kind} has no axis"
            )
        extra = {k: v for k, v in extra.items() if k != "angle_deg"}
    if kind == "knife":
        return KnifeEdge(x_mm, y_mm, force_n, length_mm=size_mm, **extra)
    if kind == "square":
        return SquareStamp(x_mm, y_mm, force_n, side_mm=size_mm, **extra)
    if kind == "cylinder":
        return CylinderProbe(x_mm, y_mm, force_n, length_mm=size_mm, **extra)
    return INDENTERS[kind](x_mm, y_mm, force_n, radius_mm=size_mm, **extra)


ANGLED = ("knife", "square", "cylinder")
"""Indenters with an axis (``angle_deg``)."""


def press(
    spec,
    *,
    x_mm: float | None = None,
    y_mm: float | None = None,
    force_n: float = FIFTY_GRAMS,
    indenter: str = "sphere",
    size_mm: float = 1.6,
    dwell_s: float = 0.5,
    lift_s: float = 0.5,
    repeats: int = 1,
    settle_s: float = 0.2,
    at_taxel: int | None = None,
    angle_deg: float = 0.0,
) -> Scenario:
    """Press an indenter ``repeats`` times at one place, lifting between presses
    (``angle_deg``: the axis of a knife, square stamp or cylinder, from x [deg])."""
    cx, cy = centre_mm(spec)
    x, y = (cx if x_mm is None else x_mm), (cy if y_mm is None else y_mm)
    _check_on(spec, x, y, indenter)
    check_positive(dwell_s, "dwell_s")
    if repeats < 1:
        raise TactsenseInputError(f"repeats must be at least 1; got {repeats}")
    extra = {"at_taxel": at_taxel} if at_taxel is not None else {}
    if angle_deg != 0.0 or indenter in ANGLED:
        extra["angle_deg"] = angle_deg
    contact = make_indenter(indenter, x, y, force_n, size_mm, **extra)
    steps = _settle(settle_s)
    for k in range(repeats):
        steps.append(Step((contact,), dwell_s, f"press {k + 1}"))
        if lift_s > 0:
            steps.append(Step((), lift_s, "lifted"))
    return Scenario(
        tuple(steps),
        "press",
        f"{indenter} of {size_mm:g} mm pressed {repeats}x with {force_n:g} N at "
        f"({x:g}, {y:g}) mm",
        {"x_mm": x, "y_mm": y, "force_n": force_n, "indenter": indenter, "size_mm": size_mm,
         "repeats": repeats, **({"angle_deg": angle_deg} if indenter in ANGLED else {})},
    )  # fmt: skip


def hold(spec, *, force_n: float = FIFTY_GRAMS, hold_s: float = 5.0, lift_s: float = 5.0, **where):
    """Press and hold, then lift: the delayed elastic response and creep of section 3.4."""
    return press(spec, force_n=force_n, dwell_s=hold_s, lift_s=lift_s, **where)


def two_probes(
    spec,
    *,
    separation_mm: float = 5.0,
    force_n: float = FIFTY_GRAMS,
    size_mm: float = 1.6,
    dwell_s: float = 0.5,
    settle_s: float = 0.2,
    angle_deg: float = 90.0,
    x_mm: float | None = None,
    y_mm: float | None = None,
) -> Scenario:
    """Two equal spheres ``separation_mm`` apart about ``(x_mm, y_mm)`` (default: the
    middle), the pair along ``angle_deg`` from the x axis (90: along y, the default)."""
    check_positive(separation_mm, "separation_mm")
    cx, cy = centre_mm(spec)
    cx, cy = (cx if x_mm is None else float(x_mm)), (cy if y_mm is None else float(y_mm))
    if not math.isfinite(angle_deg):
        raise TactsenseInputError(f"angle_deg must be a finite angle [deg]; got {angle_deg!r}")
    _check_on(spec, cx, cy, "the pair's centre (x_mm, y_mm)")
    dx = 0.5 * separation_mm * math.cos(math.radians(angle_deg))
    dy = 0.5 * separation_mm * math.sin(math.radians(angle_deg))
    first = SphereProbe(cx - dx, cy - dy, force_n, radius_mm=size_mm)
    second = SphereProbe(cx + dx, cy + dy, force_n, radius_mm=size_mm)
    for probe in (first, second):
        _check_on(spec, probe.x_mm, probe.y_mm,
                  f"a probe {separation_mm:g} mm (separation_mm) from its pair along "
                  f"{angle_deg:g} deg (angle_deg)")  # fmt: skip
    return Scenario(
        (*_settle(settle_s), Step((first, second), dwell_s, "two probes"), Step((), 0.2, "lifted")),
        "two-probes",
        f"two {size_mm:g}-mm spheres of {force_n:g} N each, {separation_mm:g} mm apart about "
        f"({cx:g}, {cy:g}) mm along {angle_deg:g} deg from x",
        {"separation_mm": separation_mm, "force_n": force_n, "size_mm": size_mm,
         "x_mm": cx, "y_mm": cy, "angle_deg": angle_deg},
    )  # fmt: skip


def slide(
    spec,
    *,
    start_mm: tuple[float, float] | None = None,
    end_mm: tuple[float, float] | None = None,
    force_n: float = FIFTY_GRAMS,
    size_mm: float = 1.6,
    speed_mm_s: float = 10.0,
    increment_mm: float = 0.25,
    settle_s: float = 0.2,
) -> Scenario:
    """A sphere sliding at constant force from ``start_mm`` to ``end_mm`` (default: across the
    middle of the pad along y), moved in steps of ``increment_mm``; on a kind that senses
    shear (a three-axis pad) it drags the skin with the friction of gross slip, mu P
    (mu = 1), along its motion."""
    check_positive(speed_mm_s, "speed_mm_s")
    check_positive(increment_mm, "increment_mm")
    cx, _ = centre_mm(spec)
    grid = kind_of(spec).surface_grid(spec)
    if grid is not None:
        margin, cols = grid[1]
        span = (cols - 1) * margin
        default_start, default_end = (cx, margin), (cx, span - margin)
    else:
        default_start, default_end = (0.0, -2.0), (0.0, 2.0)
    start = np.asarray(start_mm if start_mm is not None else default_start, dtype=float)
    end = np.asarray(end_mm if end_mm is not None else default_end, dtype=float)
    _check_on(spec, *start, "slide start")
    _check_on(spec, *end, "slide end")
    length = float(np.hypot(*(end - start)))
    n = max(1, math.ceil(length / increment_mm))
    dwell = (length / n) / speed_mm_s if length > 0 else 0.1
    steps = _settle(settle_s)
    # a kind that senses shear feels the friction the sliding sphere drags the skin with:
    # mu P (mu = 1) along the motion, gross slip (r8-triphys)
    drag = force_n * (end - start) / length if length > 0 and kind_of(spec).senses_shear else (0, 0)
    for k in range(n + 1):
        x, y = start + (end - start) * k / n
        sphere = SphereProbe(float(x), float(y), force_n, radius_mm=size_mm,
                             shear_x_n=float(drag[0]), shear_y_n=float(drag[1]))  # fmt: skip
        steps.append(Step((sphere,), dwell, f"slide {k}"))
    steps.append(Step((), 0.2, "lifted"))
    return Scenario(
        tuple(steps),
        "slide",
        f"{size_mm:g}-mm sphere sliding at {speed_mm_s:g} mm/s with {force_n:g} N",
        {"start_mm": list(start), "end_mm": list(end), "force_n": force_n,
         "speed_mm_s": speed_mm_s},
    )  # fmt: skip


def sweep(
    spec,
    *,
    force_n: float = FIFTY_GRAMS,
    size_mm: float = 1.6,
    increment_mm: float = 0.5,
    dwell_s: float = 0.1,
    settle_s: float = 0.2,
    x_mm: float | None = None,
) -> Scenario:
    """A sphere pressed at ``increment_mm`` steps along a row line (y), lifted between
    presses: Fig. 7's probe sweep on a pad."""
    check_positive(increment_mm, "increment_mm")
    cx, _ = centre_mm(spec)
    x = cx if x_mm is None else x_mm
    grid = kind_of(spec).surface_grid(spec)
    if grid is not None:
        col_pitch, cols = grid[1]
        ys = np.arange(0.0, (cols - 1) * col_pitch + 1e-9, increment_mm)
    else:
        ys = np.arange(-3.0, 3.0 + 1e-9, increment_mm)
    steps = _settle(settle_s)
    for y in ys:
        _check_on(spec, x, float(y), "probe")
        steps.append(Step((SphereProbe(x, float(y), force_n, radius_mm=size_mm),), dwell_s,
                          f"y = {y:g} mm"))  # fmt: skip
        steps.append(Step((), dwell_s, "lifted"))
    return Scenario(
        tuple(steps),
        "sweep",
        f"{size_mm:g}-mm sphere of {force_n:g} N pressed every {increment_mm:g} mm along y",
        {"x_mm": x, "force_n": force_n, "increment_mm": increment_mm},
    )


def knife(spec, *, force_n: float = FIFTY_GRAMS, length_mm: float = 10.0, angle_deg: float = 0.0,
          dwell_s: float = 0.5, settle_s: float = 0.2) -> Scenario:  # fmt: skip
    """A knife edge pressed across the middle at ``angle_deg`` from the x axis."""
    cx, cy = centre_mm(spec)
    edge = KnifeEdge(cx, cy, force_n, length_mm=length_mm, angle_deg=angle_deg)
    return Scenario(
        (*_settle(settle_s), Step((edge,), dwell_s, "knife"), Step((), 0.2, "lifted")),
        "knife-edge",
        f"{length_mm:g}-mm knife edge at {angle_deg:g} deg with {force_n:g} N",
        {"force_n": force_n, "length_mm": length_mm, "angle_deg": angle_deg},
    )


def punch(spec, *, force_n: float = FIFTY_GRAMS, radius_mm: float = 3.0, dwell_s: float = 0.5,
          settle_s: float = 0.2) -> Scenario:  # fmt: skip
    """A rigid flat punch pressed in the middle (a uniform-press calibration load)."""
    cx, cy = centre_mm(spec)
    tool = FlatPunch(cx, cy, force_n, radius_mm=radius_mm)
    return Scenario(
        (*_settle(settle_s), Step((tool,), dwell_s, "punch"), Step((), 0.2, "lifted")),
        "punch",
        f"flat punch of {radius_mm:g} mm radius with {force_n:g} N",
        {"force_n": force_n, "radius_mm": radius_mm},
    )


def raster(
    spec,
    *,
    force_n: float = FIFTY_GRAMS,
    size_mm: float = 1.6,
    dwell_s: float = 0.1,
    settle_s: float = 0.2,
    shear_ratio: float | None = None,
    angle_deg: float = 0.0,
    friction: float = 1.0,
) -> Scenario:
    """A sphere pressed on the centre of every taxel in turn, lifted between presses: the
    probe sweep a pad's or a point set's gains are calibrated from (``tactsense
    calibrate``; the finger's 'calibration' sweep on an array).

    ``shear_ratio`` (a kind that senses shear; r8-fixc8): each press also pushes along
    ``angle_deg`` (from x [deg]) with that many times the normal force, below
    ``friction`` (the contact sticks): the tangential sweeps of a three-axis calibration
    (docs/triaxial.md)."""
    check_positive(dwell_s, "dwell_s")
    load = {}
    if shear_ratio is not None:  # ---- r8-fixc8 ----
        _shear_checks(spec, shear_ratio, friction, 1.0, angle_deg)
        if shear_ratio >= friction:
            raise TactsenseInputError(
                f"shear_ratio {shear_ratio:g} is at or above the friction {friction:g}: the "
                "probe would slide; a calibration sweep holds below it"
            )
        q = shear_ratio * force_n
        ux, uy = math.cos(math.radians(angle_deg)), math.sin(math.radians(angle_deg))
        load = {"shear_x_n": q * ux, "shear_y_n": q * uy, "friction": friction}
    steps = _settle(settle_s)
    grid = kind_of(spec).surface_grid(spec)
    if grid is None and load:
        raise TactsenseInputError(f"{spec.name!r} has no grid: its calibration sweep "
                                  "takes no tangential push")  # fmt: skip
    if grid is not None:
        (row_pitch, rows), (col_pitch, cols) = grid
        for r in range(rows):
            for c in range(cols):
                x, y = r * row_pitch, c * col_pitch
                probe = SphereProbe(x, y, force_n, radius_mm=size_mm, **load)
                steps += [Step((probe,), dwell_s, f"taxel ({r}, {c})"), Step((), dwell_s, "lifted")]
    else:
        for k in range(spec.n_taxels):
            probe = make_indenter("sphere", 0.0, 0.0, force_n, size_mm, at_taxel=k)
            steps += [Step((probe,), dwell_s, f"taxel {k}"), Step((), dwell_s, "lifted")]
    pushed = "" if not load else f", pushed at Q/P = {shear_ratio:g} along {angle_deg:g} deg"
    extra = {} if not load else {"shear_ratio": shear_ratio, "angle_deg": angle_deg,
                                 "friction": friction}  # fmt: skip
    return Scenario(
        tuple(steps),
        "calibration",
        f"{size_mm:g}-mm sphere of {force_n:g} N pressed on every taxel in turn{pushed}",
        {"force_n": force_n, "size_mm": size_mm, **extra},
    )


def loads(
    spec,
    *,
    forces_n=None,
    x_mm: float | None = None,
    y_mm: float | None = None,
    places=None,
    size_mm: float = 1.6,
    dwell_s: float = 0.5,
    lift_s: float = 0.5,
    repeats: int = 1,
    settle_s: float = 0.2,
) -> Scenario:
    """Presses of varied, known force: a sphere pressed with each of ``forces_n`` in turn
    (the whole list ``repeats`` times), lifted between presses.

    What a lab records with a probe on a stage over a load cell, to fit the force curve
    of ``tactsense calibrate --force-log``: the force of every frame is in the
    recording's truth (``step_force_n`` of ``frame_step``), and ``tactsense simulate
    --force-log`` writes it as the load cell's CSV.

    Parameters
    ----------
    forces_n : sequence of float, optional
        The loads, each positive [N] (default: 8 from 10 to 100 g, light to heavy).
    x_mm, y_mm : float, optional
        Where the presses are [mm] (default: on the taxel nearest the middle of a pad,
        where a light press reaches a taxel; the middle of an even pad lies between
        taxels, where a 10-g press on ``pad4`` is missed).
    places : sequence of (x [mm], y [mm]), optional
        Several places instead, taken in turn press after press (not with ``x_mm``,
        ``y_mm``).
    """
    if forces_n is None:
        forces_n = [grams_force(g) for g in np.linspace(10.0, 100.0, 8)]
    forces = np.asarray(forces_n, dtype=float).ravel()
    if forces.size == 0 or not np.all(np.isfinite(forces) & (forces > 0)):
        raise TactsenseInputError(
            f"forces_n must be one or more positive forces [N]; got {list(forces)}"
        )
    check_positive(dwell_s, "dwell_s")
    if repeats < 1:
        raise TactsenseInputError(f"repeats must be at least 1; got {repeats}")
    cx = cy = 0.0
    grid = kind_of(spec).surface_grid(spec)
    if grid is not None:
        (row_pitch, rows), (col_pitch, cols) = grid
        cx, cy = (rows - 1) // 2 * row_pitch, (cols - 1) // 2 * col_pitch
    if places is None:
        places = [((cx if x_mm is None else x_mm), (cy if y_mm is None else y_mm))]
    elif x_mm is not None or y_mm is not None:
        raise TactsenseInputError("give places or x_mm/y_mm, not both")
    places = [(float(x), float(y)) for x, y in places]
    if not places:
        raise TactsenseInputError("places is empty; give at least one (x, y) [mm]")
    for x, y in places:
        _check_on(spec, x, y, "a press")
    extra = {"at_taxel": 0} if grid is None else {}  # in the tangent plane of taxel 0
    steps = _settle(settle_s)
    k = 0
    for _ in range(repeats):
        for force in forces:
            x, y = places[k % len(places)]
            probe = make_indenter("sphere", x, y, float(force), size_mm, **extra)
            steps.append(Step((probe,), dwell_s, f"{force:g} N at ({x:g}, {y:g}) mm"))
            if lift_s > 0:
                steps.append(Step((), lift_s, "lifted"))
            k += 1
    where = f"({places[0][0]:g}, {places[0][1]:g}) mm" if len(places) == 1 else (
        f"{len(places)} places in turn")  # fmt: skip
    return Scenario(
        tuple(steps),
        "loads",
        f"{size_mm:g}-mm sphere pressed with {forces.size} forces of {forces.min():g}-"
        f"{forces.max():g} N ({repeats}x) at {where}",
        {"forces_n": [float(f) for f in forces], "places_mm": [list(p) for p in places],
         "size_mm": size_mm, "repeats": repeats},
    )  # fmt: skip


# ---- shear and slip on three-axis taxels (r8-triphys) ----
def _ramp_steps(spec, ramp_s: float) -> tuple[int, float]:
    """A ramp over ``ramp_s`` [s] cut into steps of one scan period (at least one):
    (number of steps, duration of each [s]), so that the truth resolves every frame."""
    n = max(1, math.ceil(ramp_s / spec.scan_period_s - 1e-9))
    return n, ramp_s / n


def _shear_checks(spec, shear_ratio, friction, ramp_s, angle_deg) -> None:
    check_positive(ramp_s, "ramp_s")
    check_positive(friction, "friction")
    check_positive(shear_ratio, "shear_ratio")
    if not math.isfinite(angle_deg):
        raise TactsenseInputError(f"angle_deg must be a finite number; got {angle_deg!r}")


def shear(
    spec,
    *,
    x_mm: float | None = None,
    y_mm: float | None = None,
    force_n: float = FIFTY_GRAMS,
    size_mm: float = 1.6,
    shear_ratio: float = 0.3,
    angle_deg: float = 0.0,
    friction: float = 1.0,
    ramp_s: float = 0.5,
    dwell_s: float = 0.5,
    settle_s: float = 0.2,
) -> Scenario:
    """Press a sphere, ramp a tangential force along ``angle_deg`` (from x [deg]) up to
    ``shear_ratio`` times the normal force (below ``friction``: the contact sticks at its
    centre while slip spreads in from its edge, Cattaneo-Mindlin), hold it ``dwell_s``,
    ramp it back down, lift. Ramps are ``ramp_s`` long, in steps of one scan period."""
    _shear_checks(spec, shear_ratio, friction, ramp_s, angle_deg)
    check_positive(dwell_s, "dwell_s")
    if shear_ratio >= friction:
        raise TactsenseInputError(
            f"shear_ratio {shear_ratio:g} is at or above the friction {friction:g}: the "
            "contact would slide; 'shear' holds below it (use 'slide-to-slip' to slide)"
        )
    cx, cy = centre_mm(spec)
    x, y = (cx if x_mm is None else x_mm), (cy if y_mm is None else y_mm)
    _check_on(spec, x, y, "sphere")
    ux, uy = math.cos(math.radians(angle_deg)), math.sin(math.radians(angle_deg))
    n, each = _ramp_steps(spec, ramp_s)

    def sheared(fraction: float) -> SphereProbe:
        q = fraction * shear_ratio * force_n
        return SphereProbe(x, y, force_n, radius_mm=size_mm, shear_x_n=q * ux,
                           shear_y_n=q * uy, friction=friction)  # fmt: skip

    steps = [*_settle(settle_s), Step((sheared(0.0),), 0.2, "pressed")]
    steps += [Step((sheared(k / n),), each, f"shear up {k}") for k in range(1, n + 1)]
    steps.append(Step((sheared(1.0),), dwell_s, "shear held"))
    steps += [Step((sheared(k / n),), each, f"shear down {k}") for k in range(n - 1, -1, -1)]
    steps.append(Step((), 0.2, "lifted"))
    return Scenario(
        tuple(steps),
        "shear",
        f"{size_mm:g}-mm sphere pressed with {force_n:g} N at ({x:g}, {y:g}) mm, sheared "
        f"to Q/P = {shear_ratio:g} at {angle_deg:g} deg (mu = {friction:g})",
        {"x_mm": x, "y_mm": y, "force_n": force_n, "size_mm": size_mm,
         "shear_ratio": shear_ratio, "angle_deg": angle_deg, "friction": friction,
         "ramp_s": ramp_s, "dwell_s": dwell_s},
    )  # fmt: skip


def slide_to_slip(
    spec,
    *,
    x_mm: float | None = None,
    y_mm: float | None = None,
    force_n: float = FIFTY_GRAMS,
    size_mm: float = 1.6,
    shear_ratio: float = 1.5,
    angle_deg: float = 0.0,
    friction: float = 1.0,
    ramp_s: float = 1.0,
    speed_mm_s: float = 2.0,
    dwell_s: float = 0.3,
    settle_s: float = 0.2,
) -> Scenario:
    """Press a sphere and ramp a tangential force along ``angle_deg`` over ``ramp_s``
    toward ``shear_ratio`` times the normal force, past ``friction`` (mu): slip spreads
    in from the contact's edge (stick radius ``c/a = (1 - Q/(mu P))^(1/3)``) until, at
    ``Q = mu P``, the whole contact slides (the onset, ``parameters['slip_onset_s']`` [s]
    from the start); from then friction passes ``mu P`` and the sphere slides at
    ``speed_mm_s`` until the ramp ends, and ``dwell_s`` more, then lifts."""
    _shear_checks(spec, shear_ratio, friction, ramp_s, angle_deg)
    check_positive(speed_mm_s, "speed_mm_s")
    if dwell_s < 0:
        raise TactsenseInputError(f"dwell_s must be >= 0; got {dwell_s!r}")
    if shear_ratio <= friction:
        raise TactsenseInputError(
            f"shear_ratio {shear_ratio:g} does not exceed the friction {friction:g}: the "
            "contact would never slip; give a ratio above it (or use 'shear')"
        )
    cx, cy = centre_mm(spec)
    x, y = (cx if x_mm is None else x_mm), (cy if y_mm is None else y_mm)
    _check_on(spec, x, y, "sphere")
    ux, uy = math.cos(math.radians(angle_deg)), math.sin(math.radians(angle_deg))
    n, each = _ramp_steps(spec, ramp_s)
    n_slide = max(0, math.ceil(dwell_s / each - 1e-9))
    limit = friction * force_n
    steps = _settle(settle_s)
    press_s = 0.2
    steps.append(Step((SphereProbe(x, y, force_n, radius_mm=size_mm, friction=friction),),
                      press_s, "pressed"))  # fmt: skip
    onset_s = None
    travelled = 0.0
    for k in range(1, n + n_slide + 1):
        q = min(shear_ratio * force_n * k / n, shear_ratio * force_n)
        if q >= limit:  # gross slip: friction passes mu P, the sphere slides
            if onset_s is None:
                onset_s = sum(step.duration_s for step in steps)
            else:
                travelled += speed_mm_s * each
            q = limit
        px, py = x + travelled * ux, y + travelled * uy
        _check_on(spec, px, py, "the sliding sphere")
        steps.append(Step((SphereProbe(px, py, force_n, radius_mm=size_mm, shear_x_n=q * ux,
                                       shear_y_n=q * uy, friction=friction),),
                          each, f"shear {k}" if k <= n else f"sliding {k - n}"))  # fmt: skip
    steps.append(Step((), 0.2, "lifted"))
    return Scenario(
        tuple(steps),
        "slide-to-slip",
        f"{size_mm:g}-mm sphere pressed with {force_n:g} N at ({x:g}, {y:g}) mm, tangential "
        f"force ramped to Q/P = {shear_ratio:g} at {angle_deg:g} deg past mu = {friction:g}: "
        f"gross slip from {onset_s:.4g} s, sliding at {speed_mm_s:g} mm/s",
        {"x_mm": x, "y_mm": y, "force_n": force_n, "size_mm": size_mm,
         "shear_ratio": shear_ratio, "angle_deg": angle_deg, "friction": friction,
         "ramp_s": ramp_s, "speed_mm_s": speed_mm_s, "dwell_s": dwell_s,
         "slip_onset_s": onset_s},
    )  # fmt: skip


# ---- /shear and slip (r8-triphys) ----


SCENARIOS = {
    "press": press,
    "hold": hold,
    "two-probes": two_probes,
    "slide": slide,
    "sweep": sweep,
    "knife-edge": knife,
    "punch": punch,
    "calibration": raster,
    "loads": loads,
    # ---- r8-triphys ----
    "shear": shear,
    "slide-to-slip": slide_to_slip,
}
"""Scenario builders for pads and point sets, by the name ``--scenario`` takes."""
