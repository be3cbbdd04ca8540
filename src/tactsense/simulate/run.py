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
from dataclasses import dataclass

import numpy as np

from tactsense._validation import TactsenseInputError
from tactsense.io.recording import Recording
from tactsense.kinds import kind_of
from tactsense.physics.crosstalk import scan_conductance
from tactsense.physics.flaws import FLAW_NAMES, draw_gains, stiffening
from tactsense.physics.pad_response import resistive_counts
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
from tactsense.simulate.scenario import Scenario, Step

_CHUNK_FRAMES = 128


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
    kind = kind_of(spec)
    out = []
    for step in steps:
        contacts = []
        for contact in step.contacts:
            scale = 1.0
            if contact.force_n > 0:
                scale = max(0.0, 1.0 + rng.normal(0.0, flaws.force_jitter_n) / contact.force_n)
            d_first = rng.normal(0.0, flaws.position_jitter_mm)
            d_second = rng.normal(0.0, flaws.position_jitter_mm)
            d_first, d_second = kind.jitter(spec, d_first, d_second)  # the kind's coordinates
            contacts.append(contact.moved(d_first, d_second, scale))
        out.append(tuple(contacts))
    return out


_STEPS_PER_WINDOW = 4096
"""Scenario steps whose elastic response is computed at a time (memory bound) [-]."""


class _ElasticWindow:
    """The elastic deflection of the applied steps, computed a window of steps at a time.

    The whole scenario at once held (steps, rows, cols) floats and every contact's load
    patches: gigabytes for a long recording. The path (on a finger: the compiled one for
    scenarios of single probes, the patch sum otherwise) is chosen once for the whole
    scenario by the kind (``Kind.elastic_window_alone``), so a window gives the numbers
    the whole would.
    """

    def __init__(
        self, spec: SensorSpec, applied: list[tuple], gains: np.ndarray, forward: str = "twin"
    ):
        self.spec, self.applied, self.gains, self.forward = spec, applied, gains, forward
        self.kind = kind_of(spec)
        self.alone = self.kind.elastic_window_alone(applied)
        self.first, self.values = 0, np.zeros((0, *spec.shape))

    def get(self, lo: int, hi: int) -> np.ndarray:
        """Deflection times gain of steps ``lo`` to ``hi`` inclusive, shape (k, rows, cols)."""
        if lo < self.first or hi >= self.first + len(self.values):
            stop = min(len(self.applied), max(hi + 1, lo + _STEPS_PER_WINDOW))
            states = list(self.applied[lo:stop])
            elastic = self.kind.elastic_batch(
                self.spec, states, forward=self.forward, alone=self.alone
            )
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
    forward = kind_of(spec).check_forward(spec, forward)
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
    own = kind_of(spec).frame_blocks(spec, run, _CHUNK_FRAMES)
    if own is not None:  # a kind with its own chain (three-axis taxels)
        yield from own
        return
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
    frames = np.empty((run.n_frames, *spec.frame_shape), dtype=dtype)
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
    return kind_of(spec).reads_capacitive(spec)


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
    names = kind_of(spec).position_names
    for k, contacts in enumerate(applied):
        count[k] = len(contacts)
        force[k] = sum(c.force_n for c in contacts)
        if contacts:
            first[k] = getattr(contacts[0], names[0])
            second[k] = getattr(contacts[0], names[1])
    truth = {
        "frame_step": frame_step.astype(np.int64),
        f"step_{names[0]}": first,
        f"step_{names[1]}": second,
        "step_force_n": force,
        "step_n_contacts": count,
        "step_contacts_json": json.dumps([[c.to_dict() for c in s] for s in applied]),
    }
    # ---- shear and slip truth (r8-triphys) ----
    pressed = [c for contacts in applied for c in contacts]
    if kind_of(spec).senses_shear and pressed and all(hasattr(c, "shear_x_n") for c in pressed):
        truth.update(_shear_truth(applied))
    return truth


def _shear_truth(applied: list[tuple]) -> dict:
    """Per step: the tangential force the contacts pass to the skin (x, y) [N] (each
    limited to mu times its normal force), and the first contact's slip state
    (``step_slip``: 0 stick, 1 partial slip, 2 gross slip; 0 without contact) and stick
    ratio ``c/a`` (``step_stick_ratio`` [-], NaN without contact), Cattaneo-Mindlin's
    (:func:`tactsense.physics.triaxial.slip_state`)."""
    from tactsense.physics.triaxial import slip_state, transmitted_shear_n

    n = len(applied)
    shear = np.zeros((n, 2))
    slip = np.zeros(n, dtype=np.int64)
    stick = np.full(n, np.nan)
    for k, contacts in enumerate(applied):
        for c in contacts:
            shear[k] += transmitted_shear_n(c)
        if contacts:
            slip[k], stick[k] = slip_state(contacts[0])
    return {
        "step_shear_x_n": shear[:, 0],
        "step_shear_y_n": shear[:, 1],
        "step_slip": slip,
        "step_stick_ratio": stick,
    }
    # ---- /shear and slip truth (r8-triphys) ----
