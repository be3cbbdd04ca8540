"""Total normal force from the integral of the interpolated deflection (section 8, eqs. 54-56).

In a linear, shift-invariant elastic model the integral of the strain at a fixed
depth is exactly the zero-frequency gain times the total load:
``integral eps_z dx = E_z(0) = H(0) P(0) = H(0) F``, whatever the shape of the
pressure; the paper's approximation ``H(s) ~ H(0)`` (eq. 54) is not needed for the
integral, only the interpolation's ability to capture it. For the plane-stress half
plane ``H(0) = (1 - nu) / E`` (``docs/force.md`` discusses other models; in the
bonded strip of section 5 with nu = 0.5 the integral is zero, and force cannot be
read from it).

Around the finger the rings distribute the load with unit area, so on an endless
array the force would be ``F = E / (1 - nu) * integral integral deflection dx ds``,
with ``ds`` the arc at the ring radius. The finger's array is 7 rings long: it misses
the far negative lobes of the plane-stress response (about a quarter of its
integral at 3.8 mm depth), and around the finger 45-deg strips sample the ring's
3-mm spread coarsely. The conversion is therefore calibrated on the physics model
(not the simulator): the mean summed deflection per newton of the 3-mm probe over
one tactel period in the interior of the array.
"""

from __future__ import annotations

import functools

import numpy as np

from tactsense.estimate.finger.interpolate import kernel_integral
from tactsense.physics.array_response import deflection_batch
from tactsense.physics.contact import Probe
from tactsense.physics.halfplane import frequency_response
from tactsense.sensor import SensorSpec


def ideal_force_per_deflection(sensor: SensorSpec) -> float:
    """Newtons per unit of summed deflection on an endless array (eqs. 54-56) [N].

    ``E / (1 - nu) * b * r_ring * dphi * kappa_rows * kappa_cols``, with b the
    ring spacing, ``r_ring dphi`` the arc between strips at the ring radius
    and kappa the integral of the interpolation kernel (0.9994 for 8 samples).
    """
    elastic = sensor.elastic
    zero_gain = -float(
        frequency_response(
            0.0,
            elastic.effective_depth_mm * 1e-3,
            youngs_modulus=elastic.youngs_modulus_pa,
            poisson_ratio=elastic.effective_poisson_ratio,
            model=elastic.model,
        )
    )
    rows, cols = sensor.shape
    area = (
        sensor.array.spacing_axial_mm
        * 1e-3
        * sensor.ring_radius_mm
        * 1e-3
        * np.deg2rad(sensor.array.spacing_angle_deg)
    )
    return area * kernel_integral(rows) * kernel_integral(cols) / zero_gain


@functools.lru_cache(maxsize=64)
def force_per_deflection(sensor: SensorSpec) -> float:
    """Newtons per unit of summed cylinder-row deflection on this finger's array [N].

    The model's mean summed deflection for a 1-N, 3-mm probe over an 8 x 8 grid
    of positions spanning one ring spacing and one strip spacing in the middle
    of the cylinder; its inverse. The ideal value of
    :func:`ideal_force_per_deflection` is 20 % larger on the initial finger.
    """
    first = 1 if sensor.array.tip_row else 0
    rows = sensor.shape[0]
    middle = first + (rows - first) // 2
    axial = sensor.row_axial_mm[middle - 1] + sensor.array.spacing_axial_mm * np.arange(8) / 8
    centre = sensor.col_angle_deg[sensor.shape[1] // 2 - 1]
    angle = centre + sensor.array.spacing_angle_deg * np.arange(8) / 8
    states = [(Probe(float(a), float(b), 1.0),) for a in axial for b in angle]
    summed = deflection_batch(sensor, states)[:, first:, :].sum(axis=(-2, -1))
    return float(1.0 / summed.mean())


def total_force(deflection, sensor: SensorSpec):
    """Total normal force from a deflection frame (eqs. 55-56) [N].

    Parameters
    ----------
    deflection : ndarray, shape (..., rows, cols)
        Fractional deflection [-]. The tip row is left out: its depth and
        spacing differ and the half-plane model does not describe it.

    Returns
    -------
    ndarray, shape (...)
        F_z [N].
    """
    z = np.asarray(deflection, dtype=float)
    first = 1 if sensor.array.tip_row else 0
    return force_per_deflection(sensor) * z[..., first:, :].sum(axis=(-2, -1))
