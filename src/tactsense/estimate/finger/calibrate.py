"""Calibration and compensation of a real finger (sections 3 and 4.1 of the paper).

Everything here works from recordings alone, simulated or measured; where the truth
(what load was applied, when) is needed it is taken from the recording's metadata if
present, else detected from the frames.

* :func:`gain_table` - per-tactel gain from a probe swept along every row (section 3.1).
* :func:`track_baseline` - baseline, drift and re-zero after contact (section 3.4).
* :func:`nonlinearity_table` - measured -> linear deflection lookup table (section 3, Fig. 6).
* :func:`fit_viscoelastic`, :func:`compensate_viscoelastic` - creep (section 3.4, Fig. 12),
  in :mod:`tactsense.estimate.creep` and re-exported here.
* :func:`fit_plane_stress` - depth and nu from a knife-edge sweep (section 4.1, Fig. 16).
* :func:`array_health` - sensitivity histogram, jitter, dead/weak/noisy tactels (Figs. 8-11).
* :class:`Calibration` - all of it, saved as JSON with the sensor it belongs to.
"""

from __future__ import annotations

import functools
import json
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np
from scipy.optimize import least_squares

from tactsense._validation import CalibrationError, check_frames
from tactsense.estimate.creep import (
    CreepCompensator,
    Viscoelastic,
    compensate_viscoelastic,
    creep_bounds,
    fit_viscoelastic,
    fit_viscoelastic_recording,
    load_schedule,
)
from tactsense.estimate.finger.deflection import deflection_from_counts
from tactsense.physics.array_response import deflection_batch
from tactsense.physics.contact import Probe
from tactsense.physics.halfplane import impulse_response
from tactsense.sensor import STANDARD_GRAVITY, SensorSpec

__all__ = [
    "Calibration",
    "CalibrationError",
    "ModelFit",
    "Viscoelastic",
    "array_health",
    "calibrate_sweep",
    "check_model_fit",
    "check_viscoelastic_fit",
    "compensate_viscoelastic",
    "fit_plane_stress",
    "fit_viscoelastic",
    "fit_viscoelastic_recording",
    "gain_table",
    "jitter_statistics",
    "load_schedule",
    "nonlinearity_table",
    "track_baseline",
]

FORMAT = "tactsense-calibration"


# ---- gains -------------------------------------------------------------------------


def gain_table(deflection, *, min_response: float = 0.01, reference: float | None = None):
    """Per-tactel gain from a recording of a probe swept over every tactel (section 3.1).

    The gain parameter of the paper is each tactel's largest fractional
    deflection during the sweep; divided by a reference it becomes the gain
    that normalizes frames (Fig. 7 after calibration). The reference is the
    deflection the model predicts for the calibration probe centred on a
    tactel (absolute gains), or, without it, the median over the array
    (relative gains, as in the paper).

    Parameters
    ----------
    deflection : ndarray, shape (T, rows, cols)
        Fractional deflection of the sweep [-].
    min_response : float
        A tactel whose largest deflection stays below this is left uncalibrated
        (gain 1, reported in ``uncalibrated``) [-].

    Returns
    -------
    gains : ndarray, shape (rows, cols)
        Relative gain [-].
    peak : ndarray, shape (rows, cols)
        Largest deflection of each tactel [-].
    uncalibrated : ndarray of bool, shape (rows, cols)
    """
    deflection = np.asarray(deflection, dtype=float)
    if deflection.ndim != 3 or deflection.shape[0] < 2:
        raise CalibrationError(
            f"a gain calibration needs a sweep of frames (T, rows, cols); got {deflection.shape}"
        )
    return gains_from_peak(deflection.max(axis=0), min_response=min_response, reference=reference)


def gains_from_peak(peak, *, min_response: float = 0.01, reference=None):
    """:func:`gain_table` from each tactel's largest deflection (for sweeps read in pieces)."""
    peak = np.asarray(peak, dtype=float)
    calibrated = peak >= min_response
    if not calibrated.any():
        raise CalibrationError(
            f"no tactel deflected more than {min_response:.3g}: the recording has no contact"
        )
    if reference is None:
        reference = np.median(peak[calibrated])
    gains = np.where(calibrated, peak / reference, 1.0)
    return gains, peak, ~calibrated


# ---- baseline, drift and re-zero ---------------------------------------------------


