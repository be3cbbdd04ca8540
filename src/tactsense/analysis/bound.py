"""The physical limit of accuracy: Cramer-Rao lower bound on contact position and force.

For a probe contact with parameters theta = (axial position, angle, force), the
expected frame mu(theta) [counts] comes from the forward model (array response and
eqs. 1-2), and each tactel reading carries independent noise of variance
``sigma^2 = read_noise^2 + 1/12`` counts^2 (read noise plus quantization treated as
uniform rounding noise). The Fisher information is

    J = sum over tactels of grad mu grad mu^T / sigma^2

and no unbiased estimator has a smaller standard deviation than sqrt(diag(J^-1)).
Jitter of the load itself (Figs. 10-11) changes what is applied, not how it is read,
and is not part of the bound.
"""

from __future__ import annotations

import numpy as np

from tactsense._validation import TactsenseInputError, check_positive
from tactsense.physics.array_response import tactel_deflection
from tactsense.physics.contact import Probe
from tactsense.physics.transduction import deflection_to_counts
from tactsense.sensor import SensorSpec

PARAMETERS = ("axial_mm", "angle_deg", "force_n")
_STEPS = (1e-3, 1e-3, None)  # mm, deg; the force step is relative


def noise_variance(sensor: SensorSpec) -> float:
    """Variance of one reading: read noise plus uniform quantization [counts^2]."""
    return sensor.flaws.read_noise_counts**2 + 1.0 / 12.0


def expected_counts(
    sensor: SensorSpec, axial_mm, angle_deg, force_n, *, contact_diameter_mm: float = 3.0
):
    """Expected (unquantized) readings for a probe through eqs. 1-2 and the converter [counts]."""
    deflection = tactel_deflection(
        sensor, Probe(float(axial_mm), float(angle_deg), float(force_n), contact_diameter_mm)
    )
    return deflection_to_counts(sensor, deflection, quantize=False)


def fisher_information(
    sensor: SensorSpec,
    axial_mm: float,
    angle_deg: float,
    force_n: float,
    *,
    contact_diameter_mm: float = 3.0,
) -> np.ndarray:
    """Fisher information of (axial [mm], angle [deg], force [N]), shape (3, 3)."""
    check_positive(force_n, "force_n")
    tip_mm = np.pi / 2 * sensor.body.diameter_mm / 2  # arc from the junction to the tip's apex
    length_mm = sensor.body.cylinder_length_mm
    if not -tip_mm <= float(axial_mm) <= length_mm:
        raise TactsenseInputError(
            f"axial position {axial_mm:g} mm is off the finger; expected {-tip_mm:.2f} mm "
            f"(apex of the tip) to {length_mm:g} mm (base of the cylinder)"
        )
    theta = np.array([axial_mm, angle_deg, force_n], dtype=float)
    gradients = []
    for k in range(3):
        step = _STEPS[k] if _STEPS[k] is not None else 1e-4 * force_n
        up, down = theta.copy(), theta.copy()
        up[k] += step
        down[k] -= step
        gradients.append(
            (
                expected_counts(sensor, *up, contact_diameter_mm=contact_diameter_mm)
                - expected_counts(sensor, *down, contact_diameter_mm=contact_diameter_mm)
            ).ravel()
            / (2 * step)
        )
    g = np.array(gradients)
    return g @ g.T / noise_variance(sensor)


def cramer_rao_bound(
    sensor: SensorSpec,
    axial_mm: float,
    angle_deg: float,
    force_n: float,
    *,
    contact_diameter_mm: float = 3.0,
) -> dict:
    """Smallest standard deviations an unbiased estimator can reach.

    Returns
    -------
    dict
        ``axial_mm`` [mm], ``angle_deg`` [deg], ``force_n`` [N], the same along and
        around in tactels (``row_tactel``, ``col_tactel``), ``arc_mm`` (the angle as
        surface arc) and ``force_relative`` [-].
    """
    information = fisher_information(
        sensor, axial_mm, angle_deg, force_n, contact_diameter_mm=contact_diameter_mm
    )
    try:
        covariance = np.linalg.inv(information)
    except np.linalg.LinAlgError:
        raise TactsenseInputError(
            "the contact is not identifiable here (singular Fisher information): it does "
            "not reach enough tactels"
        ) from None
    std = np.sqrt(np.diag(covariance))
    return {
        "axial_mm": float(std[0]),
        "angle_deg": float(std[1]),
        "force_n": float(std[2]),
        "row_tactel": float(std[0] / sensor.array.spacing_axial_mm),
        "col_tactel": float(std[1] / sensor.array.spacing_angle_deg),
        "arc_mm": float(np.deg2rad(std[1]) * sensor.radius_mm),
        "force_relative": float(std[2] / force_n),
    }
