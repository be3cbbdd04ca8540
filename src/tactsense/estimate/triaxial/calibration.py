"""The three-axis calibration: every taxel's rest reading and 3x3 matrix.

A three-axis Hall sensor's three axes differ in gain and are not quite square to the
pad's (its package, its solder, the magnet's strength and tilt): its reading of a
change of field is ``G_i^-1`` times the change the model predicts, a 3x3 matrix per
taxel. :func:`calibrate_triaxial` fits each ``G_i`` by least squares from frames under
known loads (a normal sweep, a probe pressed on every taxel in turn, and tangential
sweeps, the probe loaded along x and along y): the change the kind's response
(:mod:`.response`) predicts for the known loads against the change read, regularised
toward the identity where a taxel saw little. Applied, ``G_i`` maps every taxel's
change [counts] to the model's before the fit (:mod:`.fit`), so that gains, cross-axis
terms and magnet strength are taken out and the fitted loads are in newtons.

A lab does it on the bench: the skin on a six-axis force/torque sensor, a probe on a
three-axis stage pressed on every taxel (normal sweep), then at each taxel pushed
tangentially along x and along y (tangential sweeps), the stage's positions and the
force/torque sensor's loads logged; here the known loads are the simulated recording's
truth (``step_contacts_json``).
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from tactsense._validation import TactsenseInputError

FORMAT = "tactsense-triaxial-calibration"
"""The ``format`` of a three-axis calibration file (JSON)."""

RIDGE = 1e-3
"""Regularisation toward the identity, as a share of a taxel's mean squared reading [-]."""


class TriaxialCalibrationError(TactsenseInputError):
    """A three-axis calibration that cannot be made or does not fit the sensor."""


def is_triaxial_calibration(data) -> bool:
    """Whether parsed JSON ``data`` is a three-axis calibration."""
    return isinstance(data, dict) and data.get("format") == FORMAT


@dataclass
class TriaxialCalibration:
    """Every taxel's rest reading [counts], shape (rows, cols, 3), and 3x3 matrix [-],
    shape (rows, cols, 3, 3), of the sensor named ``sensor_name``."""

    sensor_name: str
    baseline: np.ndarray
    matrices: np.ndarray
    notes: dict = field(default_factory=dict)

    def check_sensor(self, sensor) -> None:
        """A one-line error unless the calibration is of ``sensor``'s shape."""
        want = tuple(sensor.frame_shape)
        if tuple(self.baseline.shape) != want:
            raise TriaxialCalibrationError(
                f"the calibration is of a {self.baseline.shape} sensor "
                f"({self.sensor_name!r}); {sensor.name!r} reads frames of {want}"
            )

    def apply(self, change: np.ndarray) -> np.ndarray:
        """Every taxel's change [counts] (..., rows, cols, 3) through its matrix."""
        return np.einsum("rcij,...rcj->...rci", self.matrices, change)

    def to_dict(self) -> dict:
        return {
            "format": FORMAT,
            "version": 1,
            "sensor": self.sensor_name,
            "shape": list(self.baseline.shape),
            "baseline_counts": self.baseline.tolist(),
            "matrices": self.matrices.tolist(),
            "notes": self.notes,
        }

    @classmethod
    def from_dict(cls, data: dict, *, source: str = "calibration") -> TriaxialCalibration:
        try:
            baseline = np.asarray(data["baseline_counts"], dtype=float)
            matrices = np.asarray(data["matrices"], dtype=float)
            name = str(data["sensor"])
        except (KeyError, TypeError, ValueError) as error:
            raise TriaxialCalibrationError(
                f"{source}: not a three-axis calibration ({error})"
            ) from None
        if (baseline.ndim != 3 or matrices.shape != (*baseline.shape, 3)
                or not (np.isfinite(baseline).all() and np.isfinite(matrices).all())):  # fmt: skip
            raise TriaxialCalibrationError(
                f"{source}: baseline (rows, cols, 3) and matrices (rows, cols, 3, 3) of "
                f"finite numbers expected; got {baseline.shape} and {matrices.shape}"
            )
        return cls(name, baseline, matrices, dict(data.get("notes", {})))

    def save(self, path: str | Path) -> None:
        Path(path).write_text(json.dumps(self.to_dict(), indent=1), encoding="utf-8")

    @classmethod
    def load(cls, path: str | Path, sensor=None) -> TriaxialCalibration:
        try:
            data = json.loads(Path(path).read_text(encoding="utf-8"))
        except (OSError, UnicodeDecodeError, json.JSONDecodeError) as error:
            raise TriaxialCalibrationError(f"cannot read {path}: {error}") from None
        if not is_triaxial_calibration(data):
            raise TriaxialCalibrationError(f"{path} is not a three-axis calibration")
        calibration = cls.from_dict(data, source=str(path))
        if sensor is not None:
            calibration.check_sensor(sensor)
        return calibration


