"""The paper's Hann-windowed sinc on a grid, around a contact's peak (compiled): the
window's taps and the interpolated surface."""

from __future__ import annotations

import math

import numpy as np

from tactsense._jit import jit

HALF_WINDOW = 3
"""Taxels on each side of the peak that the interpolation uses [taxel]."""
_WINDOW = HALF_WINDOW + 1.0  # the Hann window reaches zero 4 taxels from the point
_TAYLOR = 1e-4


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