def track_baseline(
    frames,
    initial_baseline,
    sensor: SensorSpec,
    *,
    touch: float = 0.005,
    release: float = 0.003,
    rate: float = 0.2,
    settle_frames: int = 2,
):
    """Follow the zero of every tactel while nothing touches, and re-zero after contact.

    A frame is *touched* when its largest deflection against the current
    baseline exceeds ``touch``; contact is *broken* when it falls below
    ``release``. While untouched, the baseline follows the readings with an
    exponential average (``rate`` per frame), which absorbs slow drift; once
    contact has been broken for ``settle_frames`` frames, the baseline is reset
    to the current reading (the paper's "new zero deflection point after
    contact is broken"), so that residual strain is not read as force.

    Parameters
    ----------
    frames : ndarray, shape (T, rows, cols)
        Readings [counts].
    initial_baseline : ndarray, shape (rows, cols)
        Zero before the first frame [counts].

    Returns
    -------
    baselines : ndarray, shape (T, rows, cols)
        Baseline to use for each frame [counts].
    touched : ndarray of bool, shape (T,)
    """
    frames = check_frames(frames, sensor.shape).astype(float)
    if frames.ndim != 3:
        raise CalibrationError(f"frames has shape {frames.shape}; expected (T, rows, cols)")
    baseline = np.array(initial_baseline, dtype=float)
    baselines = np.empty_like(frames)
    touched = np.zeros(frames.shape[0], dtype=bool)
    in_contact, quiet = False, 0
    for k, frame in enumerate(frames):
        level = np.nanmax((frame - baseline) / np.where(frame > 0, frame, np.inf))
        if in_contact:
            if level < release:
                quiet += 1
                if quiet >= settle_frames:
                    in_contact, quiet = False, 0
                    baseline = frame.copy()
        elif level > touch:
            in_contact, quiet = True, 0
        touched[k] = in_contact
        if not in_contact:
            baseline = np.where(np.isfinite(frame), (1 - rate) * baseline + rate * frame, baseline)
        baselines[k] = baseline
    return baselines, touched


# ---- nonlinearity -----------------------------------------------------------------


def nonlinearity_table(loads, deflections, *, linear_below: float | None = None):
    """Lookup table from measured deflection to the deflection of a linear sensor (Fig. 6).

    The linear reference is the straight line through the origin and the
    response to the loads up to ``linear_below`` (default: the smallest half
    of the series), as the paper compares the 1-N response with "the straight
    line from the origin through the strain for a 0.5-N load".

    Parameters
    ----------
    loads : array_like, shape (n,)
        Applied forces [N], increasing.
    deflections : array_like, shape (n,)
        Measured fractional deflection of one cell at each load [-].

    Returns
    -------
    measured, linear : ndarray, shape (n + 1,)
        Table knots, starting at (0, 0); apply with :func:`apply_nonlinearity`.
    """
    loads = np.asarray(loads, dtype=float)
    deflections = np.asarray(deflections, dtype=float)
    if loads.shape != deflections.shape or loads.ndim != 1 or loads.size < 2:
        raise CalibrationError("loads and deflections must be 1-D arrays of the same length >= 2")
    order = np.argsort(loads)
    loads, deflections = loads[order], deflections[order]
    if np.any(np.diff(deflections) <= 0):
        raise CalibrationError("the deflection must grow with the load to build a lookup table")
    limit = np.median(loads) if linear_below is None else linear_below
    low = loads <= limit
    slope = np.sum(deflections[low] * loads[low]) / np.sum(loads[low] ** 2)
    return np.r_[0.0, deflections], np.r_[0.0, slope * loads]


def apply_nonlinearity(deflection, measured, linear):
    """Map measured deflection to linear deflection; the end slopes extrapolate."""
    deflection = np.asarray(deflection, dtype=float)
    result = np.interp(deflection, measured, linear)
    high = (linear[-1] - linear[-2]) / (measured[-1] - measured[-2])
    low = (linear[1] - linear[0]) / (measured[1] - measured[0])
    result = np.where(
        deflection > measured[-1], linear[-1] + high * (deflection - measured[-1]), result
    )
    return np.where(deflection < measured[0], linear[0] + low * (deflection - measured[0]), result)


# ---- the plane-stress fit of section 4.1 --------------------------------------------


