"""Compiled per-frame estimation (Numba): Newton on the interpolated surface, force, skew.

The same mathematics as :mod:`~tactsense.estimate.finger.interpolate`,
:mod:`~tactsense.estimate.finger.localize` and :mod:`~tactsense.estimate.finger.angle`, written as
one loop over frames so that each frame stays in cache and no temporary arrays are
made; the test suite checks that both give the same numbers. Trigonometric functions
are evaluated once per axis and step and shifted with angle-addition identities.
"""

from __future__ import annotations

import math

import numpy as np

from tactsense._jit import jit

_TAYLOR = 1e-4
SKEW_OFFSETS = np.arange(1, 9) * 0.25  # tactel: 0.25 ... 2.0
FASTMATH = {"nsz", "arcp", "contract", "reassoc"}
"""LLVM may reorder sums, fuse multiply-adds and multiply by reciprocals (about 10 % of
the kernel's time); NaN and infinity keep their meaning (no ``nnan``, ``ninf``), and the
numbers move by rounding only (tests/estimate/test_fast.py holds the compiled and the
NumPy forms to 1e-7 tactel in position and 1e-10 relative in peak and force). The kernel
also uses NumPy's error model (no zero check before each division: every division in it
is guarded by the algorithm itself)."""


@jit(inline="always")
def _axis_weights(u, n, periodic, cos_i, sin_i, k0, k1, k2):
    """Kernel weights and derivatives at fractional position u for samples 0..n-1.

    ``cos_i``, ``sin_i`` hold cos and sin of ``omega * i`` (omega = 2 pi / (n - 1)) for
    i = -n .. 2n - 1 (index i + n), so that the window needs no trigonometric call
    per sample.
    """
    half = 0.5 * (n - 1)
    omega = math.pi / half
    m = math.floor(u)
    if u == m and -n <= m < 2 * n:
        # a whole tactel (Newton's start, the largest tactel): no trigonometric call
        k = int(m)
        su = 0.0
        cu = -1.0 if k % 2 != 0 else 1.0
        swu = sin_i[k + n]
        cwu = cos_i[k + n]
    else:
        su = math.sin(math.pi * u)
        cu = math.cos(math.pi * u)
        swu = math.sin(omega * u)
        cwu = math.cos(omega * u)
    for i in range(n):
        t = u - i
        j = i  # the sample's image: i, or i -+ n across the seam of a closed ring
        if periodic:
            if t > 0.5 * n:
                t -= n
                j = i + n
            elif t < -0.5 * n:
                t += n
                j = i - n
        if abs(t) > half:
            k0[i] = 0.0
            k1[i] = 0.0
            k2[i] = 0.0
            continue
        sign = -1.0 if j % 2 != 0 else 1.0  # sin(pi (u - j)) = (-1)^j sin(pi u)
        sin_pt = sign * su
        cos_pt = sign * cu
        if abs(t) < _TAYLOR:
            s = 1.0 - math.pi**2 * t * t / 6.0
            ds = -(math.pi**2) * t / 3.0
            d2s = -(math.pi**2) / 3.0 + math.pi**4 * t * t / 10.0
        else:
            s = sin_pt / (math.pi * t)
            ds = (cos_pt - s) / t
            d2s = (-math.pi * sin_pt - 2.0 * ds) / t
        cw = cwu * cos_i[j + n] + swu * sin_i[j + n]  # cos(omega (u - j))
        sw = swu * cos_i[j + n] - cwu * sin_i[j + n]
        w = 0.5 * (1.0 + cw)
        dw = -0.5 * omega * sw
        d2w = -0.5 * omega * omega * cw
        k0[i] = s * w
        k1[i] = ds * w + s * dw
        k2[i] = d2s * w + 2.0 * ds * dw + s * d2w


@jit()
def _trig_table(n):
    omega = 2.0 * math.pi / (n - 1)
    index = np.arange(-n, 2 * n)
    return np.cos(omega * index), np.sin(omega * index)


