"""From plate deflection to A/D counts (section 2.2 of the paper, eqs. 1-4).

The junction is a parallel-plate capacitor (eq. 2) read through a load
capacitance C_L and resistance R_L (eq. 1); an amplifier and an A/D
converter turn the voltage into counts. The amplifier gain is set so that
an undeflected tactel reads the sensor's ``nominal_counts`` (V_o of the
paper, about 2000 A/D units).

A pad or point set whose ``[transduction] polarity`` is ``falling`` reads the rising
reading mirrored about its rest value (:func:`polarized`): ``2 V_o - V``, so that it
falls from ``nominal_counts`` by the change the rising chain would read, and saturates
at 0 (the converter's bottom) instead of at full scale.
"""

from __future__ import annotations

import numpy as np

from tactsense._validation import TactsenseInputError, as_float_array
from tactsense.sensor import SensorSpec


def junction_capacitance(spec: SensorSpec, deflection):
    """Capacitance of a junction whose plates close by ``deflection * d_o`` (eq. 2).

    Parameters
    ----------
    deflection : array_like
        Fractional deflection dd / d_o [-], compression positive, < 1.

    Returns
    -------
    ndarray
        C_S [F].
    """
    deflection = as_float_array(deflection, "deflection")
    if np.any(deflection >= 1.0):
        raise TactsenseInputError("deflection must stay below 1: the plates would touch")
    return spec.junction_capacitance_f / (1.0 - deflection)


def divider_voltage(spec: SensorSpec, capacitance):
    """Amplitude |V_S| of the sensed voltage before the amplifier, eq. 1 without approximation [V].

    ``|V_S| = C_S R_L w / sqrt(1 + [w R_L (C_S + C_L)]^2) |V_d|``.
    """
    el = spec.electronics
    omega = 2.0 * np.pi * el.drive_frequency_hz
    c_load = el.load_capacitance_pf * 1e-12
    capacitance = np.asarray(capacitance, dtype=float)
    rc = omega * el.load_resistance_ohm
    return capacitance * rc / np.sqrt(1.0 + (rc * (capacitance + c_load)) ** 2) * el.drive_voltage_v


def amplifier_gain(spec: SensorSpec) -> float:
    """Gain that maps the undeflected junction to ``nominal_counts`` [V/V].

    One number, or one per taxel for a point set whose taxels differ in area.
    """
    el = spec.electronics
    target = el.nominal_counts / 2**el.adc_bits * el.adc_full_scale_v
    gain = target / divider_voltage(spec, np.asarray(spec.junction_capacitance_f, dtype=float))
    return float(gain) if np.ndim(gain) == 0 else gain


def deflection_to_voltage(spec: SensorSpec, deflection):
    """Amplified sensor voltage for a fractional deflection (eqs. 1-2) [V]."""
    return amplifier_gain(spec) * divider_voltage(spec, junction_capacitance(spec, deflection))


def falling(spec) -> bool:
    """Whether the sensor's reading falls under load (``[transduction] polarity``; a
    finger, which has no transduction section, rises)."""
    t = getattr(spec, "transduction", None)
    return t is not None and t.polarity == "falling"


def polarized(spec, rising):
    """The reading of ``spec`` given the reading ``rising`` a rising sensor would give,
    unquantized [counts]: itself, or for a falling sensor ``2 nominal_counts - rising``
    (the same change, downward from the rest reading)."""
    if not falling(spec):
        return rising
    return 2.0 * spec.electronics.nominal_counts - np.asarray(rising, dtype=float)


def voltage_to_counts(spec: SensorSpec, voltage, *, quantize: bool = True):
    """A/D reading of a voltage; saturates at 0 and 2^bits - 1 [counts].

    With ``quantize=False`` the ideal (real-valued, unclipped) reading.
    """
    el = spec.electronics
    counts = np.asarray(voltage, dtype=float) / el.adc_full_scale_v * 2**el.adc_bits
    if not quantize:
        return counts
    return np.clip(np.rint(counts), 0, 2**el.adc_bits - 1)


def deflection_to_counts(spec: SensorSpec, deflection, *, quantize: bool = True):
    """A/D counts for a fractional deflection, through eqs. 1-2 and the converter (a
    falling sensor's mirrored, :func:`polarized`)."""
    if not falling(spec):
        return voltage_to_counts(spec, deflection_to_voltage(spec, deflection), quantize=quantize)
    counts = polarized(
        spec, voltage_to_counts(spec, deflection_to_voltage(spec, deflection), quantize=False)
    )
    if not quantize:
        return counts
    return np.clip(np.rint(counts), 0, 2**spec.electronics.adc_bits - 1)


def fractional_deflection(reading, baseline):
    """Fractional deflection from a reading and the undeflected reading (eq. 4).

    ``(V_S - V_o) / V_S = dd / d_o`` when C_L >> C_S. Works on voltages or
    counts alike, since the ratio is independent of the constant gains.

    Parameters
    ----------
    reading : array_like, shape (..., rows, cols)
        V_S [V or counts].
    baseline : array_like, broadcastable to ``reading``
        V_o, the reading with nothing touching [V or counts].

    Returns
    -------
    ndarray
        dd / d_o [-]; NaN where the reading is not positive (a dead tactel).
    """
    reading = np.asarray(reading, dtype=float)
    baseline = np.asarray(baseline, dtype=float)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(reading > 0, (reading - baseline) / reading, np.nan)


def sample_offsets(spec: SensorSpec) -> np.ndarray:
    """Instant within a frame at which each tactel is sampled, shape (rows, cols) [s].

    The scan selects one row and column at a time in row-major order and
    spreads the samples evenly over the frame period.
    """
    rows, cols = spec.shape
    order = np.arange(rows * cols, dtype=float).reshape(rows, cols)
    return order / (rows * cols) * spec.scan_period_s
