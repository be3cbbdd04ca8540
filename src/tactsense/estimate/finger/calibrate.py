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

from tactsense._validation import CalibrationError, check_frames
from tactsense.estimate.creep import (
    CreepCompensator,
    Viscoelastic,
    compensate_viscoelastic,
    fit_viscoelastic,
    fit_viscoelastic_recording,
    load_schedule,
)
from tactsense.estimate.finger.deflection import deflection_from_counts
from tactsense.estimate.finger.fit_checks import (
    DEPTH_BOUNDS,
    MAX_FIT_RMS_PERCENT,
    NU_BOUNDS,
    ModelFit,
    array_health,
    check_model_fit,
    check_viscoelastic_fit,
    fit_plane_stress,
    jitter_statistics,
)
from tactsense.estimate.finger.tables import (
    apply_nonlinearity,
    gain_table,
    gains_from_peak,
    nonlinearity_table,
    track_baseline,
)
from tactsense.physics.array_response import deflection_batch
from tactsense.physics.contact import Probe
from tactsense.sensor import STANDARD_GRAVITY, SensorSpec

__all__ = [
    "DEPTH_BOUNDS",
    "MAX_FIT_RMS_PERCENT",
    "NU_BOUNDS",
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
