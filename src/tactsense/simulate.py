"""The simulator: a scenario of contacts over time in, a recording of A/D frames out.

A :class:`Scenario` is a sequence of :class:`Step` s, each a set of contacts
held for a duration (an empty set: nothing touches). :func:`simulate` runs
it through the forward model:

contacts -> elastic deflection (array_response) -> per-tactel gain ->
viscoelastic memory -> stiffening -> capacitance and voltage (eqs. 1-2) ->
read noise -> A/D counts, each tactel sampled at its own instant of the
row/column scan.

The scan clock (``rows * cols`` samples per frame) is the simulation's time
step: the load is held constant over each sample interval, so step
boundaries are resolved to one sample (2.2 ms at 7 Hz on an 8x8 array).
"""

from __future__ import annotations

import json
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np

from tactsense._validation import TactsenseInputError, check_positive
from tactsense.io.recording import Recording
from tactsense.physics.array_response import deflection_batch
from tactsense.physics.contact import Probe, contact_from_dict, grams_force, knife_edge
from tactsense.physics.crosstalk import scan_conductance
from tactsense.physics.flaws import FLAW_NAMES, draw_gains, stiffening
from tactsense.physics.pad_response import deflection_batch_flat, resistive_counts
from tactsense.physics.piezo import piezo_counts
from tactsense.physics.transduction import (
    amplifier_gain,
    divider_voltage,
    polarized,
    sample_offsets,
    voltage_to_counts,
)
from tactsense.physics.viscoelastic import sampled_viscoelastic_response
from tactsense.sensor import SensorSpec, SpecBase

_CHUNK_FRAMES = 128


@dataclass(frozen=True)
class Step:
    """Contacts held for a duration.

    Parameters
    ----------
    contacts : tuple of contacts
        What touches the skin during the step; empty for nothing.
    duration_s : float
        [s].
    label : str
        Free text stored with the recording.
    """

    contacts: tuple = ()
    duration_s: float = 1.0
    label: str = ""

    def __post_init__(self) -> None:
        check_positive(self.duration_s, "step duration_s")
        object.__setattr__(self, "contacts", tuple(self.contacts))


@dataclass(frozen=True)
class Scenario:
    """A time line of steps, with a name and a description for the recording."""

    steps: tuple[Step, ...]
    name: str = "custom"
    description: str = ""
    parameters: dict = field(default_factory=dict)

    def __post_init__(self) -> None:
        if not self.steps:
            raise TactsenseInputError("a scenario needs at least one step")
        object.__setattr__(self, "steps", tuple(self.steps))

    @property
    def duration_s(self) -> float:
        """Total duration [s]."""
        return float(sum(step.duration_s for step in self.steps))

    def to_dict(self) -> dict:
        return {
            "name": self.name,
            "description": self.description,
            "parameters": self.parameters,
            "steps": [
                {
                    "duration_s": s.duration_s,
                    "label": s.label,
                    "contacts": [c.to_dict() for c in s.contacts],
                }
                for s in self.steps
            ],
        }

    @classmethod
    def from_dict(cls, data: dict) -> Scenario:
        try:
            steps = tuple(
                Step(
                    tuple(contact_from_dict(c) for c in s["contacts"]),
                    s["duration_s"],
                    s.get("label", ""),
                )
                for s in data["steps"]
            )
        except (KeyError, TypeError) as error:
            raise TactsenseInputError(f"malformed scenario description: {error}") from None
        return cls(
            steps,
            data.get("name", "custom"),
            data.get("description", ""),
            data.get("parameters", {}),
        )


# ---- scenario builders ----------------------------------------------------------


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


# ---- the simulator --------------------------------------------------------------


def _resolve_flaws(flaws) -> tuple[str, ...]:
    if flaws is None or flaws == "none":
        return ()
    if flaws == "all":
        return FLAW_NAMES
    names = tuple(flaws.split(",")) if isinstance(flaws, str) else tuple(flaws)
    names = tuple(n.strip() for n in names if n.strip())
    unknown = [n for n in names if n not in FLAW_NAMES]
    if unknown:
        raise TactsenseInputError(
            f"unknown flaw(s) {', '.join(unknown)}; choose from {', '.join(FLAW_NAMES)}, "
            "'all' or 'none'"
        )
    return names


