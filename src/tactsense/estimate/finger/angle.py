"""Force angle from the asymmetry of the strain profile (section 9, eqs. 57-72).

The strain under an even pressure with proportional traction ``beta p(x)``
(eq. 58) is the sum of an even part from the normal load and an odd part from the
tangential load (eqs. 59-61). About the peak, eq. 62 splits a measured profile
into the two, and the skew index (eq. 63) ``max f_odd / max f_even`` tracks the
angle. For a line load it is ``k(nu) tan(alpha)`` with k = 0.2805 at nu = 0.5
(:func:`tactsense.physics.halfplane.line_load_skew_coefficient`; the paper prints
0.2441).
"""

from __future__ import annotations

import numpy as np

from tactsense.estimate.finger.interpolate import surface
from tactsense.physics.halfplane import (
    frequency_response,
    frequency_response_tangential,
    line_load_skew_coefficient,
)


def even_odd(profile_plus, profile_minus):
    """Even and odd parts about the peak (eq. 62).

    Parameters
    ----------
    profile_plus, profile_minus : ndarray, shape (..., n)
        f(x0 + t) and f(x0 - t) at the same offsets t >= 0.

    Returns
    -------
    even, odd : ndarray
    """
    plus = np.asarray(profile_plus, float)
    minus = np.asarray(profile_minus, float)
    return 0.5 * (plus + minus), 0.5 * (plus - minus)


def skew_index(even, odd):
    """Skew index of eq. 63: the odd part at its largest magnitude over the even maximum.

    Signed: positive when the profile leans toward +t.
    """
    even = np.asarray(even, float)
    odd = np.asarray(odd, float)
    pick = np.argmax(np.abs(odd), axis=-1)
    odd_peak = np.take_along_axis(odd, pick[..., None], axis=-1)[..., 0]
    even_peak = even.max(axis=-1)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(even_peak > 0, odd_peak / even_peak, np.nan)


def skew_along_finger(
    deflection,
    row,
    col,
    *,
    periodic: bool = False,
    first_row: int = 1,
    reach: float = 2.0,
    step: float = 0.25,
):
    """Skew index of the interpolated profile along the finger through the peak.

    Parameters
    ----------
    deflection : ndarray, shape (..., rows, cols)
    row, col : array_like
        The peak [tactel].
    first_row : int
        First row of the cylinder (the tip row is left out).
    reach : float
        Largest offset used, in tactels; shortened to stay within the rows.

    Returns
    -------
    ndarray
        Skew index [-]; NaN where less than half a tactel fits on both sides.
    """
    z = np.asarray(deflection, float)
    rows = z.shape[-2]
    row = np.asarray(row, float)
    room = np.minimum(row - first_row, rows - 1 - row)
    t = np.arange(0.0, reach + 1e-9, step)
    usable = t[None, :] <= np.atleast_1d(room)[:, None]
    offsets = np.broadcast_to(t, (*row.shape, t.size))
    zz = z[..., None, :, :]
    plus = surface(
        zz, row[..., None] + offsets, np.asarray(col, float)[..., None], periodic=periodic
    )
    minus = surface(
        zz, row[..., None] - offsets, np.asarray(col, float)[..., None], periodic=periodic
    )
    usable = usable.reshape(offsets.shape)
    even, odd = even_odd(np.where(usable, plus, -np.inf), np.where(usable, minus, -np.inf))
    odd = np.where(usable, odd, 0.0)
    skew = skew_index(even, odd)
    return np.where(room >= 0.5, skew, np.nan)


def angle_from_skew(skew, poisson_ratio):
    """Force angle alpha of a line load from its skew index (eq. 67, corrected) [rad]."""
    return np.arctan(np.asarray(skew, float) / line_load_skew_coefficient(poisson_ratio))


def inverse_filter(
    profile,
    spacing,
    depth,
    *,
    youngs_modulus,
    poisson_ratio,
    model="plane_stress",
    band=None,
    regularization=0.05,
):
    """Recover the pressure spectrum and the tangential ratio beta (eqs. 68-72).

    The deflection profile (compression positive) about its peak has the
    transform ``D(s) = P(s) [G_n(s) + beta G_t(s)]`` with ``G = -H`` of the
    half plane: real ``G_n`` from the normal load, imaginary ``G_t`` from the
    tangential one. With Tikhonov regularisation ``eps = regularization *
    max G_n`` (explicit, so that noise above the band is not amplified):

    ``P = Re D G_n / (G_n^2 + eps^2)``, ``beta P = Im D Im G_t / ((Im G_t)^2 + eps^2)``

    and beta is the least-squares ratio of the two over the band.

    Parameters
    ----------
    profile : ndarray, shape (n,)
        Deflection on a uniform grid centred on the peak (sample n // 2) [-].
    spacing : float
        Grid step [m].
    depth : float
        Effective depth [m].
    band : float, optional
        Highest frequency used [cycles/m]; default 1 / (4 depth).
    regularization : float
        eps as a share of max G_n [-].

    Returns
    -------
    dict
        ``s`` [cycles/m], ``pressure`` P(s) and ``tangential`` beta P(s) [N/m],
        ``line_load`` P(0) [N/m], ``beta`` [-], ``alpha`` [rad].
    """
    profile = np.asarray(profile, float)
    n = profile.size
    centred = np.fft.ifftshift(profile)  # peak at index 0: phase referenced to the peak
    spectrum = np.fft.rfft(centred) * spacing
    s = np.fft.rfftfreq(n, spacing)
    kwargs = {"youngs_modulus": youngs_modulus, "poisson_ratio": poisson_ratio, "model": model}
    g_n = -frequency_response(s, depth, **kwargs)
    g_t = -frequency_response_tangential(s, depth, **kwargs).imag
    # numpy's rfft uses exp(-2 pi i s x), the convention of the half-plane transforms
    eps = regularization * g_n.max()
    pressure = spectrum.real * g_n / (g_n**2 + eps**2)
    tangential = spectrum.imag * g_t / (g_t**2 + eps**2)
    band = 1.0 / (4.0 * depth) if band is None else band
    inside = (s > 0) & (s <= band)
    beta = (
        float(np.sum(tangential[inside] * pressure[inside]) / np.sum(pressure[inside] ** 2))
        if inside.any()
        else float("nan")
    )
    return {
        "s": s,
        "pressure": pressure,
        "tangential": tangential,
        "line_load": float(pressure[0]),
        "beta": beta,
        "alpha": float(np.arctan(beta)),
    }
