"""Elastic half plane under a line load (section 4 of the paper, eqs. 5-10, 38, 41).

Coordinates: x along the surface [m], z depth into the medium [m] (z > 0
inside). Stresses and strains are positive in tension, so a normal load
pressing on the surface gives negative (compressive) ``sigma_z`` and
``eps_z``. A line load is a force per unit length of the slab [N/m]; at
angle ``alpha`` to the normal its tangential component points toward +x for
``alpha > 0`` (see ``docs/errata.md`` on the sign printed in eq. 7).

The Flamant solution (Johnson, *Contact Mechanics*, 1985, eqs. 2.15-2.20)
gives the stresses; eq. 5 of the paper turns them into strains, with
``sigma_y = 0`` (plane stress, eq. 7) or ``eps_y = 0`` (plane strain,
eqs. 8-9).

References
----------
.. [1] R. S. Fearing, "Tactile Sensing Mechanisms", IJRR 9(3), 1990.
.. [2] K. L. Johnson, *Contact Mechanics*, Cambridge University Press, 1985.
.. [3] G. M. L. Gladwell, *Contact Problems in the Classical Theory of
   Elasticity*, Sijthoff & Noordhoff, 1980.
"""

from __future__ import annotations

import numpy as np

from tactsense._validation import (
    as_float_array,
    check_choice,
    check_poisson_ratio,
    check_positive,
)

MODELS = ("plane_stress", "plane_strain")


def flamant_stresses(x, z, normal_load, tangential_load=0.0):
    """Stresses under a line load on an elastic half plane (Flamant).

    Parameters
    ----------
    x, z : array_like
        Position across the surface and depth below it [m]; ``z > 0``.
    normal_load : float or array_like
        Normal line load pressing into the surface [N/m].
    tangential_load : float or array_like
        Tangential line load toward +x [N/m].

    Returns
    -------
    sigma_x, sigma_z, tau_xz : ndarray
        In-plane stresses [Pa], tension positive.

    Notes
    -----
    Eq. 6 of [1] for the normal load; eq. 2.20 of [2] for the tangential one.
    """
    x = as_float_array(x, "x")
    z = as_float_array(z, "z")
    r4 = (x * x + z * z) ** 2
    common = -2.0 / (np.pi * r4)
    push = normal_load * z + tangential_load * x
    return common * x * x * push, common * z * z * push, common * x * z * push


def strain_from_stress(sigma_x, sigma_z, youngs_modulus, poisson_ratio, model="plane_stress"):
    """Normal strain eps_z from in-plane stresses (eq. 5 with eq. 7 or eqs. 8-9 of [1]).

    Parameters
    ----------
    sigma_x, sigma_z : array_like
        Stresses [Pa].
    youngs_modulus : float
        E [Pa].
    poisson_ratio : float
        nu [-].
    model : {"plane_stress", "plane_strain"}

    Returns
    -------
    ndarray
        eps_z [-].
    """
    check_choice(model, "model", MODELS)
    nu = check_poisson_ratio(poisson_ratio)
    E = check_positive(youngs_modulus, "youngs_modulus")
    sigma_x = np.asarray(sigma_x, dtype=float)
    sigma_z = np.asarray(sigma_z, dtype=float)
    if model == "plane_stress":
        return (sigma_z - nu * sigma_x) / E
    return (1.0 + nu) / E * ((1.0 - nu) * sigma_z - nu * sigma_x)


def plane_strain_equivalent(youngs_modulus, poisson_ratio):
    """Plane-strain constants that reproduce a plane-stress medium (eq. 10 of [1]).

    A plane-stress medium (E, nu) has the strains of a plane-strain medium
    with ``nu* = nu / (1 + nu)`` (eq. 10 read backwards: nu = nu*/(1 - nu*))
    and ``E* = E (1 + 2 nu) / (1 + nu)^2``; the paper states only the first.

    Returns
    -------
    E_star : float
        [Pa].
    nu_star : float
        [-].
    """
    nu = check_poisson_ratio(poisson_ratio)
    E = check_positive(youngs_modulus, "youngs_modulus")
    return E * (1.0 + 2.0 * nu) / (1.0 + nu) ** 2, nu / (1.0 + nu)


def plane_stress_equivalent(youngs_modulus, poisson_ratio):
    """Plane-stress constants that reproduce a plane-strain medium (inverse of eq. 10).

    ``nu' = nu / (1 - nu)`` and ``E' = E / (1 - nu^2)``.

    Returns
    -------
    E_prime : float
        [Pa].
    nu_prime : float
        [-]; may exceed 0.5 (a plane-strain medium with nu > 1/3).
    """
    nu = check_poisson_ratio(poisson_ratio)
    E = check_positive(youngs_modulus, "youngs_modulus")
    return E / (1.0 - nu * nu), nu / (1.0 - nu)