def _jittered_steps(spec: SensorSpec, steps: Sequence[Step], rng) -> list[tuple]:
    """Each application drawn once: force and position jitter of Figs. 10-11."""
    flaws = spec.flaws
    out = []
    for step in steps:
        contacts = []
        for contact in step.contacts:
            scale = 1.0
            if contact.force_n > 0:
                scale = max(0.0, 1.0 + rng.normal(0.0, flaws.force_jitter_n) / contact.force_n)
            d_first = rng.normal(0.0, flaws.position_jitter_mm)
            d_second = rng.normal(0.0, flaws.position_jitter_mm)
            if spec.kind == "finger":  # along the finger [mm] and around it [deg]
                d_second = math.degrees(d_second / spec.radius_mm)
            contacts.append(contact.moved(d_first, d_second, scale))
        out.append(tuple(contacts))
    return out


_STEPS_PER_WINDOW = 4096
"""Scenario steps whose elastic response is computed at a time (memory bound) [-]."""

_WRITE_FRAMES = 1024
"""Frames per HDF5 chunk and per write of :func:`simulate_to_file` [-]."""


class _ElasticWindow:
    """The elastic deflection of the applied steps, computed a window of steps at a time.

    The whole scenario at once held (steps, rows, cols) floats and every contact's load
    patches: gigabytes for a long recording. The path (the compiled one for scenarios of
    single probes, the patch sum otherwise) is chosen once for the whole scenario, as
    :func:`deflection_batch` chooses it, so a window gives the numbers the whole would.
    """

    def __init__(
        self, spec: SensorSpec, applied: list[tuple], gains: np.ndarray, forward: str = "twin"
    ):
        self.spec, self.applied, self.gains, self.forward = spec, applied, gains, forward
        probes = [s[0] for s in applied if len(s) == 1 and type(s[0]) is Probe]
        self.compiled = (
            len(probes) == len(applied) and len({p.contact_diameter_mm for p in probes}) == 1
        )
        self.first, self.values = 0, np.zeros((0, *spec.shape))

    def get(self, lo: int, hi: int) -> np.ndarray:
        """Deflection times gain of steps ``lo`` to ``hi`` inclusive, shape (k, rows, cols)."""
        if lo < self.first or hi >= self.first + len(self.values):
            stop = min(len(self.applied), max(hi + 1, lo + _STEPS_PER_WINDOW))
            states = list(self.applied[lo:stop])
            if self.spec.kind != "finger":  # a pad or a point set: the layer model
                elastic = deflection_batch_flat(self.spec, states)
            elif self.forward != "twin":  # the 3-D skin's tabulated response
                from tactsense.physics.finger3d_table import deflection_batch_3d

                elastic = deflection_batch_3d(self.spec, states, self.forward)
            elif self.compiled:
                elastic = deflection_batch(self.spec, states)
            else:  # an empty state keeps a window of probes alone on the path of the whole
                elastic = deflection_batch(self.spec, [*states, ()])[:-1]
            self.first, self.values = lo, elastic * self.gains
        return self.values[lo - self.first : hi + 1 - self.first]


@dataclass
class _Run:
    """Everything a simulation draws before its first frame."""

    active: tuple[str, ...]
    rng: np.random.Generator
    gains: np.ndarray
    applied: list[tuple]
    n_frames: int
    boundaries: np.ndarray
    offsets: np.ndarray
    forward: str = "twin"


def _prepare(spec, scenario, flaws, rng, gains, forward="twin") -> _Run:
    if not isinstance(spec, SpecBase):
        raise TactsenseInputError(
            "spec must be a sensor description (SensorSpec, PadSpec, PointsSpec); "
            f"got {type(spec).__name__}"
        )
    if not isinstance(scenario, Scenario):
        raise TactsenseInputError(f"scenario must be a Scenario; got {type(scenario).__name__}")
    from tactsense.physics.finger3d_table import check_forward

    forward = check_forward(forward, spec)
    active = _resolve_flaws(flaws)
    rng = np.random.default_rng(rng)
    n_frames = max(1, math.floor(scenario.duration_s / spec.scan_period_s + 1e-9))
    if gains is not None:
        gains = np.asarray(gains, dtype=float)
        if gains.shape != spec.shape:
            raise TactsenseInputError(f"gains has shape {gains.shape}; expected {spec.shape}")
    elif "gain_spread" in active:
        gains = draw_gains(spec)  # the finger's own gains (flaws.gain_seed)
    else:
        gains = np.ones(spec.shape)
    applied = (
        _jittered_steps(spec, scenario.steps, rng)
        if "jitter" in active
        else [step.contacts for step in scenario.steps]
    )
    boundaries = np.cumsum([0.0] + [s.duration_s for s in scenario.steps])
    if forward != "twin":  # every contact must be tabulated: say so before the work
        from tactsense.physics.finger3d_table import _tabulated

        for state in applied:
            for contact in state:
                _tabulated(contact)
    return _Run(active, rng, gains, applied, n_frames, boundaries, sample_offsets(spec), forward)


