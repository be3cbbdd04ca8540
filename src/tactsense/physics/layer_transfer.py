"""The bonded layer's closed-form transfer functions in the wavenumber domain.

The Fourier-mode solution of :mod:`tactsense.physics.layer` (its module docstring derives
it): for a mode of wavenumber k, the displacements and strains at depth z of a layer of
thickness h (Poisson's ratio nu) per unit surface load, with the k -> 0 limits where
the closed form cancels, and the half space's mean (k = 0) terms.
"""

from __future__ import annotations

import numpy as np

from tactsense._validation import (
    TactsenseInputError,
    as_float_array,
    check_poisson_ratio,
    check_positive,
)

_SMALL_KH = 1e-6  # below this k*h the k -> 0 limits replace the closed form (cancellation)


def shear_modulus(youngs_modulus, poisson_ratio):
    """mu = E / (2 (1 + nu)) [Pa]."""
    return youngs_modulus / (2.0 * (1.0 + poisson_ratio))


def _check_layer(thickness, youngs_modulus, poisson_ratio):
    h = float(thickness)
    if not (h > 0):  # also rejects NaN
        raise TactsenseInputError(
            f"thickness must be positive (np.inf: half space); got {thickness!r}"
        )
    check_positive(youngs_modulus, "youngs_modulus")
    nu = check_poisson_ratio(poisson_ratio)
    return h, float(youngs_modulus), nu


def transfer_functions(k, z, thickness, poisson_ratio):
    """Closed-form transfer functions of the bonded layer at wavenumber k and depth z.

    For a load mode ``(P, Q_L, Q_T) exp(i k.x)`` (pressure, traction along and across
    the wavevector), the displacement at depth z is

        2 mu w   = W_P P + W_Q Q_L
        2 mu u_L = U_P P + U_Q Q_L,        2 mu u_T = T Q_T

    and the ``d...`` entries are their derivatives d/dz.

    Parameters
    ----------
    k : array_like
        Radial wavenumber |k| > 0 [rad/m] (k = 0: the limits for a finite layer).
    z : array_like
        Depth below the surface, 0 <= z <= thickness [m].
    thickness : float
        h [m]; ``np.inf`` for the half space.
    poisson_ratio : float
        nu, in (-1, 0.5] [-].

    Returns
    -------
    dict of ndarray
        Complex ``W_P, W_Q, U_P, U_Q, T`` [m] and ``dW_P, dW_Q, dU_P, dU_Q, dT`` [-],
        broadcast over k and z. ``W_Q`` and ``U_P`` are imaginary, the rest real.
    """
    h = float(thickness)
    nu = check_poisson_ratio(poisson_ratio)
    k = as_float_array(k, "k")
    z = as_float_array(z, "z")
    if np.any(k < 0):
        raise TactsenseInputError("k must be non-negative [rad/m]")
    if np.any(z < 0) or np.any(z > h * (1 + 1e-12)):
        raise TactsenseInputError("depth z must lie within the layer, 0 <= z <= thickness")
    if not np.isfinite(h) and np.any(k == 0):
        raise TactsenseInputError("the half space has no finite k = 0 transfer function")
    k, z = np.broadcast_arrays(k, z)
    small = k * h < _SMALL_KH if np.isfinite(h) else np.zeros(k.shape, bool)
    ks = np.where(small, 1.0, k)  # the closed form on a safe k; the limits replace it below
    out = _closed_form(ks, z, h, nu)
    if np.any(small):
        for name, value in _k0_limits(z, h, nu).items():
            out[name] = np.where(small, value, out[name])
    return out


