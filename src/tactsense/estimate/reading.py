"""A taxel's signal from its readings, on any kind of array: the contact threshold, the
reading's mode (capacitive or resistive, rising or falling), unusable baselines, the rail,
and the noise of the signal. Shared by both jobs of :mod:`tactsense.estimate`."""

from __future__ import annotations

import numpy as np

from tactsense._signals import deferred_interrupts
from tactsense._validation import TactsenseInputError, check_frames
from tactsense.estimate.results import Flag


def threshold_counts(sensor, noise_gain: float = 1.0) -> float:
    """The change of reading that counts as contact by default [counts]: 10 counts on a
    converter of 12 bits or more (0.24 % of a 12-bit range, some 25 times the read noise
    of 0.3 counts with quantization, 0.39 counts rms); on fewer bits the same share of
    the range, but at least 3 counts (7.7 times that rms), so that an 8-bit converter
    (iCub's fingertips) is not held to 10 counts, 3.9 % of its range. A sensor whose
    described read noise is larger (1-2 % of full scale, 40-80 counts at 12 bits, as FSR
    and piezoresistive arrays read) would cross that in every frame: there five standard
    deviations of its ``read_noise_counts`` (crossed by chance once in 3.5 million
    readings) set it, times ``noise_gain`` where the signal is read through a filter that
    amplifies the noise (the creep compensation,
    :func:`~tactsense.estimate.creep.compensation_noise_gain`)."""
    # ---- three-axis taxels (r8-triest): the length of a taxel's change ----
    if int(getattr(sensor, "components", 1)) > 1:
        return vector_threshold_counts(sensor) * noise_gain
    # ---- /r8-triest ----
    bits = int(sensor.electronics.adc_bits)
    counts = 10.0 if bits >= 12 else max(3.0, 10.0 * 2.0 ** (bits - 12))
    return max(counts, 5.0 * float(sensor.flaws.read_noise_counts) * noise_gain)


def default_threshold(sensor, creep=None, frame_period_s: float | None = None) -> float:
    """Smallest signal that counts as contact [-]: :func:`threshold_counts` from the
    baseline (10 counts on 12 bits, more on a noisy sensor).

    Capacitive taxels: the signal of that change from the rest reading ``V_o``
    (``nominal_counts``), ``n / (V_o + n)`` whichever the polarity, but at least 0.005
    (10 counts at the nominal 2000, the finger's rule); resistive and piezoresistive
    ones: ``n / counts_per_strain`` of strain, whatever the rest reading (0 included)
    and the polarity.

    With ``creep`` (the :class:`~tactsense.estimate.creep.Viscoelastic` taken out of the
    signal before it is thresholded, at ``frame_period_s``, default the sensor's scan
    period), the noise floor is raised by the compensation's noise gain: on a pad16
    reading 2 % of full scale of noise, a flat stamp's presses through ``locate`` (creep
    compensated) found one contact in 66 % of loaded frames, 356 ids for 8 presses and
    contacts in 187 unloaded frames; the frames without creep gave 100 % and 8 ids.
    """
    gain = 1.0
    if creep is not None:
        from tactsense.estimate.creep import compensation_noise_gain

        gain = compensation_noise_gain(creep, frame_period_s or sensor.scan_period_s)
    n = threshold_counts(sensor, gain)
    # ---- three-axis taxels (r8-triest): a share of the converter's full scale ----
    if int(getattr(sensor, "components", 1)) > 1:
        return n / (2 ** int(sensor.electronics.adc_bits) - 1)
    # ---- /r8-triest ----
    transduction = getattr(sensor, "transduction", None)
    if transduction is not None and transduction.kind != "capacitive":
        return n / transduction.counts_per_strain
    return max(0.005, n / (sensor.electronics.nominal_counts + n))


def reading_mode(sensor) -> tuple[bool, bool, float]:
    """``(resistive, falling, per_count)`` of a sensor's readings: whether its taxels are
    resistive, whether their reading falls under load (``[transduction] polarity``; a
    finger's rises) and the strain per count of a resistive one (1 otherwise)."""
    transduction = getattr(sensor, "transduction", None)
    resistive = transduction is not None and transduction.kind != "capacitive"
    falling = transduction is not None and transduction.polarity == "falling"
    per_count = 1.0 / transduction.counts_per_strain if resistive else 1.0
    return resistive, falling, per_count