@jit(nogil=True)
def locate_frames(z, valid, periodic, first_row, tolerance, max_iterations, max_step):
    """Peak, Newton steps, convergence, summed deflection, skew and second maximum per frame.

    Parameters
    ----------
    z : float64 array (N, rows, cols)
        Fractional deflection.
    valid : bool array (N,)
        Frames to process (others are left NaN).

    Returns
    -------
    row, col, value, iterations, converged, summed, skew, second
        ``summed`` is the sum of the cylinder rows; ``second`` the largest separate
        local tactel maximum as a share of the largest.
    """
    n_frames = z.shape[0]
    row = np.empty(n_frames)
    col = np.empty(n_frames)
    value = np.empty(n_frames)
    iterations = np.empty(n_frames, np.int64)
    converged = np.empty(n_frames, np.bool_)
    summed = np.empty(n_frames)
    skew = np.empty(n_frames)
    second = np.empty(n_frames)
    locate_into(
        z, valid, periodic, first_row, tolerance, max_iterations, max_step,
        row, col, value, iterations, converged, summed, skew, second,
    )  # fmt: skip
    if first_row == 1:
        place_tip_gap(z, periodic, row, col)
    return row, col, value, iterations, converged, summed, skew, second


@jit(nogil=True, fastmath=FASTMATH, error_model="numpy")
def place_tip_gap(z, periodic, row, col):
    """Peaks between the tip row and row 1 placed in the true step between them.

    The tip row lies a long step (11.1 mm on the paper's fingers) before row 1, not one
    spacing, so the sinc interpolation cannot place a peak inside that step. A frame
    whose ``row`` is below 1 gets ``row = z1 / (z0 + z1)``, with ``z0``, ``z1`` the two
    rows interpolated around the finger at ``col`` (negative values as 0): the
    deflection-weighted mean of the two rows' true positions once the geometry maps
    the row linearly onto the step. Other frames (and NaN rows) are left alone. A pass
    of its own after :func:`locate_into`, so that the Newton kernel stays as it was.
    """
    n_frames, _, cols = z.shape
    ky0 = np.empty(cols)
    ky1 = np.empty(cols)
    ky2 = np.empty(cols)
    cos_c, sin_c = _trig_table(cols)
    for f in range(n_frames):
        if not row[f] < 1.0:
            continue
        _axis_weights(col[f], cols, periodic, cos_c, sin_c, ky0, ky1, ky2)
        tip = 0.0
        ring = 0.0
        for c in range(cols):
            tip += z[f, 0, c] * ky0[c]
            ring += z[f, 1, c] * ky0[c]
        tip = max(tip, 0.0)
        ring = max(ring, 0.0)
        if tip + ring > 0.0:
            row[f] = ring / (tip + ring)