def _closed_form(k, z, h, nu):
    kappa = 3.0 - 4.0 * nu
    finite = np.isfinite(h)
    with np.errstate(under="ignore"):
        e = np.exp(-k * h) if finite else np.zeros_like(k)
        e2 = e * e
        t = k * h if finite else np.zeros_like(k)  # t only ever appears multiplied by e
        ez = np.exp(-k * z)
        ehz = np.exp(-k * (h - z)) if finite else np.zeros_like(k)
    den = kappa + (kappa * kappa + 1.0 + 4.0 * t * t) * e2 + kappa * e2 * e2
    out = {}
    for load in ("P", "Q"):
        if load == "P":
            kA = -(2 * t * e2 - e2 - kappa) / den
            kB = -e * (kappa * e2 + 2 * t + 1) / den
            k2C = (
                8 * e2 * nu**2
                - 4 * e2 * nu * t
                - 10 * e2 * nu
                + 2 * e2 * t**2
                + 2 * e2 * t
                + 3 * e2
                - 8 * nu**2
                + 10 * nu
                - 3
            ) / den
            k2D = (
                e
                * (
                    -8 * e2 * nu**2
                    + 10 * e2 * nu
                    - 3 * e2
                    + 8 * nu**2
                    + 4 * nu * t
                    - 10 * nu
                    + 2 * t**2
                    - 2 * t
                    + 3
                )
                / den
            )
        else:
            kA = -1j * (2 * t * e2 + e2 + kappa) / den
            kB = -1j * e * (kappa * e2 - 2 * t + 1) / den
            k2C = (
                1j
                * (
                    8 * e2 * nu**2
                    - 4 * e2 * nu * t
                    - 14 * e2 * nu
                    + 2 * e2 * t**2
                    + 4 * e2 * t
                    + 6 * e2
                    + 8 * nu**2
                    - 14 * nu
                    + 6
                )
                / den
            )
            k2D = (
                1j
                * e
                * (
                    -8 * e2 * nu**2
                    + 14 * e2 * nu
                    - 6 * e2
                    - 8 * nu**2
                    - 4 * nu * t
                    + 14 * nu
                    - 2 * t**2
                    + 4 * t
                    - 6
                )
                / den
            )
        # psi = A e^{-kz} + B e^{-k(h-z)}, phi = C e^{-kz} + D e^{-k(h-z)}; scaled by k, k^2
        psi_k = kA * ez + kB * ehz  # k psi
        dpsi = -kA * ez + kB * ehz  # psi'
        phi_k = k2C * ez + k2D * ehz  # k^2 phi
        dphi_k = -k2C * ez + k2D * ehz  # k phi'
        out["W_" + load] = (kappa * psi_k - k * z * dpsi - dphi_k) / k
        out["dW_" + load] = (kappa - 1.0) * dpsi - k * z * psi_k - phi_k
        out["U_" + load] = -1j * (k * z * psi_k + phi_k) / k
        out["dU_" + load] = -1j * (psi_k + k * z * dpsi + dphi_k)
    ratio = 1.0 / (1.0 + e2)
    with np.errstate(under="ignore"):
        e_deep = np.exp(-2.0 * k * (h - z)) if finite else np.zeros_like(k)
    out["T"] = 2.0 * ez * (1.0 - e_deep) * ratio / k + 0j
    out["dT"] = -2.0 * ez * (1.0 + e_deep) * ratio + 0j
    return out


def _k0_limits(z, h, nu):
    """Limits k -> 0 of :func:`transfer_functions` for a finite layer (uniform load)."""
    zero = np.zeros_like(z) + 0j
    return {
        "W_P": (1 - 2 * nu) * (h - z) / (1 - nu) + zero,
        "dW_P": -(1 - 2 * nu) / (1 - nu) + zero,
        "W_Q": zero,
        "dW_Q": zero,
        "U_P": zero,
        "dU_P": zero,
        "U_Q": 2 * (h - z) + zero,
        "dU_Q": -2.0 + zero,
        "T": 2 * (h - z) + zero,
        "dT": -2.0 + zero,
    }


def _half_space_k0(z, nu, dkx, dky):
    """Half space: the k = 0 bin as the average of each transfer function over its cell.

    ``W_P``, ``U_Q`` and ``T`` grow as c / k; the cell average of 1 / k over
    ``[-dkx/2, dkx/2] x [-dky/2, dky/2]`` is ``4 (a asinh(b/a) + b asinh(a/b)) / (dkx dky)``
    with a, b the half-widths, and the smooth rest is taken at k = 0.
    """
    a, b = dkx / 2, dky / 2
    mean_inverse_k = 4 * (a * np.arcsinh(b / a) + b * np.arcsinh(a / b)) / (dkx * dky)
    return {
        "W_P": 2 * (1 - nu) * mean_inverse_k + z * (2 * nu - 1),
        "dW_P": -(1 - 2 * nu),
        "U_Q": 2 * (1 - nu) * mean_inverse_k + z * (2 * nu - 3),
        "dU_Q": 2 * nu - 3,
        "T": 2 * mean_inverse_k - 2 * z,
        "dT": -2.0,
    }