@dataclass(frozen=True)
class ModelFit:
    """Depth and Poisson's ratio fitted to a knife-edge sweep (section 4.1)."""

    depth_mm: float
    poisson_ratio: float
    centre_mm: float
    amplitude: float
    rms_percent: float
    """RMS residual as a percentage of full scale (the largest reading)."""


def fit_plane_stress(positions_mm, response, *, youngs_modulus: float = 2.5e5) -> ModelFit:
    """Least-squares fit of eq. 7's depth and nu to one tactel's knife-edge sweep.

    After amplitude normalization (a free amplitude) and a free centre, the
    shape of the plane-stress line-load response fixes the depth and nu.

    Parameters
    ----------
    positions_mm : ndarray, shape (n,)
        Knife-edge positions along the finger [mm].
    response : ndarray, shape (n,)
        Fractional deflection of the tactel [-].
    """
    x = np.asarray(positions_mm, dtype=float)
    r = np.asarray(response, dtype=float)
    if x.shape != r.shape or x.size < 6:
        raise CalibrationError("a model fit needs at least 6 positions with one response each")
    if r.max() <= 0:
        raise CalibrationError("the tactel never responded: no contact in the sweep")

    def shape(p):
        depth, nu, centre, amplitude = p
        h = -impulse_response(
            (x - centre) * 1e-3, depth * 1e-3, youngs_modulus=youngs_modulus, poisson_ratio=nu
        )
        return amplitude * h / h.max() if h.max() > 0 else amplitude * h

    start = [3.0, 0.3, float(x[np.argmax(r)]), float(r.max())]
    fit = least_squares(
        lambda p: shape(p) - r,
        start,
        bounds=(
            [DEPTH_BOUNDS[0], NU_BOUNDS[0], x.min(), 0],
            [DEPTH_BOUNDS[1], NU_BOUNDS[1], x.max(), np.inf],
        ),
    )
    depth, nu, centre, amplitude = fit.x
    rms = 100 * float(np.sqrt(np.mean(fit.fun**2)) / r.max())
    return ModelFit(float(depth), float(nu), float(centre), float(amplitude), rms)


DEPTH_BOUNDS = (0.2, 30.0)
"""Depths a knife-edge fit may return [mm]."""
NU_BOUNDS = (0.0, 0.5)
"""Poisson's ratios a knife-edge fit may return [-]: rubber is 0 to 0.5."""
MAX_FIT_RMS_PERCENT = 10.0
"""A fit whose RMS residual exceeds this share of full scale describes another tactel,
another load, or no contact at all [%]."""


def _at(value: float, bound: float) -> bool:
    return abs(value - bound) <= 1e-3 * max(1.0, abs(bound))


def check_model_fit(fit: ModelFit) -> list[str]:
    """Why a knife-edge fit cannot be trusted (empty if it can)."""
    problems = []
    for name, value, bounds, unit in (
        ("depth", fit.depth_mm, DEPTH_BOUNDS, " mm"),
        ("Poisson's ratio", fit.poisson_ratio, NU_BOUNDS, ""),
    ):
        for bound in bounds:
            if _at(value, bound):
                problems.append(f"{name} stopped at its bound {bound:g}{unit}")
    if fit.rms_percent > MAX_FIT_RMS_PERCENT:
        problems.append(
            f"the residual is {fit.rms_percent:.1f} % of full scale (at most "
            f"{MAX_FIT_RMS_PERCENT:g} % expected)"
        )
    return problems


def check_viscoelastic_fit(model: Viscoelastic, rms: float, dt: float, fine: int = 16) -> list[str]:
    """Why a creep fit cannot be trusted (empty if it can); ``rms`` as a share [-].

    A fraction at its upper bound, or a time constant at a bound while its fraction is
    more than 1 %, means the data did not hold the steps the model describes (a sweep
    given as --steps, a tactel the load never reached). A fraction of 0 is allowed: a
    finger may well show no creep.
    """
    problems = []
    lower, upper = creep_bounds(dt, fine)
    fractions = (
        ("delayed fraction", model.delayed_fraction, upper[1]),
        ("creep fraction", model.creep_fraction, upper[3]),
    )
    for name, value, bound in fractions:
        if _at(value, bound):
            problems.append(f"{name} stopped at its bound {bound:g}")
    taus = (
        ("delayed time constant", model.delayed_time_constant_s, model.delayed_fraction, 2),
        ("creep time constant", model.creep_time_constant_s, model.creep_fraction, 4),
    )
    for name, tau, fraction, k in taus:
        if fraction > 0.01:
            for bound in (np.exp(lower[k]), np.exp(upper[k])):
                if _at(np.log(tau), np.log(bound)):
                    problems.append(f"{name} stopped at its bound {bound:.3g} s")
    if 100 * rms > MAX_FIT_RMS_PERCENT:
        problems.append(
            f"the residual is {100 * rms:.1f} % of full scale "
            f"(at most {MAX_FIT_RMS_PERCENT:g} % expected)"
        )
    return problems


