"""A pad contact's force and position from the tabulated response (compiled): the
amplitude at a position, the maximum-likelihood fit, and two loads in one contact."""

from __future__ import annotations

import math

import numpy as np

from tactsense._jit import jit


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
