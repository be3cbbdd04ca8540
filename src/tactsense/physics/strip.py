"""Elastic strip bonded to a rigid core (section 5 of the paper, eqs. 11-36, Figs. 17-18).

A layer of thickness h lies on a rigid foundation at depth z = h, bonded
(u = w = 0 there), and is pressed on top (z = 0) by a frictionless pressure
p(x) (tau_xz = 0, sigma_z = -p). z points into the layer; w > 0 is a
displacement toward the core, so a pressure gives w > 0 and a compressive
strain eps_z = dw/dz < 0.

Derivation (``docs/strip.md`` gives it in full): with the Papkovich-Neuber
potentials ``psi_3 = (A e^{-kz} + B e^{kz}) cos kx`` and
``phi = (C e^{-kz} + D e^{kz}) cos kx`` (eqs. 14-15 with psi_1 = 0), the four
boundary conditions fix A..D; the displacement under a pressure
``p_hat cos kx`` is ``w = p_hat H(k, z) cos kx / (2 mu)`` with

    H(k, z) = exp(-kz) N(k, z) / (k D(k))
    N = kappa (kz + 2(1-nu))
        + [-2k^2 h (h-z) - 4kh(1-nu) + kz - 2 kappa (1-nu)] exp(-2k(h-z))
        + kappa (kz - 2(1-nu)) exp(-2k(2h-z))
        + [ 2k^2 h (h-z) - 4kh(1-nu) + kz + 2 kappa (1-nu)] exp(-2kh)
    D = kappa + (4 k^2 h^2 + kappa^2 + 1) exp(-2kh) + kappa exp(-4kh)

where ``kappa = 3 - 4 nu`` and k = 2 pi |s|. Every exponent is non-positive
for 0 <= z <= h, so nothing overflows at large kh; for kh < 1e-3 the
cancellation in N is avoided with the Taylor series to O(k^2). Plane stress
uses ``nu* = nu / (1 + nu)`` with the same shear modulus (section 5).

As h -> infinity, H -> (kz + 2(1 - nu)) exp(-kz) / k, the half plane.

References
----------
.. [1] R. S. Fearing, "Tactile Sensing Mechanisms", IJRR 9(3), 1990.
.. [2] G. M. L. Gladwell, *Contact Problems in the Classical Theory of
   Elasticity*, 1980.
"""

from __future__ import annotations

import numpy as np

from tactsense._validation import (
    TactsenseInputError,
    as_float_array,
    check_choice,
    check_poisson_ratio,
)

MODELS = ("plane_stress", "plane_strain")
_SERIES_LIMIT = 1e-3  # below this k*h the Taylor series replaces the closed form


def effective_poisson_ratio(poisson_ratio, model):
    """Poisson's ratio to use in the plane-strain formulas: nu, or nu/(1+nu) in plane stress."""
    check_choice(model, "model", MODELS)
    nu = check_poisson_ratio(poisson_ratio)
    return nu / (1.0 + nu) if model == "plane_stress" else nu


def shear_modulus(youngs_modulus, poisson_ratio):
    """mu = E / (2 (1 + nu)) (eq. 13 of [1]) [Pa]."""
    return youngs_modulus / (2.0 * (1.0 + poisson_ratio))


def _kernels(k, z, h, nu):
    """H(k, z) and dH/dz for plane strain with Poisson's ratio nu (arrays broadcast)."""
    k, z, h, nu = np.broadcast_arrays(*(np.asarray(a, dtype=float) for a in (k, z, h, nu)))
    kappa = 3.0 - 4.0 * nu
    one = 1.0 - nu
    with np.errstate(divide="ignore", invalid="ignore", over="ignore", under="ignore"):
        e_hz = np.exp(-2.0 * k * (h - z))
        e_2hz = np.exp(-2.0 * k * (2.0 * h - z))
        e_h = np.exp(-2.0 * k * h)
        a = -2.0 * k * k * h * (h - z) - 4.0 * k * h * one + k * z - 2.0 * kappa * one
        b = 2.0 * k * k * h * (h - z) - 4.0 * k * h * one + k * z + 2.0 * kappa * one
        c = kappa * (k * z - 2.0 * one)
        numerator = kappa * (k * z + 2.0 * one) + a * e_hz + c * e_2hz + b * e_h
        d_numerator = (
            kappa * k
            + (2.0 * k * k * h + k + 2.0 * k * a) * e_hz
            + (kappa * k + 2.0 * k * c) * e_2hz
            + (-2.0 * k * k * h + k) * e_h
        )
        denominator = kappa + (4.0 * k * k * h * h + kappa * kappa + 1.0) * e_h + kappa * e_h**2
        decay = np.exp(-k * z)
        H = decay * numerator / (k * denominator)
        dH = decay * (d_numerator - k * numerator) / (k * denominator)
    H = np.where(z >= h, 0.0, H)  # bonded to the core: exactly no displacement there
    dH = np.array(dH, dtype=float)
    small = k * h < _SERIES_LIMIT
    if np.any(small):
        ks, zs, hs, ns = k[small], z[small], h[small], nu[small]
        depth_left = hs - zs
        H0 = depth_left * (1.0 - 2.0 * ns) / (1.0 - ns)
        H2 = (
            ns
            * depth_left
            * (8 * hs**2 * ns - 2 * hs**2 - 4 * hs * ns * zs + hs * zs + 2 * ns * zs**2 - 2 * zs**2)
            / (6.0 * (1.0 - ns) ** 2)
        )
        dH0 = -(1.0 - 2.0 * ns) / (1.0 - ns)
        dH2 = (
            -ns
            * (4 * hs**2 * ns - hs**2 - 4 * hs * ns * zs + 2 * hs * zs + 2 * ns * zs**2 - 2 * zs**2)
            / (2.0 * (1.0 - ns) ** 2)
        )
        H[small] = H0 + H2 * ks**2
        dH[small] = dH0 + dH2 * ks**2
    return H, dH