# ---- health of the array ------------------------------------------------------------


def array_health(
    peak_deflection,
    baseline_frames,
    *,
    probe_grams: float = 50.0,
    nominal_counts: float = 2000.0,
    weak: float = 0.5,
    noisy: float = 4.0,
    expected=None,
):
    """Sensitivity of every tactel and detection of dead, weak and noisy ones (Figs. 8-11).

    Parameters
    ----------
    peak_deflection : ndarray, shape (rows, cols)
        Largest deflection of each tactel under the calibration probe [-].
    baseline_frames : ndarray, shape (T, rows, cols)
        Untouched readings [counts].
    probe_grams : float
        Load of the calibration probe [g].
    weak : float
        A tactel below this share of the median sensitivity is weak [-].
    noisy : float
        A tactel whose untouched noise exceeds this many times the median is noisy [-].
    expected : ndarray, shape (rows, cols), optional
        The model's peak deflection of each tactel (:func:`expected_peaks`); with it,
        weakness is judged on measured over expected, not on the raw peak.

    Returns
    -------
    dict
        ``threshold_g`` (grams per A/D unit, Fig. 8), ``noise_counts`` (standard
        deviation untouched), and boolean masks ``dead``, ``weak``, ``noisy``.
    """
    peak = np.asarray(peak_deflection, dtype=float)
    base = np.asarray(baseline_frames, dtype=float)
    counts_change = nominal_counts * peak / np.maximum(1.0 - peak, 1e-9)
    with np.errstate(divide="ignore"):
        threshold = np.where(counts_change > 0, probe_grams / counts_change, np.inf)
    dead = (base.mean(axis=0) <= 0) | (peak <= 0)
    alive = ~dead
    relative = peak if expected is None else peak / np.asarray(expected, dtype=float)
    median_peak = np.median(relative[alive]) if alive.any() else 0.0
    noise = base.std(axis=0)
    # quantization alone gives 1/sqrt(12) counts; do not call a quiet array noisy
    floor = max(np.median(noise[alive]) if alive.any() else 0.0, 1 / np.sqrt(12))
    return {
        "threshold_g": threshold,
        "noise_counts": noise,
        "dead": dead,
        "weak": alive & (relative < weak * median_peak),
        "noisy": alive & (noise > noisy * floor),
    }


def jitter_statistics(readings, counts_per_gram):
    """Jitter of repeated loads (Figs. 10-11): standard deviation in counts and grams."""
    readings = np.asarray(readings, dtype=float)
    if readings.size < 3:
        raise CalibrationError("jitter needs at least 3 repeated applications")
    std = float(readings.std(ddof=1))
    return {
        "mean_counts": float(readings.mean()),
        "std_counts": std,
        "std_grams": std / counts_per_gram,
        "applications": int(readings.size),
    }


# ---- the calibration object ---------------------------------------------------------


def check_in_use(source, used, calibration, error, word: str, sensor=None) -> None:
    """Raise ``error`` unless the gains and the baseline of every ``used`` cell of a
    calibration read from ``source`` are positive finite numbers (a finger's and an
    array's calibration alike; ``word``: tactel or taxel). With ``sensor``, a baseline
    is checked by its reading's rule instead (a resistive taxel may rest at 0,
    :func:`~tactsense.estimate.contacts.unusable_baseline`)."""
    for name, values in (("gains", calibration.gains), ("baseline_counts", calibration.baseline)):
        bad = used & ~(np.isfinite(values) & (values > 0))
        if name == "baseline_counts" and sensor is not None:
            from tactsense.estimate.reading import unusable_baseline

            bad = used & unusable_baseline(values, sensor)
        if bad.any():
            where = ", ".join(f"({r}, {c})" for r, c in np.argwhere(bad)[:8])
            raise error(
                f"{source}: {name} of {int(bad.sum())} {word}(s) in use is not a positive "
                f"finite number, e.g. at {where}; expected > 0 (mark such {word}s dead, "
                "or calibrate again)"
            )


