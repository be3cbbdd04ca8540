"""Windowed-sinc interpolation of the sparse array (section 6-7, eqs. 46-48 of the paper).

The interpolated deflection surface (eq. 48), in tactel units::

    f(x, y) = sum_ij z[i, j] K_N(x - i) K_M(y - j),   K_N(t) = sinc(t) w_N(t)

with the Hann window of eq. 47, ``w_N(t) = (1 + cos(2 pi t / (N - 1))) / 2`` for
``|t| <= (N - 1) / 2`` (0 outside), N the number of samples along that axis.
x runs along the finger (rows), y around it (columns). Where the layout closes on
itself (8 columns at 45 deg) the column offset is wrapped, so the surface is
periodic around the finger; elsewhere samples beyond the array count as zero, as
in the paper.

All first and second derivatives are analytic, so Newton's method (eq. 53) and
contour tracking (eqs. 49-51) need no finite differences.
"""

from __future__ import annotations

import numpy as np

_TAYLOR = 1e-4


def sinc_derivatives(t):
    """sinc(t) = sin(pi t)/(pi t) and its first two derivatives.

    Parameters
    ----------
    t : array_like
        [tactel].

    Returns
    -------
    s, ds, d2s : ndarray
    """
    t = np.asarray(t, dtype=float)
    small = np.abs(t) < _TAYLOR
    safe = np.where(small, 1.0, t)
    s = np.sinc(t)
    cos = np.cos(np.pi * safe)
    ds = np.where(small, -(np.pi**2) * t / 3.0, (cos - s) / safe)
    d2s = np.where(
        small,
        -(np.pi**2) / 3.0 + np.pi**4 * t * t / 10.0,
        (-np.pi * np.sin(np.pi * safe) - 2.0 * ds) / safe,
    )
    return s, ds, d2s


def hann_derivatives(t, n_samples: int):
    """Hann window of eq. 47 centred at 0, and its first two derivatives."""
    t = np.asarray(t, dtype=float)
    half = (n_samples - 1) / 2.0
    inside = np.abs(t) <= half
    omega = np.pi / half  # 2 pi / (N - 1)
    w = np.where(inside, 0.5 * (1.0 + np.cos(omega * t)), 0.0)
    dw = np.where(inside, -0.5 * omega * np.sin(omega * t), 0.0)
    d2w = np.where(inside, -0.5 * omega**2 * np.cos(omega * t), 0.0)
    return w, dw, d2w


def kernel(t, n_samples: int, *, derivatives: int = 0):
    """Windowed-sinc kernel K(t) = sinc(t) w(t) (eqs. 46-47) and its derivatives.

    Parameters
    ----------
    t : array_like
        Offset from a sample [tactel].
    n_samples : int
        N of eq. 47: the number of samples along the axis.
    derivatives : {0, 1, 2}
        How many derivatives to return besides K.

    Returns
    -------
    ndarray or tuple of ndarray
        K, then dK/dt, then d2K/dt2.
    """
    if n_samples < 2:
        raise ValueError(f"interpolation needs at least 2 samples along an axis; got {n_samples}")
    s, ds, d2s = sinc_derivatives(t)
    w, dw, d2w = hann_derivatives(t, n_samples)
    k = s * w
    if derivatives == 0:
        return k
    dk = ds * w + s * dw
    if derivatives == 1:
        return k, dk
    return k, dk, d2s * w + 2.0 * ds * dw + s * d2w


def kernel_integral(n_samples: int) -> float:
    """Integral of K over the real line [tactel]: the area one unit sample adds."""
    half = (n_samples - 1) / 2.0
    t = np.linspace(-half, half, 20001)
    return float(np.trapezoid(kernel(t, n_samples), t))


def _offsets(position, n: int, periodic: bool):
    """Offsets (..., n) of positions from the samples 0..n-1, wrapped when periodic."""
    offset = np.asarray(position, dtype=float)[..., None] - np.arange(n)
    if periodic:
        offset = np.mod(offset + n / 2.0, n) - n / 2.0
    return offset


def row_weights(x, n_rows: int, *, derivatives: int = 2):
    """Kernel weights of the rows at fractional row ``x``: arrays (..., rows)."""
    return kernel(_offsets(x, n_rows, False), n_rows, derivatives=derivatives)


def col_weights(y, n_cols: int, periodic: bool, *, derivatives: int = 2):
    """Kernel weights of the columns at fractional column ``y``: arrays (..., cols)."""
    return kernel(_offsets(y, n_cols, periodic), n_cols, derivatives=derivatives)


def surface(deflection, x, y, *, periodic: bool = False, derivatives: int = 0):
    """Evaluate the interpolated deflection surface f(x, y) of eq. 48.

    Parameters
    ----------
    deflection : ndarray, shape (..., rows, cols)
        z[i, j] of eq. 48 [-].
    x, y : array_like, broadcastable to the leading shape of ``deflection``
        Fractional row and column [tactel].
    periodic : bool
        Whether the columns close around the finger.
    derivatives : {0, 1, 2}
        0: f; 1: (f, f_x, f_y); 2: (f, f_x, f_y, f_xx, f_xy, f_yy).

    Returns
    -------
    ndarray or tuple of ndarray
        Values with the leading shape.
    """
    z = np.asarray(deflection, dtype=float)
    rows, cols = z.shape[-2:]
    x, y = np.broadcast_arrays(np.asarray(x, float), np.asarray(y, float))
    kx = row_weights(x, rows, derivatives=derivatives)
    ky = col_weights(y, cols, periodic, derivatives=derivatives)
    if derivatives == 0:
        return np.einsum("...r,...rc,...c->...", kx, z, ky)
    zy = [np.einsum("...rc,...c->...r", z, k) for k in ky]  # contract columns first
    f = np.einsum("...r,...r->...", kx[0], zy[0])
    fx = np.einsum("...r,...r->...", kx[1], zy[0])
    fy = np.einsum("...r,...r->...", kx[0], zy[1])
    if derivatives == 1:
        return f, fx, fy
    fxx = np.einsum("...r,...r->...", kx[2], zy[0])
    fxy = np.einsum("...r,...r->...", kx[1], zy[1])
    fyy = np.einsum("...r,...r->...", kx[0], zy[2])
    return f, fx, fy, fxx, fxy, fyy


def reconstruct_row(samples, x, *, n_window: int | None = None):
    """1-D windowed-sinc reconstruction of one row of samples (eq. 46).

    Parameters
    ----------
    samples : ndarray, shape (..., n)
        h[nb] at unit spacing [-].
    x : array_like
        Where to evaluate [tactel]; sample n sits at x = n.
    n_window : int, optional
        N of the Hann window; default the number of samples.

    Returns
    -------
    ndarray, shape (..., len(x))
    """
    samples = np.asarray(samples, dtype=float)
    n = samples.shape[-1]
    weights = kernel(np.asarray(x, float)[..., None] - np.arange(n), n_window or n)
    return np.einsum("...n,xn->...x", samples, np.atleast_2d(weights).reshape(-1, n)).reshape(
        *samples.shape[:-1], *np.shape(x)
    )
