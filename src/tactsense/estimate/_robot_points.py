"""A point set's contacts, compiled (Numba): the same mathematics as
:mod:`tactsense.estimate.contacts.points` (the neighbour graph's steepest ascent, the
saddle merge, the quadratic peak in the tangent plane, the amplitude of the response to
a load at the nearest taxel), for the whole hand's one compiled call
(:mod:`._robot_kernel`)."""

from __future__ import annotations

import math

import numpy as np

from tactsense._jit import jit


@jit(inline="always")
def _find(final, a):
    while final[a] != a:
        a = final[a]
    return a


@jit(inline="always")
def _before(v0, a0, b0, v, a, b):
    """Whether (v0, a0, b0) sorts before (v, a, b) in decreasing tuple order."""
    return v0 < v or (v0 == v and (a0 < a or (a0 == a and b0 < b)))


@jit(nogil=True)
def points_labels(s, threshold, saddle, floor, nb_offset, neighbours, label):
    """Labels of one frame (the maximum each taxel climbs to, -1 below the threshold),
    as ``points._points_segment``."""
    n = s.shape[0]
    parent = np.full(n, -1, np.int64)
    for i in range(n):
        if not s[i] > threshold:
            continue
        best = i
        value = s[i]
        for q in range(nb_offset[i], nb_offset[i + 1]):
            j = neighbours[q]
            if s[j] > value or (s[j] == value and j > best):
                best = j
                value = s[j]
        parent[i] = best
    root = parent.copy()
    for i in range(n):
        if parent[i] >= 0:
            q = i
            while parent[q] != q:
                q = parent[q]
            root[i] = q
    # edges between regions, sorted as Python sorts (value, a, b) tuples, largest first
    m = 0
    for i in range(n):
        if parent[i] >= 0:
            m += nb_offset[i + 1] - nb_offset[i]
    e_v = np.empty(m)
    e_a = np.empty(m, np.int64)
    e_b = np.empty(m, np.int64)
    m = 0
    for i in range(n):
        if parent[i] < 0:
            continue
        for q in range(nb_offset[i], nb_offset[i + 1]):
            j = neighbours[q]
            if j > i and parent[j] >= 0 and root[j] != root[i]:
                v, a, b = min(s[i], s[j]), root[i], root[j]
                t = m
                while t > 0 and _before(e_v[t - 1], e_a[t - 1], e_b[t - 1], v, a, b):
                    e_v[t] = e_v[t - 1]
                    e_a[t] = e_a[t - 1]
                    e_b[t] = e_b[t - 1]
                    t -= 1
                e_v[t] = v
                e_a[t] = a
                e_b[t] = b
                m += 1
    final = np.arange(n)
    for t in range(m):
        a = _find(final, e_a[t])
        b = _find(final, e_b[t])
        if a == b:
            continue
        low = min(s[a], s[b])
        if e_v[t] >= saddle * low or low - e_v[t] < floor:
            if s[a] >= s[b]:
                final[b] = a
            else:
                final[a] = b
    for i in range(n):
        label[i] = _find(final, root[i]) if root[i] >= 0 else -1


@jit(nogil=True)
def _tangent(normal):
    if abs(normal[2]) < 0.9:
        hx, hy, hz = 0.0, 0.0, 1.0
    else:
        hx, hy, hz = 1.0, 0.0, 0.0
    t1 = np.empty(3)
    t1[0] = normal[1] * hz - normal[2] * hy
    t1[1] = normal[2] * hx - normal[0] * hz
    t1[2] = normal[0] * hy - normal[1] * hx
    t1 /= math.sqrt(t1[0] ** 2 + t1[1] ** 2 + t1[2] ** 2)
    t2 = np.empty(3)
    t2[0] = normal[1] * t1[2] - normal[2] * t1[1]
    t2[1] = normal[2] * t1[0] - normal[0] * t1[2]
    t2[2] = normal[0] * t1[1] - normal[1] * t1[0]
    return t1, t2