@functools.lru_cache(maxsize=16)
def damaged(source, error: Exception, kind: str, keys) -> str:
    """The one-line message for a calibration file whose content cannot be read: which
    key is missing (or which value is wrong) and what the file should be.

    Parameters
    ----------
    source : str or Path
        The file.
    error : KeyError, TypeError or ValueError
        What reading it raised.
    kind : str
        What the file should be (``"finger's calibration"``...).
    keys : sequence of str
        The keys such a file holds.
    """
    if isinstance(error, KeyError):
        what = f"the key {error.args[0]!r} is missing"
    else:
        what = f"a value is not what it should be ({error})"
    return (
        f"{source} is damaged: {what}; a tactsense {kind} is the JSON file 'tactsense "
        f"calibrate' writes, with the keys {', '.join(keys)}: make it anew"
    )


def sensor_of(sensor_toml: str):
    """The sensor a calibration's TOML describes, parsed once (a live stream checks it
    every frame)."""
    return SensorSpec.from_toml_string(sensor_toml)


def save_json(data: dict, path: str | Path, *, overwrite: bool = False) -> Path:
    """Write a calibration's dictionary as JSON to ``path`` (refused if it exists unless
    ``overwrite``), under a temporary name moved into place when complete."""
    path = Path(path)
    if path.exists() and not overwrite:
        raise FileExistsError(f"{path} exists; pass --force to replace it")
    tmp = path.with_name(path.name + ".tmp")
    tmp.write_text(json.dumps(data, indent=1), encoding="utf-8")
    tmp.replace(path)
    return path