def predicted_change(sensor, contacts: list[dict], table) -> np.ndarray:
    """The change of every taxel [counts] (rows, cols, 3) the response predicts under
    ``contacts`` (dicts with ``x_mm``, ``y_mm``, ``force_n`` and optionally
    ``shear_x_n``, ``shear_y_n`` [mm, N]), each its own contact, superposed.
    ``table``: a :class:`~.response.ResponseTable`, or a function of a contact dict
    giving the one for its indenter."""
    total = np.zeros(int(np.prod(sensor.frame_shape)))
    for c in contacts:
        own = table(c) if callable(table) else table
        response = own.at(float(c["x_mm"]), float(c["y_mm"]))
        loads = np.array([c["force_n"], c.get("shear_x_n", 0.0), c.get("shear_y_n", 0.0)])
        total += loads @ response
    return total.reshape(sensor.frame_shape)


def calibrate_triaxial(recordings, sensor, *, baseline_frames: int = 5,
                       settle_frames: int = 2,
                       radius_mm: float | None = None) -> TriaxialCalibration:  # fmt: skip
    """Every taxel's 3x3 matrix from recordings under known loads.

    Parameters
    ----------
    recordings : iterable of (frames (T, rows, cols, 3) [counts], frame_step (T,),
        step_contacts (list per step of contact dicts))
        The sweeps; the first ``baseline_frames`` frames of the first one untouched
        (its median is the baseline).
    sensor : the three-axis sensor description
    settle_frames : int
        Frames after each change of step left out (the scan and the layer settle).
    radius_mm : float, optional
        Radius of the sphere pressed on the bench [mm], for loads that do not give their
        own (a load's ``radius_mm`` with ``kind`` "sphere", as a simulated recording's
        truth has, comes first). Each taxel's gains are judged against the kind's
        response to THAT indenter (:func:`.response.response_table`), so that a bench
        ball other than the kind's default probe gives unbiased gains (noise-free, every
        gain 1 within 0.5 %: ``tests/estimate/test_triaxial_radius.py``); None: the
        kind's default probe.

    Returns
    -------
    TriaxialCalibration
        With ``notes``: the frames used, the residual [counts] before and after, and
        the taxels left at the identity (too little signal).
    """
    from tactsense.estimate.triaxial.response import response_table

    def table(contact: dict):
        return response_table(sensor, radius_mm=_radius_of(contact, radius_mm))

    rows, cols = sensor.shape
    radii: set = set()
    read, want = [], []
    baseline = None
    for frames, frame_step, step_contacts in recordings:
        frames = np.asarray(frames, dtype=float)
        if baseline is None:
            if len(frames) < baseline_frames:
                raise TriaxialCalibrationError(
                    f"the first sweep has {len(frames)} frames; {baseline_frames} untouched "
                    "ones are needed at its start for the baseline"
                )
            baseline = np.median(frames[:baseline_frames], axis=0)
        step = np.asarray(frame_step)
        steady = np.ones(len(step), bool)
        for lag in range(1, settle_frames + 1):
            steady[lag:] &= step[lag:] == step[:-lag]
            steady[:lag] = False
        cache: dict[int, np.ndarray] = {}
        for t in np.flatnonzero(steady):
            s = int(step[t])
            if not step_contacts[s]:
                continue
            if s not in cache:
                cache[s] = predicted_change(sensor, step_contacts[s], table)
                radii.update(_radius_of(c, radius_mm) for c in step_contacts[s])
            read.append(frames[t] - baseline)
            want.append(cache[s])
    if not read:
        raise TriaxialCalibrationError(
            "no frame under a known load: the sweeps need the loads of their steps "
            "(a simulated recording's truth, step_contacts_json)"
        )
    m = np.stack(read).reshape(len(read), rows * cols, 3)
    p = np.stack(want).reshape(len(want), rows * cols, 3)
    matrices = np.empty((rows * cols, 3, 3))
    weak = []
    noise = float(getattr(sensor.flaws, "read_noise_counts", 0.0) or 1.0)
    for i in range(rows * cols):
        mm = m[:, i].T @ m[:, i]
        scale = np.trace(mm) / 3.0
        if math.sqrt(scale / len(m)) < 5.0 * noise:  # under 5 read noises (rms)
            weak.append(i)
        lam = RIDGE * max(scale, 1e-12)
        # G minimises |p - G m|^2 + lam |G - I|^2
        matrices[i] = np.linalg.solve(
            mm + lam * np.eye(3), (p[:, i].T @ m[:, i] + lam * np.eye(3)).T
        ).T
    before = float(np.sqrt(np.mean((p - m) ** 2)))
    after = float(np.sqrt(np.mean((p - np.einsum("nij,tnj->tni", matrices, m)) ** 2)))
    notes = {"frames": len(read), "rms_before_counts": before, "rms_after_counts": after,
             "weak_taxels": [[int(i // cols), int(i % cols)] for i in weak],
             "method": "least squares of the response's predicted change on the read change, "
                       f"ridge {RIDGE:g} toward the identity",
             "indenter_radius_mm": sorted(radii, key=lambda r: (r is None, r or 0.0))}  # fmt: skip
    if not math.isfinite(after):
        raise TriaxialCalibrationError("the calibration's fit failed (non-finite residual)")
    return TriaxialCalibration(sensor.name, baseline, matrices.reshape(rows, cols, 3, 3), notes)


def _radius_of(contact: dict, default: float | None) -> float | None:
    """The radius of the sphere whose response a bench load is judged against [mm]
    (None: the kind's default probe)."""
    own = contact.get("radius_mm") if contact.get("kind", "sphere") == "sphere" else None
    return default if own is None else float(own)
