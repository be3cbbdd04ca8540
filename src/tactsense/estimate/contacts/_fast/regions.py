"""Regions of a frame as a union-find (compiled): the join of two regions and the
groups of maxima joined by ridges (a stamp's rim, a cylinder's two ends)."""

from __future__ import annotations

import math

import numpy as np

from tactsense._jit import jit


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