def strip_kernel(s, z, thickness, poisson_ratio, model="plane_strain"):
    """Kernel H(s, z) of eq. 27: ``2 mu w_hat(s, z) = P(s) H(s, z)``.

    Parameters
    ----------
    s : array_like
        Spatial frequency [cycles/m].
    z : array_like
        Depth below the surface, 0 <= z <= thickness [m].
    thickness : array_like
        h, thickness of the strip [m].
    poisson_ratio : float
        nu of the material [-].
    model : {"plane_strain", "plane_stress"}

    Returns
    -------
    ndarray
        H [m]; positive (displacement toward the core).
    """
    nu = effective_poisson_ratio(poisson_ratio, model)
    s, z, h = _check_geometry(s, z, thickness)
    return _kernels(2.0 * np.pi * np.abs(s), z, h, nu)[0]


def strip_strain_kernel(s, z, thickness, poisson_ratio, model="plane_strain"):
    """Kernel of the normal strain: ``2 mu eps_hat_z(s, z) = P(s) dH/dz`` [-]; negative."""
    nu = effective_poisson_ratio(poisson_ratio, model)
    s, z, h = _check_geometry(s, z, thickness)
    return _kernels(2.0 * np.pi * np.abs(s), z, h, nu)[1]


def half_plane_kernel(s, z, poisson_ratio, model="plane_strain"):
    """The limit h -> infinity of :func:`strip_kernel`: ``(kz + 2(1-nu)) exp(-kz) / k`` [m]."""
    nu = effective_poisson_ratio(poisson_ratio, model)
    k = 2.0 * np.pi * np.abs(as_float_array(s, "s"))
    z = as_float_array(z, "z")
    with np.errstate(divide="ignore"):
        return (k * z + 2.0 * (1.0 - nu)) * np.exp(-k * z) / k


def _check_geometry(s, z, thickness):
    s = as_float_array(s, "s")
    z = as_float_array(z, "z")
    h = as_float_array(thickness, "thickness")
    if np.any(h <= 0):
        raise TactsenseInputError("thickness must be positive")
    if np.any(z < 0) or np.any(z > h * (1 + 1e-12)):
        raise TactsenseInputError("depth z must lie within the strip, 0 <= z <= thickness")
    return s, z, h


def parabolic_pressure_transform(s, line_load, width):
    """Fourier transform P(s) of a parabolic pressure of total ``line_load`` and ``width``.

    ``p(x) = (3 F / 2 w) (1 - (2x / w)^2)`` on ``|x| < w / 2``;
    ``P(s) = 3 F (sin(ka) - ka cos(ka)) / (ka)^3`` with ``a = w / 2``, ``k = 2 pi s``.

    Parameters
    ----------
    s : array_like
        [cycles/m].
    line_load : array_like
        F [N/m].
    width : array_like
        Full width of the contact [m].

    Returns
    -------
    ndarray
        P(s) [N/m].
    """
    t = 2.0 * np.pi * np.abs(np.asarray(s, dtype=float)) * np.asarray(width, dtype=float) / 2.0
    t_safe = np.where(t < 1e-3, 1.0, t)
    ratio = np.where(
        t < 1e-3, 1.0 / 3.0 - t * t / 30.0, (np.sin(t_safe) - t_safe * np.cos(t_safe)) / t_safe**3
    )
    return 3.0 * np.asarray(line_load, dtype=float) * ratio


# Composite Gauss-Legendre rule on [0, 1] in u, mapped to k = k_max u^2 so that nodes
# crowd near k = 0 where the kernel varies on the scale 1/h.
_NODES, _WEIGHTS = np.polynomial.legendre.leggauss(24)
_PANELS = 24


def _frequency_grid(k_max):
    """Nodes k [1/m] and weights for integrals over [0, k_max] (shape (..., n))."""
    edges = np.linspace(0.0, 1.0, _PANELS + 1)
    half = 0.5 * np.diff(edges)
    centre = 0.5 * (edges[1:] + edges[:-1])
    u = (centre[:, None] + half[:, None] * _NODES[None, :]).ravel()
    w = (half[:, None] * _WEIGHTS[None, :]).ravel()
    k_max = np.asarray(k_max, dtype=float)[..., None]
    return k_max * u**2, w * 2.0 * u * k_max