def _frame_blocks(spec: SensorSpec, run: _Run):
    """Yield ``(first, last, counts)``: the frames ``first`` to ``last`` (exclusive),
    computed :data:`_CHUNK_FRAMES` at a time; memory does not grow with the recording."""
    active, rng = run.active, run.rng
    rows, cols = spec.shape
    period = spec.scan_period_s
    ticks_per_frame = rows * cols
    dt = period / ticks_per_frame
    n_steps = len(run.applied)
    elastic = _ElasticWindow(spec, run.applied, run.gains, run.forward)
    flat_index = np.arange(ticks_per_frame)
    row_of_tick, col_of_tick = np.divmod(flat_index, cols)
    dead = np.zeros(spec.shape, dtype=bool)
    if "dead" in active:
        for r, c in spec.flaws.dead_tactels:
            dead[r, c] = True
    gain_v = amplifier_gain(spec)
    c0 = spec.junction_capacitance_f
    full_scale = 2**spec.electronics.adc_bits - 1
    state = piezo = None
    for first in range(0, run.n_frames, _CHUNK_FRAMES):
        last = min(run.n_frames, first + _CHUNK_FRAMES)
        ticks = np.arange(first * ticks_per_frame, last * ticks_per_frame)
        # the same arithmetic as Recording.sample_step: frame start + the tactel's offset
        tick_time = (ticks // ticks_per_frame) * period + run.offsets.ravel()[
            ticks % ticks_per_frame
        ]
        step_of_tick = np.clip(
            np.searchsorted(run.boundaries, tick_time, side="right") - 1, 0, n_steps - 1
        )
        lo, hi = int(step_of_tick.min()), int(step_of_tick.max())
        window = elastic.get(lo, hi)
        local = step_of_tick - lo
        if "viscoelastic" in active:
            f = spec.flaws
            # each tactel is read at its own tick of the scan (tick i of a frame reads
            # tactel i, row-major): the memories are evaluated there alone
            sample_ticks = np.arange(last - first)[:, None] * ticks_per_frame + flat_index[None, :]
            sampled, state = sampled_viscoelastic_response(
                window.reshape(len(window), -1),
                local,
                sample_ticks,
                dt,
                delayed_fraction=f.delayed_fraction,
                delayed_time_constant_s=f.delayed_time_constant_s,
                creep_fraction=f.creep_fraction,
                creep_time_constant_s=f.creep_time_constant_s,
                state=state,
            )
            sampled = sampled.reshape(last - first, rows, cols)
        else:  # no memory: only the sampled instants matter
            own_step = local.reshape(last - first, ticks_per_frame)
            sampled = window[own_step, row_of_tick, col_of_tick].reshape(last - first, rows, cols)
        if "nonlinearity" in active:
            sampled = stiffening(sampled, spec.flaws.nonlinear_saturation)
        if _capacitive(spec):
            sampled = np.minimum(sampled, 0.95)  # plates cannot touch
            counts = polarized(
                spec,
                voltage_to_counts(
                    spec, gain_v * divider_voltage(spec, c0 / (1.0 - sampled)), quantize=False
                ),
            )
        elif spec.transduction.kind == "piezoresistive":
            times = np.arange(first, last) * period
            counts, piezo = piezo_counts(spec, sampled, times, active, piezo)
        else:
            if "crosstalk" in active and spec.flaws.crosstalk > 0:
                sampled = scan_conductance(np.maximum(sampled, 0.0), spec.flaws.crosstalk)
            counts = resistive_counts(spec, sampled)
        if "noise" in active:
            counts = counts + rng.normal(0.0, spec.flaws.read_noise_counts, counts.shape)
        counts = np.clip(np.rint(counts) if "quantization" in active else counts, 0, full_scale)
        counts[:, dead] = 0.0
        yield first, last, counts


