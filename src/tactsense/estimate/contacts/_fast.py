"""Compiled passes of :mod:`tactsense.estimate.contacts` (Numba): from counts to the signal
of every taxel, segmentation of a grid frame into contacts, and each contact's position,
moments and force.

One loop over the frames of a block, each frame kept in cache; no temporary arrays per
frame (the work arrays are made once per block). The NumPy reference of the same
mathematics is in :mod:`tactsense.estimate.contacts` (``_segment_reference``); the test
suite holds the two to rounding.
"""

from __future__ import annotations

import math

import numpy as np

from tactsense._jit import jit
from tactsense.estimate.finger._fast import taxel_signal

HALF_WINDOW = 3
"""Taxels on each side of the peak that the interpolation uses [taxel]."""
_WINDOW = HALF_WINDOW + 1.0  # the Hann window reaches zero 4 taxels from the point
_TAYLOR = 1e-4


@jit(nogil=True)
def prepare_signal(
    frames, baseline, unusable, full_scale, resistive, falling, per_count, nan_flag, sat_flag,
    dead_flag,
):  # fmt: skip
    """Signal of every taxel and the flags of each frame, in one pass.

    Compression positive whichever way the reading moves (``falling``):
    :func:`~tactsense.estimate._fast.taxel_signal`. Unusable taxels (excluded, NaN, an
    open capacitive junction) read 0.
    """
    n, rows, cols = frames.shape
    signal = np.empty((n, rows, cols), np.float64)
    flags = np.zeros(n, np.int64)
    any_unusable = False
    for r in range(rows):
        for c in range(cols):
            if unusable[r, c]:
                any_unusable = True
    for f in range(n):
        flag = dead_flag if any_unusable else 0
        for r in range(rows):
            for c in range(cols):
                d, bits = taxel_signal(
                    float(frames[f, r, c]), baseline[r, c], unusable[r, c], full_scale,
                    resistive, falling, per_count, nan_flag, sat_flag, dead_flag,
                )  # fmt: skip
                flag |= bits
                signal[f, r, c] = d
        flags[f] = flag
    return signal, flags


_OMEGA = math.pi / _WINDOW
_COS_J = np.cos(_OMEGA * np.arange(2 * HALF_WINDOW + 2))
_SIN_J = np.sin(_OMEGA * np.arange(2 * HALF_WINDOW + 2))


@jit(inline="always")
def _axis_kernel(d, span, k0, k1, k2):
    """:func:`_kernel` at ``d - j`` for j = 0 .. span - 1 with four trigonometric calls
    in all: sin(pi (d - j)) = (-1)^j sin(pi d), and the window's cos(w (d - j)) by the
    angle-difference identity from tabulated cos(w j), sin(w j)."""
    sd = math.sin(math.pi * d)
    cd = math.cos(math.pi * d)
    swd = math.sin(_OMEGA * d)
    cwd = math.cos(_OMEGA * d)
    for j in range(span):
        t = d - j
        if abs(t) >= _WINDOW:
            k0[j] = 0.0
            k1[j] = 0.0
            k2[j] = 0.0
            continue
        sign = -1.0 if j % 2 else 1.0
        sp = sign * sd
        cp = sign * cd
        if abs(t) < _TAYLOR:
            sv = 1.0 - (math.pi * t) ** 2 / 6.0
            ds = -(math.pi**2) * t / 3.0
            d2s = -(math.pi**2) / 3.0 + math.pi**4 * t * t / 10.0
        else:
            sv = sp / (math.pi * t)
            ds = (cp - sv) / t
            d2s = (-math.pi * sp - 2.0 * ds) / t
        cw = cwd * _COS_J[j] + swd * _SIN_J[j]
        sw = swd * _COS_J[j] - cwd * _SIN_J[j]
        w = 0.5 * (1.0 + cw)
        dw = -0.5 * _OMEGA * sw
        d2w = -0.5 * _OMEGA * _OMEGA * cw
        k0[j] = sv * w
        k1[j] = ds * w + sv * dw
        k2[j] = d2s * w + 2.0 * ds * dw + sv * d2w