@jit(nogil=True, fastmath=FASTMATH, error_model="numpy")
def locate_into(
    z, valid, periodic, first_row, tolerance, max_iterations, max_step,
    row, col, value, iterations, converged, summed, skew, second,
):  # fmt: skip
    """:func:`locate_frames` writing into given arrays (N,) (e.g. slices of a recording's
    outputs: no per-block result to join)."""
    n_frames, rows, cols = z.shape
    for f in range(n_frames):
        row[f] = np.nan
        col[f] = np.nan
        value[f] = np.nan
        iterations[f] = 0
        converged[f] = False
        summed[f] = np.nan
        skew[f] = np.nan
        second[f] = 0.0
    kx0 = np.empty(rows)
    kx1 = np.empty(rows)
    kx2 = np.empty(rows)
    ky0 = np.empty(cols)
    ky1 = np.empty(cols)
    ky2 = np.empty(cols)
    zy0 = np.empty(rows)
    zy1 = np.empty(rows)
    zy2 = np.empty(rows)
    offsets = SKEW_OFFSETS
    n_off = offsets.size
    cos_r, sin_r = _trig_table(rows)
    inv_pi = 1.0 / math.pi
    sgn_r = np.empty(rows)
    for r in range(rows):
        sgn_r[r] = -1.0 if r % 2 == 1 else 1.0
    left = np.empty(cols, np.int64)
    right = np.empty(cols, np.int64)
    for c in range(cols):
        left[c] = (c - 1) % cols
        right[c] = (c + 1) % cols
    cos_c, sin_c = _trig_table(cols)
    omega_r = 2.0 * math.pi / (rows - 1)
    cos_w_off = np.cos(omega_r * offsets)
    sin_w_off = np.sin(omega_r * offsets)
    cos_off = np.cos(math.pi * offsets)
    sin_off = np.sin(math.pi * offsets)
    for f in range(n_frames):
        if not valid[f]:
            continue
        frame = z[f]
        best = -np.inf
        x = 0.0
        y = 0.0
        total = 0.0
        for r in range(rows):
            for c in range(cols):
                v = frame[r, c]
                if r >= first_row:
                    total += v
                if v > best:
                    best = v
                    x = float(r)
                    y = float(c)
        summed[f] = total
        # second separate maximum: local maxima of the tactel frame
        top = 0.0
        for r in range(rows):
            r0 = r - 1 if r > 0 else r
            r1 = r + 1 if r < rows - 1 else r
            for c in range(cols):
                v = frame[r, c]
                if v >= best or v <= top or v <= 0.0:
                    continue
                if periodic:
                    c0 = left[c]
                    c1 = right[c]
                else:
                    c0 = c - 1 if c > 0 else c
                    c1 = c + 1 if c < cols - 1 else c
                is_max = True
                for rr in range(r0, r1 + 1):
                    if frame[rr, c0] > v or frame[rr, c] > v or frame[rr, c1] > v:
                        is_max = False
                        break
                if is_max:
                    top = v
        second[f] = top / best if best > 0 else 0.0
        done = False
        steps = 0
        for _ in range(max_iterations):
            _axis_weights(x, rows, False, cos_r, sin_r, kx0, kx1, kx2)
            _axis_weights(y, cols, periodic, cos_c, sin_c, ky0, ky1, ky2)
            for r in range(rows):
                a0 = 0.0
                a1 = 0.0
                a2 = 0.0
                for c in range(cols):
                    v = frame[r, c]
                    a0 += v * ky0[c]
                    a1 += v * ky1[c]
                    a2 += v * ky2[c]
                zy0[r] = a0
                zy1[r] = a1
                zy2[r] = a2
            fx = 0.0
            fy = 0.0
            fxx = 0.0
            fxy = 0.0
            fyy = 0.0
            for r in range(rows):
                fx += kx1[r] * zy0[r]
                fy += kx0[r] * zy1[r]
                fxx += kx2[r] * zy0[r]
                fxy += kx1[r] * zy1[r]
                fyy += kx0[r] * zy2[r]
            det = fxx * fyy - fxy * fxy
            if fxx < 0.0 and det > 0.0:
                dx = -(fyy * fx - fxy * fy) / det
                dy = -(fxx * fy - fxy * fx) / det
                concave = True
            else:
                g = math.sqrt(fx * fx + fy * fy)
                if g > 0.0:
                    dx = fx * max_step / g
                    dy = fy * max_step / g
                else:
                    dx = 0.0
                    dy = 0.0
                concave = False
            length = math.sqrt(dx * dx + dy * dy)
            if length > max_step:
                dx *= max_step / length
                dy *= max_step / length
            x = min(max(x + dx, 0.0), rows - 1.0)
            y = y + dy
            if periodic:
                y = y % cols
            else:
                y = min(max(y, 0.0), cols - 1.0)
            steps += 1
            if concave and length < tolerance:
                done = True
                break
        iterations[f] = steps
        converged[f] = done
        row[f] = x
        col[f] = y
        # value and the column-contracted row profile at the final point
        _axis_weights(x, rows, False, cos_r, sin_r, kx0, kx1, kx2)
        _axis_weights(y, cols, periodic, cos_c, sin_c, ky0, ky1, ky2)
        peak = 0.0
        for r in range(rows):
            a0 = 0.0
            for c in range(cols):
                a0 += frame[r, c] * ky0[c]
            zy0[r] = a0
            peak += kx0[r] * a0
        value[f] = peak
        # skew along the finger (eqs. 62-63) at offsets within the cylinder rows
        room = min(x - first_row, rows - 1 - x)
        if room < 0.5:
            continue
        best_even = peak
        best_odd = 0.0
        su = math.sin(math.pi * x)
        cu = math.cos(math.pi * x)
        swx = math.sin(omega_r * x)
        cwx = math.cos(omega_r * x)
        half = 0.5 * (rows - 1)
        for k in range(n_off):
            t_off = offsets[k]
            if t_off > room:
                break
            plus = 0.0
            minus = 0.0
            for side in range(2):
                sgn = 1.0 if side == 0 else -1.0
                u = x + sgn * t_off
                # sin(pi u) from sin(pi x) and the precomputed offset
                s_u = su * cos_off[k] + sgn * cu * sin_off[k]
                cw_u = cwx * cos_w_off[k] - sgn * swx * sin_w_off[k]  # cos(omega u)
                sw_u = swx * cos_w_off[k] + sgn * cwx * sin_w_off[k]
                acc = 0.0
                for r in range(rows):
                    t = u - r
                    if abs(t) > half:
                        continue
                    if abs(t) < _TAYLOR:
                        s = 1.0 - math.pi**2 * t * t / 6.0
                    else:
                        s = sgn_r[r] * s_u * inv_pi / t
                    cw = cw_u * cos_r[r + rows] + sw_u * sin_r[r + rows]
                    acc += s * (1.0 + cw) * zy0[r]
                acc *= 0.5
                if side == 0:
                    plus = acc
                else:
                    minus = acc
            even = 0.5 * (plus + minus)
            odd = 0.5 * (plus - minus)
            if even > best_even:
                best_even = even
            if abs(odd) > abs(best_odd):
                best_odd = odd
        skew[f] = best_odd / best_even if best_even > 0 else np.nan