def _frame_steps(spec: SensorSpec, run: _Run, first: int, last: int) -> np.ndarray:
    """The step at the middle of the scan of frames ``first`` to ``last`` (exclusive)."""
    period = spec.scan_period_s
    mid_scan = np.arange(first, last) * period + 0.5 * period
    return np.clip(
        np.searchsorted(run.boundaries, mid_scan, side="right") - 1, 0, len(run.applied) - 1
    )


def simulate(
    spec: SensorSpec,
    scenario: Scenario,
    *,
    flaws="all",
    rng=None,
    gains: np.ndarray | None = None,
    progress: Callable[[int, int], None] | None = None,
    forward: str = "twin",
) -> Recording:
    """Run a scenario through the forward model and return the recorded frames.

    The frames are held in memory; for a long scenario write them to a file as they
    are made with :func:`simulate_to_file` (the same frames, in bounded memory).

    Parameters
    ----------
    spec : SensorSpec
        The finger.
    scenario : Scenario
        Contacts over time.
    flaws : "all", "none" or iterable of str
        Flaws to switch on, from ``gain_spread``, ``jitter``, ``noise``,
        ``quantization``, ``nonlinearity``, ``viscoelastic``, ``dead``, and the habits
        of resistive arrays ``hysteresis``, ``drift`` (piezoresistive cells) and
        ``crosstalk`` (resistive and piezoresistive matrices).
        Their parameters come from ``spec.flaws``.
    rng : int, numpy.random.Generator or None
        Source of every random draw (gains, jitter, noise).
    gains : ndarray, shape (rows, cols), optional
        Per-tactel gains to use instead of the finger's own (``gain_spread``;
        those are drawn from ``spec.flaws.gain_seed``, the same in every run).
    progress : callable(done, total), optional
        Called after each chunk of frames.
    forward : {"twin", "finger3d", "finger3d-foam"}
        The finger's elastic model: the paper's 2-D twin, or the 3-D skin's tabulated
        finite-element response with its tip (:mod:`tactsense.physics.finger3d_table`;
        probes and section 4.1's knife edge), alone or on the foam dielectric,
        recorded in the scenario's ``forward_model``.

    Returns
    -------
    Recording
        ``frames`` (T, rows, cols) A/D counts, timestamps, the truth of
        every step, the sensor and the scenario.
    """
    run = _prepare(spec, scenario, flaws, rng, gains, forward)
    dtype = np.uint16 if "quantization" in run.active else np.float64
    frames = np.empty((run.n_frames, *spec.shape), dtype=dtype)
    for first, last, counts in _frame_blocks(spec, run):
        frames[first:last] = counts
        if progress is not None:
            progress(last, run.n_frames)
    truth = _truth(spec, run.applied, _frame_steps(spec, run, 0, run.n_frames))
    return Recording(
        frames=frames,
        time_s=np.arange(run.n_frames) * spec.scan_period_s,
        sample_offset_s=run.offsets,
        sensor=spec,
        scenario={**scenario.to_dict(), "forward_model": run.forward},
        flaws=run.active,
        truth=truth,
        gains=run.gains,
    )


def _capacitive(spec) -> bool:
    """Whether the sensor reads through the paper's capacitive chain (eqs. 1-4)."""
    return spec.kind == "finger" or spec.transduction.kind == "capacitive"