@jit(inline="always")
def _wrap(c, cols, periodic):
    if periodic:
        c %= cols
        return c
    return c if 0 <= c < cols else -1


@jit(nogil=True)
def _surface(s, label, own, u, v, periodic, kr0, kr1, kr2, kc0, kc1, kc2):
    """Value, gradient and Hessian at (u, v) of the interpolated surface of the taxels
    labelled ``own`` (other contacts' taxels count as 0; the rest as read)."""
    rows, cols = s.shape
    r0 = math.floor(u) - HALF_WINDOW
    c0 = math.floor(v) - HALF_WINDOW
    span = 2 * HALF_WINDOW + 2
    _axis_kernel(u - r0, span, kr0, kr1, kr2)
    _axis_kernel(v - c0, span, kc0, kc1, kc2)
    f = 0.0
    fu = 0.0
    fv = 0.0
    fuu = 0.0
    fvv = 0.0
    fuv = 0.0
    for i in range(span):
        r = r0 + i
        if r < 0 or r >= rows or (kr0[i] == 0.0 and kr1[i] == 0.0):
            continue
        a0 = 0.0
        a1 = 0.0
        a2 = 0.0
        for j in range(span):
            c = _wrap(c0 + j, cols, periodic)
            if c < 0:
                continue
            lab = label[r, c]
            if lab >= 0 and lab != own:
                continue
            z = s[r, c]
            a0 += kc0[j] * z
            a1 += kc1[j] * z
            a2 += kc2[j] * z
        f += kr0[i] * a0
        fu += kr1[i] * a0
        fv += kr0[i] * a1
        fuu += kr2[i] * a0
        fvv += kr0[i] * a2
        fuv += kr1[i] * a1
    return f, fu, fv, fuu, fvv, fuv


@jit(inline="always")
def _find(uf, a):
    while uf[a] != a:
        a = uf[a]
    return a


@jit(inline="always")
def _join(link, final, root_of, q, anchor):
    """Link the region of taxel ``q`` to ``anchor`` (the first region met, if none yet);
    the anchor after."""
    m = _find(link, _find(final, root_of[q]))
    if anchor < 0:
        return m
    if m != anchor:
        link[m] = anchor
    return anchor