@jit(inline="always")
def taxel_signal(
    v, base, unusable, full_scale, resistive, falling, per_count, nan_flag, sat_flag, dead_flag
):
    """The signal of one reading ``v`` [counts] against its baseline ``base`` and the flag
    bits it sets, compression positive whichever way the reading moves:

    * capacitive, rising: eq. 4, ``(v - base) / v``; a reading of 0 or below is an open
      junction (0, ``dead_flag``);
    * capacitive, falling (``falling``): eq. 4 of the reading mirrored about its rest,
      ``w = 2 base - v``: ``(base - v) / (2 base - v)``, the inverse of the twin's falling
      chain (0, ``dead_flag`` where ``w`` is not positive);
    * resistive: the strain, ``(v - base) * per_count``, or ``(base - v) * per_count``
      falling; any reading, 0 included, is valid (a cell at rest reads 0).

    ``sat_flag`` where the reading is at the rail it moves toward (full scale rising, 0
    falling); 0 where it is unusable (NaN: ``nan_flag``; excluded: no flag). One
    definition for the finger's kernel, the contacts' and the drift-following
    baseline's."""
    if not math.isfinite(v):
        return 0.0, nan_flag
    if unusable:
        return 0.0, 0
    if falling:
        flag = sat_flag if v <= 0.0 else 0
        if resistive:
            return (base - v) * per_count, flag
        w = 2.0 * base - v
        if w <= 0.0:
            return 0.0, dead_flag
        return (base - v) / w, flag
    flag = sat_flag if v >= full_scale else 0
    if resistive:
        return (v - base) * per_count, flag
    if v <= 0.0:
        return 0.0, dead_flag
    return (v - base) / v, flag


