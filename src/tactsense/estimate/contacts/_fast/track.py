"""The tracker's compiled passes: the least-cost assignment and the track loop."""

from __future__ import annotations

import math

import numpy as np

from tactsense._jit import jit


@jit(nogil=True)
def hungarian(cost, far):
    """Least-cost assignment of a rectangular cost matrix (the shortest augmenting path
    form of the Hungarian method, O(n^2 m)); ``match[i]`` is the column of row ``i``, or
    -1 when it is unmatched or its pair costs ``far`` or more."""
    n0, m0 = cost.shape
    transpose = n0 > m0
    n = m0 if transpose else n0
    m = n0 if transpose else m0
    u = np.zeros(n + 1)
    v = np.zeros(m + 1)
    p = np.zeros(m + 1, np.int64)
    way = np.zeros(m + 1, np.int64)
    minv = np.empty(m + 1)
    used = np.empty(m + 1, np.bool_)
    for i in range(1, n + 1):
        p[0] = i
        j0 = 0
        minv[:] = np.inf
        used[:] = False
        while True:
            used[j0] = True
            i0 = p[j0]
            delta = np.inf
            j1 = 0
            for j in range(1, m + 1):
                if not used[j]:
                    a = cost[j - 1, i0 - 1] if transpose else cost[i0 - 1, j - 1]
                    cur = a - u[i0] - v[j]
                    if cur < minv[j]:
                        minv[j] = cur
                        way[j] = j0
                    if minv[j] < delta:
                        delta = minv[j]
                        j1 = j
            for j in range(m + 1):
                if used[j]:
                    u[p[j]] += delta
                    v[j] -= delta
                else:
                    minv[j] -= delta
            j0 = j1
            if p[j0] == 0:
                break
        while True:
            j1 = way[j0]
            p[j0] = p[j1]
            j0 = j1
            if j0 == 0:
                break
    match = np.full(n0, -1, np.int64)
    for j in range(1, m + 1):
        if p[j] != 0:
            row = j - 1 if transpose else p[j] - 1
            col = p[j] - 1 if transpose else j - 1
            if cost[row, col] < far:
                match[row] = col
    return match


@jit(inline="always")
def _move_track(i, to, t_pos, t_vel, t_force, t_dforce, t_last, t_id):
    """Track ``i``'s state into slot ``to`` (compacting the living tracks)."""
    if to != i:
        t_pos[to] = t_pos[i]
        t_vel[to] = t_vel[i]
        t_force[to] = t_force[i]
        t_dforce[to] = t_dforce[i]
        t_last[to] = t_last[i]
        t_id[to] = t_id[i]