@jit(nogil=True)
def _ridge_groups(
    s, above, active, parent, root_of, final, top, significant, edge_a, edge_b, edge_v,
    n_edges, ring, periodic, link, group_size, group_top, group_ring, reach, stack, extended,
    weak, far, pair_share, box,
):  # fmt: skip
    """Merge (in ``final``) the regions of one frame that make one extended contact:
    those joined by ridges (saddles of at least ``ring`` of the lower maximum) into a
    group holding three or more significant maxima (not bumps of the noise), and those
    around a hole (taxels below ``weak`` that the array's border does not reach through
    taxels below it: a stamp's or a punch's rim around its unstrained middle, taxels
    between ``weak`` and the threshold counting as rim).
    Two maxima at least ``far`` taxels apart (beyond the reach of two point loads' tails)
    joined by a ridge of at least ``pair_share`` of their summed heights are one contact
    too (a cylinder's two ends). The maximum a group is merged into is marked
    ``extended`` (its position is the centre of its signal, not a peak)."""
    rows, cols = s.shape
    n_regions = 0
    for t in range(above):
        p = active[t]
        if parent[p] == p:
            link[p] = p
            group_size[p] = 0
            group_top[p] = -1
            group_ring[p] = False
            if final[p] == p:
                n_regions += 1
    if n_regions < 2:
        return
    for t in range(n_edges):
        a = _find(final, edge_a[t])
        b = _find(final, edge_b[t])
        if a == b or edge_v[t] < ring * min(top[a], top[b]):
            continue
        ra = a // cols
        rb = b // cols
        dcol = abs((a - ra * cols) - (b - rb * cols))
        if periodic and dcol > cols // 2:
            dcol = cols - dcol
        apart = math.hypot(ra - rb, dcol) >= far
        pair = apart and edge_v[t] >= pair_share * (top[a] + top[b])
        a = _find(link, a)
        b = _find(link, b)
        if a != b:
            link[b] = a
        if pair:
            group_ring[a] = True
    # holes: flood the taxels below the threshold from the border (4-connected), once
    # through all of them and once through those below ``weak`` only (the others a rim)
    n = rows * cols
    for pass_ in range(2):
        limit = np.inf if pass_ == 0 else weak
        for p in range(n):
            reach[p] = 0  # 0: not reached, 1: reached from the border, 2: a hole's, seen
        top_ = 0
        for p in range(n):
            r = p // cols
            c = p - r * cols
            border = r == 0 or r == rows - 1 or (not periodic and (c == 0 or c == cols - 1))
            if border and parent[p] < 0 and s[r, c] <= limit:
                reach[p] = 1
                stack[top_] = p
                top_ += 1
        while top_ > 0:
            top_ -= 1
            p = stack[top_]
            r = p // cols
            c = p - r * cols
            for k in range(4):
                rr = r + (1 if k == 0 else -1 if k == 1 else 0)
                cc = c + (1 if k == 2 else -1 if k == 3 else 0)
                if rr < 0 or rr >= rows:
                    continue
                if periodic:
                    cc %= cols
                elif cc < 0 or cc >= cols:
                    continue
                q = rr * cols + cc
                if reach[q] == 0 and parent[q] < 0 and s[rr, cc] <= limit:
                    reach[q] = 1
                    stack[top_] = q
                    top_ += 1
        for p0 in range(n):
            if reach[p0] != 0 or parent[p0] >= 0 or s[p0 // cols, p0 % cols] > limit:
                continue
            # a hole: every region that touches it is one contact
            anchor = -1
            reach[p0] = 2
            stack[0] = p0
            top_ = 1
            while top_ > 0:
                top_ -= 1
                p = stack[top_]
                r = p // cols
                c = p - r * cols
                for dr in range(-1, 2):
                    rr = r + dr
                    if rr < 0 or rr >= rows:
                        continue
                    for dc in range(-1, 2):
                        cc = c + dc
                        if periodic:
                            cc %= cols
                        elif cc < 0 or cc >= cols:
                            continue
                        q = rr * cols + cc
                        if parent[q] >= 0:
                            anchor = _join(link, final, root_of, q, anchor)
                        elif s[rr, cc] > limit:
                            # a wall taxel below the threshold: the regions it touches
                            for dr2 in range(-1, 2):
                                r2 = rr + dr2
                                if r2 < 0 or r2 >= rows:
                                    continue
                                for dc2 in range(-1, 2):
                                    c2 = cc + dc2
                                    if periodic:
                                        c2 %= cols
                                    elif c2 < 0 or c2 >= cols:
                                        continue
                                    q2 = r2 * cols + c2
                                    if parent[q2] >= 0:
                                        anchor = _join(link, final, root_of, q2, anchor)
                        elif reach[q] == 0 and (dr == 0 or dc == 0):
                            reach[q] = 2
                            stack[top_] = q
                            top_ += 1
            if anchor >= 0:
                group_ring[anchor] = True
    for t in range(above):
        p = active[t]
        if parent[p] != p:
            continue
        g = _find(link, _find(final, p))
        if group_ring[p]:
            group_ring[g] = True
        if significant[p]:
            group_size[g] += 1
    for t in range(above):
        p = active[t]
        if parent[p] == p and final[p] == p:
            g = _find(link, p)
            if group_top[g] < 0 or top[p] > top[group_top[g]]:
                group_top[g] = p
    for t in range(above):
        p = active[t]
        if parent[p] == p and final[p] == p:
            g = _find(link, p)
            if (group_size[g] >= 3 or group_ring[g]) and group_top[g] != p:
                final[p] = group_top[g]
                extended[group_top[g]] = True
    if periodic:
        return
    # a piece whose maximum lies within a taxel of an extended contact's bounding box is
    # part of it (a corner of a stamp's rim cut off by a low-gain taxel)
    any_extended = False
    for t in range(above):
        p = active[t]
        if parent[p] == p and final[p] == p and extended[p]:
            any_extended = True
            box[p, 0] = rows
            box[p, 1] = -1
            box[p, 2] = cols
            box[p, 3] = -1
    if not any_extended:
        return
    for t in range(above):
        p = active[t]
        m = _find(final, root_of[p])
        if extended[m]:
            r = p // cols
            c = p - r * cols
            box[m, 0] = min(box[m, 0], r)
            box[m, 1] = max(box[m, 1], r)
            box[m, 2] = min(box[m, 2], c)
            box[m, 3] = max(box[m, 3], c)
    for t in range(above):
        p = active[t]
        if not (parent[p] == p and final[p] == p) or extended[p]:
            continue
        r = p // cols
        c = p - r * cols
        for t2 in range(above):
            m = active[t2]
            if not (parent[m] == m and final[m] == m and extended[m]):
                continue
            if box[m, 0] - 1 <= r <= box[m, 1] + 1 and box[m, 2] - 1 <= c <= box[m, 3] + 1:
                final[p] = m
                break


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


@jit(nogil=True)
def amplitude_fit(signal, label_frames, frame_of, root, row, col, kernel, step, half, force):
    """Least-squares force of each contact: the amplitude of the tabulated response to
    1 N at its position, over the window of taxels around it (other contacts' taxels
    left out).

    ``kernel[a, b, i, j]`` is the signal of the taxel at offset ``(i - half, j - half)``
    from the taxel nearest below a load at sub-taxel offset ``(a, b) * step``.
    """
    rows = signal.shape[1]
    cols = signal.shape[2]
    n_sub = kernel.shape[0] - 1
    for k in range(row.shape[0]):
        f = frame_of[k]
        u = row[k]
        v = col[k]
        if not (math.isfinite(u) and math.isfinite(v)):
            force[k] = np.nan
            continue
        r0 = math.floor(u)
        c0 = math.floor(v)
        a = (u - r0) / step
        b = (v - c0) / step
        ia = min(int(a), n_sub - 1)
        ib = min(int(b), n_sub - 1)
        ta = a - ia
        tb = b - ib
        num = 0.0
        den = 0.0
        for i in range(2 * half + 1):
            r = r0 + i - half
            if r < 0 or r >= rows:
                continue
            for j in range(2 * half + 1):
                c = c0 + j - half
                if c < 0 or c >= cols:
                    continue
                lab = label_frames[f, r, c]
                if lab >= 0 and lab != root[k]:
                    continue
                g = (
                    (1 - ta) * (1 - tb) * kernel[ia, ib, i, j]
                    + ta * (1 - tb) * kernel[ia + 1, ib, i, j]
                    + (1 - ta) * tb * kernel[ia, ib + 1, i, j]
                    + ta * tb * kernel[ia + 1, ib + 1, i, j]
                )
                num += g * signal[f, r, c]
                den += g * g
        force[k] = num / den if den > 0.0 else np.nan


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
    """The compiled :class:`~tactsense.estimate.track.ContactTracker` (same rules, same
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


@jit(nogil=True)
def _fit_score(signal, labels, f, own, pr, pc, kernel, half, n_sub, ia, ib):
    """Least-squares amplitude and score ``<g, s>^2 / <g, g>`` of the tabulated response
    for the probe at ``(pr - 1 + ia / n_sub, pc - 1 + ib / n_sub)`` [taxel], over the
    fixed taxels within ``half - 1`` of the maximum ``(pr, pc)`` (other contacts' taxels
    left out). The same taxels for every position: the score is smooth in it."""
    rows = signal.shape[1]
    cols = signal.shape[2]
    span = 2 * n_sub + 1
    ua = ia if ia < span - 1 else ia - 1
    ub = ib if ib < span - 1 else ib - 1
    r0 = pr - 1 + ua // n_sub  # the taxel below the position, and the offset from it
    c0 = pc - 1 + ub // n_sub
    a = ia - (r0 - (pr - 1)) * n_sub
    b = ib - (c0 - (pc - 1)) * n_sub
    reach = half - 1
    num = 0.0
    den = 0.0
    for r in range(max(0, pr - reach), min(rows, pr + reach + 1)):
        i = r - r0 + half
        for c in range(max(0, pc - reach), min(cols, pc + reach + 1)):
            lab = labels[f, r, c]
            if lab >= 0 and lab != own:
                continue
            g = kernel[a, b, i, c - c0 + half]
            num += g * signal[f, r, c]
            den += g * g
    if den > 0.0 and num > 0.0:
        return num * num / den, num / den
    return 0.0, np.nan


@jit(nogil=True)
def fit_into(signal, labels, frame_of, root, peak_row, peak_col, kernel, half, row, col, force):
    """Maximum-likelihood position and force of each contact under white Gaussian noise:
    the tabulated response that, scaled by its least-squares amplitude, leaves the least
    residual over the taxels around the contact's maximum (:func:`_fit_score`), searched
    over every tabulated sub-taxel position in the four cells around the maximum, then
    refined by a parabola through the best and its table neighbours.

    ``kernel[a, b, i, j]`` as in :func:`amplitude_fit`; ``row``, ``col`` [taxel] and
    ``force`` [N] are written.
    """
    n_sub = kernel.shape[0] - 1
    step = 1.0 / n_sub
    span = 2 * n_sub + 1
    for k in range(frame_of.shape[0]):
        f = frame_of[k]
        pr = peak_row[k]
        pc = peak_col[k]
        own = root[k]
        # start at the maximum's taxel and move only for a clearly better score: where
        # the score is flat (a probe near a taxel's centre that moves no neighbour: the
        # data cannot tell where it is) the answer stays at the taxel, not at the first
        # position searched. Every tabulated position is tried: where few taxels respond
        # the score peaks within a fraction of a table step, which a coarse search misses
        best_a = n_sub
        best_b = n_sub
        best, _ = _fit_score(signal, labels, f, own, pr, pc, kernel, half, n_sub, n_sub, n_sub)
        for ia in range(span):
            for ib in range(span):
                sc, _ = _fit_score(signal, labels, f, own, pr, pc, kernel, half, n_sub, ia, ib)
                if sc > best * (1.0 + 1e-9):
                    best, best_a, best_b = sc, ia, ib
        if not best > 0.0:
            row[k] = np.nan
            col[k] = np.nan
            force[k] = np.nan
            continue
        da = 0.0
        db = 0.0
        if 0 < best_a < span - 1:
            lo, _ = _fit_score(
                signal, labels, f, own, pr, pc, kernel, half, n_sub, best_a - 1, best_b
            )
            hi, _ = _fit_score(
                signal, labels, f, own, pr, pc, kernel, half, n_sub, best_a + 1, best_b
            )
            curv = lo - 2.0 * best + hi
            if curv < 0.0:
                da = min(max(0.5 * (lo - hi) / curv, -0.5), 0.5)
        if 0 < best_b < span - 1:
            lo, _ = _fit_score(
                signal, labels, f, own, pr, pc, kernel, half, n_sub, best_a, best_b - 1
            )
            hi, _ = _fit_score(
                signal, labels, f, own, pr, pc, kernel, half, n_sub, best_a, best_b + 1
            )
            curv = lo - 2.0 * best + hi
            if curv < 0.0:
                db = min(max(0.5 * (lo - hi) / curv, -0.5), 0.5)
        _, amp = _fit_score(signal, labels, f, own, pr, pc, kernel, half, n_sub, best_a, best_b)
        row[k] = pr - 1 + (best_a + da) * step
        col[k] = pc - 1 + (best_b + db) * step
        force[k] = amp


@jit(inline="always")
def _kernel_at(kernel, step, half, qr, qc, r, c):
    """The tabulated response [-/N] of taxel (r, c) to 1 N at (qr, qc) [taxel]
    (bilinear between the table's sub-taxel positions), 0 outside its window."""
    n_sub = kernel.shape[0] - 1
    r0 = math.floor(qr)
    c0 = math.floor(qc)
    i = r - r0 + half
    j = c - c0 + half
    if i < 0 or i > 2 * half or j < 0 or j > 2 * half:
        return 0.0
    a = (qr - r0) / step
    b = (qc - c0) / step
    ia = min(int(a), n_sub - 1)
    ib = min(int(b), n_sub - 1)
    ta = a - ia
    tb = b - ib
    return (
        (1 - ta) * (1 - tb) * kernel[ia, ib, i, j]
        + ta * (1 - tb) * kernel[ia + 1, ib, i, j]
        + (1 - ta) * tb * kernel[ia, ib + 1, i, j]
        + ta * tb * kernel[ia + 1, ib + 1, i, j]
    )


@jit(inline="always")
def _pair_gain(signal, label_frames, f, own, ru, cv, reach, u, v, er, ec, h, kernel, step,
               half, floor, top, threshold):  # fmt: skip
    """Residual reduction [-^2] and summed amplitude [N] of two loads at ``(u, v) +- h e``
    with non-negative least-squares amplitudes (reduction -1 where one would be
    negative, the two are not independent, fewer than five taxels carry them (two
    amplitudes and two places fit four readings whatever they are), either alone would
    read more than twice the contact's largest signal ``top``, or together they would
    read more than ``threshold`` on a taxel that reads at most ``floor``: a pair whose
    compression and tension cancel to fit, not two loads that the signal shows)."""
    rows = signal.shape[1]
    cols = signal.shape[2]
    s11 = 0.0
    s22 = 0.0
    s12 = 0.0
    y1 = 0.0
    y2 = 0.0
    p1 = 0.0
    p2 = 0.0
    used = 0
    for r in range(max(0, ru - reach), min(rows, ru + reach + 1)):
        for c in range(max(0, cv - reach), min(cols, cv + reach + 1)):
            lab = label_frames[f, r, c]
            s = signal[f, r, c]
            if lab >= 0 and lab != own:
                continue
            g1 = _kernel_at(kernel, step, half, u - h * er, v - h * ec, r, c)
            g2 = _kernel_at(kernel, step, half, u + h * er, v + h * ec, r, c)
            p1 = max(p1, g1)
            p2 = max(p2, g2)
            if not s > floor:
                continue
            used += 1
            s11 += g1 * g1
            s22 += g2 * g2
            s12 += g1 * g2
            y1 += g1 * s
            y2 += g2 * s
    det = s11 * s22 - s12 * s12
    if not det > 0.1 * s11 * s22:  # the two responses too alike: no split to trust
        return -1.0, 0.0
    a1 = (s22 * y1 - s12 * y2) / det
    a2 = (s11 * y2 - s12 * y1) / det
    if used < 5 or a1 < 0.0 or a2 < 0.0 or a1 * p1 > 2.0 * top or a2 * p2 > 2.0 * top:
        return -1.0, 0.0
    for r in range(max(0, ru - reach), min(rows, ru + reach + 1)):
        for c in range(max(0, cv - reach), min(cols, cv + reach + 1)):
            lab = label_frames[f, r, c]
            if (lab >= 0 and lab != own) or signal[f, r, c] > floor:
                continue
            g1 = _kernel_at(kernel, step, half, u - h * er, v - h * ec, r, c)
            g2 = _kernel_at(kernel, step, half, u + h * er, v + h * ec, r, c)
            if a1 * g1 + a2 * g2 > threshold:
                return -1.0, 0.0
    return a1 * y1 + a2 * y2, a1 + a2


@jit(inline="always")
def _one_gain(signal, label_frames, f, own, ru, cv, reach, qr, qc, kernel, step, half, floor):
    """Residual reduction [-^2] and least-squares amplitude [N] of one load at (qr, qc)."""
    rows = signal.shape[1]
    cols = signal.shape[2]
    num = 0.0
    den = 0.0
    for r in range(max(0, ru - reach), min(rows, ru + reach + 1)):
        for c in range(max(0, cv - reach), min(cols, cv + reach + 1)):
            lab = label_frames[f, r, c]
            s = signal[f, r, c]
            if (lab >= 0 and lab != own) or not s > floor:
                continue
            g = _kernel_at(kernel, step, half, qr, qc, r, c)
            num += g * s
            den += g * g
    if not den > 0.0:
        return -1.0, 0.0
    return num * num / den, num / den


@jit(nogil=True)
def merged_force(
    signal, label_frames, frame_of, root, row, col, mrr, mcc, mrc, kernel, step, half,
    halves, noise_var, gain, floor, threshold, spread, force, kernel_max,
):  # fmt: skip
    """Force of each contact as the sum of two loads where two explain its signal
    clearly better than one: a contact that the segmentation holds as one may cover two
    loads too close to part (below the resolution limit), and one load's least-squares
    amplitude then carries only part of their force.

    ``kernel`` is :func:`~tactsense.estimate.contacts.pad_force_kernel`'s signed table
    (responses that add up). Only a contact wider along its major axis ``e`` (from its
    second moments ``mrr, mcc, mrc`` [taxel^2]) than one load at its position would be,
    by more than ``spread`` [taxel^2], is looked at (one load's width: the second
    moment of the table's response above ``threshold``, scaled by the contact's
    one-load amplitude). Over the taxels within ``half + 1`` of it whose signal
    exceeds ``floor`` (other contacts' taxels left out): one load at ``(row, col) + t
    e`` and two loads at ``(row, col) + (t +- h) e``, with non-negative least-squares
    amplitudes, for ``t`` in [-0.5, 0.5] taxel and ``h`` each of ``halves`` [taxel],
    the best of each refined twice. The two loads' summed amplitudes replace
    ``force[k]`` when they lower the residual by more than the best single load does,
    by more than ``gain`` times ``noise_var`` (the variance of one taxel's signal
    [-^2]). Contacts whose force is NaN are left so.

    Cheap where it cannot apply (the forces are those of the full check, bit for bit):
    a contact no wider than ``spread`` along its major axis is skipped before any
    look-up (one load's width is >= 0); the one-load amplitude interpolates the table
    only on taxels that carry it (above ``floor``), and the width only where
    ``kernel_max`` (each window taxel's largest tabulated response [-/N]) times the
    amplitude can exceed ``threshold``.
    """
    rows = signal.shape[1]
    cols = signal.shape[2]
    reach = half + 1
    n_t = 9
    g_one = np.empty((2 * half + 1, 2 * half + 1))
    for k in range(frame_of.shape[0]):
        f = frame_of[k]
        u = row[k]
        v = col[k]
        if not (math.isfinite(u) and math.isfinite(v) and math.isfinite(force[k])):
            continue
        # the contact's second moment along its major axis: no wider than ``spread``,
        # it cannot be wider than one load by more (one load's width is >= 0): skip
        # before any trigonometry or table look-up (most contacts end here)
        mid = 0.5 * (mrr[k] + mcc[k])
        along = mid + math.sqrt(0.25 * (mrr[k] - mcc[k]) ** 2 + mrc[k] * mrc[k])
        if not along > spread:
            continue
        angle = 0.5 * math.atan2(2.0 * mrc[k], mrr[k] - mcc[k])
        er = math.cos(angle)
        ec = math.sin(angle)
        along = er * er * mrr[k] + 2.0 * er * ec * mrc[k] + ec * ec * mcc[k]
        ru = math.floor(u + 0.5)
        cv = math.floor(v + 0.5)
        # one pass over the taxels one load at (u, v) reaches (the table's window):
        # its response there (kept for the width, interpolated with the weights of
        # _kernel_at, computed once), and its least-squares amplitude; the other
        # taxels of the wider window add nothing to either
        own = root[k]
        r0 = math.floor(u)
        c0 = math.floor(v)
        n_sub = kernel.shape[0] - 1
        ia = min(int((u - r0) / step), n_sub - 1)
        ib = min(int((v - c0) / step), n_sub - 1)
        ta = (u - r0) / step - ia
        tb = (v - c0) / step - ib
        k00 = (1 - ta) * (1 - tb)
        k10 = ta * (1 - tb)
        k01 = (1 - ta) * tb
        k11 = ta * tb
        num = 0.0
        den = 0.0
        for i in range(2 * half + 1):
            r = r0 - half + i
            for j in range(2 * half + 1):
                c = c0 - half + j
                g_one[i, j] = math.nan  # not looked up (yet)
                if r < 0 or r >= rows or c < 0 or c >= cols:
                    g_one[i, j] = 0.0
                    continue
                lab = label_frames[f, r, c]
                sig = signal[f, r, c]
                if (lab >= 0 and lab != own) or not sig > floor:
                    continue
                g = (
                    k00 * kernel[ia, ib, i, j]
                    + k10 * kernel[ia + 1, ib, i, j]
                    + k01 * kernel[ia, ib + 1, i, j]
                    + k11 * kernel[ia + 1, ib + 1, i, j]
                )
                g_one[i, j] = g
                num += g * sig
                den += g * g
        if not den > 0.0:
            continue
        one = num * num / den
        amp = num / den
        if not amp > 0.0:
            continue
        # how wide one load of that amplitude would read, along e
        w0 = 0.0
        w1 = 0.0
        w2 = 0.0
        for i in range(2 * half + 1):
            for j in range(2 * half + 1):
                # no table position reads above the threshold here at this amplitude:
                # neither can their interpolation (a convex combination)
                if not amp * kernel_max[i, j] * (1.0 + 1e-9) > threshold:
                    continue
                g = g_one[i, j]
                if math.isnan(g):
                    g = (
                        k00 * kernel[ia, ib, i, j]
                        + k10 * kernel[ia + 1, ib, i, j]
                        + k01 * kernel[ia, ib + 1, i, j]
                        + k11 * kernel[ia + 1, ib + 1, i, j]
                    )
                w = amp * g
                if w > threshold:
                    x = (r0 - half + i - u) * er + (c0 - half + j - v) * ec
                    w0 += w
                    w1 += w * x
                    w2 += w * x * x
        if w0 > 0.0:
            mean = w1 / w0
            if not along - (w2 / w0 - mean * mean) > spread:
                continue
        # the contact's top (its largest signal), for the pair's bound
        top = 0.0
        for r in range(max(0, ru - reach), min(rows, ru + reach + 1)):
            for c in range(max(0, cv - reach), min(cols, cv + reach + 1)):
                if label_frames[f, r, c] == own:
                    top = max(top, signal[f, r, c])
        best_one = one
        best = -1.0
        best_force = -1.0
        best_t = 0.0
        best_h = -1.0
        for it in range(n_t):
            t = (it - (n_t - 1) / 2) / (n_t - 1)
            g1, _ = _one_gain(
                signal, label_frames, f, root[k], ru, cv, reach, u + t * er, v + t * ec,
                kernel, step, half, floor,
            )  # fmt: skip
            best_one = max(best_one, g1)
            for m in range(halves.shape[0]):
                gained, total = _pair_gain(
                    signal, label_frames, f, root[k], ru, cv, reach, u + t * er,
                    v + t * ec, er, ec, halves[m], kernel, step, half, floor, top,
                    threshold,
                )  # fmt: skip
                if gained > best:
                    best, best_force, best_t, best_h = gained, total, t, halves[m]
        if best_h < 0.0:
            continue
        # the response changes fast with the loads' places: refine the centre and the
        # spacing in turn, twice, each on 17 points across the step before
        width_t = 1.0 / (n_t - 1)
        width_h = halves[1] - halves[0] if halves.shape[0] > 1 else 0.125
        for _ in range(2):
            for which in range(2):
                centre_t = best_t
                centre_h = best_h
                for m in range(17):
                    t = centre_t
                    h = centre_h
                    if which == 0:
                        t = centre_t + (m - 8) * width_t / 8.0
                    else:
                        h = centre_h + (m - 8) * width_h / 8.0
                    if h <= 0.0:
                        continue
                    gained, total = _pair_gain(
                        signal, label_frames, f, root[k], ru, cv, reach, u + t * er,
                        v + t * ec, er, ec, h, kernel, step, half, floor, top,
                        threshold,
                    )  # fmt: skip
                    if gained > best:
                        best, best_force, best_t, best_h = gained, total, t, h
            width_t = width_t / 8.0
            width_h = width_h / 8.0
        if best_force >= 0.0 and best - best_one > gain * noise_var:
            force[k] = best_force
