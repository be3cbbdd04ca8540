"""Contacts on a point set: no grid, the neighbour graph of the taxels."""

from __future__ import annotations

import functools
import math

import numpy as np

from tactsense.estimate.contacts.segment import _extent, dip_floor
from tactsense.estimate.results import ContactTable, Flag
from tactsense.kinds import kind_of


@functools.lru_cache(maxsize=16)
def _points_geometry(sensor):
    """Positions [mm], normals, and each taxel's neighbours: the taxels closer than 1.5
    times the distance to its nearest one (at least its 3 nearest)."""
    positions = np.asarray(sensor.taxel_positions_mm(), dtype=float)
    normals = np.asarray(sensor.taxel_normals(), dtype=float)
    distance = np.linalg.norm(positions[:, None, :] - positions[None, :, :], axis=-1)
    np.fill_diagonal(distance, np.inf)
    nearest = distance.min(axis=1)
    neighbours = []
    for i in range(len(positions)):
        chosen = np.flatnonzero(distance[i] <= 1.5 * nearest[i])
        if len(chosen) < 3:
            chosen = np.argsort(distance[i])[: min(3, len(positions) - 1)]
        neighbours.append(chosen)
    # symmetric: a neighbour of a neighbour's list
    links = [set(map(int, n)) for n in neighbours]
    for i, n in enumerate(neighbours):
        for j in n:
            links[int(j)].add(i)
    return positions, normals, tuple(np.array(sorted(x), dtype=np.int64) for x in links)


@functools.lru_cache(maxsize=16)
def points_force_kernel(sensor):
    """The signal of every taxel per newton of the scenarios' probe (1.6-mm sphere)
    centred on each taxel, shape (N, N) [-/N]: row i for the probe on taxel i (the
    kind's :meth:`~tactsense.kinds.Kind.contact_response`)."""
    return kind_of(sensor).contact_response(sensor)


def _points_segment(s, threshold, saddle, neighbours, floor=None):
    """Labels (the maximum each taxel climbs to, -1 below the threshold) of one frame
    (``floor``: the smallest dip that keeps two maxima apart, :func:`dip_floor`)."""
    floor = threshold if floor is None else floor
    n = len(s)
    parent = np.full(n, -1)
    for i in range(n):
        if not s[i] > threshold:
            continue
        best, value = i, s[i]
        for j in neighbours[i]:
            if s[j] > value or (s[j] == value and j > best):
                best, value = int(j), s[j]
        parent[i] = best
    root = parent.copy()
    for i in np.flatnonzero(parent >= 0):
        q = i
        while parent[q] != q:
            q = parent[q]
        root[i] = q
    edges = []
    for i in np.flatnonzero(parent >= 0):
        for j in neighbours[i]:
            if j > i and parent[j] >= 0 and root[j] != root[i]:
                edges.append((min(s[i], s[j]), root[i], root[j]))
    final = {int(r): int(r) for r in np.unique(root[root >= 0])}

    def find(a):
        while final[a] != a:
            a = final[a]
        return a

    for value, a, b in sorted(edges, reverse=True):
        a, b = find(int(a)), find(int(b))
        if a == b:
            continue
        low = min(s[a], s[b])
        if value >= saddle * low or low - value < floor:
            if s[a] >= s[b]:
                final[b] = a
            else:
                final[a] = b
    return np.array([find(int(r)) if r >= 0 else -1 for r in root])


def _tangent_frame(normal):
    helper = np.array([0.0, 0.0, 1.0]) if abs(normal[2]) < 0.9 else np.array([1.0, 0.0, 0.0])
    t1 = np.cross(normal, helper)
    t1 /= np.linalg.norm(t1)
    return t1, np.cross(normal, t1)