@jit(nogil=True)
def prepare_frames(frames, baseline, unusable, full_scale, nan_flag, saturated_flag, dead_flag):
    """Eq. 4 deflection, per-frame flags and the largest tactel, in one pass.

    The compiled twin of :func:`tactsense.estimate.finger.deflection.deflection_from_counts`.

    Parameters
    ----------
    frames : array (N, rows, cols), any integer or float type
        Readings [counts].
    baseline : float64 array (rows, cols)
    unusable : bool array (rows, cols)
        Tactels known dead or excluded (a non-positive baseline included).
    """
    n_frames, rows, cols = frames.shape
    # any numeric input (uint16 counts straight from a recording: no float64 copy)
    deflection = np.empty((n_frames, rows, cols), np.float64)
    flags = np.zeros(n_frames, np.int64)
    peak = np.full(n_frames, -np.inf)
    any_unusable = False
    for r in range(rows):
        for c in range(cols):
            if unusable[r, c]:
                any_unusable = True
    for f in range(n_frames):
        flag = dead_flag if any_unusable else 0
        best = -np.inf
        for r in range(rows):
            for c in range(cols):
                d, bits = taxel_signal(
                    float(frames[f, r, c]), baseline[r, c], unusable[r, c], full_scale,
                    False, False, 1.0, nan_flag, saturated_flag, dead_flag,
                )  # fmt: skip
                flag |= bits
                deflection[f, r, c] = d
                if d > best:
                    best = d
        flags[f] = flag
        peak[f] = best
    return deflection, flags, peak


@jit(inline="always")
def _locate_into_out(deflection, peak, settings, out):
    """:func:`locate_frames` on one frame (1, rows, cols) whose largest value is ``peak``,
    its results into ``out[0:8]`` and whether it is touched into ``out[9]`` (the layout
    of :func:`locate_one`); NaN estimates where it is not touched."""
    touched = peak >= settings[1]
    out[9] = 1.0 if touched else 0.0
    if not touched:
        out[0:7] = np.nan
        out[3] = 0.0
        out[4] = 0.0
        out[7] = 0.0
        return
    valid = np.ones(1, np.bool_)
    row, col, value, iterations, converged, summed, skew, second = locate_frames(
        deflection, valid, settings[4] != 0.0, int(settings[5]), settings[2],
        int(settings[6]), settings[3],
    )  # fmt: skip
    out[0] = row[0]
    out[1] = col[0]
    out[2] = value[0]
    out[3] = iterations[0]
    out[4] = 1.0 if converged[0] else 0.0
    out[5] = summed[0]
    out[6] = skew[0]
    out[7] = second[0]


@jit(nogil=True)
def locate_deflection_one(deflection, settings, out):
    """:func:`locate_frames` for one frame of fractional deflection (rows, cols) [-] that a
    calibration made (its gains, nonlinearity and creep applied; excluded tactels 0), in
    one compiled call: ``settings`` and ``out`` as in :func:`locate_one` (``out[8]``, the
    flags of the readings, is 0 here: the calibration reports its own)."""
    rows, cols = deflection.shape
    peak = -np.inf
    for r in range(rows):
        for c in range(cols):
            v = deflection[r, c]
            if v > peak:
                peak = v
    out[8] = 0.0
    frames = np.empty((1, rows, cols), np.float64)
    frames[0] = deflection
    _locate_into_out(frames, peak, settings, out)


@jit(nogil=True)
def locate_one(frame, baseline, unusable, settings, out):
    """Eq. 4, the contact test and :func:`locate_frames` for one frame (rows, cols)
    [counts] in one compiled call with few arguments (a real-time loop pays for each
    argument and each array returned): the same numbers as :func:`prepare_frames` then
    :func:`locate_frames`.

    ``settings`` (float64): full scale, threshold, tolerance, max step, periodic, first
    row, max iterations, and the NaN, saturated and dead flags. ``out`` (10,) gets row,
    col, value, iterations, converged, summed, skew, second, flags and touched (1 or 0);
    the estimates are NaN (``second`` 0) where the frame is not touched.
    """
    rows, cols = frame.shape
    frames = np.empty((1, rows, cols), frame.dtype)
    frames[0] = frame
    deflection, flags, peak = prepare_frames(
        frames, baseline, unusable, settings[0], int(settings[7]), int(settings[8]),
        int(settings[9]),
    )  # fmt: skip
    out[8] = flags[0]
    _locate_into_out(deflection, peak[0], settings, out)
