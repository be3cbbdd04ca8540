"""What the view runs on each frame: the contact estimator the sensor's kind names, or the
deflection alone where its contacts are not estimated yet (:class:`DeflectionOnly`).

A kind says whether its contacts are estimated
(:attr:`~tactsense.kinds.Kind.contact_estimation`) and whether many contacts are
tracked per frame (:attr:`~tactsense.kinds.Kind.multi_contact`: :class:`LiveContacts`)
or the one contact of each frame is located (the paper's finger: :class:`LiveLocator`).
"""

from __future__ import annotations

import numpy as np

from tactsense._validation import TactsenseInputError
from tactsense.estimate.finger.deflection import deflection_from_counts
from tactsense.kinds import kind_of, kinds
from tactsense.sensor import SpecBase
from tactsense.stream.live import LiveContacts, LiveLocator
from tactsense.stream.reader import StreamFrame
from tactsense.view.vectors import VectorReading, is_vector, warmed


def _capacitive_deflection(counts, baseline, sensor) -> np.ndarray:
    # eq. 4, (counts - baseline) / counts; 0 where a taxel reads nothing usable
    if sensor.transduction.polarity == "falling":  # the mirrored reading's eq. 4
        from tactsense.estimate.contacts import signal_from_counts

        counts = np.asarray(counts, dtype=float)
        return signal_from_counts(counts, baseline, sensor)[0].reshape(counts.shape)
    return deflection_from_counts(counts, baseline, sensor)[0]


def _resistive_deflection(counts, baseline, sensor) -> np.ndarray:
    # the compressive strain: the reading moves by counts_per_strain per unit strain
    strain = (np.asarray(counts, dtype=float) - baseline) / sensor.transduction.counts_per_strain
    if sensor.transduction.polarity == "falling":
        strain = -strain
    return np.where(np.isfinite(strain), strain, 0.0)


DEFLECTION = {
    "capacitive": _capacitive_deflection,
    "resistive": _resistive_deflection,
    "piezoresistive": _resistive_deflection,
}
"""Transduction kind -> the deflection [-] of a frame from its counts and the baseline."""


class DeflectionOnly:
    """The deflection of every frame of a sensor whose contacts are not estimated yet.

    The same interface as :class:`~tactsense.stream.live.LiveLocator` for a feed: called
    with a frame it returns no estimate (None) and keeps the frame's deflection in
    :attr:`last_deflection` once the baseline is known. The baseline is the median of the
    first ``baseline_frames`` frames (untouched), or given. The deflection follows the
    sensor's transduction (:data:`DEFLECTION`): a capacitive taxel's is eq. 4,
    ``(counts - baseline) / counts``; a resistive taxel's ``(counts - baseline) /
    counts_per_strain``.
    """

    calibration = None

    def __init__(self, sensor: SpecBase, *, baseline_frames: int = 5, baseline=None):
        self.sensor = sensor
        self._deflection = DEFLECTION[sensor.transduction.kind]
        self._baseline_frames = max(1, int(baseline_frames))
        self._collected: list[np.ndarray] = []
        self._baseline = None if baseline is None else np.asarray(baseline, dtype=float)
        self.last_deflection: np.ndarray | None = None
        """Deflection of the last frame [-] (None until the baseline is known)."""

    @property
    def ready(self) -> bool:
        return self._baseline is not None

    def reset(self) -> None:
        """Nothing to forget (no creep compensation)."""

    def __call__(self, frame: StreamFrame) -> None:
        counts = np.asarray(frame.counts, dtype=float)
        if self._baseline is None:
            self._collected.append(counts)
            if len(self._collected) >= self._baseline_frames:
                self._baseline = np.median(np.stack(self._collected), axis=0)
                self._collected = []
            return None
        self.last_deflection = self._deflection(counts, self._baseline, self.sensor)
        return None


def live_estimator(sensor: SpecBase) -> type | None:
    """What estimates the contacts of ``sensor`` frame by frame: every contact, tracked
    (:class:`LiveContacts`) where its kind has many a frame, the one contact of each frame
    (:class:`LiveLocator`, the paper's finger) where not; None where its kind's contacts
    are not estimated yet (the view runs :class:`DeflectionOnly`)."""
    return _estimator_of(kind_of(sensor))


