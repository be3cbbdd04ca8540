"""The per-frame flaws and the transducer of ``frames_from_contacts``'s fast path.

The same arithmetic, in the same order, as the scan loop of :mod:`tactsense.simulate.run`
(``_frame_blocks``) without its memories: gains, stiffening (``nonlinearity``), the
capacitive chain (eqs. 1-2, plates held apart at 0.95) or the resistive cell, read noise,
quantization, clipping to the converter's range and dead taxels. The capacitive and the
resistive chain run compiled in one pass (:func:`_counts_pass`); a piezoresistive cell or
a resistive matrix with crosstalk runs the scan loop's own functions on each block.

The read noise is drawn in blocks by ``rng.standard_normal(dtype=float32)`` (Numpy's
ziggurat) and scaled by ``read_noise_counts``: the same distribution as the scan loop's
``rng.normal`` in float64 (not the same draws), at a fraction of its cost.
"""

from __future__ import annotations

import math

import numpy as np

from tactsense._jit import jit

BLOCK_FRAMES = 1024
"""Frames computed at a time (memory bound: a few MB whatever N)."""

_CAPACITIVE, _RESISTIVE = 0, 1


@jit(fastmath=True)
def _counts_pass(
    values,
    gains,
    nonlinear,
    saturation,
    mode,
    falling,
    nominal,
    counts_per_strain,
    c0,
    rc,
    c_load,
    drive_v,
    gain_v,
    adc_full_scale_v,
    adc_levels,
    noise,
    noise_sd,
    quantize,
    full_scale,
    alive,
    out,
):
    """Counts into ``out`` (frames, taxels) from the deflections ``values`` [-];
    ``noise`` (frames, taxels) float32 standard normals or an empty array; ``alive``
    1.0 for a taxel that reads, 0.0 for a dead one. The branches on the flaws are taken
    outside the loops over taxels, which the compiler vectorizes."""
    n, m = values.shape
    with_noise = noise.shape[0] > 0
    low = -0.5 * saturation
    sign = -1.0 if falling else 1.0
    for p in range(n):
        row = out[p]
        for q in range(m):
            row[q] = values[p, q] * gains[q]
        if nonlinear:
            for q in range(m):
                d = max(row[q], low)
                row[q] = d / (1.0 + d / saturation)
        if mode == _CAPACITIVE:
            for q in range(m):
                cap = c0[q] / (1.0 - min(row[q], 0.95))
                volts = cap * rc / math.sqrt(1.0 + (rc * (cap + c_load)) ** 2) * drive_v
                counts = gain_v[q] * volts / adc_full_scale_v * adc_levels
                row[q] = 2.0 * nominal - counts if falling else counts
        else:
            for q in range(m):
                row[q] = nominal + sign * (counts_per_strain * max(row[q], 0.0))
        if with_noise:
            for q in range(m):
                row[q] += noise_sd * noise[p, q]
        if quantize:
            for q in range(m):
                row[q] = np.rint(row[q])
        for q in range(m):
            row[q] = min(max(row[q], 0.0), full_scale) * alive[q]


def _numpy_counts(spec, values, gains, active, noise, first, last):
    """Counts of a block by the scan loop's own functions (piezoresistive cells, or a
    resistive matrix with crosstalk), ``values`` (frames, taxels) [-]."""
    from tactsense.physics.crosstalk import scan_conductance
    from tactsense.physics.flaws import stiffening
    from tactsense.physics.pad_response import resistive_counts
    from tactsense.physics.piezo import piezo_counts

    sampled = (values * gains).reshape(len(values), *spec.shape)
    if "nonlinearity" in active:
        sampled = stiffening(sampled, spec.flaws.nonlinear_saturation)
    if spec.transduction.kind == "piezoresistive":
        times = np.arange(first, last) * spec.scan_period_s
        counts, _ = piezo_counts(spec, sampled, times, active)
    else:
        if "crosstalk" in active and spec.flaws.crosstalk > 0:
            sampled = scan_conductance(np.maximum(sampled, 0.0), spec.flaws.crosstalk)
        counts = resistive_counts(spec, sampled)
    counts = counts.reshape(len(values), -1)
    if noise is not None:
        counts = counts + spec.flaws.read_noise_counts * noise
    full_scale = 2**spec.electronics.adc_bits - 1
    return np.clip(np.rint(counts) if "quantization" in active else counts, 0, full_scale)


def _compiled_mode(spec, kind, active) -> int | None:
    """The compiled chain for ``spec``, or None where the scan loop's functions run."""
    if kind.reads_capacitive(spec):
        return _CAPACITIVE
    if spec.transduction.kind == "resistive" and not (
        "crosstalk" in active and spec.flaws.crosstalk > 0
    ):
        return _RESISTIVE
    return None


def fast_frames(spec, contacts, block, active, gains, rng) -> np.ndarray:
    """Frames (N, taxels) [counts] from the kind's fast forward (``block(first, last)``,
    what its ``prepare(contacts)`` returned) and the per-frame flaws."""
    from tactsense.kinds import kind_of
    from tactsense.physics.transduction import amplifier_gain

    kind = kind_of(spec)
    n, taxels = contacts.n_frames, math.prod(spec.shape)
    out = np.empty((n, taxels))
    gains = np.ascontiguousarray(np.asarray(gains, dtype=float).reshape(taxels))
    dead = np.zeros(spec.shape, dtype=bool)
    if "dead" in active:
        for r, c in spec.flaws.dead_tactels:
            dead[r, c] = True
    dead = dead.reshape(taxels)
    alive = np.where(dead, 0.0, 1.0)
    mode = _compiled_mode(spec, kind, active)
    el, f = spec.electronics, spec.flaws
    with_noise = "noise" in active
    if mode == _CAPACITIVE:
        c0 = np.broadcast_to(np.asarray(spec.junction_capacitance_f, dtype=float), spec.shape)
        gain_v = np.broadcast_to(np.asarray(amplifier_gain(spec), dtype=float), spec.shape)
        c0 = np.ascontiguousarray(c0).reshape(taxels)
        gain_v = np.ascontiguousarray(gain_v).reshape(taxels)
        rc = 2.0 * np.pi * el.drive_frequency_hz * el.load_resistance_ohm
        c_load, drive_v = el.load_capacitance_pf * 1e-12, el.drive_voltage_v
    else:
        c0 = gain_v = np.zeros(taxels)
        rc = c_load = drive_v = 0.0
    t = getattr(spec, "transduction", None)
    falling = t is not None and t.polarity == "falling"
    counts_per_strain = t.counts_per_strain if t is not None and mode == _RESISTIVE else 0.0
    empty = np.zeros((0, taxels), dtype=np.float32)
    for first in range(0, n, BLOCK_FRAMES):
        last = min(n, first + BLOCK_FRAMES)
        values = block(first, last)
        noise = (
            rng.standard_normal((last - first, taxels), dtype=np.float32) if with_noise else None
        )
        if mode is None:
            out[first:last] = _numpy_counts(spec, values, gains, active, noise, first, last)
            out[first:last, dead] = 0.0
            continue
        _counts_pass(
            values,
            gains,
            "nonlinearity" in active,
            float(f.nonlinear_saturation),
            mode,
            falling,
            float(el.nominal_counts),
            float(counts_per_strain),
            c0,
            float(rc),
            float(c_load),
            float(drive_v),
            gain_v,
            float(el.adc_full_scale_v),
            float(2**el.adc_bits),
            empty if noise is None else noise,
            float(f.read_noise_counts),
            "quantization" in active,
            float(2**el.adc_bits - 1),
            alive,
            out[first:last],
        )
    return out