def displacement(
    x, z, thickness, line_load, width, *, youngs_modulus, poisson_ratio, model="plane_stress"
):
    """Displacement w(x, z) toward the core under a parabolic pressure (eq. 34) [m].

    ``2 mu w(x, z) = 2 integral_0^inf P(s) H(s, z) cos(2 pi s x) ds``,
    evaluated on a mapped Gauss-Legendre rule (576 nodes) up to the
    frequency where ``exp(-kz)`` and the pressure spectrum have decayed.

    Parameters
    ----------
    x : array_like
        Offset from the centre of the pressure [m].
    z : array_like
        Depth [m], 0 <= z <= thickness.
    thickness : array_like
        h [m].
    line_load : array_like
        Total load per unit length of the slab [N/m].
    width : array_like
        Width of the parabolic pressure [m] (the paper: 3 mm probe).
    youngs_modulus : float
        E [Pa].
    poisson_ratio : float
        nu of the material [-]; plane stress uses nu / (1 + nu) (section 5).
    model : {"plane_stress", "plane_strain"}

    Returns
    -------
    ndarray
        w [m], broadcast over all inputs.
    """
    return _transform(
        x, z, thickness, line_load, width, youngs_modulus, poisson_ratio, model, strain=False
    )


def normal_strain(
    x, z, thickness, line_load, width, *, youngs_modulus, poisson_ratio, model="plane_stress"
):
    """Normal strain eps_z(x, z) = dw/dz under a parabolic pressure [-] (negative)."""
    return _transform(
        x, z, thickness, line_load, width, youngs_modulus, poisson_ratio, model, strain=True
    )


def _transform(x, z, thickness, line_load, width, youngs_modulus, poisson_ratio, model, strain):
    nu = effective_poisson_ratio(poisson_ratio, model)
    mu = shear_modulus(youngs_modulus, poisson_ratio)
    x = as_float_array(x, "x")
    _, z, h = _check_geometry(0.0, z, thickness)
    line_load = as_float_array(line_load, "line_load")
    width = as_float_array(width, "width")
    if np.any(width < 0):
        raise TactsenseInputError("width must be non-negative (0 is a line load)")
    x, z, h, line_load, width = np.broadcast_arrays(x, z, h, line_load, width)
    # decay scale: depth, else a fraction of the contact width, else the thickness
    scale = np.maximum(np.maximum(z, 0.05 * width), 1e-3 * h)
    k, weight = _frequency_grid(40.0 / scale)
    s = k / (2.0 * np.pi)
    H, dH = _kernels(k, z[..., None], h[..., None], nu)
    spectrum = parabolic_pressure_transform(s, line_load[..., None], width[..., None])
    kernel = dH if strain else H
    integrand = spectrum * kernel * np.cos(k * x[..., None])
    # ds = dk / (2 pi); eq. 34: 2 mu w = 2 integral_0^inf ... ds
    return 2.0 * np.sum(integrand * weight, axis=-1) / (2.0 * np.pi) / (2.0 * mu)


def capacitor_gain(
    top_depth,
    bottom_depth,
    thickness,
    line_load,
    width,
    *,
    youngs_modulus,
    poisson_ratio,
    model="plane_stress",
):
    """Fractional closing of a capacitor between two depths under the centre of a pressure.

    ``gain = (w(0, top) - w(0, bottom)) / (bottom - top)``; with the bottom
    plate on the core (bottom = thickness, w = 0) this is eq. 36 of [1],
    ``w(0, d) / (h - d)``. Arrays broadcast: one call evaluates many designs.

    Parameters
    ----------
    top_depth, bottom_depth : array_like
        Depths of the top and bottom plates [m]; top < bottom <= thickness.
    thickness : array_like
        h, thickness of the elastic layer over the rigid core [m].
    line_load : array_like
        F [N/m].
    width : array_like
        Width of the parabolic pressure [m].

    Returns
    -------
    ndarray
        dd / d_o [-].
    """
    top = as_float_array(top_depth, "top_depth")
    bottom = as_float_array(bottom_depth, "bottom_depth")
    if np.any(bottom <= top):
        raise TactsenseInputError("bottom_depth must be deeper than top_depth")
    kwargs = {"youngs_modulus": youngs_modulus, "poisson_ratio": poisson_ratio, "model": model}
    w_top = displacement(0.0, top, thickness, line_load, width, **kwargs)
    w_bottom = displacement(0.0, bottom, thickness, line_load, width, **kwargs)
    return (w_top - w_bottom) / (bottom - top)


def impulse_response(x, depth, thickness, *, youngs_modulus, poisson_ratio, model="plane_stress"):
    """Normal strain at ``depth`` under a unit line load on the strip (Fig. 18) [m/N].

    The strip's counterpart of :func:`tactsense.physics.halfplane.impulse_response`;
    it tends to it as the thickness grows.
    """
    return normal_strain(
        x,
        depth,
        thickness,
        1.0,
        0.0,
        youngs_modulus=youngs_modulus,
        poisson_ratio=poisson_ratio,
        model=model,
    )
