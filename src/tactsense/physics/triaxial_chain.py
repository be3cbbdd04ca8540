"""The three-axis pad's chain from contacts to counts over a scan (``simulate``).

Each taxel is read at its own tick of the row-major scan (``rows * cols`` ticks per
frame, as the other kinds' chains): the magnets' displacement of the step held at that
tick (:func:`tactsense.physics.triaxial.magnet_displacement`), through the layer's
memory (the flaw ``viscoelastic``: the delayed elastic response and creep of
:func:`tactsense.physics.viscoelastic.sampled_viscoelastic_response` on every
displacement component), the dipole field of all magnets and the background field,
each sensor's gain (``gain_spread``, all three axes) and offset per axis
(``gain_spread``: assembly), read noise (``noise``), quantization and the converter's
range, dead sensors (``dead``: 0 on all three axes). ``nonlinearity``, ``hysteresis``,
``drift`` and ``crosstalk`` (the capacitive and resistive chains' habits) do not act here.
"""

from __future__ import annotations

import numpy as np

from tactsense.physics.triaxial import (
    background_field_t,
    dipole_field_t,
    field_counts,
    sensor_offsets_t,
)
from tactsense.physics.viscoelastic import sampled_viscoelastic_response

_CACHED_STEPS = 4096
"""Steps whose displacement is held at a time (memory bound) [-]."""


def triaxial_frame_blocks(kind, spec, run, chunk_frames: int):
    """Yield ``(first, last, counts)``, counts of shape (last - first, rows, cols, 3)
    [counts] (float; integers where ``quantization`` is on). ``kind.elastic_batch`` gives
    the displacement of a list of states (S, rows, cols, 3) [mm]; ``run`` is the
    simulation's draw (``tactsense.simulate.run._Run``)."""
    rows, cols = spec.shape
    n_taxels = rows * cols
    period = spec.scan_period_s
    dt = period / n_taxels
    active = run.active
    n_steps = len(run.applied)
    full_scale = 2**spec.electronics.adc_bits - 1
    dead = np.zeros(spec.shape, dtype=bool)
    if "dead" in active:
        for r, c in spec.flaws.dead_tactels:
            dead[r, c] = True
    gains = np.asarray(run.gains, dtype=float)[..., None]  # one sensitivity, all axes
    offsets = sensor_offsets_t(spec) if "gain_spread" in active else 0.0
    background = background_field_t(spec)
    flat = np.arange(n_taxels)
    cache: dict[int, np.ndarray] = {}
    state = None
    for first in range(0, run.n_frames, chunk_frames):
        last = min(run.n_frames, first + chunk_frames)
        ticks = np.arange(first * n_taxels, last * n_taxels)
        tick_time = (ticks // n_taxels) * period + run.offsets.ravel()[ticks % n_taxels]
        step_of_tick = np.clip(
            np.searchsorted(run.boundaries, tick_time, side="right") - 1, 0, n_steps - 1
        )
        lo, hi = int(step_of_tick.min()), int(step_of_tick.max())
        needed = [s for s in range(lo, hi + 1) if s not in cache]
        if needed:
            if len(cache) + len(needed) > _CACHED_STEPS:
                cache = {s: v for s, v in cache.items() if lo <= s <= hi}
            values = kind.elastic_batch(spec, [run.applied[s] for s in needed])
            cache.update(zip(needed, values.reshape(len(needed), n_taxels * 3), strict=True))
        window = np.stack([cache[s] for s in range(lo, hi + 1)])  # (S, N * 3) [mm]
        local = step_of_tick - lo
        n = last - first
        if "viscoelastic" in active:
            f = spec.flaws
            sample_ticks = np.arange(n)[:, None] * n_taxels + flat[None, :]
            sampled, state = sampled_viscoelastic_response(
                window,
                local,
                np.repeat(sample_ticks, 3, axis=1),
                dt,
                delayed_fraction=f.delayed_fraction,
                delayed_time_constant_s=f.delayed_time_constant_s,
                creep_fraction=f.creep_fraction,
                creep_time_constant_s=f.creep_time_constant_s,
                state=state,
            )
        else:  # no memory: each taxel's displacement at its own tick
            own_step = local.reshape(n, n_taxels)
            sampled = window.reshape(len(window), n_taxels, 3)[own_step, flat[None, :]]
        field = dipole_field_t(spec, sampled.reshape(n, rows, cols, 3)) + background
        counts = field_counts(spec, field * gains + offsets)
        if "noise" in active:
            counts = counts + run.rng.normal(0.0, spec.flaws.read_noise_counts, counts.shape)
        counts = np.clip(np.rint(counts) if "quantization" in active else counts, 0, full_scale)
        counts[:, dead] = 0.0
        yield first, last, counts