@dataclass
class Calibration:
    """A finger's calibration: gains, baseline, masks and the fitted models.

    Saved as JSON by :meth:`save`, with the sensor description it belongs to;
    :meth:`load` refuses to apply it to another sensor.
    """

    sensor_toml: str
    gains: np.ndarray
    baseline: np.ndarray
    dead: np.ndarray
    weak: np.ndarray
    noisy: np.ndarray
    threshold_g: np.ndarray
    nonlinearity: tuple[list, list] | None = None
    viscoelastic: Viscoelastic | None = None
    model_fit: ModelFit | None = None
    notes: dict = field(default_factory=dict)

    def check_sensor(self, sensor: SensorSpec) -> None:
        """Raise unless this calibration was made for ``sensor``."""
        mine = sensor_of(self.sensor_toml)
        if mine != sensor:
            raise CalibrationError(
                f"this calibration belongs to sensor {mine.name!r}, not {sensor.name!r} "
                "(or a differently configured one): calibrate this finger anew"
            )

    @property
    def excluded(self) -> np.ndarray:
        """Tactels the estimation ignores: dead, weak or noisy."""
        return self.dead | self.weak | self.noisy

    def to_dict(self) -> dict:
        return {
            "format": FORMAT,
            "version": 1,
            "sensor_toml": self.sensor_toml,
            "gains": self.gains.tolist(),
            "baseline_counts": self.baseline.tolist(),
            "dead": self.dead.tolist(),
            "weak": self.weak.tolist(),
            "noisy": self.noisy.tolist(),
            "threshold_g_per_count": np.where(
                np.isfinite(self.threshold_g), self.threshold_g, -1.0
            ).tolist(),
            "nonlinearity": None
            if self.nonlinearity is None
            else {"measured": list(self.nonlinearity[0]), "linear": list(self.nonlinearity[1])},
            "viscoelastic": None if self.viscoelastic is None else asdict(self.viscoelastic),
            "model_fit": None if self.model_fit is None else asdict(self.model_fit),
            "notes": self.notes,
        }

    def save(self, path: str | Path, *, overwrite: bool = False) -> Path:
        return save_json(self.to_dict(), path, overwrite=overwrite)

    @classmethod
    def load(cls, path: str | Path, sensor: SensorSpec | None = None) -> Calibration:
        path = Path(path)
        try:
            data = json.loads(path.read_text(encoding="utf-8"))
        except OSError as error:
            raise CalibrationError(f"cannot read calibration {path}: {error.strerror}") from None
        except UnicodeDecodeError:
            raise CalibrationError(
                f"{path} is not a tactsense calibration: not JSON text (a calibration is the "
                ".json file that `tactsense calibrate` writes)"
            ) from None
        except json.JSONDecodeError as error:
            raise CalibrationError(f"{path} is not valid JSON ({error})") from None
        if not isinstance(data, dict) or data.get("format") != FORMAT:
            raise CalibrationError(f"{path} is not a tactsense calibration")
        try:
            threshold = np.array(data["threshold_g_per_count"], dtype=float)
            nonlinear = data.get("nonlinearity")
            calibration = cls(
                sensor_toml=data["sensor_toml"],
                gains=np.array(data["gains"], dtype=float),
                baseline=np.array(data["baseline_counts"], dtype=float),
                dead=np.array(data["dead"], dtype=bool),
                weak=np.array(data["weak"], dtype=bool),
                noisy=np.array(data["noisy"], dtype=bool),
                threshold_g=np.where(threshold < 0, np.inf, threshold),
                nonlinearity=None
                if nonlinear is None
                else (nonlinear["measured"], nonlinear["linear"]),
                viscoelastic=None
                if data.get("viscoelastic") is None
                else Viscoelastic(**data["viscoelastic"]),
                model_fit=None if data.get("model_fit") is None else ModelFit(**data["model_fit"]),
                notes=data.get("notes", {}),
            )
        except (KeyError, TypeError, ValueError) as error:
            keys = (
                "format", "sensor_toml", "gains", "baseline_counts", "dead", "weak", "noisy",
                "threshold_g_per_count", "nonlinearity", "viscoelastic", "model_fit",
            )  # fmt: skip
            raise CalibrationError(damaged(path, error, "finger's calibration", keys)) from None
        shape = SensorSpec.from_toml_string(calibration.sensor_toml).shape
        for name in ("gains", "baseline", "dead", "weak", "noisy"):
            if getattr(calibration, name).shape != shape:
                raise CalibrationError(f"{path}: {name} has the wrong shape, expected {shape}")
        check_in_use(path, ~calibration.excluded, calibration, CalibrationError, "tactel")
        if sensor is not None:
            calibration.check_sensor(sensor)
        return calibration

    def compensator(self, frame_period_s: float, shape: tuple[int, ...]):
        """A :class:`CreepCompensator` for this calibration's creep model (None without
        one): pass it to :meth:`apply` so that consecutive pieces of one recording are
        compensated as one sequence."""
        if self.viscoelastic is None:
            return None
        return CreepCompensator(self.viscoelastic, frame_period_s, tuple(shape))

    def apply(
        self,
        frames,
        sensor: SensorSpec,
        *,
        frame_period_s: float | None = None,
        compensator=None,
    ):
        """Calibrated fractional deflection of a sequence of frames, and their flags.

        Order: eq. 4 against the stored baseline -> nonlinearity table ->
        creep compensation (frames in time order, needs ``frame_period_s``, or a
        ``compensator`` from :meth:`compensator` carried from the previous piece) ->
        division by the gains; excluded tactels are zeroed and flagged.
        """
        self.check_sensor(sensor)
        deflection, flags = deflection_from_counts(
            frames, self.baseline, sensor, dead=self.excluded
        )
        if self.nonlinearity is not None:
            measured, linear = (np.asarray(v, float) for v in self.nonlinearity)
            deflection = apply_nonlinearity(deflection, measured, linear)
        if compensator is not None and deflection.ndim == 3:
            deflection = np.stack([compensator(frame) for frame in deflection])
        elif self.viscoelastic is not None and frame_period_s is not None and deflection.ndim == 3:
            deflection = compensate_viscoelastic(deflection, frame_period_s, self.viscoelastic)
        deflection = np.where(self.excluded, 0.0, deflection / self.gains)
        return deflection, flags


