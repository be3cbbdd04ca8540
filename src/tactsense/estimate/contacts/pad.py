"""A pad's contacts: force and position from the layer's response to the scenarios'
probe, which the pad's kind tabulates (:meth:`~tactsense.kinds.Kind.contact_response`)."""

from __future__ import annotations

import functools
import math

import numpy as np

from tactsense._signals import deferred_interrupts
from tactsense.estimate._kind import kind_or_none
from tactsense.estimate.reading import signal_noise_variance
from tactsense.kinds import kind_of


@functools.lru_cache(maxsize=16)
def point_taxels(sensor) -> int:
    """Most taxels two point loads cover on a pad (inf otherwise): twice the most taxels
    reading 0.1 of a 1.6-mm probe's peak or more, over its sub-taxel positions [-]. A
    contact over more is placed at the centre of its signal, not at its peak."""
    kind = kind_or_none(sensor)
    if kind is None or not kind.response_fit:
        return 1 << 30
    kernel, _, _ = pad_force_kernel(sensor)
    peak = kernel.max(axis=(2, 3), keepdims=True)
    return 2 * int((kernel >= 0.1 * peak).sum(axis=(2, 3)).max())


@functools.lru_cache(maxsize=16)
def point_reach(sensor) -> float:
    """Distance between two maxima beyond which two point loads cannot make a ridge
    between them [taxel] (pads; inf otherwise): twice the farthest a 1.6-mm probe's
    response reaches 0.1 of its peak (over its sub-taxel positions), plus twice the
    farthest a load lies from its peak taxel along a row or a column (half a taxel),
    plus one taxel."""
    kind = kind_or_none(sensor)
    if kind is None or not kind.response_fit:
        return math.inf
    kernel, step, half = pad_force_kernel(sensor)
    reach = 0.0
    n = kernel.shape[0]
    offsets = np.arange(-half, half + 1, dtype=float)
    for a in range(n):
        for b in range(n):
            k = kernel[a, b]
            ii, jj = np.nonzero(k >= 0.1 * k.max())
            d = np.hypot(offsets[ii] - a * step, offsets[jj] - b * step)
            reach = max(reach, float(d.max()))
    return 2.0 * reach + 2.0


@functools.lru_cache(maxsize=16)
def pad_force_kernel(sensor, n_sub: int = 8, signed: bool = False):
    """The signal of the taxels around the scenarios' probe (1.6-mm sphere) per newton,
    for the probe at ``n_sub + 1`` sub-taxel offsets along each axis.

    ``signed``: a resistive taxel's strain before it is clipped at zero (a resistive
    taxel reads compression only), so that the responses to several loads add up (the
    tension beside one load cancels part of the compression under the next).

    Returns ``(kernel, step, half)``: ``kernel[a, b, i, j]`` is the signal [-/N] of the
    taxel at offset ``(i - half, j - half)`` from the taxel nearest below the probe, for
    the probe at ``(a, b) * step`` taxels from that taxel. Computed on a pad of the same
    pitch, electrodes, layer and transduction large enough for the window (the layer's
    response does not depend on where it is applied): the kind's
    :meth:`~tactsense.kinds.Kind.contact_response`.
    """
    from tactsense.estimate.contacts._fast import HALF_WINDOW

    half = HALF_WINDOW
    kernel = kind_of(sensor).contact_response(sensor, half=half, n_sub=n_sub, signed=signed)
    return kernel, 1.0 / n_sub, half


FIT_STEPS = 32
"""Sub-taxel positions per taxel of the model-based fit's table (1/32 taxel apart)."""


def pad_fit(signal, labels, seg, sensor):
    """Maximum-likelihood row, column [taxel] and force [N] of each contact of a pad
    (:func:`~tactsense.estimate.contacts._fast.fit_into`)."""
    from tactsense.estimate.contacts._fast import fit_into

    n = len(seg["frame"])
    row, col, force = np.empty(n), np.empty(n), np.empty(n)
    if n:
        kernel, _, half = pad_force_kernel(sensor, FIT_STEPS)
        with deferred_interrupts():
            fit_into(
                signal, labels, seg["frame"], seg["root"], seg["peak_row"], seg["peak_col"],
                kernel, half, row, col, force,
            )  # fmt: skip
    return row, col, force


def pad_contact_force(signal, labels, seg, sensor) -> np.ndarray:
    """Force of each contact of a pad [N] (see :func:`find_contacts`)."""
    from tactsense.estimate.contacts._fast import amplitude_fit

    n = len(seg["frame"])
    force = np.empty(n)
    if n == 0:
        return force
    kernel, step, half = pad_force_kernel(sensor)
    with deferred_interrupts():
        amplitude_fit(
            signal, labels, seg["frame"], seg["root"], seg["row"], seg["col"], kernel, step,
            half, force,
        )  # fmt: skip
    return force


MERGED_GAIN = 25.0
"""Two loads replace one in a contact's force only when they lower the residual by more
than this many times one taxel's noise variance (:func:`pad_merged_force`) [-]."""

MERGED_SPREAD = 0.2
"""A contact is looked at for two loads only when it is wider along its major axis
than one load would be by more than this [taxel^2] (two loads d apart add (d/2)^2)."""

MERGED_HALVES = np.arange(0.25, 2.51, 0.125)
"""Half-separations of the two loads tried along a contact's major axis [taxel]."""


@functools.lru_cache(maxsize=16)
def _kernel_total(sensor) -> float:
    """The summed signal of :func:`pad_force_kernel`'s window per newton, averaged over
    the load's sub-taxel positions [-/N]: an extended contact's force is its summed
    signal over this (``find_contacts``)."""
    kernel, _, _ = pad_force_kernel(sensor)
    return float(kernel.sum(axis=(2, 3)).mean())


@functools.lru_cache(maxsize=16)
def _kernel_max(sensor) -> np.ndarray:
    """The largest response of each taxel of :func:`pad_force_kernel`'s signed window
    over every tabulated load position [-/N] (for :func:`pad_merged_force`'s skip)."""
    kernel, _, _ = pad_force_kernel(sensor, FIT_STEPS, signed=True)
    return np.ascontiguousarray(kernel.max(axis=(0, 1)))


def pad_merged_force(signal, labels, seg, row, col, sensor, threshold, force) -> None:
    """A pad contact that holds two loads too close to part carries the force of both:
    ``force`` [N] is replaced in place by the two loads' summed amplitudes where two
    explain the contact's signal clearly better than one
    (:func:`~tactsense.estimate.contacts._fast.merged_force`, :data:`MERGED_GAIN`)."""
    from tactsense.estimate.contacts._fast import merged_force

    if len(force) == 0:
        return
    kernel, step, half = pad_force_kernel(sensor, FIT_STEPS, signed=True)
    noise_var = signal_noise_variance(sensor)
    # a resistive taxel's zero may hide tension: only the taxels clearly compressed
    # tell the loads' sum; a capacitive taxel reads both signs
    resistive = sensor.transduction.kind != "capacitive"
    floor = 3.0 * math.sqrt(noise_var) if resistive else -math.inf
    with deferred_interrupts():
        merged_force(
            signal, labels, seg["frame"], seg["root"], np.asarray(row, float),
            np.asarray(col, float), seg["rr"], seg["cc"], seg["rc"], kernel, step, half,
            MERGED_HALVES, noise_var, MERGED_GAIN, floor, float(threshold), MERGED_SPREAD,
            force, _kernel_max(sensor),
        )  # fmt: skip
