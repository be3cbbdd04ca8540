"""Delayed elasticity and creep of the skin (section 3.4 of the paper, Fig. 12): fit the
two-memory model to force steps on one tactel, and compensate frames with it."""

from __future__ import annotations

import json
from dataclasses import dataclass

import numpy as np
from scipy.optimize import least_squares
from scipy.signal import lfilter

from tactsense._validation import CalibrationError, TactsenseInputError
from tactsense.estimate._kind import kind_or_none


@dataclass(frozen=True)
class Viscoelastic:
    """Delayed elasticity and creep: ``y = (1 - a_d) u + a_d m_d + a_c m_c`` (Fig. 12)."""

    delayed_fraction: float
    delayed_time_constant_s: float
    creep_fraction: float
    creep_time_constant_s: float


def described_creep(sensor) -> Viscoelastic | None:
    """The creep model a sensor's description gives (its ``[flaws]`` table), or None.

    The same two-memory form as :class:`Viscoelastic` (Fig. 12 of the paper): a delayed
    share ``delayed_fraction`` with time constant ``delayed_time_constant_s`` and creep
    ``creep_fraction`` with ``creep_time_constant_s``, read from the description that
    both a real sensor's TOML file and a simulation carry.

    Parameters
    ----------
    sensor : SensorSpec, PadSpec or PointsSpec

    Returns
    -------
    Viscoelastic or None
        None when the description has no flaws table or describes neither delayed
        elasticity nor creep (both fractions zero).
    """
    flaws = getattr(sensor, "flaws", None)
    if flaws is None:
        return None
    a_d, a_c = float(flaws.delayed_fraction), float(flaws.creep_fraction)
    if a_d <= 0.0 and a_c <= 0.0:
        return None
    return Viscoelastic(
        a_d, float(flaws.delayed_time_constant_s), a_c, float(flaws.creep_time_constant_s)
    )


def recording_creep(sensor, attrs) -> tuple[Viscoelastic | None, float]:
    """The creep to take out of a pad's or point set's recording, and the stiffening
    scale that acts after it (:func:`creep_applied` without its label)."""
    creep, stiffening, _ = creep_applied(sensor, attrs)
    return creep, stiffening


def creep_applied(sensor, attrs) -> tuple[Viscoelastic | None, float, str]:
    """The creep to take out of a pad's or point set's recording, the stiffening scale
    that acts after it, and a label saying where it came from.

    Creep is compensated only where it is known:

    * a simulated recording (no ``source``, a scenario with steps) with ``viscoelastic``
      switched on: the twin's own description, which made the creep (label
      ``"described (simulation)"``); stiffening is undone only if ``nonlinearity`` was
      on too. Creep left off there is not compensated;
    * a measured recording (``source`` set: imported, streamed, recorded): the
      description's creep only when it says ``creep_known = true`` in ``[flaws]``
      (label ``"described (sensor file)"``), else nothing (``"none"``): the default
      values are the paper's rubber, not this sensor's, and subtracting them would
      under-read held forces and leave readings below the baseline after a lift.

    None on a finger: its creep compensation is its calibration's
    (``tactsense calibrate --steps``), so that its long table's force stays ``locate``'s.

    Parameters
    ----------
    sensor : SensorSpec, PadSpec or PointsSpec
    attrs : dict
        The recording's attributes (``RecordingReader.attrs``).

    Returns
    -------
    creep : Viscoelastic or None
    stiffening : float
        The scale ``c`` of ``d_meas = d / (1 + d / c)`` [-]; 0 for none.
    label : str
        ``"described (simulation)"``, ``"described (sensor file)"`` or ``"none"``.
    """
    kind = kind_or_none(sensor)
    if kind is not None and not kind.array_calibration:  # its calibration's compensation
        return None, 0.0, "none"
    on = _simulation_flaws(attrs)
    if on is None:
        creep, stiffening = described_compensation(sensor)
        return creep, stiffening, "none" if creep is None else "described (sensor file)"
    creep = described_creep(sensor) if "viscoelastic" in on else None
    if creep is None:
        return None, 0.0, "none"
    if "nonlinearity" not in on:
        return creep, 0.0, "described (simulation)"
    return creep, float(sensor.flaws.nonlinear_saturation), "described (simulation)"


MEMORY_FLAWS = ("viscoelastic", "hysteresis", "drift")
"""The twin's flaws whose reading depends on the past: creep after a lift, a loop,
a drifting zero."""


def _from_mujoco(attrs) -> bool:
    """Whether the recording was made by ``tactsense mujoco`` (its frames from
    :func:`~tactsense.simulate.frames_from_contacts`, its flaws listed)."""
    return str(attrs.get("source", "")).startswith("mujoco")


