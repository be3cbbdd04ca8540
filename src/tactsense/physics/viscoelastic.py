"""Delayed elastic response and creep of the rubber (section 3.4, Fig. 12 of the paper).

The reading follows the instantaneous elastic deflection u(t) through two
first-order memories::

    y = (1 - a_d) u + a_d m_d + a_c m_c,     tau_k dm_k/dt = u - m_k

``m_d`` is the delayed elastic response (a_d, tau_d: tens of milliseconds)
and ``m_c`` creep and elastic set (a_c, tau_c: tens of seconds). After a
held load the delayed part decays quickly and creep leaves a slowly fading
residual. The preset's constants are chosen so that, after a 1-s, 50-g
step, the reading falls to 25 % of its peak 40 ms after removal, to 10 %
at 0.1 s and to 5 % at 1 s: the three numbers of section 3.4 (see
``docs/model.md``).
"""

from __future__ import annotations

import numpy as np
from scipy.signal import lfilter

from tactsense._validation import check_positive


def first_order_memory(u, dt, time_constant, axis=0, state=None):
    """First-order lag of a sampled signal, input held over each step.

    ``m[n] = e m[n-1] + (1 - e) u[n]`` with ``e = exp(-dt / tau)``.

    Parameters
    ----------
    u : ndarray
        Input samples along ``axis``.
    dt : float
        Sample interval [s].
    time_constant : float
        tau [s].
    state : ndarray, optional
        Memory before the first sample (shape of ``u`` without ``axis``); zero if None.

    Returns
    -------
    m : ndarray
        Memory at each sample, same shape as ``u``.
    last : ndarray
        Memory after the last sample, to continue in the next chunk.
    """
    check_positive(dt, "dt")
    check_positive(time_constant, "time_constant")
    u = np.asarray(u, dtype=float)
    decay = np.exp(-dt / time_constant)
    moved = np.moveaxis(u, axis, 0)
    zi = np.zeros((1, *moved.shape[1:])) if state is None else decay * np.asarray(state)[None]
    m, _ = lfilter([1.0 - decay], [1.0, -decay], moved, axis=0, zi=zi)
    return np.moveaxis(m, 0, axis), m[-1]


def viscoelastic_response(
    u,
    dt,
    *,
    delayed_fraction,
    delayed_time_constant_s,
    creep_fraction,
    creep_time_constant_s,
    axis=0,
    state=None,
):
    """Reading of a viscoelastic sensor for an elastic deflection history.

    Parameters
    ----------
    u : ndarray
        Instantaneous elastic deflection sampled every ``dt`` along ``axis`` [-].
    dt : float
        [s].
    delayed_fraction, creep_fraction : float
        a_d, a_c [-].
    delayed_time_constant_s, creep_time_constant_s : float
        tau_d, tau_c [s].
    state : tuple of two ndarrays, optional
        Memories (m_d, m_c) carried over from a previous chunk.

    Returns
    -------
    y : ndarray
        Reading [-], same shape as ``u``.
    state : tuple of two ndarrays
        Memories after the last sample.
    """
    m_d_prev, m_c_prev = (None, None) if state is None else state
    m_d, last_d = first_order_memory(u, dt, delayed_time_constant_s, axis, m_d_prev)
    m_c, last_c = first_order_memory(u, dt, creep_time_constant_s, axis, m_c_prev)
    y = (1.0 - delayed_fraction) * np.asarray(u, float) + delayed_fraction * m_d
    return y + creep_fraction * m_c, (last_d, last_c)


def sampled_viscoelastic_response(
    values,
    tick_step,
    sample_ticks,
    dt,
    *,
    delayed_fraction,
    delayed_time_constant_s,
    creep_fraction,
    creep_time_constant_s,
    state=None,
):
    """:func:`viscoelastic_response` read only where it is sampled, for a piecewise-constant
    input: the same memories, in time linear in the number of taxels.

    The scan holds each step's elastic deflection over whole ticks and reads each taxel
    at one tick per frame. Between step changes the recursion ``m[n] = e m[n-1] +
    (1 - e) u`` has the closed form ``m[a + n] = e^(n+1) m[a-1] + (1 - e^(n+1)) u``, so
    the memories are advanced from one step change to the next (for every taxel at
    once) and evaluated at the sampled ticks alone, instead of at every tick for every
    taxel (``rows * cols`` ticks per frame, each over ``rows * cols`` taxels).

    Parameters
    ----------
    values : ndarray, shape (S, N)
        Elastic deflection of each of N taxels during each of S steps [-].
    tick_step : ndarray of int, shape (K,)
        The step (an index into ``values``) held at each of K consecutive ticks.
    sample_ticks : ndarray of int, shape (F, N)
        The tick (an index into ``tick_step``) at which each taxel is read in each frame.
    dt : float
        Tick interval [s].
    delayed_fraction, creep_fraction, delayed_time_constant_s, creep_time_constant_s
        As :func:`viscoelastic_response`.
    state : tuple of two ndarrays of shape (N,), optional
        Memories after the tick before the first (zero if None).

    Returns
    -------
    y : ndarray, shape (F, N)
        Readings at the sampled ticks [-].
    state : tuple of two ndarrays
        Memories after the last of the K ticks.
    """
    check_positive(dt, "dt")
    values = np.asarray(values, dtype=float)
    tick_step = np.asarray(tick_step)
    n_taxels = values.shape[1]
    starts = np.flatnonzero(np.r_[True, tick_step[1:] != tick_step[:-1]])  # run starts
    lengths = np.diff(np.r_[starts, len(tick_step)])
    run_values = values[tick_step[starts]]  # (R, N)
    run_of_tick = np.cumsum(np.r_[False, tick_step[1:] != tick_step[:-1]])
    runs = run_of_tick[sample_ticks]  # (F, N)
    ticks_into_run = sample_ticks - starts[runs] + 1
    sampled_u = run_values[runs, np.arange(n_taxels)[None, :]]  # (F, N)
    previous = (None, None) if state is None else state
    out = (1.0 - delayed_fraction) * sampled_u
    last = []
    for fraction, tau, before in (
        (delayed_fraction, delayed_time_constant_s, previous[0]),
        (creep_fraction, creep_time_constant_s, previous[1]),
    ):
        check_positive(tau, "time_constant")
        memory = np.zeros(n_taxels) if before is None else np.asarray(before, dtype=float)
        at_start = np.empty_like(run_values)  # memory after the tick before each run
        for r in range(len(starts)):
            at_start[r] = memory
            keep = np.exp(-lengths[r] * dt / tau)
            memory = keep * memory + (1.0 - keep) * run_values[r]
        keep = np.exp(-ticks_into_run * dt / tau)
        sampled = keep * at_start[runs, np.arange(n_taxels)[None, :]] + (1.0 - keep) * sampled_u
        out = out + fraction * sampled
        last.append(memory)
    return out, (last[0], last[1])
