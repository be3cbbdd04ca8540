"""Piezoresistive cells (force-sensing resistors, conductive rubber): strain to A/D counts.

The chain of one taxel, each step a function below:

compressive strain ``eps`` at the sensing depth -> the cell's conductance over the divider
resistor's, ``g = (eps / eps_half) ** n`` (:func:`conductance_ratio`; zero at rest and in
tension: the cell is one-sided) -> the unloading branch above the loading one
(:func:`hysteresis`) -> the rise under a held load (:func:`load_drift`) and with warming
(:func:`temperature_factor`) -> the parallel paths of a passive row/column scan
(:func:`tactsense.physics.crosstalk.scan_conductance`) -> the voltage divider read by a
ratiometric converter, ``rest + span g / (1 + g)`` (:func:`divider_counts`), which
saturates at the converter's full scale.

Sources, with what each figure is:

* Interlink Electronics, *FSR 400 Series Data Sheet* (device characteristics, measured at
  1000 g): actuation force about 0.2 N, sensitivity range 0.2-20 N, non-actuated
  resistance > 10 MOhm (a cell at rest reads the divider's rest: zero), hysteresis
  "+10 % average (R_F+ - R_F-)/R_F+", long-term drift "< 5 % log10(time)" (1 kg, 35 days),
  resistance -15 % after 1 h at +85 degC.
* Interlink Electronics, *FSR Integration Guide* (94-00004): "the FSR resistance is
  roughly inversely proportional to applied force" (conductance about proportional:
  ``n = 1``); the voltage divider ``V_out = V+ R_M / (R_M + R_FSR)`` as the simplest
  interface, whose output saturates; static readings settle over seconds.
* Sensitronics, *LowDrift FSR* note: drift is a rise of the conductance, total drift
  ``drift_log * log10(t)`` with ``t`` in seconds; standard inks about 12 % in 48 h at
  2 psi (2.3 % per decade).

Assumptions, said where they are made: the unloading branch's shape (linear in the
load below the peak, :func:`hysteresis`), the reference time of the drift (1 s), a
constant temperature coefficient (the data sheet gives one hot point).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from tactsense._validation import TactsenseInputError

DRIFT_REFERENCE_S = 1.0
"""Time scale of the logarithmic drift: ``log10(1 + t / DRIFT_REFERENCE_S)`` [s]
(an assumption: the data sheets give the rate per decade, not its origin)."""


def _check_fraction(value: float, name: str) -> float:
    if not (isinstance(value, int | float) and np.isfinite(value) and 0.0 <= value <= 1.0):
        raise TactsenseInputError(f"{name} must lie in [0, 1]; got {value!r}")
    return float(value)


def conductance_ratio(strain, half_scale_strain: float, exponent: float = 1.0) -> np.ndarray:
    """Conductance of a cell over the divider resistor's, ``(eps / eps_half) ** n`` [-].

    Parameters
    ----------
    strain : array_like
        Compressive strain at the sensing depth [-], positive when compressed; tension
        and rest give 0 (an FSR at rest is open, > 10 MOhm).
    half_scale_strain : float
        Strain at which the cell's conductance equals the divider resistor's [-].
    exponent : float
        Power of the strain [-] (an FSR: about 1, its resistance about 1 / force).

    Returns
    -------
    ndarray
        ``G / G_M`` [-], >= 0.
    """
    if not (np.isfinite(half_scale_strain) and half_scale_strain > 0):
        raise TactsenseInputError(
            f"half_scale_strain must be a positive number; got {half_scale_strain!r}"
        )
    if not (np.isfinite(exponent) and exponent > 0):
        raise TactsenseInputError(f"exponent must be a positive number; got {exponent!r}")
    compression = np.maximum(np.asarray(strain, dtype=float), 0.0)
    return (compression / half_scale_strain) ** exponent


def divider_counts(g, rest_counts: float, full_scale_counts: float) -> np.ndarray:
    """Reading of a cell of conductance ratio ``g`` through a voltage divider [counts].

    ``V_out = V+ G / (G + G_M)`` (the Integration Guide's divider, ``R_M`` to ground),
    read by a converter whose reference is ``V+`` (ratiometric): ``rest +
    (full - rest) g / (1 + g)``: the rest reading untouched, half the span when the cell
    conducts as the divider resistor, the full scale only in the limit. Unquantized and
    unclipped.
    """
    g = np.asarray(g, dtype=float)
    if np.any(g < 0):
        raise TactsenseInputError("a conductance ratio is never negative")
    return rest_counts + (full_scale_counts - rest_counts) * g / (1.0 + g)


def divider_conductance(counts, rest_counts: float, full_scale_counts: float) -> np.ndarray:
    """The inverse of :func:`divider_counts`: ``g = (c - rest) / (full - c)`` [-].

    NaN at or above the full scale (a saturated reading tells no conductance).
    """
    counts = np.asarray(counts, dtype=float)
    with np.errstate(divide="ignore", invalid="ignore"):
        g = (counts - rest_counts) / (full_scale_counts - counts)
    return np.where(counts < full_scale_counts, g, np.nan)


def hysteresis(g, amount: float, peak=None) -> tuple[np.ndarray, np.ndarray]:
    """The reading's conductance with the unloading branch above the loading one [-].

    Along axis 0 (time), each taxel keeps the largest conductance ``P`` reached since it
    last rested (``g == 0``). Loading to a new peak reads ``g`` (the virgin curve);
    below the peak it reads ``g (1 + h (1 - g / P))``: equal at the peak, ``1 + h``
    times the loading reading at light load, back to 0 at rest. The loop between 0 and
    ``P`` encloses ``h P^2 / 6`` (:func:`hysteresis_loop_area`); the mean excess over
    the branch is ``h / 2``, so the FSR 400 data sheet's "+10 % average" reads as
    ``h = 0.2``. The branch's shape is an assumption (the data sheet gives one number).

    Parameters
    ----------
    g : ndarray, shape (T, ...)
        Conductance ratio over time [-], >= 0.
    amount : float
        ``h`` in [0, 1] [-].
    peak : ndarray, shape (...), optional
        Peak carried from earlier frames (default: all at rest).

    Returns
    -------
    read : ndarray, shape (T, ...)
    peak : ndarray, shape (...)
        The peak after the last frame, to carry into the next call.
    """
    amount = _check_fraction(amount, "hysteresis")
    g = np.asarray(g, dtype=float)
    if g.ndim < 1 or len(g) == 0:
        raise TactsenseInputError(f"g must have a time axis with frames; got shape {g.shape}")
    previous = np.zeros(g.shape[1:]) if peak is None else np.asarray(peak, dtype=float)
    # each rest (g == 0) starts a new segment; the running maximum within a segment is
    # the cumulative maximum of g lifted by a step larger than any g per segment
    rest = g <= 0.0
    segment = np.cumsum(rest, axis=0)
    lift = 2.0 * float(max(g.max(), previous.max(initial=0.0))) + 1.0
    lifted = g + segment * lift
    carried = np.where(segment[0] == 0, previous, 0.0)  # the first segment continues
    running = np.maximum.accumulate(np.concatenate([carried[None], lifted]), axis=0)[1:]
    running = running - segment * lift
    running = np.maximum(running, g)
    with np.errstate(divide="ignore", invalid="ignore"):
        below = np.where(running > 0, 1.0 - g / running, 0.0)
    return g * (1.0 + amount * below), running[-1]


def hysteresis_loop_area(peak: float, amount: float) -> float:
    """Area between the unloading and loading branches from 0 to ``peak`` [-^2]:
    ``integral_0^P h g (1 - g / P) dg = h P^2 / 6`` (:func:`hysteresis`)."""
    return _check_fraction(amount, "hysteresis") * float(peak) ** 2 / 6.0


def load_drift(g, times_s, per_decade: float, start=None) -> tuple[np.ndarray, np.ndarray]:
    """The conductance's rise under a held load: ``g (1 + d log10(1 + t_on / 1 s))`` [-].

    ``t_on`` is the time since the taxel was last loaded (``g`` rose from 0): the
    FSR 400 data sheet's drift "< 5 % log10(time)" and Sensitronics' ``drift_log *
    log10(t)``; a rest (``g == 0``) ends it.

    Parameters
    ----------
    g : ndarray, shape (T, ...)
    times_s : ndarray, shape (T,)
        Time of each frame [s], increasing.
    per_decade : float
        ``d`` in [0, 1] [-].
    start : ndarray, shape (...), optional
        Time each taxel was loaded, NaN where at rest, carried from earlier frames.

    Returns
    -------
    read : ndarray, shape (T, ...)
    start : ndarray, shape (...)
        The load start after the last frame.
    """
    per_decade = _check_fraction(per_decade, "drift_per_decade")
    g = np.asarray(g, dtype=float)
    times = np.asarray(times_s, dtype=float).reshape((-1,) + (1,) * (g.ndim - 1))
    if len(times) != len(g):
        raise TactsenseInputError(f"times_s has {len(times)} values for {len(g)} frames")
    previous = np.full(g.shape[1:], np.nan) if start is None else np.asarray(start, dtype=float)
    loaded = g > 0.0
    was_loaded = np.concatenate([np.isfinite(previous)[None], loaded[:-1]], axis=0)
    onset = loaded & ~was_loaded
    marks = np.where(onset, np.broadcast_to(times, g.shape), -np.inf)
    first = np.where(np.isfinite(previous), previous, -np.inf)
    since = np.maximum.accumulate(np.concatenate([first[None], marks]), axis=0)[1:]
    since = np.where(loaded, since, np.nan)
    t_on = np.where(loaded, np.broadcast_to(times, g.shape) - np.nan_to_num(since), 0.0)
    factor = 1.0 + per_decade * np.log10(1.0 + np.maximum(t_on, 0.0) / DRIFT_REFERENCE_S)
    return g * factor, since[-1]


def temperature_factor(times_s, coefficient_per_k: float, rate_k_per_s: float) -> np.ndarray:
    """Relative conductance of a sensor warming at a constant rate: ``1 + a r t`` [-].

    The FSR 400 data sheet gives resistance -15 % after 1 h at +85 degC (conductance
    +18 % over about 60 K: ``a`` about 0.003/K); a constant coefficient is an assumption.
    """
    times = np.asarray(times_s, dtype=float)
    factor = 1.0 + coefficient_per_k * rate_k_per_s * times
    if np.any(factor <= 0):
        raise TactsenseInputError(
            "the temperature drift would make the conductance negative within the "
            f"recording (coefficient {coefficient_per_k!r}/K at {rate_k_per_s!r} K/s)"
        )
    return factor


@dataclass
class PiezoState:
    """What a piezoresistive simulation carries from one block of frames to the next."""

    peak: np.ndarray | None = None
    start: np.ndarray | None = None


def half_scale_strain(spec) -> float:
    """Strain at which a piezoresistive cell of ``spec`` reads half its span [-]:
    the span over ``counts_per_strain``."""
    el = spec.electronics
    return (2**el.adc_bits - 1 - el.nominal_counts) / spec.transduction.counts_per_strain


def piezo_counts(spec, strain, times_s, active, state: PiezoState | None = None):
    """Readings of a piezoresistive pad or point set, unquantized and unclipped [counts].

    Parameters
    ----------
    spec : PadSpec or PointsSpec
        ``transduction.kind = "piezoresistive"``.
    strain : ndarray, shape (T, rows, cols)
        Compressive strain of each taxel at its sampled instant, gains applied [-].
    times_s : ndarray, shape (T,)
        Time of each frame [s].
    active : collection of str
        The simulation's flaws: ``hysteresis``, ``drift``, ``crosstalk`` apply theirs.
    state : PiezoState, optional
        Carried from the previous block of the same recording.

    Returns
    -------
    counts : ndarray, shape (T, rows, cols)
    state : PiezoState
    """
    from tactsense.physics.crosstalk import scan_conductance

    state = PiezoState() if state is None else state
    t, f, el = spec.transduction, spec.flaws, spec.electronics
    g = conductance_ratio(strain, half_scale_strain(spec), t.exponent)
    if "hysteresis" in active and f.hysteresis > 0:
        g, state.peak = hysteresis(g, f.hysteresis, state.peak)
    if "drift" in active:
        if f.drift_per_decade > 0:
            g, state.start = load_drift(g, times_s, f.drift_per_decade, state.start)
        if f.temperature_coefficient_per_k and f.temperature_rate_k_per_s:
            factor = temperature_factor(
                times_s, f.temperature_coefficient_per_k, f.temperature_rate_k_per_s
            )
            g = g * factor.reshape((-1,) + (1,) * (g.ndim - 1))
    if "crosstalk" in active and f.crosstalk > 0:
        g = scan_conductance(g, f.crosstalk)
    full = 2**el.adc_bits - 1
    if t.polarity == "falling":  # the divider the other way up
        return el.nominal_counts - divider_counts(g, 0.0, el.nominal_counts), state
    return divider_counts(g, el.nominal_counts, full), state