def _simulation_flaws(attrs) -> set[str] | None:
    """The flaws tactsense switched on where it made the frames (its ``flaws``
    attribute): ``simulate`` (no ``source``, a scenario with steps) or ``tactsense
    mujoco`` (``source`` ``mujoco:...``); None for a measured recording (unknown)."""
    if _from_mujoco(attrs):
        return {f for f in str(attrs.get("flaws", "")).split(",") if f}
    if str(attrs.get("source", "")):
        return None
    try:
        scenario = json.loads(str(attrs.get("scenario_json", "{}")))
    except ValueError:
        return None
    if not (isinstance(scenario, dict) and scenario.get("steps")):
        return None
    return {f for f in str(attrs.get("flaws", "")).split(",") if f}


def memory_possible(attrs) -> bool:
    """Whether a recording's readings may carry a memory of earlier loads (creep after a
    lift, hysteresis, drift), which the long table's baseline re-zeros after a lift
    (``DriftBaseline``'s ``release``): True for a measured recording (imported,
    streamed, recorded: its flaws are unknown) and for a simulation with one of
    :data:`MEMORY_FLAWS` on; False for a simulation or a MuJoCo recording without them,
    where a reading that falls under a contact is the contact moving (a ball sliding off
    a taxel), not creep.

    Parameters
    ----------
    attrs : dict
        The recording's attributes (``RecordingReader.attrs``).
    """
    on = _simulation_flaws(attrs)
    return on is None or bool(on & set(MEMORY_FLAWS))


def described_compensation(sensor) -> tuple[Viscoelastic | None, float]:
    """The creep to take out of a pad's or point set's measured frames (a live stream,
    a recording that is no simulation) and the stiffening scale after it.

    The sensor description's (:func:`described_creep`, ``nonlinear_saturation``) when
    it says its creep is known (``creep_known = true`` in ``[flaws]``); ``(None, 0)``
    otherwise, and on a finger, whose creep compensation is its calibration's.

    Returns
    -------
    creep : Viscoelastic or None
    stiffening : float
        [-]; 0 for none.
    """
    kind = kind_or_none(sensor)
    if kind is not None and not kind.array_calibration:
        return None, 0.0
    flaws = getattr(sensor, "flaws", None)
    if flaws is None or not getattr(flaws, "creep_known", False):
        return None, 0.0
    creep = described_creep(sensor)
    if creep is None:
        return None, 0.0
    return creep, max(float(sensor.flaws.nonlinear_saturation), 0.0)


def _memory_response(u, dt, model: Viscoelastic):
    """Reading for an elastic input u sampled every dt (input held over each sample)."""
    y = (1.0 - model.delayed_fraction) * u
    for fraction, tau in (
        (model.delayed_fraction, model.delayed_time_constant_s),
        (model.creep_fraction, model.creep_time_constant_s),
    ):
        decay = np.exp(-dt / tau)
        y = y + fraction * lfilter([1.0 - decay], [1.0, -decay], u, axis=0)
    return y


def creep_bounds(dt: float, fine: int = 16) -> tuple[list[float], list[float]]:
    """Bounds of :func:`fit_viscoelastic`'s parameters (gain, a_d, log tau_d, a_c, log tau_c)."""
    return (
        [0.0, 0.0, float(np.log(dt / fine)), 0.0, float(np.log(0.5))],
        [np.inf, 1.0, float(np.log(5.0)), 10.0, float(np.log(1000.0))],
    )


def fit_viscoelastic(signal, dt, loaded, *, fine: int = 16) -> tuple[Viscoelastic, float, float]:
    """Fit delayed elasticity and creep to a tactel's response to force steps.

    Parameters
    ----------
    signal : ndarray, shape (T,)
        Fractional deflection of the tactel under the load, one sample per frame [-].
    dt : float
        Frame period [s].
    loaded : ndarray of bool, shape (T,) or (T * fine,)
        Whether the load was on, per frame or on a ``fine`` times denser clock
        (from the recording's truth, or from contact detection).
    fine : int
        Sub-steps per frame on which the model is integrated.

    Returns
    -------
    model : Viscoelastic
    gain : float
        Elastic deflection of the load [-].
    rms : float
        RMS residual as a share of the largest reading [-].
    """
    signal = np.asarray(signal, dtype=float)
    loaded = np.asarray(loaded, dtype=bool)
    n = signal.size
    if n < 10 or not loaded.any() or loaded.all():
        raise CalibrationError(
            "a creep fit needs a recording with load steps on and off (at least 10 frames)"
        )
    if loaded.size == n:
        loaded = np.repeat(loaded, fine)
    elif loaded.size != n * fine:
        raise CalibrationError(f"loaded has {loaded.size} samples; expected {n} or {n * fine}")
    u = loaded.astype(float)

    def model_output(p):
        gain, a_d, log_tau_d, a_c, log_tau_c = p
        model = Viscoelastic(a_d, np.exp(log_tau_d), a_c, np.exp(log_tau_c))
        return gain * _memory_response(u, dt / fine, model)[fine - 1 :: fine]

    start = [signal.max(), 0.3, np.log(0.05), 0.2, np.log(10.0)]
    fit = least_squares(lambda p: model_output(p) - signal, start, bounds=creep_bounds(dt, fine))
    gain, a_d, log_tau_d, a_c, log_tau_c = fit.x
    rms = float(np.sqrt(np.mean(fit.fun**2)) / np.abs(signal).max())
    return (
        Viscoelastic(float(a_d), float(np.exp(log_tau_d)), float(a_c), float(np.exp(log_tau_c))),
        float(gain),
        rms,
    )