def unusable_baseline(baseline, sensor) -> np.ndarray:
    """Taxels whose baseline [counts] gives no signal, (rows, cols) bool: NaN or
    infinite; at or below 0 where the reading is the capacitive chain's (eq. 4 needs a
    positive rest reading: 0 is an open junction) or falls under load (a reading resting
    at 0 cannot fall). A resistive taxel rising from 0 (an FSR at rest) is usable."""
    baseline = np.asarray(baseline, dtype=float)
    resistive, falling, _ = reading_mode(sensor)
    unusable = ~np.isfinite(baseline)
    if falling or not resistive:
        unusable |= ~(baseline > 0)
    return unusable


def at_rail(frames, sensor) -> np.ndarray:
    """Readings at the converter's rail the reading moves toward under load (full scale
    rising, 0 falling): saturated, the load there unknown; bool of ``frames``' shape."""
    if reading_mode(sensor)[1]:
        return frames <= 0
    return frames >= 2**sensor.electronics.adc_bits - 1


def signal_from_counts(frames, baseline, sensor, *, dead=None):
    """The signal of every taxel from A/D counts, and the flags of each frame.

    Compression positive, whichever way the reading moves under load
    (``[transduction] polarity``). Capacitive taxels (the finger, capacitive pads and
    point sets): the fractional plate deflection of eq. 4, ``(V - V_o) / V``; falling,
    the same of the reading mirrored about its rest (the twin's falling chain reads
    ``2 V_o - V``), ``(V_o - V) / (2 V_o - V)``. Resistive ones: the strain,
    ``(V - V_o) / counts_per_strain``, or ``(V_o - V) / counts_per_strain`` falling. A
    baseline of 0 is valid for a rising resistive taxel (an FSR at rest).

    Unusable taxels (``dead``, a NaN baseline, one that gives no signal:
    :func:`unusable_baseline`) read 0 and set ``DEAD_TACTEL``; a reading at the rail the
    reading moves toward (full scale rising, 0 falling) sets ``SATURATED``; otherwise as
    :func:`~tactsense.estimate.finger.deflection.deflection_from_counts`.

    Returns
    -------
    signal : ndarray, shape (N, rows, cols) [-]
    flags : ndarray of int64, shape (N,)
    """
    from tactsense.estimate.contacts._fast import prepare_signal

    frames = check_frames(frames, sensor.shape)
    baseline = check_frames(baseline, sensor.shape, "baseline").astype(float)
    if baseline.ndim != 2:
        raise TactsenseInputError(f"baseline has shape {baseline.shape}; expected {sensor.shape}")
    unusable = unusable_baseline(baseline, sensor)
    if dead is not None:
        dead = np.asarray(dead, dtype=bool)
        if dead.shape != tuple(sensor.shape):
            raise TactsenseInputError(f"dead has shape {dead.shape}; expected {sensor.shape}")
        unusable = unusable | dead
    resistive, falling, per_count = reading_mode(sensor)
    source = frames.reshape(-1, *sensor.shape)
    if source.dtype not in (np.uint16, np.int32, np.int64, np.float64):
        source = source.astype(np.float64)
    with deferred_interrupts():
        return prepare_signal(
            np.ascontiguousarray(source),
            np.where(unusable, 1.0, baseline),
            unusable,
            float(2**sensor.electronics.adc_bits - 1),
            resistive,
            falling,
            per_count,
            int(Flag.NAN_INPUT),
            int(Flag.SATURATED),
            int(Flag.DEAD_TACTEL),
        )


def signal_noise_variance(sensor) -> float:
    """Variance of one taxel's signal from read noise and quantization [-^2], from the
    sensor's description: ``read_noise_counts^2 + 1/12`` counts^2 over counts per unit
    strain squared (resistive) or the nominal reading squared (capacitive, eq. 4 at
    small deflection)."""
    counts = sensor.flaws.read_noise_counts**2 + 1.0 / 12.0
    transduction = getattr(sensor, "transduction", None)
    if transduction is not None and transduction.kind != "capacitive":
        return counts / transduction.counts_per_strain**2
    return counts / sensor.electronics.nominal_counts**2


# ---- three-axis taxels (r8-triest) ----
def vector_threshold_counts(sensor) -> float:
    """Smallest change of a three-axis taxel's field (the length of its components'
    change) that counts as contact [counts]: 8 times the read noise of one component
    times sqrt(3), at least 10 counts."""
    import math

    noise = float(getattr(sensor.flaws, "read_noise_counts", 0.0) or 0.0)
    return max(10.0, 8.0 * math.sqrt(3.0) * noise)


# ---- /r8-triest ----
