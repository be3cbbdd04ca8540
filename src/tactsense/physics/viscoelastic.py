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
