"""Aliasing of the sampled strain (section 6, eqs. 37-47, Figs. 19-20).

The plane-stress impulse response at depth d has the spectrum (eq. 41)
``G(s) = [(1 - nu) + 2 pi d |s| (1 + nu)] exp(-2 pi d |s|) / E``
(here with compression positive). Sampling at spacing b folds
``A(s) = G(s + 1/b) + G(s - 1/b)`` into the band (eq. 44), and an ideal low-pass
reconstruction keeps only ``|s| < 1/(2b)``, losing the energy ratio xi of eq. 45.
"""

from __future__ import annotations

import numpy as np

from tactsense._validation import as_float_array, check_poisson_ratio, check_positive
from tactsense.estimate.finger.interpolate import kernel
from tactsense.physics.halfplane import frequency_response, impulse_response


def normalized_response(s, depth, poisson_ratio):
    """Compressive-strain spectrum G(s) / G(0) of a line load (eq. 41) [-]."""
    g = -frequency_response(s, depth, youngs_modulus=1.0, poisson_ratio=poisson_ratio)
    return g / (1.0 - poisson_ratio)


def aliased_spectrum(s, depth, spacing, poisson_ratio):
    """First-order aliased spectrum A(s) = G(1/b + s) + G(s - 1/b), normalised (eq. 44) [-]."""
    s = as_float_array(s, "s")
    spacing = check_positive(spacing, "spacing")
    return normalized_response(s + 1.0 / spacing, depth, poisson_ratio) + normalized_response(
        s - 1.0 / spacing, depth, poisson_ratio
    )


def _energy(limit, depth, nu):
    """integral_0^limit G(s)^2 ds for G = (a + c s) exp(-beta s / 2), closed form."""
    a = 1.0 - nu
    c = 2.0 * np.pi * depth * (1.0 + nu)
    beta = 4.0 * np.pi * depth

    def antiderivative(s):
        poly = (
            a * a / beta
            + 2 * a * c * (s / beta + 1 / beta**2)
            + c * c * (s * s / beta + 2 * s / beta**2 + 2 / beta**3)
        )
        return -np.exp(-beta * s) * poly

    upper = np.where(np.isinf(limit), 0.0, antiderivative(np.where(np.isinf(limit), 0.0, limit)))
    return upper - antiderivative(0.0)


def reconstruction_error(depth, spacing, poisson_ratio=0.5):
    """Energy ratio xi of eq. 45: the share of |H|^2 outside the band |s| < 1/(2b) [-].

    Parameters
    ----------
    depth : array_like
        Sensor depth d [m] (or any unit, the same as ``spacing``).
    spacing : array_like
        Sensor spacing b, in the unit of ``depth``.
    poisson_ratio : float

    Returns
    -------
    ndarray
        xi [-]. Its square root is the RMS amplitude error of the reconstruction.
    """
    nu = check_poisson_ratio(poisson_ratio)
    depth = as_float_array(depth, "depth")
    spacing = as_float_array(spacing, "spacing")
    total = _energy(np.inf, depth, nu)
    return (total - _energy(1.0 / (2.0 * spacing), depth, nu)) / total


def interpolation_errors(positions, depth, spacing, poisson_ratio=0.5, n_samples=7):
    """Peak position and amplitude errors of the windowed-sinc reconstruction (Fig. 20).

    A line load at ``position`` (in tactels from the middle sensor) is sampled
    by ``n_samples`` sensors at spacing b; eq. 46 reconstructs the profile and
    its maximum is found on a fine grid.

    Returns
    -------
    position_error : ndarray
        Estimated minus true position [tactel].
    amplitude_error : ndarray
        Reconstructed peak over true peak, minus one [-].
    """
    positions = np.atleast_1d(as_float_array(positions, "positions"))
    half = (n_samples - 1) // 2
    sensors = np.arange(-half, half + 1)
    x_fine = np.linspace(-half, half, 60 * (2 * half) + 1)
    kw = {"youngs_modulus": 1.0, "poisson_ratio": poisson_ratio}
    samples = -impulse_response((sensors[None, :] - positions[:, None]) * spacing, depth, **kw)
    weights = kernel(x_fine[:, None] - sensors[None, :], n_samples)
    profile = samples @ weights.T
    best = profile.argmax(axis=1)
    # parabolic refinement of the grid maximum
    left = profile[np.arange(len(best)), np.clip(best - 1, 0, None)]
    mid = profile[np.arange(len(best)), best]
    right = profile[np.arange(len(best)), np.clip(best + 1, None, x_fine.size - 1)]
    denom = left - 2 * mid + right
    shift = np.where(denom < 0, 0.5 * (left - right) / np.where(denom < 0, denom, 1.0), 0.0)
    step = x_fine[1] - x_fine[0]
    peak_x = x_fine[best] + shift * step
    peak_value = mid - 0.25 * (left - right) * shift
    true_peak = -impulse_response(0.0, depth, **kw)
    return peak_x - positions, peak_value / true_peak - 1.0


def aliasing_summary(depth, spacing, poisson_ratio=0.5):
    """The designer's numbers for one depth and spacing (SI or any common unit)."""
    nu = check_poisson_ratio(poisson_ratio)
    xi = float(reconstruction_error(depth, spacing, nu))
    positions = np.linspace(-0.5, 0.5, 101)
    pos_err, amp_err = interpolation_errors(positions, depth, spacing, nu)
    return {
        "depth": depth,
        "spacing": spacing,
        "poisson_ratio": nu,
        "xi": xi,
        "rms_amplitude_error": float(np.sqrt(xi)),
        "peak_frequency": float(nu / (np.pi * depth * (1 + nu))),
        "nyquist_frequency": 1.0 / (2.0 * spacing),
        "response_at_nyquist": float(normalized_response(1.0 / (2.0 * spacing), depth, nu)),
        "worst_position_error_tactel": float(np.abs(pos_err).max()),
        "worst_amplitude_error": float(np.abs(amp_err).max()),
    }