def expected_peaks(sensor: SensorSpec, probe_grams: float) -> np.ndarray:
    """The model's deflection of every tactel under the probe centred on it [-].

    The reference of the gains: a tactel's gain is its measured largest deflection over
    this, so that where the finger's geometry alone makes a tactel respond less (the tip
    row on the hemisphere, the rows at the ends of the cylinder) it is not called weak.
    """
    rows, cols = sensor.shape
    force = probe_grams * 1e-3 * STANDARD_GRAVITY
    contacts = [
        (Probe(float(sensor.row_axial_mm[r]), float(sensor.col_angle_deg[c]), force),)
        for r in range(rows)
        for c in range(cols)
    ]
    frames = deflection_batch(sensor, contacts).reshape(rows, cols, rows, cols)
    return frames[
        np.arange(rows)[:, None], np.arange(cols), np.arange(rows)[:, None], np.arange(cols)
    ]


def calibrate_sweep(
    frames,
    sensor: SensorSpec,
    *,
    baseline_frames: int = 5,
    probe_grams: float = 50.0,
    min_response: float = 0.01,
) -> Calibration:
    """Build a calibration from a recording of a probe swept over every tactel.

    Parameters
    ----------
    frames : ndarray, shape (T, rows, cols), or an iterable of such pieces
        Readings [counts]; the first ``baseline_frames`` untouched. Pieces (consecutive
        parts of one recording, e.g. ``(f for _, f, _ in reader.chunks())``) are read
        one at a time, so a sweep of any length fits in memory.
    probe_grams : float
        Load of the sweeping probe, for the sensitivity thresholds [g].

    Returns
    -------
    Calibration
        Gains (relative to the model's deflection for the probe centred on a
        tactel), baseline, health masks and thresholds; no fitted models yet.
    """
    nested = isinstance(frames, list | tuple) and not all(hasattr(p, "shape") for p in frames)
    if hasattr(frames, "shape") or nested:
        whole = check_frames(frames, sensor.shape)
        if whole.ndim != 3:
            raise CalibrationError(f"frames has shape {whole.shape}; expected (T, rows, cols)")
        pieces = (whole[k : k + 65_536] for k in range(0, max(whole.shape[0], 1), 65_536))
    else:
        pieces = iter(frames)
    full_scale = 2**sensor.electronics.adc_bits - 1
    base_parts: list[np.ndarray] = []
    have_base = 0
    baseline = None
    peak = None
    total = saturated_count = 0
    for piece in pieces:
        piece = check_frames(piece, sensor.shape).astype(float)
        if piece.ndim != 3:
            raise CalibrationError(f"a piece has shape {piece.shape}; expected (T, rows, cols)")
        total += piece.shape[0]
        saturated_count += int(np.count_nonzero(piece >= full_scale))
        if have_base < baseline_frames:
            take = piece[: baseline_frames - have_base]
            base_parts.append(take)
            have_base += take.shape[0]
            piece = piece[take.shape[0] :]
            if have_base == baseline_frames:
                baseline = np.median(np.concatenate(base_parts), axis=0)
        if baseline is None or piece.shape[0] == 0:
            continue
        deflection, _ = deflection_from_counts(piece, baseline, sensor)
        most = deflection.max(axis=0)
        peak = most if peak is None else np.maximum(peak, most)
    if total <= baseline_frames + 1 or peak is None:
        raise CalibrationError(
            f"the recording has {total} frames: too short for a baseline of "
            f"{baseline_frames} frames and a sweep"
        )
    saturated = saturated_count / (total * np.prod(sensor.shape))
    if saturated > 0.001:
        raise CalibrationError(
            f"{100 * saturated:.2g} % of the readings are saturated at {full_scale} counts: "
            "lighten the probe or lower the amplifier gain and record again"
        )
    base = np.concatenate(base_parts)
    reference = expected_peaks(sensor, probe_grams)
    gains, peak, uncalibrated = gains_from_peak(
        peak, min_response=min_response, reference=reference
    )
    health = array_health(
        peak,
        base,
        probe_grams=probe_grams,
        nominal_counts=float(np.median(baseline)),
        expected=reference,
    )
    return Calibration(
        sensor_toml=sensor.to_toml_string(),
        gains=gains,
        baseline=baseline,
        # a tactel the probe never reached is uncalibrated, not dead: dead is one that
        # reads nothing, or that the probe reached without a response
        dead=health["dead"] & ~(uncalibrated & (baseline > 0)),
        weak=health["weak"] & ~uncalibrated,
        noisy=health["noisy"],
        threshold_g=np.where(uncalibrated, np.inf, health["threshold_g"]),
        notes={
            "uncalibrated_tactels": np.argwhere(uncalibrated).tolist(),
            "probe_grams": probe_grams,
        },
    )