def load_schedule(frame_times, sample_offset: float, step_durations, step_loaded, fine: int = 16):
    """Whether the load was on, on a clock ``fine`` times denser than the frames.

    Sub-sample k of frame n ends at ``frame_times[n] + sample_offset - (fine - 1 - k) dt / fine``
    so that the last sub-sample of each frame is the tactel's sampling instant.

    Parameters
    ----------
    frame_times : ndarray, shape (T,)
        Frame start times [s].
    sample_offset : float
        When the tactel is sampled within a frame [s].
    step_durations : sequence of float
        Durations of the recording's scenario steps [s].
    step_loaded : sequence of bool
        Whether each step loads the tactel.
    """
    times = np.asarray(frame_times, dtype=float)
    if times.size < 2:
        raise CalibrationError("a load schedule needs at least two frames")
    dt = times[1] - times[0]
    sub = (np.arange(fine) - (fine - 1)) * dt / fine
    instants = (times[:, None] + sample_offset + sub[None, :]).ravel()
    bounds = np.cumsum(np.r_[0.0, np.asarray(step_durations, dtype=float)])
    index = np.clip(np.searchsorted(bounds, instants, side="right") - 1, 0, len(bounds) - 2)
    return np.asarray(step_loaded, dtype=bool)[index]


def fit_viscoelastic_recording(
    recording, row: int = 4, col: int = 0, *, baseline_frames: int = 5, fine: int = 16
):
    """Fit the creep model to tactel (row, col) of a recording of force steps.

    The load schedule comes from the recording's scenario when it has one
    (simulated), else from the signal itself (on above half its largest value).

    Parameters
    ----------
    recording : Recording
        Anything with ``frames``, ``time_s``, ``sample_offset_s``, ``scenario`` and
        ``sensor`` (a :class:`tactsense.io.Recording`).

    Returns
    -------
    model, gain, rms : see :func:`fit_viscoelastic`
    """
    frames = np.asarray(recording.frames, dtype=float)
    if frames.shape[0] <= baseline_frames:
        raise CalibrationError("the steps recording is too short for its baseline")
    baseline = np.median(frames[:baseline_frames], axis=0)
    signal = (frames[:, row, col] - baseline[row, col]) / frames[:, row, col]
    steps = recording.scenario.get("steps") if recording.scenario else None
    if steps:
        schedule = load_schedule(
            recording.time_s,
            recording.sample_offset_s[row, col],
            [s["duration_s"] for s in steps],
            [bool(s["contacts"]) for s in steps],
            fine,
        )
    else:
        schedule = signal > 0.5 * signal.max()
    return fit_viscoelastic(signal, recording.sensor.scan_period_s, schedule, fine=fine)


def compensation_noise_gain(model: Viscoelastic, dt: float) -> float:
    """How much :class:`CreepCompensator` amplifies white read noise: the standard
    deviation of its output over that of its input, in the steady state [-].

    The compensation divides each frame by ``c`` (below 1: 0.58 for the paper's rubber
    at 100 Hz) and subtracts its own low-passed past, so a noisy array read through it
    is noisier than its description says (1.77 times for pad16 at 100 Hz, 1.54 for
    dome12 at 50 Hz); the default contact threshold, set on the read noise, is raised
    by this gain where the creep is taken out. Exact, from the compensator's two-state
    recursion: ``m[n] = A m[n-1] + B y[n]``, ``u[n] = C m[n-1] + D y[n]``, output variance
    ``D^2 + C P C`` with ``P`` the solution of ``P = A P A' + B B'`` (the discrete
    Lyapunov equation).
    """
    from scipy.linalg import solve_discrete_lyapunov

    coefficients = CreepCompensator(model, dt).coefficients
    k = np.array(coefficients[:2])  # a_d e_d, a_c e_c
    inv_c, e = coefficients[2], np.array(coefficients[3:5])
    b = (1.0 - e) * inv_c
    a = np.diag(e) - np.outer(b, k)
    p = solve_discrete_lyapunov(a, np.outer(b, b))
    cvec = -k * inv_c
    return float(np.sqrt(inv_c**2 + cvec @ p @ cvec))


