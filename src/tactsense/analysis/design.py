"""Capacitor design in the elastic strip on the rigid core (section 5, Fig. 17)."""

from __future__ import annotations

import numpy as np

from tactsense._validation import TactsenseInputError, as_float_array
from tactsense.physics import strip


def strip_capacitor_design(
    thickness,
    separation,
    line_load,
    width,
    *,
    backing=0.0,
    youngs_modulus=2.5e5,
    poisson_ratio=0.5,
    model="plane_stress",
):
    """Gain and plate deflections of capacitors in a skin bonded to a rigid core.

    The bottom plate lies at depth ``thickness``, the top plate ``separation``
    above it, and a layer ``backing`` thick separates the bottom plate from
    the core (0: the plate sits on the core, the first case of Fig. 17; > 0:
    a soft backing, the second case). The load is a parabolic pressure of
    ``width`` and total ``line_load`` (the paper: a 3-mm probe, ~200 N/m).
    All arguments broadcast, so one call evaluates many designs.

    Parameters
    ----------
    thickness : array_like
        Depth of the bottom plate [m].
    separation : array_like
        Nominal plate separation d_o [m].
    line_load : array_like
        Load per unit length of the slab [N/m].
    width : array_like
        Width of the parabolic pressure [m].
    backing : array_like
        Elastic layer between the bottom plate and the core [m].
    youngs_modulus : float
        E [Pa].
    poisson_ratio : float
        nu [-].
    model : {"plane_stress", "plane_strain"}

    Returns
    -------
    dict of ndarray
        ``gain`` (dd / d_o, eq. 36) [-]; ``top_plate_deflection``,
        ``bottom_plate_deflection``, ``surface_deflection`` [m] (toward the
        core, under the centre of the load); ``closing`` = dd [m].
    """
    thickness = as_float_array(thickness, "thickness")
    separation = as_float_array(separation, "separation")
    backing = as_float_array(backing, "backing")
    if np.any(separation <= 0) or np.any(separation >= thickness):
        raise TactsenseInputError("separation must be positive and smaller than thickness")
    if np.any(backing < 0):
        raise TactsenseInputError("backing must be non-negative")
    thickness, separation, backing, line_load, width = np.broadcast_arrays(
        thickness,
        separation,
        backing,
        as_float_array(line_load, "line_load"),
        as_float_array(width, "width"),
    )
    top = thickness - separation
    kwargs = {"youngs_modulus": youngs_modulus, "poisson_ratio": poisson_ratio, "model": model}
    depths = np.stack([np.zeros_like(top), top, thickness])
    w = strip.displacement(
        0.0, depths, (thickness + backing)[None], line_load[None], width[None], **kwargs
    )
    surface, w_top, w_bottom = w
    closing = w_top - w_bottom
    return {
        "gain": closing / separation,
        "top_plate_deflection": w_top,
        "bottom_plate_deflection": w_bottom,
        "surface_deflection": surface,
        "closing": closing,
    }
