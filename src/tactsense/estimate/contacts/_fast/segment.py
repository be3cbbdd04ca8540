"""Segmentation of a grid frame into contacts (compiled): steepest ascent to a maximum,
saddles, ridges, each contact's peak, moments and taxels."""

from __future__ import annotations

import math

import numpy as np

from tactsense._jit import jit
from tactsense.estimate.contacts._fast.regions import _ridge_groups
from tactsense.estimate.contacts._fast.window import HALF_WINDOW, _surface, _wrap


@jit(nogil=True)
def segment_into(
    signal, threshold, ratio, periodic, max_contacts, refine, tolerance, max_iterations,
    count, peak_row, peak_col, row, col, value, total, mrr, mcc, mrc, taxels, converged,
    root, labels, dip_floor, ring, weak, wide, far, pair_share, point_taxels,
):  # fmt: skip
    """Segment every frame into contacts and estimate each (see ``find_contacts``).

    Merging (``find_contacts``): two maxima are one contact when the saddle between them
    is at least ``ratio`` of the lower or dips from it by less than ``dip_floor``; then
    maxima joined by ridges (saddles of at least ``ring`` of the lower maximum; taxels
    above ``weak`` but below ``threshold`` bridge regions they touch) into a group of
    three or more are one contact (a flat stamp's corners and edges, a punch's rim), as
    are regions around a hole; ``wide[f, k]``: the contact is such a group (its
    position is the centre of its signal).

    Per frame ``f`` and contact ``k < count[f]`` (by decreasing summed signal): the peak
    taxel, the fractional peak (Newton on the interpolated surface when ``refine``,
    else the centre of the region's signal), the interpolated peak value, the summed
    signal of the region, its second central moments [taxel^2], its taxel count and
    whether Newton converged; ``root[f, k]`` the flat index of its maximum, and
    ``labels[f]`` (rows, cols) that index on every taxel of the contact (-1 elsewhere).
    """
    n, rows, cols = signal.shape
    p_all = rows * cols
    parent = np.empty(p_all, np.int64)
    root_of = np.empty(p_all, np.int64)
    n_cap = 4 * p_all + 28 * p_all  # 4 forward pairs a taxel, 28 pairs a bridge
    edge_a = np.empty(n_cap, np.int64)
    edge_b = np.empty(n_cap, np.int64)
    edge_v = np.empty(n_cap, np.float64)
    edge_weak = np.zeros(n_cap, np.bool_)  # a bridge: for the ridges of the groups only
    link = np.empty(p_all, np.int64)
    group_size = np.empty(p_all, np.int64)
    group_top = np.empty(p_all, np.int64)
    touched = np.empty(8, np.int64)
    significant = np.empty(p_all, np.bool_)
    group_ring = np.empty(p_all, np.bool_)
    reach = np.empty(p_all, np.int64)
    stack = np.empty(p_all, np.int64)
    extended = np.zeros(p_all, np.bool_)
    n_sig = np.zeros(p_all, np.int64)
    box = np.zeros((p_all, 4), np.int64)
    top = np.empty(p_all, np.float64)
    sums = np.empty((p_all, 7), np.float64)  # w, w dr, w dc, w dr2, w dc2, w dr dc, count
    final = np.empty(p_all, np.int64)
    order = np.empty(p_all, np.int64)
    kr0 = np.empty(2 * HALF_WINDOW + 2)
    kr1 = np.empty_like(kr0)
    kr2 = np.empty_like(kr0)
    kc0 = np.empty_like(kr0)
    kc1 = np.empty_like(kr0)
    kc2 = np.empty_like(kr0)
    active = np.empty(p_all, np.int64)
    edge_order = np.empty(n_cap, np.int64)
    ranked = np.empty(p_all, np.int64)
    for f in range(n):
        s = signal[f]
        label = labels[f]
        # 1. the taxels above the threshold (the later passes visit only these) ...
        above = 0
        p = 0
        for r in range(rows):
            for c in range(cols):
                label[r, c] = -1
                if s[r, c] > threshold:
                    active[above] = p
                    above += 1
                else:
                    parent[p] = -1
                p += 1
        # ... each pointing to its highest neighbour (8 of them; ties go to the larger
        # index, so that no chain closes on itself)
        for t in range(above):
            p = active[t]
            r = p // cols
            c = p - r * cols
            v0 = s[r, c]
            best = p
            bv = v0
            for dr in range(-1, 2):
                rr = r + dr
                if rr < 0 or rr >= rows:
                    continue
                for dc in range(-1, 2):
                    if dr == 0 and dc == 0:
                        continue
                    cc = _wrap(c + dc, cols, periodic)
                    if cc < 0:
                        continue
                    q = rr * cols + cc
                    w = s[rr, cc]
                    if w > bv or (w == bv and q > best):
                        best = q
                        bv = w
            parent[p] = best
        count[f] = 0
        if above == 0:
            continue
        # 2. follow the chains to their maxima (steepest ascent = a watershed)
        for t in range(above):
            p = active[t]
            q = p
            while parent[q] != q:
                q = parent[q]
            root_of[p] = q
        # 3. merge maxima separated by a shallow saddle: the edges between regions,
        # highest saddle first (a union-find over the maxima)
        n_edges = 0
        for t in range(above):
            p = active[t]
            r = p // cols
            c = p - r * cols
            for k in range(4):  # forward neighbours: each pair once
                dr = 0 if k == 0 else 1
                dc = 1 if k == 0 else k - 2
                rr = r + dr
                if rr >= rows:
                    continue
                cc = _wrap(c + dc, cols, periodic)
                if cc < 0:
                    continue
                q = rr * cols + cc
                if q == p or parent[q] < 0 or root_of[q] == root_of[p]:
                    continue
                edge_a[n_edges] = root_of[p]
                edge_b[n_edges] = root_of[q]
                edge_v[n_edges] = min(s[r, c], s[rr, cc])
                edge_weak[n_edges] = False
                n_edges += 1
        # ... and taxels above ``weak`` but below the threshold that touch two regions
        # bridge them (at their own value): a rim broken by a low-gain taxel
        if weak < threshold:
            for r in range(rows):
                for c in range(cols):
                    w = s[r, c]
                    if not (w > weak and w <= threshold):
                        continue
                    n_touched = 0
                    for dr in range(-1, 2):
                        rr = r + dr
                        if rr < 0 or rr >= rows:
                            continue
                        for dc in range(-1, 2):
                            cc = _wrap(c + dc, cols, periodic)
                            if cc < 0 or (dr == 0 and dc == 0):
                                continue
                            q = rr * cols + cc
                            if parent[q] < 0:
                                continue
                            m = root_of[q]
                            seen = False
                            for u in range(n_touched):
                                if touched[u] == m:
                                    seen = True
                            if not seen:
                                touched[n_touched] = m
                                n_touched += 1
                    for u in range(n_touched):
                        for u2 in range(u + 1, n_touched):
                            edge_a[n_edges] = touched[u]
                            edge_b[n_edges] = touched[u2]
                            edge_v[n_edges] = w
                            edge_weak[n_edges] = True
                            n_edges += 1
        for t in range(above):
            p = active[t]
            if parent[p] == p:
                final[p] = p  # union-find parent among maxima
                top[p] = s[p // cols, p % cols]
                significant[p] = True
                extended[p] = False
        if n_edges > 0:
            # highest saddle first: an insertion sort (few edges), no allocation
            for t in range(n_edges):
                edge_order[t] = t
            for t in range(1, n_edges):
                e = edge_order[t]
                q = t - 1
                while q >= 0 and edge_v[edge_order[q]] < edge_v[e]:
                    edge_order[q + 1] = edge_order[q]
                    q -= 1
                edge_order[q + 1] = e
            for t in range(n_edges):
                e = edge_order[t]
                if edge_weak[e]:
                    continue
                a = edge_a[e]
                while final[a] != a:
                    a = final[a]
                b = edge_b[e]
                while final[b] != b:
                    b = final[b]
                if a == b:
                    continue
                low = min(top[a], top[b])
                saddle = edge_v[e]
                if saddle >= ratio * low or low - saddle < dip_floor:
                    # the lower maximum is a bump of the noise, or a shoulder of the
                    # higher one (it counts for the ridge groups, a noise bump does not)
                    lower = b if top[a] >= top[b] else a
                    significant[lower] = low - saddle >= dip_floor
                    if top[a] >= top[b]:
                        final[b] = a
                    else:
                        final[a] = b
            if ring > 0.0:
                _ridge_groups(
                    s, above, active, parent, root_of, final, top, significant, edge_a, edge_b,
                    edge_v, n_edges, ring, periodic, link, group_size, group_top, group_ring,
                    reach, stack, extended, weak, far, pair_share, box,
                )  # fmt: skip
        # 4. label each taxel with its merged maximum and accumulate its moments about
        # that maximum (columns unwrapped across the seam of a closed ring)
        for t in range(above):
            p = active[t]
            m = root_of[p]
            while final[m] != m:
                m = final[m]
            root_of[p] = m
        # a region holding two significant maxima or more (a shoulder besides its peak),
        # or more taxels than two point loads cover, is placed at its centre: its peak
        # may sit anywhere on it, its centre does not
        for t in range(above):
            p = active[t]
            if parent[p] == p:
                n_sig[root_of[p]] = 0
        for t in range(above):
            p = active[t]
            if parent[p] == p and significant[p]:
                n_sig[root_of[p]] += 1
        n_regions = 0
        for t in range(above):
            p = active[t]
            if parent[p] == p and final[p] == p:
                order[n_regions] = p
                for k in range(7):
                    sums[p, k] = 0.0
                n_regions += 1
        for t in range(above):
            p = active[t]
            r = p // cols
            c = p - r * cols
            m = root_of[p]
            label[r, c] = m
            mr = m // cols
            mc = m - mr * cols
            dr = float(r - mr)
            dcol = c - mc
            if periodic:
                if dcol > cols // 2:
                    dcol -= cols
                elif dcol < -(cols // 2):
                    dcol += cols
            dc = float(dcol)
            w = s[r, c]
            sums[m, 0] += w
            sums[m, 1] += w * dr
            sums[m, 2] += w * dc
            sums[m, 3] += w * dr * dr
            sums[m, 4] += w * dc * dc
            sums[m, 5] += w * dr * dc
            sums[m, 6] += 1.0
        # 5. the largest regions (by summed signal), at most max_contacts of them
        for t in range(n_regions):
            ranked[t] = t
        for t in range(1, n_regions):  # by decreasing summed signal
            e = ranked[t]
            q = t - 1
            while q >= 0 and sums[order[ranked[q]], 0] < sums[order[e], 0]:
                ranked[q + 1] = ranked[q]
                q -= 1
            ranked[q + 1] = e
        kept = min(n_regions, max_contacts)
        count[f] = kept
        for k in range(kept):
            m = order[ranked[k]]
            mr = m // cols
            mc = m - mr * cols
            w = sums[m, 0]
            cr = sums[m, 1] / w
            cc = sums[m, 2] / w
            root[f, k] = m
            peak_row[f, k] = mr
            peak_col[f, k] = mc
            total[f, k] = w
            mrr[f, k] = max(sums[m, 3] / w - cr * cr, 0.0)
            mcc[f, k] = max(sums[m, 4] / w - cc * cc, 0.0)
            mrc[f, k] = sums[m, 5] / w - cr * cc
            taxels[f, k] = int(sums[m, 6])
            u = float(mr)
            v = float(mc)
            ok = False
            centred = extended[m] or (ring > 0.0 and (n_sig[m] >= 2 or sums[m, 6] > point_taxels))
            if refine and not centred:
                # Newton on the interpolated surface of this contact, from its maximum
                for _ in range(max_iterations):
                    f0, fu, fv, fuu, fvv, fuv = _surface(
                        s, label, m, u, v, periodic, kr0, kr1, kr2, kc0, kc1, kc2
                    )
                    det = fuu * fvv - fuv * fuv
                    if not (fuu < 0.0 and det > 0.0):
                        break  # not concave here: keep the centre of the region
                    du = -(fvv * fu - fuv * fv) / det
                    dv = -(fuu * fv - fuv * fu) / det
                    step = math.hypot(du, dv)
                    if step > 0.5:
                        du *= 0.5 / step
                        dv *= 0.5 / step
                    u += du
                    v += dv
                    if abs(u - mr) > 1.0 or abs(v - mc) > 1.0:
                        break  # left the maximum's neighbourhood: not a peak of it
                    if step < tolerance:
                        ok = True
                        break
            if ok:
                row[f, k] = u
                col[f, k] = v
            else:
                row[f, k] = mr + cr
                col[f, k] = mc + cc
            f0, fu, fv, fuu, fvv, fuv = _surface(
                s, label, m, row[f, k], col[f, k], periodic, kr0, kr1, kr2, kc0, kc1, kc2
            )
            value[f, k] = f0
            converged[f, k] = ok
            wide[f, k] = extended[m]
            if periodic:
                col[f, k] = col[f, k] % cols