class CreepCompensator:
    """Causal creep compensation, one frame at a time (for a live stream).

    With the input held over each frame, ``y[n] = c u[n] + a_d e_d m_d[n-1] +
    a_c e_c m_c[n-1]`` with ``c = (1 - a_d) + a_d (1 - e_d) + a_c (1 - e_c)``, so
    ``u[n]`` follows exactly from ``y[n]`` and the memories, which are then updated.

    Parameters
    ----------
    model : Viscoelastic
    dt : float
        Frame period [s].
    shape : tuple of int
        Shape of one frame.
    """

    def __init__(self, model: Viscoelastic, dt: float, shape: tuple[int, ...] = ()):
        self._e_d = float(np.exp(-dt / model.delayed_time_constant_s))
        self._e_c = float(np.exp(-dt / model.creep_time_constant_s))
        self._a_d, self._a_c = model.delayed_fraction, model.creep_fraction
        self._c = (1 - self._a_d) + self._a_d * (1 - self._e_d) + self._a_c * (1 - self._e_c)
        self._m_d = np.zeros(shape)
        self._m_c = np.zeros(shape)

    @property
    def coefficients(self) -> tuple[float, float, float, float, float]:
        """``(a_d e_d, a_c e_c, 1 / c, e_d, e_c)``: ``u = (y - a_d e_d m_d - a_c e_c
        m_c) / c``, then ``m <- e m + (1 - e) u`` for each memory (the compiled twin in
        :mod:`tactsense.estimate.contacts.baseline`)."""
        return (
            self._a_d * self._e_d,
            self._a_c * self._e_c,
            1.0 / self._c,
            self._e_d,
            self._e_c,
        )

    @property
    def state(self) -> np.ndarray:
        """The two memories (delayed, creep) per tactel: array (2, *shape) [-]."""
        return np.stack([self._m_d, self._m_c])

    @state.setter
    def state(self, value) -> None:
        value = np.asarray(value, dtype=float)
        if value.shape != (2, *self._m_d.shape):
            raise TactsenseInputError(
                f"creep state has shape {value.shape}; expected {(2, *self._m_d.shape)}"
            )
        self._m_d, self._m_c = value[0].copy(), value[1].copy()

    def transition(self) -> np.ndarray:
        """The 2x2 matrix A of the memories' recursion ``s[n] = A s[n-1] + b y[n]``.

        With ``u = (y - a_d e_d m_d - a_c e_c m_c) / c`` substituted into the memory
        updates; the same for every tactel. A range of frames compensated from zero
        memories ends in ``z``; from memories ``s0`` it ends in ``A^L s0 + z``
        (:meth:`carry`), which lets the ranges of one recording run in parallel.
        """
        e_d, e_c, a_d, a_c, c = self._e_d, self._e_c, self._a_d, self._a_c, self._c
        return np.array(
            [
                [e_d - (1 - e_d) * a_d * e_d / c, -(1 - e_d) * a_c * e_c / c],
                [-(1 - e_c) * a_d * e_d / c, e_c - (1 - e_c) * a_c * e_c / c],
            ]
        )

    def carry(self, state, n_frames: int) -> np.ndarray:
        """Memories ``state`` (2, *shape) after ``n_frames`` frames of zero readings:
        ``A^n_frames`` applied to each tactel's pair."""
        state = np.asarray(state, dtype=float)
        power = np.linalg.matrix_power(self.transition(), int(n_frames))
        return np.tensordot(power, state, axes=(1, 0))

    def __call__(self, reading) -> np.ndarray:
        """The elastic deflection of one frame of readings [-]."""
        y = np.asarray(reading, dtype=float)
        u = (y - self._a_d * self._e_d * self._m_d - self._a_c * self._e_c * self._m_c) / self._c
        self._m_d = self._e_d * self._m_d + (1 - self._e_d) * u
        self._m_c = self._e_c * self._m_c + (1 - self._e_c) * u
        return u


def compensate_viscoelastic(deflection, dt, model: Viscoelastic):
    """Invert the creep model frame by frame: the elastic deflection from the readings.

    Causal (:class:`CreepCompensator` applied to each frame in turn): usable in a
    real-time loop.

    Parameters
    ----------
    deflection : ndarray, shape (T, ...)
        Readings over time (axis 0) [-].
    dt : float
        Frame period [s].

    Returns
    -------
    ndarray, shape (T, ...)
        Estimated elastic deflection [-].
    """
    y = np.asarray(deflection, dtype=float)
    compensate = CreepCompensator(model, dt, y.shape[1:])
    u = np.empty_like(y)
    for n in range(y.shape[0]):
        u[n] = compensate(y[n])
    return u