def _plane_stress_constants(youngs_modulus, poisson_ratio, model):
    check_choice(model, "model", MODELS)
    nu = check_poisson_ratio(poisson_ratio)
    E = check_positive(youngs_modulus, "youngs_modulus")
    if model == "plane_strain":
        return plane_stress_equivalent(E, nu)
    return E, nu


def line_load_strain(
    x, z, line_load, alpha=0.0, *, youngs_modulus, poisson_ratio, model="plane_stress"
):
    """Normal strain eps_z under a line load at angle ``alpha`` (eqs. 7 and 9 of [1]).

    Parameters
    ----------
    x, z : array_like
        Position [m]; ``z > 0``.
    line_load : float
        Magnitude of the line load [N/m].
    alpha : float
        Angle of the load from the surface normal [rad]; the tangential
        component points toward +x for ``alpha > 0``.
    youngs_modulus : float
        [Pa].
    poisson_ratio : float
        [-].
    model : {"plane_stress", "plane_strain"}

    Returns
    -------
    ndarray
        eps_z [-], negative (compressive) under the load.
    """
    E, nu = _plane_stress_constants(youngs_modulus, poisson_ratio, model)
    x = as_float_array(x, "x")
    z = as_float_array(z, "z")
    r4 = (x * x + z * z) ** 2
    return (
        -2.0
        * line_load
        / (E * np.pi * r4)
        * (z * np.cos(alpha) + x * np.sin(alpha))
        * (z * z - nu * x * x)
    )


def impulse_response(x, depth, *, youngs_modulus, poisson_ratio, model="plane_stress"):
    """Normal-strain impulse response h(x) at ``depth`` for a unit normal line load (eq. 38).

    Parameters
    ----------
    x : array_like
        Horizontal offset from the load [m].
    depth : float
        Depth of the sensor [m].

    Returns
    -------
    ndarray
        h(x) [m/N] (strain per N/m of line load), negative.
    """
    depth = check_positive(depth, "depth")
    return line_load_strain(
        x, depth, 1.0, 0.0, youngs_modulus=youngs_modulus, poisson_ratio=poisson_ratio, model=model
    )


def impulse_response_tangential(x, depth, *, youngs_modulus, poisson_ratio, model="plane_stress"):
    """Normal-strain response to a unit tangential line load toward +x (odd in x).

    Returns
    -------
    ndarray
        h_t(x) [m/N].
    """
    depth = check_positive(depth, "depth")
    return line_load_strain(
        x,
        depth,
        1.0,
        np.pi / 2,
        youngs_modulus=youngs_modulus,
        poisson_ratio=poisson_ratio,
        model=model,
    )


def frequency_response(s, depth, *, youngs_modulus, poisson_ratio, model="plane_stress"):
    """Fourier transform H(s) of the impulse response h(x) (eq. 41 of [1]).

    ``H(s) = integral h(x) exp(-2 pi i s x) dx
    = -[(1 - nu) + 2 pi d |s| (1 + nu)] exp(-2 pi d |s|) / E``.
    Eq. 41 prints the same expression without the minus sign, i.e. the
    transform of the compressive strain -h(x).

    Parameters
    ----------
    s : array_like
        Spatial frequency [cycles/m].
    depth : float
        [m].

    Returns
    -------
    ndarray
        H(s) [m/N * m] = strain per unit line load per cycle/m [m^2/N].
        Real and even.
    """
    E, nu = _plane_stress_constants(youngs_modulus, poisson_ratio, model)
    depth = check_positive(depth, "depth")
    s = np.abs(as_float_array(s, "s"))
    k = 2.0 * np.pi * depth * s
    return -((1.0 - nu) + k * (1.0 + nu)) * np.exp(-k) / E


def frequency_response_tangential(s, depth, *, youngs_modulus, poisson_ratio, model="plane_stress"):
    """Fourier transform H_t(s) of the tangential impulse response (eq. 69 of [1]).

    ``H_t(s) = (2 i / E) [pi (1 + nu) d s - nu sign(s)] exp(-2 pi d |s|)``,
    purely imaginary and odd.

    Returns
    -------
    ndarray of complex
        H_t(s) [m^2/N].
    """
    E, nu = _plane_stress_constants(youngs_modulus, poisson_ratio, model)
    depth = check_positive(depth, "depth")
    s = as_float_array(s, "s")
    return (
        2j
        / E
        * (np.pi * (1.0 + nu) * depth * s - nu * np.sign(s))
        * np.exp(-2.0 * np.pi * depth * np.abs(s))
    )


def frequency_peak(depth, poisson_ratio):
    """Spatial frequency at which |H(s)| is largest [cycles/m].

    ``s_max = nu / (pi d (1 + nu))``; for nu = 0.5 this is the paper's
    ``1 / (3 pi d)``. For nu <= 0 the maximum is at s = 0.
    """
    nu = check_poisson_ratio(poisson_ratio)
    depth = check_positive(depth, "depth")
    return max(nu, 0.0) / (np.pi * depth * (1.0 + nu))