@jit(nogil=True)
def points_peak(s, usable, peak, positions, normals, nb_offset, neighbours, point):
    """The quadratic peak of ``points._points_peak`` into ``point`` (3,) [mm]; returns
    the fitted peak value and whether the fit had a peak within reach."""
    t1, t2 = _tangent(normals[peak])
    size = nb_offset[peak + 1] - nb_offset[peak] + 1
    around = np.empty(size, np.int64)
    m = 0
    if usable[peak]:
        around[0] = peak
        m = 1
    for q in range(nb_offset[peak], nb_offset[peak + 1]):
        if usable[neighbours[q]]:
            around[m] = neighbours[q]
            m += 1
    u = np.empty(m)
    v = np.empty(m)
    values = np.empty(m)
    for i in range(m):
        d = positions[around[i]] - positions[peak]
        u[i] = d[0] * t1[0] + d[1] * t1[1] + d[2] * t1[2]
        v[i] = d[0] * t2[0] + d[1] * t2[1] + d[2] * t2[2]
        values[i] = s[around[i]]
    if m >= 6:
        design = np.empty((m, 6))
        for i in range(m):
            design[i, 0] = 1.0
            design[i, 1] = u[i]
            design[i, 2] = v[i]
            design[i, 3] = u[i] * u[i]
            design[i, 4] = v[i] * v[i]
            design[i, 5] = u[i] * v[i]
        coef = np.linalg.lstsq(design, values, rcond=-1.0)[0]
        b, c, d, e, f = coef[1], coef[2], coef[3], coef[4], coef[5]
        det = 4.0 * d * e - f * f
        if d < 0 and det > 0:
            du = (-b * 2.0 * e + c * f) / det
            dv = (-c * 2.0 * d + b * f) / det
            reach = 0.0
            for i in range(m):
                reach = max(reach, math.hypot(u[i], v[i]))
            if math.hypot(du, dv) <= reach:
                for i in range(3):
                    point[i] = positions[peak, i] + du * t1[i] + dv * t2[i]
                value = coef[0] + b * du + c * dv + d * du * du + e * dv * dv + f * du * dv
                return value, True
    weight = 0.0
    for i in range(3):
        point[i] = 0.0
    for i in range(m):
        w = max(values[i], 0.0)
        weight += w
        for a in range(3):
            point[a] += w * positions[around[i], a]
    for a in range(3):
        point[a] /= weight
    return s[peak], False


@jit(nogil=True)
def points_patch(
    signal, rail, threshold, saddle, floor, max_contacts, positions, normals, nb_offset,
    neighbours, kernel, frame_flags, saturated_flag, not_converged_flag,
    out_point, out_value, out_force, out_taxels, out_flags, out_count, out_nearest,
):  # fmt: skip
    """The contacts of one point set over ``n`` frames of its signal (n, 1, N), as
    ``find_contacts(..., method="interpolate")``, largest summed signal first.
    ``kernel`` (N * N): row i the response to 1 N on taxel i [-/N]."""
    n = signal.shape[0]
    size = signal.shape[2]
    label = np.empty(size, np.int64)
    usable = np.empty(size, np.bool_)
    roots = np.empty(size, np.int64)
    totals = np.empty(size)
    point = np.empty(3)
    found_point = np.empty((size, 3))
    found_value = np.empty(size)
    found_force = np.empty(size)
    found_taxels = np.empty(size, np.int64)
    found_flag = np.empty(size, np.int64)
    found_nearest = np.empty(size, np.int64)
    for f in range(n):
        s = signal[f, 0]
        points_labels(s, threshold, saddle, floor, nb_offset, neighbours, label)
        n_roots = 0
        for r in range(size):  # the regions in increasing root, as np.unique gives them
            if label[r] != r:
                continue
            total = 0.0
            own_count = 0
            for i in range(size):
                usable[i] = label[i] == r or label[i] < 0
                if label[i] == r:
                    total += s[i]
                    own_count += 1
            value, ok = points_peak(s, usable, r, positions, normals, nb_offset, neighbours, point)
            nearest = 0
            best = math.inf
            for i in range(size):
                d = math.sqrt(
                    (positions[i, 0] - point[0]) ** 2 + (positions[i, 1] - point[1]) ** 2
                    + (positions[i, 2] - point[2]) ** 2
                )  # fmt: skip
                if d < best:
                    best = d
                    nearest = i
            num = 0.0
            den = 0.0
            for i in range(size):
                if usable[i]:
                    g = kernel[nearest * size + i]
                    num += g * s[i]
                    den += g * g
            force = num / den
            flag = frame_flags[f] | (0 if ok else not_converged_flag)
            if flag & saturated_flag:
                clipped = False
                for i in range(size):
                    if label[i] == r and rail[f, 0, i]:
                        clipped = True
                if clipped:
                    force = np.nan
                else:
                    flag &= ~saturated_flag
            # insert by decreasing total, after equal ones (Python's stable sort)
            t = n_roots
            while t > 0 and totals[t - 1] < total:
                roots[t] = roots[t - 1]
                totals[t] = totals[t - 1]
                found_point[t] = found_point[t - 1]
                found_value[t] = found_value[t - 1]
                found_force[t] = found_force[t - 1]
                found_taxels[t] = found_taxels[t - 1]
                found_flag[t] = found_flag[t - 1]
                found_nearest[t] = found_nearest[t - 1]
                t -= 1
            roots[t] = r
            totals[t] = total
            found_point[t] = point
            found_value[t] = value
            found_force[t] = force
            found_taxels[t] = own_count
            found_flag[t] = flag
            found_nearest[t] = nearest
            n_roots += 1
        out_count[f] = min(n_roots, max_contacts)
        for j in range(out_count[f]):
            out_point[f, j] = found_point[j]
            out_value[f, j] = found_value[j]
            out_force[f, j] = found_force[j]
            out_taxels[f, j] = found_taxels[j]
            out_flags[f, j] = found_flag[j]
            out_nearest[f, j] = found_nearest[j]