def _vector_kind(kind) -> bool:
    """Whether a kind's taxels report several components (its sensors' frames end with a
    component axis: ``SpecBase.components``)."""
    return int(getattr(kind.spec_class, "components", 1)) > 1


def _estimator_of(kind) -> type | None:
    if not kind.contact_estimation:
        return None
    if _vector_kind(kind):  # r8-triview: taxels of several components: shear and slip
        from tactsense.estimate.triaxial import LiveShearContacts

        return LiveShearContacts
    return LiveContacts if kind.multi_contact else LiveLocator


def estimates(sensor: SpecBase) -> bool:
    """Whether contacts on this kind of sensor are estimated (fingers, pads and point
    sets: every built-in kind)."""
    return live_estimator(sensor) is not None


def multi_contact(sensor: SpecBase) -> bool:
    """Whether the view tracks several contacts a frame on ``sensor`` (pads, point sets),
    drawn on the plane of its taxels, rather than the finger's one."""
    return live_estimator(sensor) is not None and bool(kind_of(sensor).multi_contact)


def view_locator(
    sensor: SpecBase,
    *,
    calibration=None,
    baseline_frames: int = 5,
    threshold: float | None = None,
    frame_period_s: float | None = None,
    baseline=None,
):
    """What the view runs on each frame of ``sensor``: a contact locator where one exists
    for its kind, else :class:`DeflectionOnly` (which takes no calibration yet).
    ``threshold`` None: the sensor's default (0.005 on the finger). A sensor whose
    taxels have several components (a three-axis pad) gets its estimator (or none)
    wrapped in :class:`~tactsense.view.vectors.VectorReading`: the map and the arrows."""
    # ---- taxels of several components (r8-triview) ----
    if is_vector(sensor):
        inner = None
        if estimates(sensor) or calibration is not None:
            inner = _estimator(sensor, calibration, baseline_frames, threshold,
                               frame_period_s, baseline)  # fmt: skip
        return VectorReading(sensor, inner, baseline_frames=baseline_frames, baseline=baseline)
    # ---- /taxels of several components (r8-triview) ----
    return _estimator(sensor, calibration, baseline_frames, threshold, frame_period_s, baseline)


def _estimator(sensor, calibration, baseline_frames, threshold, frame_period_s, baseline):
    locator = live_estimator(sensor)
    if locator is not None and _vector_kind(kind_of(sensor)):  # r8-triview
        # --threshold: a fraction of the converter's full scale, locate's rule (r8-fixb8)
        from tactsense.estimate.triaxial.locate import threshold_counts_of

        warmed(locator, sensor)
        return locator(
            sensor,
            baseline_frames=baseline_frames,
            baseline=baseline,
            calibration=calibration,
            threshold_counts=threshold_counts_of(sensor, threshold),
        )
    if locator is LiveContacts:
        return LiveContacts(
            sensor,
            baseline_frames=baseline_frames,
            threshold=threshold,
            frame_period_s=frame_period_s,
            baseline=baseline,
            keep_deflection=True,
            calibration=calibration,
        )
    if locator is not None and calibration is not None and not hasattr(calibration, "apply"):
        raise TactsenseInputError(
            f"an array's calibration does not apply to {sensor.name!r}, a "
            f"{kind_of(sensor).label}: "
            "calibrate it with 'tactsense calibrate' on a probe sweep of the finger"
        )
    if locator is not None:
        if threshold is None:
            threshold = 0.005
        return locator(
            sensor,
            calibration=calibration,
            baseline_frames=baseline_frames,
            threshold=threshold,
            frame_period_s=frame_period_s,
            baseline=baseline,
            keep_deflection=True,
        )
    if calibration is not None:
        raise TactsenseInputError(
            f"--calibration applies to fingers, not to {kind_of(sensor).plural} "
            f"(sensor {sensor.name!r}), whose calibration does not exist yet: leave "
            "--calibration out"
        )
    return DeflectionOnly(sensor, baseline_frames=baseline_frames, baseline=baseline)


def __getattr__(name: str):
    """``LOCATORS`` and ``PLURAL``, the tables by kind name this module had, read from the
    registered kinds (:func:`tactsense.kinds.kinds`) for code that still asks them."""
    if name == "LOCATORS":
        every = {n: _estimator_of(k) for n, k in kinds().items()}
        return {n: estimator for n, estimator in every.items() if estimator is not None}
    if name == "PLURAL":
        return {n: k.plural for n, k in kinds().items()}
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