def cumulative_normal(x, depth, youngs_modulus, poisson_ratio):
    """Antiderivative of the plane-stress normal impulse response in x [1/N].

    ``G_n(x) = -[(1 + nu) x d / (x^2 + d^2) + (1 - nu) atan(x / d)] / (pi E)``,
    so that ``integral_a^b h(x) dx = G_n(b) - G_n(a)``.
    """
    r2 = x * x + depth * depth
    return -(
        (1.0 + poisson_ratio) * x * depth / r2 + (1.0 - poisson_ratio) * np.arctan2(x, depth)
    ) / (np.pi * youngs_modulus)


def cumulative_tangential(x, depth, youngs_modulus, poisson_ratio):
    """Antiderivative of the plane-stress tangential impulse response in x [1/N].

    ``G_t(x) = [(1 + nu) d^2 / (x^2 + d^2) + nu ln((x^2 + d^2) / d^2)] / (pi E)``.
    """
    r2 = x * x + depth * depth
    return (
        (1.0 + poisson_ratio) * depth * depth / r2 + poisson_ratio * np.log(r2 / (depth * depth))
    ) / (np.pi * youngs_modulus)


def strain_from_pressure(
    x, depth, cell_edges, pressure, *, beta=0.0, youngs_modulus, poisson_ratio, model="plane_stress"
):
    """Normal strain at depth under a surface pressure p(x) with traction beta*p(x).

    The pressure is taken as constant on each cell (eq. 58-59 of [1]: the
    tangential traction is proportional to the pressure). The convolution
    with the impulse responses is integrated exactly over every cell with
    the antiderivatives :func:`cumulative_normal` and
    :func:`cumulative_tangential`, so the result does not depend on a
    quadrature rule, however shallow the sensor.

    Parameters
    ----------
    x : array_like
        Where to evaluate the strain [m].
    depth : float
        [m].
    cell_edges : array_like, shape (n + 1,)
        Increasing edges of the pressure cells [m].
    pressure : array_like, shape (..., n)
        Pressure on each cell, compressive positive [Pa]; leading axes batch.
    beta : float
        Ratio of tangential traction (toward +x) to pressure, tan(alpha) [-].

    Returns
    -------
    ndarray, shape (..., len(x))
        eps_z [-].
    """
    E, nu = _plane_stress_constants(youngs_modulus, poisson_ratio, model)
    depth = check_positive(depth, "depth")
    x = as_float_array(x, "x")
    edges = as_float_array(cell_edges, "cell_edges")
    pressure = as_float_array(pressure, "pressure")
    if edges.ndim != 1 or edges.size < 2 or np.any(np.diff(edges) <= 0):
        raise ValueError("cell_edges must be a 1-D increasing array of at least two edges")
    if pressure.shape[-1] != edges.size - 1:
        raise ValueError(
            f"pressure has {pressure.shape[-1]} cells on its last axis; "
            f"expected {edges.size - 1} (one per cell between the edges)"
        )
    offset = x.reshape(-1, 1) - edges.reshape(1, -1)  # (nx, n + 1)
    weights = -np.diff(cumulative_normal(offset, depth, E, nu), axis=1)
    if beta:
        weights = weights - beta * np.diff(cumulative_tangential(offset, depth, E, nu), axis=1)
    return (pressure @ weights.T).reshape(pressure.shape[:-1] + x.shape)


def odd_peak_offset(depth, poisson_ratio):
    """Offset from the load at which the odd (tangential) strain of a line load peaks [m].

    ``x = d sqrt(T)``, ``T = [3 (1 + nu) - sqrt(9 (1 + nu)^2 - 4 nu)] / (2 nu)``:
    the root of ``nu T^2 - 3 (1 + nu) T + 1 = 0``. Eq. 65 of [1] prints
    ``- 4`` for ``- 4 nu`` under the inner root (``docs/errata.md``). For nu = 0
    the offset is ``d / sqrt(3)``.
    """
    nu = check_poisson_ratio(poisson_ratio)
    depth = check_positive(depth, "depth")
    if nu == 0.0:
        return depth / np.sqrt(3.0)
    root = (3.0 * (1.0 + nu) - np.sqrt(9.0 * (1.0 + nu) ** 2 - 4.0 * nu)) / (2.0 * nu)
    return depth * np.sqrt(root)


def line_load_skew_coefficient(poisson_ratio):
    """Skew index of a line load per unit tan(alpha), plane stress (eqs. 63-67 of [1]) [-].

    ``max eps_odd / max eps_even = k tan(alpha)`` with
    ``k = t (1 - nu t^2) / (1 + t^2)^2`` at ``t = odd_peak_offset / d``; 0.2805
    for nu = 0.5 (the paper prints 0.2441, see ``docs/errata.md``).
    """
    t = odd_peak_offset(1.0, poisson_ratio)
    return t * (1.0 - poisson_ratio * t * t) / (1.0 + t * t) ** 2