def simulate_to_file(
    spec: SensorSpec,
    scenario: Scenario,
    path,
    *,
    flaws="all",
    rng=None,
    gains: np.ndarray | None = None,
    progress: Callable[[int, int], None] | None = None,
    forward: str = "twin",
) -> int:
    """Run a scenario and write the recording to a new HDF5 file as its frames are made.

    The same recording as ``write_recording(path, simulate(...))`` (the same layout,
    the same frames for the same ``rng``), in memory that does not grow with its length:
    frames, their times and the step of each frame go to the file
    :data:`_WRITE_FRAMES` at a time. The caller chooses the name (the command line
    writes to a temporary one and moves it into place); an existing file is refused.

    Parameters
    ----------
    path : path
        The new file.
    spec, scenario, flaws, rng, gains, progress
        As for :func:`simulate`.

    Returns
    -------
    int
        Frames written [-].
    """
    import datetime as _dt
    from pathlib import Path

    import h5py

    from tactsense._version import __version__
    from tactsense.io.recording import FORMAT, FORMAT_VERSION

    path = Path(path)
    if path.exists():
        raise FileExistsError(f"{path} exists; choose a new name")
    run = _prepare(spec, scenario, flaws, rng, gains, forward)
    n, shape = run.n_frames, spec.shape
    dtype = np.uint16 if "quantization" in run.active else np.float64
    chunk = max(1, min(n, _WRITE_FRAMES))
    try:
        with h5py.File(path, "w", libver=("earliest", "latest")) as h5:
            h5.attrs["format"] = FORMAT
            h5.attrs["format_version"] = FORMAT_VERSION
            h5.attrs["tactsense_version"] = __version__
            h5.attrs["created"] = _dt.datetime.now(_dt.UTC).isoformat(timespec="seconds")
            h5.attrs["sensor_toml"] = spec.to_toml_string()
            h5.attrs["scenario_json"] = json.dumps(
                {**scenario.to_dict(), "forward_model": run.forward}
            )
            h5.attrs["flaws"] = ",".join(run.active)
            h5.attrs["scan_rate_hz"] = spec.electronics.scan_rate_hz
            h5.attrs["source"] = ""
            frames = h5.create_dataset(
                "frames",
                (n, *shape),
                dtype,
                chunks=(chunk, *shape),
                maxshape=(None, *shape),
                compression="gzip",
                fletcher32=True,
            )
            frames.attrs["units"] = "counts"
            frames.attrs["axes"] = (
                "time, row (along the finger, 0 = tip), col (around)"
                if spec.kind == "finger"
                else "time, row, col"
            )
            times = h5.create_dataset("time", (n,), float, chunks=(chunk,), fletcher32=True)
            times.attrs["units"] = "s"
            h5.create_dataset("sample_offset", data=run.offsets).attrs["units"] = "s"
            h5.create_dataset("gains", data=run.gains).attrs["units"] = "1"
            truth = h5.create_group("truth")
            frame_step = truth.create_dataset(
                "frame_step", (n,), np.int64, chunks=(chunk,), compression="gzip", fletcher32=True
            )
            frame_step.attrs["units"] = "1"
            pending: list[np.ndarray] = []
            written = 0
            for _, last, counts in _frame_blocks(spec, run):
                pending.append(counts)
                if last - written >= chunk or last == n:
                    block = np.concatenate(pending).astype(dtype, copy=False)
                    pending.clear()
                    frames[written:last] = block
                    times[written:last] = np.arange(written, last) * spec.scan_period_s
                    frame_step[written:last] = _frame_steps(spec, run, written, last)
                    written = last
                if progress is not None:
                    progress(last, n)
            units = {
                "step_axial_mm": "mm",
                "step_angle_deg": "deg",
                "step_x_mm": "mm",
                "step_y_mm": "mm",
                "step_force_n": "N",
            }
            for key, value in _truth(spec, run.applied, np.zeros(0, np.int64)).items():
                if key == "frame_step":
                    continue
                if isinstance(value, str):
                    truth.attrs[key] = value
                else:
                    truth.create_dataset(key, data=value).attrs["units"] = units.get(key, "1")
    except BaseException:
        path.unlink(missing_ok=True)  # interrupted: leave nothing behind
        raise
    return written


def _truth(spec: SensorSpec, applied: list[tuple], frame_step: np.ndarray) -> dict:
    """Per-step truth (as applied, jitter included) and the step of each frame.

    The first contact's position: ``step_axial_mm``, ``step_angle_deg`` on a finger,
    ``step_x_mm``, ``step_y_mm`` on a pad or a point set.
    """
    n = len(applied)
    first = np.full(n, np.nan)
    second = np.full(n, np.nan)
    force = np.zeros(n)
    count = np.zeros(n, dtype=np.int64)
    names = ("axial_mm", "angle_deg") if spec.kind == "finger" else ("x_mm", "y_mm")
    for k, contacts in enumerate(applied):
        count[k] = len(contacts)
        force[k] = sum(c.force_n for c in contacts)
        if contacts:
            first[k] = getattr(contacts[0], names[0])
            second[k] = getattr(contacts[0], names[1])
    return {
        "frame_step": frame_step.astype(np.int64),
        f"step_{names[0]}": first,
        f"step_{names[1]}": second,
        "step_force_n": force,
        "step_n_contacts": count,
        "step_contacts_json": json.dumps([[c.to_dict() for c in s] for s in applied]),
    }