def _points_peak(s, own, peak, positions, normals, neighbours):
    """Peak of a weighted quadratic fit in the tangent plane of the contact's largest
    taxel, over it and its neighbours: ``s = a + b u + c v + d u^2 + e v^2 + f u v``.

    A point set has no grid for a sinc interpolation; a quadratic through the largest
    reading and its neighbours is the smallest smooth surface with a peak (the
    two-dimensional form of the three-point parabola), and the fit needs no spacing.
    Returns the 3-D point, the fitted peak, and whether the fit had a peak within one
    neighbour distance (else the centre of the contact's signal is used)."""
    t1, t2 = _tangent_frame(normals[peak])
    around = np.concatenate([[peak], neighbours[peak]])
    around = around[own[around]]
    offsets = positions[around] - positions[peak]
    u, v = offsets @ t1, offsets @ t2
    values = s[around]
    if len(around) >= 6:
        design = np.column_stack([np.ones_like(u), u, v, u * u, v * v, u * v])
        coef, *_ = np.linalg.lstsq(design, values, rcond=None)
        _, b, c, d, e, f = coef
        hessian = np.array([[2 * d, f], [f, 2 * e]])
        if d < 0 and np.linalg.det(hessian) > 0:
            du, dv = np.linalg.solve(hessian, [-b, -c])
            reach = np.max(np.hypot(u, v))
            if math.hypot(du, dv) <= reach:
                value = coef @ [1.0, du, dv, du * du, dv * dv, du * dv]
                return positions[peak] + du * t1 + dv * t2, float(value), True
    weights = np.clip(values, 0.0, None)
    centre = weights @ positions[around] / weights.sum()
    return centre, float(s[peak]), False


def _points_contacts(signal, sensor, threshold, saddle, max_contacts, method) -> ContactTable:
    positions, normals, neighbours = _points_geometry(sensor)
    kernel = points_force_kernel(sensor)
    floor = dip_floor(sensor, threshold)
    rows = []
    labels = np.full(signal.shape, -1, dtype=np.int64)
    for f in range(len(signal)):
        s = signal[f, 0]
        label = _points_segment(s, threshold, saddle, neighbours, floor)
        labels[f, 0] = label
        found = []
        for r in np.unique(label[label >= 0]):
            own = label == r
            w = np.where(own, s, 0.0)
            total = w.sum()
            centre = w @ positions / total
            d = positions[own] - centre
            cov = (w[own, None] * d).T @ d / total
            t1, t2 = _tangent_frame(normals[r])
            plane = np.array([[t1 @ cov @ t1, t1 @ cov @ t2], [t2 @ cov @ t1, t2 @ cov @ t2]])
            major, minor, angle = _extent(plane[0, 0], plane[1, 1], plane[0, 1], 1.0, 1.0)
            ok = True
            if method == "interpolate":
                point, peak, ok = _points_peak(
                    s, own | (label < 0), r, positions, normals, neighbours
                )
            else:
                point, peak = centre, float(s[r])
            nearest = int(np.argmin(np.linalg.norm(positions - point, axis=1)))
            g = kernel[nearest]
            use = own | (label < 0)
            force = float(g[use] @ s[use] / (g[use] @ g[use]))
            flag = 0 if ok else int(Flag.NOT_CONVERGED)
            found.append(
                (total, f, point, peak, force, major, minor, angle, int(own.sum()), flag, r)
            )
        found.sort(key=lambda item: -item[0])
        for rank, item in enumerate(found[:max_contacts]):
            rows.append((rank, *item))
    if not rows:
        table = ContactTable.empty(len(signal))
        table.extra["_root"] = np.zeros(0, np.int64)
        table.extra["_labels"] = labels
        table.extra["_total"] = np.zeros(0)
        return table
    rank, total, frame, point, peak, force, major, minor, angle, taxels, flag, root = zip(
        *rows, strict=True
    )
    point = np.array(point)
    nan = np.full(len(rows), np.nan)
    return ContactTable(
        frame=np.array(frame, np.int64), contact=np.array(rank, np.int64), x_mm=point[:, 0],
        y_mm=point[:, 1], z_mm=point[:, 2], row=nan, col=nan.copy(), force_n=np.array(force),
        peak=np.array(peak), major_mm=np.array(major, float), minor_mm=np.array(minor, float),
        orientation_deg=np.array(angle, float), taxels=np.array(taxels, np.int64),
        area_mm2=np.full(len(rows), np.nan), flags=np.array(flag, np.int64), n_frames=len(signal),
        extra={"_root": np.array(root, np.int64), "_labels": labels,
               "_total": np.array(total, float)},
    )  # fmt: skip