@jit(nogil=True)
def track_into(
    frame, pos, force, start, end, t_pos, t_vel, t_force, t_dforce, t_last, t_id, counters,
    dt, gate, weight, max_missing, smoothing, slip_speed, slip_rate, far, reach,
    out_id, out_vel, out_slip, ev_frame, ev_kind, ev_id, ev_other,
):  # fmt: skip
    """The compiled :class:`~tactsense.estimate.contacts.track.ContactTracker` (same rules, same
    order of events as its Python reference ``ReferenceTracker``).

    Tracks live in ``t_*[:counters[0]]``; ``counters`` = (tracks alive, next id,
    events written). Event kinds: 0 birth, 1 death, 2 merge, 3 split. Returns -1 when
    the track or event arrays are full (the caller grows them and runs again from its
    saved state), else 0. ``reach[k]``: the gate of row ``k``'s contact for matching
    [mm] (the gate, or more for a contact larger than it); merges and splits are told
    within the gate.
    """
    n = frame.shape[0]
    cap = t_id.shape[0]
    cap_ev = ev_id.shape[0]
    lo = 0
    while lo <= n:
        f = frame[lo] if lo < n else end
        hi = lo
        while hi < n and frame[hi] == f:
            hi += 1
        # tracks unseen for more than max_missing frames die
        alive = 0
        for i in range(counters[0]):
            if f - 1 - t_last[i] > max_missing:
                if counters[2] >= cap_ev:
                    return -1
                e = counters[2]
                ev_frame[e] = t_last[i] + max_missing + 1
                ev_kind[e] = 1
                ev_id[e] = t_id[i]
                ev_other[e] = -1
                counters[2] += 1
            else:
                _move_track(i, alive, t_pos, t_vel, t_force, t_dforce, t_last, t_id)
                alive += 1
        counters[0] = alive
        if lo == n:
            break
        n_t = alive
        n_c = hi - lo
        distance = np.empty((n_t, n_c))
        cost = np.empty((n_t, n_c))
        for i in range(n_t):
            elapsed = f - t_last[i]
            for j in range(n_c):
                d2 = 0.0
                for a in range(3):
                    diff = t_pos[i, a] + t_vel[i, a] * dt * elapsed - pos[lo + j, a]
                    d2 += diff * diff
                d = math.sqrt(d2)
                distance[i, j] = d
                if d <= reach[lo + j]:
                    cost[i, j] = d + weight * abs(t_force[i] - force[lo + j])
                else:
                    cost[i, j] = far
        match = hungarian(cost, far) if n_t > 0 and n_c > 0 else np.full(n_t, -1, np.int64)
        owner = np.full(n_c, -1, np.int64)
        for i in range(n_t):
            j = match[i]
            if j < 0:
                continue
            owner[j] = i
            elapsed = dt * (f - t_last[i])
            speed2 = 0.0
            for a in range(3):
                step = (pos[lo + j, a] - t_pos[i, a]) / elapsed
                t_vel[i, a] = smoothing * step + (1.0 - smoothing) * t_vel[i, a]
                t_pos[i, a] = pos[lo + j, a]
                out_vel[lo + j, a] = t_vel[i, a]
                speed2 += t_vel[i, a] ** 2
            rate = (force[lo + j] - t_force[i]) / elapsed
            t_dforce[i] = smoothing * rate + (1.0 - smoothing) * t_dforce[i]
            t_force[i] = force[lo + j]
            t_last[i] = f
            out_id[lo + j] = t_id[i]
            steady = abs(t_dforce[i]) <= slip_rate * max(abs(t_force[i]), 1e-12)
            out_slip[lo + j] = math.sqrt(speed2) > slip_speed and steady
        # unmatched tracks that fell into another track's contact: merges
        keep = np.ones(n_t, np.bool_)
        for i in range(n_t):
            if match[i] >= 0:
                continue
            best = -1
            for j in range(n_c):
                if owner[j] >= 0 and distance[i, j] <= gate:
                    if best < 0 or distance[i, j] < distance[i, best]:
                        best = j
            if best >= 0:
                if counters[2] >= cap_ev:
                    return -1
                e = counters[2]
                ev_frame[e] = f
                ev_kind[e] = 2
                ev_id[e] = t_id[i]
                ev_other[e] = t_id[owner[best]]
                counters[2] += 1
                keep[i] = False
        # unmatched contacts: births, or splits off the nearest matched track
        parents = np.full(n_c, -1, np.int64)
        for j in range(n_c):
            if owner[j] >= 0:
                continue
            best = -1
            for i in range(n_t):
                if match[i] >= 0 and distance[i, j] <= gate:
                    if best < 0 or distance[i, j] < distance[best, j]:
                        best = i
            parents[j] = t_id[best] if best >= 0 else -1
        alive = 0
        for i in range(n_t):
            if keep[i]:
                _move_track(i, alive, t_pos, t_vel, t_force, t_dforce, t_last, t_id)
                alive += 1
        for j in range(n_c):
            if owner[j] >= 0:
                continue
            if alive >= cap or counters[2] >= cap_ev:
                return -1
            t_pos[alive] = pos[lo + j]
            t_vel[alive] = 0.0
            t_force[alive] = force[lo + j]
            t_dforce[alive] = 0.0
            t_last[alive] = f
            t_id[alive] = counters[1]
            e = counters[2]
            ev_frame[e] = f
            ev_kind[e] = 3 if parents[j] >= 0 else 0
            ev_id[e] = counters[1]
            ev_other[e] = parents[j]
            counters[2] += 1
            out_id[lo + j] = counters[1]
            for a in range(3):
                out_vel[lo + j, a] = 0.0
            out_slip[lo + j] = False
            counters[1] += 1
            alive += 1
        counters[0] = alive
        lo = hi
    return 0
