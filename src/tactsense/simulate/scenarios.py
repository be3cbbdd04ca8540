"""The paper's scenarios for the finger: probe sweeps, repeated loads, the calibration
sweep and section 4.1's knife edge, each over (row, col) tactels of the finger."""

from __future__ import annotations

import numpy as np

from tactsense._validation import TactsenseInputError, check_positive
from tactsense.physics.contact import Probe, grams_force, knife_edge
from tactsense.sensor import SensorSpec
from tactsense.simulate.scenario import Scenario, Step


def default_row(spec: SensorSpec) -> int:
    """The row a scenario loads when none is named: the paper's row 4 (the middle of the
    initial finger's eight), or the middle row of a smaller array [-]."""
    return min(4, spec.shape[0] // 2)


def default_col(spec: SensorSpec) -> int:
    """The column a scenario loads when none is named: column 0 (every array has it) [-]."""
    return 0


def _tactel(spec: SensorSpec, row: int | None, col: int | None) -> tuple[int, int]:
    """(row, col) with the defaults of this sensor filled in, checked against its array."""
    row = default_row(spec) if row is None else int(row)
    col = default_col(spec) if col is None else int(col)
    spec.check_tactel(row, col)
    return row, col


def _check_row(spec: SensorSpec, row: int) -> None:
    rows = spec.shape[0]
    if not 0 <= row < rows:
        raise TactsenseInputError(
            f"row {row} is outside the {rows}x{spec.shape[1]} array of wired tactels "
            f"(rows 0-{rows - 1})"
        )


def _check_col(spec: SensorSpec, col: int) -> None:
    cols = spec.shape[1]
    if not 0 <= col < cols:
        raise TactsenseInputError(
            f"column {col} is outside the {spec.shape[0]}x{cols} array of wired tactels "
            f"(columns 0-{cols - 1})"
        )


def _settle(settle_s: float) -> list[Step]:
    """The untouched start of a scenario, from which a baseline is taken."""
    return [Step((), settle_s, "baseline")] if settle_s > 0 else []


def probe_sweep(
    spec: SensorSpec,
    *,
    along: str = "axial",
    row: int | None = None,
    col: int | None = None,
    start: float | None = None,
    stop: float | None = None,
    increment: float | None = None,
    force_n: float | None = None,
    dwell_s: float = 0.5,
    lift_s: float = 0.0,
    settle_s: float = 1.0,
    contact_diameter_mm: float = 3.0,
) -> Scenario:
    """The paper's probe sweep (Figs. 7 and 13): a 50-g probe stepped along a row or around.

    Parameters
    ----------
    along : {"axial", "around"}
        Sweep along the finger at the angle of column ``col`` (Fig. 7,
        0.6-mm increments), or around it at the axial position of row
        ``row`` (Fig. 13, 3-deg increments).
    start, stop : float, optional
        First and last position [mm] (axial) or [deg] (around); default the
        whole cylinder, or one column spacing either side of ``col``... for
        a full turn on a closed layout.
    increment : float, optional
        Step between positions [mm] or [deg]; default 0.6 mm or 3 deg.
    force_n : float, optional
        Probe force [N]; default 50 g.
    dwell_s : float
        Time the probe is held at each position (equal times, as in the paper) [s].
    lift_s : float
        Time the probe is lifted between positions (0: it slides) [s].
    settle_s : float
        Untouched time before the sweep, for a baseline [s].
    """
    if along not in ("axial", "around"):
        raise TactsenseInputError(f"along must be 'axial' or 'around'; got {along!r}")
    row = default_row(spec) if row is None else int(row)
    col = default_col(spec) if col is None else int(col)
    if along == "axial":
        _check_col(spec, col)
    else:
        _check_row(spec, row)
    force_n = grams_force(50.0) if force_n is None else check_positive(force_n, "force_n")
    if along == "axial":
        increment = 0.6 if increment is None else increment
        start = 0.0 if start is None else start
        stop = spec.body.cylinder_length_mm if stop is None else stop
        fixed_angle = float(spec.col_angle_deg[col])
    else:
        increment = 3.0 if increment is None else increment
        half_span = (
            180.0
            if spec.closes_circumference
            else (spec.array.wired_cols / 2 * spec.array.spacing_angle_deg)
        )
        centre = 0.0 if spec.closes_circumference else float(np.mean(spec.col_angle_deg))
        start = centre - half_span if start is None else start
        stop = centre + half_span if stop is None else stop
        fixed_axial = float(spec.row_axial_mm[row])
    check_positive(increment, "increment")
    if stop < start:
        raise TactsenseInputError(f"stop ({stop}) must not be smaller than start ({start})")
    positions = np.arange(start, stop + 1e-9, increment)
    steps = _settle(settle_s)
    for position in positions:
        if along == "axial":
            probe = Probe(float(position), fixed_angle, force_n, contact_diameter_mm)
        else:
            probe = Probe(fixed_axial, float(position), force_n, contact_diameter_mm)
        steps.append(Step((probe,), dwell_s, f"{along}={position:.4g}"))
        if lift_s > 0:
            steps.append(Step((), lift_s, "lifted"))
    unit = "mm" if along == "axial" else "deg"
    return Scenario(
        tuple(steps),
        name=f"probe_sweep_{along}",
        description=(
            f"{force_n:.3g} N probe swept {along} from {start:g} to {stop:g} {unit} "
            f"in {increment:g} {unit} increments, {dwell_s:g} s each"
        ),
        parameters={
            "along": along,
            "row": row,
            "col": col,
            "start": start,
            "stop": stop,
            "increment": increment,
            "force_n": force_n,
            "dwell_s": dwell_s,
            "lift_s": lift_s,
            "settle_s": settle_s,
        },
    )


def repeated_load(
    spec: SensorSpec,
    *,
    row: int | None = None,
    col: int | None = None,
    force_n: float | None = None,
    repeats: int = 100,
    on_s: float = 1.0,
    off_s: float = 1.0,
    settle_s: float = 1.0,
) -> Scenario:
    """A weight applied repeatedly above one tactel (Figs. 10-12: jitter and creep)."""
    row, col = _tactel(spec, row, col)
    force_n = grams_force(50.0) if force_n is None else check_positive(force_n, "force_n")
    if repeats < 1:
        raise TactsenseInputError(f"repeats must be at least 1; got {repeats}")
    probe = Probe(float(spec.row_axial_mm[row]), float(spec.col_angle_deg[col]), force_n)
    steps = _settle(settle_s)
    for k in range(repeats):
        steps += [Step((probe,), on_s, f"on {k}"), Step((), off_s, f"off {k}")]
    return Scenario(
        tuple(steps),
        name="repeated_load",
        description=f"{force_n:.3g} N applied {repeats} times above tactel ({row}, {col})",
        parameters={
            "row": row,
            "col": col,
            "force_n": force_n,
            "repeats": repeats,
            "on_s": on_s,
            "off_s": off_s,
            "settle_s": settle_s,
        },
    )


def calibration_sweep(
    spec: SensorSpec,
    *,
    force_n: float | None = None,
    increment: float = 0.6,
    dwell_s: float | None = None,
    settle_s: float = 1.0,
) -> Scenario:
    """The section 3.1 calibration: a 50-g probe swept along every column in turn.

    Each sweep runs the length of the cylinder at the angle of one wired
    column, starting over the tip row when the finger has one (so that every
    tactel is reached); the probe is lifted for a second between columns.
    ``dwell_s`` [s] defaults to 0.3 s, or one scan period on a slower sensor (as is the
    lift).
    """
    period = spec.scan_period_s
    dwell_s = max(0.3, period) if dwell_s is None else check_positive(dwell_s, "dwell_s")
    force_n = grams_force(50.0) if force_n is None else check_positive(force_n, "force_n")
    steps = _settle(settle_s)
    start = float(spec.row_axial_mm[0]) if spec.array.tip_row else 0.0
    positions = np.arange(start, spec.body.cylinder_length_mm + 1e-9, increment)
    for col, angle in enumerate(spec.col_angle_deg):
        steps += [
            Step((Probe(float(p), float(angle), force_n),), dwell_s, f"col {col}")
            for p in positions
        ]
        steps.append(Step((), max(1.0, period), "lifted"))
    return Scenario(
        tuple(steps),
        name="calibration_sweep",
        description=f"{force_n:.3g} N probe swept along each of {spec.shape[1]} columns",
        parameters={"force_n": force_n, "increment": increment, "dwell_s": dwell_s},
    )


def force_steps(
    spec: SensorSpec,
    *,
    row: int | None = None,
    col: int | None = None,
    force_n: float | None = None,
    on_s: float = 1.0,
    off_s: float = 1.0,
    repeats: int = 3,
    settle_s: float = 1.0,
) -> Scenario:
    """Force steps above one tactel (Fig. 12): the load applied and removed ``repeats`` times."""
    scene = repeated_load(
        spec,
        row=row,
        col=col,
        force_n=force_n,
        repeats=repeats,
        on_s=on_s,
        off_s=off_s,
        settle_s=settle_s,
    )
    return Scenario(
        scene.steps, name="force_steps", description=scene.description, parameters=scene.parameters
    )


def knife_edge_sweep(
    spec: SensorSpec,
    *,
    row: int | None = None,
    col: int | None = None,
    force_n: float = 0.5,
    span_mm: float = 12.0,
    increment: float = 0.6,
    dwell_s: float | None = None,
    lift_s: float | None = None,
    settle_s: float = 1.0,
) -> Scenario:
    """Section 4.1: a knife edge across the finger stepped past one tactel (Fig. 16).

    ``dwell_s`` and ``lift_s`` [s] default to 0.5 s, or one scan period on a slower
    sensor.
    """
    period = spec.scan_period_s
    dwell_s = max(0.5, period) if dwell_s is None else dwell_s
    lift_s = max(0.5, period) if lift_s is None else lift_s
    row, col = _tactel(spec, row, col)
    centre = float(spec.row_axial_mm[row])
    angle = float(spec.col_angle_deg[col])
    positions = np.arange(centre - span_mm / 2, centre + span_mm / 2 + 1e-9, increment)
    steps = _settle(settle_s)
    for position in positions:
        steps.append(
            Step((knife_edge(float(position), angle, force_n),), dwell_s, f"axial={position:.4g}")
        )
        if lift_s > 0:
            steps.append(Step((), lift_s, "lifted"))
    return Scenario(
        tuple(steps),
        name="knife_edge_sweep",
        description=f"{force_n:.3g} N knife edge stepped past tactel ({row}, {col})",
        parameters={
            "row": row,
            "col": col,
            "force_n": force_n,
            "increment": increment,
            "dwell_s": dwell_s,
            "lift_s": lift_s,
        },
    )


def load_series(
    spec: SensorSpec,
    *,
    row: int | None = None,
    col: int | None = None,
    forces_n=None,
    on_s: float = 1.0,
    off_s: float = 1.0,
    settle_s: float = 1.0,
) -> Scenario:
    """Increasing weights on one cell (Fig. 6): each applied, held and removed."""
    row, col = _tactel(spec, row, col)
    forces = np.linspace(0.1, 1.0, 10) if forces_n is None else np.asarray(forces_n, float)
    probe = Probe(float(spec.row_axial_mm[row]), float(spec.col_angle_deg[col]), 1.0)
    steps = _settle(settle_s)
    for force in forces:
        steps += [
            Step((probe.moved(force_scale=float(force)),), on_s, f"{force:.4g} N"),
            Step((), off_s, "off"),
        ]
    return Scenario(
        tuple(steps),
        name="load_series",
        description=f"{forces.size} loads from {forces.min():.3g} to "
        f"{forces.max():.3g} N on tactel ({row}, {col})",
        parameters={"row": row, "col": col, "forces_n": forces.tolist()},
    )


def static(contacts, duration_s: float = 1.0, *, settle_s: float = 1.0) -> Scenario:
    """Contacts held still after an untouched settle time."""
    if not isinstance(contacts, list | tuple):
        contacts = [contacts]
    steps = _settle(settle_s)
    steps.append(Step(tuple(contacts), duration_s, "hold"))
    return Scenario(tuple(steps), name="static", description=f"{len(contacts)} contact(s) held")
