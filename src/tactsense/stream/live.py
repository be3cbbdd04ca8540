"""Contacts from a live stream, frame by frame, as they arrive."""

from __future__ import annotations

import copy
import time

import numpy as np

from tactsense._validation import TactsenseInputError
from tactsense.estimate import Flag, locate
from tactsense.estimate.creep import CreepCompensator
from tactsense.estimate.finger.deflection import deflection_from_counts
from tactsense.estimate.finger.locate import CONTACT_THRESHOLD
from tactsense.estimate.finger.realtime import RealTimeLocator
from tactsense.kinds import kind_of
from tactsense.physics.contact import newtons_to_grams
from tactsense.sensor import SensorSpec
from tactsense.stream.reader import StreamFrame

FIELDS = (
    "sequence",
    "device_time_s",
    "host_time_s",
    "row",
    "col",
    "axial_mm",
    "angle_deg",
    "force_n",
    "force_g",
    "skew",
    "peak_deflection",
    "flags",
    "flag_names",
    "latency_ms",
)
"""Fields of every estimate :class:`LiveLocator` returns, in output order."""


def warm_frames(sensor, baseline=None, amplitude: float = 0.3) -> list[StreamFrame]:
    """Synthetic frames that take an estimator down every path a real touch takes: a
    bump of ``amplitude`` (a fraction of the baseline, or of a tenth of the full scale
    where the baseline is 0) pressed both ways (counts up and
    down: the sign depends on the transducer), and the baseline itself [counts, uint16].
    """
    rows, cols = sensor.shape
    base = (
        np.full(sensor.shape, float(sensor.electronics.nominal_counts))
        if baseline is None
        else np.asarray(baseline, dtype=float)
    )
    r, c = np.mgrid[0:rows, 0:cols]
    bump = np.exp(-((r - (rows - 1) / 2) ** 2 + (c - (cols - 1) / 2) ** 2) / 2.0)
    top = 2 ** min(int(sensor.electronics.adc_bits), 16) - 1
    # a taxel resting at 0 (a resistive cell) moves by a share of the full scale instead
    step = amplitude * bump * np.where(base > 0, base, 0.1 * top)
    frames = []
    for k, counts in enumerate((base + step, base - step, base, base)):
        counts = np.clip(np.nan_to_num(np.rint(counts)), 0, top).astype(np.uint16)
        frames.append(StreamFrame(k, k, k * sensor.scan_period_s, 0.0, time.perf_counter(), counts))
    return frames


def flag_names(flags: int) -> str:
    """The set flags of an estimate as ``A|B`` (empty when none)."""
    return "|".join(flag.name for flag in Flag if flag and flags & flag)


class LiveLocator:
    """The contact of every frame of a stream, with its latency.

    Without a calibration the first ``baseline_frames`` frames (untouched) give the
    baseline and then :class:`~tactsense.estimate.finger.realtime.RealTimeLocator` runs on
    each frame. With a calibration its baseline, nonlinearity table, gains and excluded
    tactels apply from the first frame, and its creep model is inverted causally
    (:class:`~tactsense.estimate.creep.CreepCompensator`).

    Parameters
    ----------
    sensor : SensorSpec
    calibration : Calibration, optional
    baseline_frames : int
        Untouched frames that make the baseline when there is no calibration.
    threshold : float
        Smallest tactel deflection that counts as a contact [-].
    frame_period_s : float, optional
        Time between frames [s], for the creep compensation; default the sensor's.
    baseline : array_like, shape (rows, cols), optional
        Without a calibration: the undeflected readings [counts], known in advance
        (e.g. from the start of a recording); no frames are spent collecting one.
    keep_deflection : bool
        Keep the fractional deflection of the last frame in :attr:`last_deflection`
        (for a display; costs a few microseconds a frame).
    """

    def __init__(
        self,
        sensor: SensorSpec,
        *,
        calibration=None,
        baseline_frames: int = 5,
        threshold: float = CONTACT_THRESHOLD,
        frame_period_s: float | None = None,
        baseline=None,
        keep_deflection: bool = False,
    ):
        self.sensor = sensor
        self.calibration = calibration
        self.threshold = threshold
        self._baseline_frames = int(baseline_frames)
        self._collected: list[np.ndarray] = []
        self._locator: RealTimeLocator | None = None
        self._creep = None
        self._keep = bool(keep_deflection)
        self._baseline = None
        self.last_deflection: np.ndarray | None = None
        """Fractional deflection of the last frame [-] (with ``keep_deflection``)."""
        # compile (or load from Numba's cache) now, not while frames queue up
        RealTimeLocator(sensor, np.full(sensor.shape, 1000.0), threshold=threshold)
        if calibration is not None:
            locate(np.full((1, *sensor.shape), 0.05), sensor, counts=False)
        if calibration is not None:
            calibration.check_sensor(sensor)
            # the compiled per-frame path, on the calibrated deflection
            self._calibrated_locator = RealTimeLocator(
                sensor, calibration.baseline, threshold=threshold
            )
            self._calibrated_locator.from_deflection(np.zeros(sensor.shape))
            if calibration.viscoelastic is not None:
                self._period = frame_period_s or sensor.scan_period_s
                self._creep = CreepCompensator(calibration.viscoelastic, self._period, sensor.shape)
        elif baseline is not None:
            self._set_baseline(np.asarray(baseline, dtype=float))
        self._warm_up()

    def _warm_up(self) -> None:
        """Run the per-frame path on a synthetic touch (:func:`warm_frames`), so that
        nothing compiles or loads at the first real frame or the first contact; then
        forget it (baseline, creep history)."""
        saved = (self._locator, self._baseline, list(self._collected), self.last_deflection)
        frames = warm_frames(self.sensor, self._baseline)
        if not self.ready:  # the baseline's frames too, as a run begins
            frames = [frames[-1]] * self._baseline_frames + frames
        for frame in frames:
            self(frame)
        self._locator, self._baseline, self._collected, self.last_deflection = saved
        self.reset()

    def _set_baseline(self, baseline: np.ndarray) -> None:
        self._baseline = baseline
        self._locator = RealTimeLocator(self.sensor, baseline, threshold=self.threshold)

    def reset(self) -> None:
        """Forget the creep history (after a jump in time, e.g. a seek in a recording)."""
        if self._creep is not None:
            self._creep = CreepCompensator(
                self.calibration.viscoelastic, self._period, self.sensor.shape
            )

    @property
    def ready(self) -> bool:
        """True once estimates come out (the baseline is known)."""
        return self.calibration is not None or self._locator is not None

    def rezero(self) -> None:
        """Take the baseline anew from the next ``baseline_frames`` frames (untouched).

        With a calibration its baseline stands (it was measured with the gains): nothing
        changes."""
        if self.calibration is None:
            self._locator = None
            self._baseline = None
            self._collected = []

    def __call__(self, frame: StreamFrame) -> dict | None:
        """The estimate of one frame (a dict of :data:`FIELDS`), or None while the
        baseline is being collected."""
        if self.calibration is not None:
            contact = self._calibrated(frame.counts)
        else:
            if self._locator is None:
                self._collected.append(frame.counts)
                if len(self._collected) < self._baseline_frames:
                    return None
                self._set_baseline(np.median(np.stack(self._collected), axis=0))
                self._collected = []
                return None
            c = self._locator(frame.counts)
            if self._keep:
                self.last_deflection = deflection_from_counts(
                    frame.counts, self._baseline, self.sensor
                )[0]
            contact = (
                c.row, c.col, c.axial_mm, c.angle_deg, c.force_n, c.skew,
                c.peak_deflection, c.flags,
            )  # fmt: skip
        row, col, axial, angle, force, skew, peak, flags = contact
        return {
            "sequence": frame.sequence,
            "device_time_s": frame.device_time_s,
            "host_time_s": frame.host_time_s,
            "row": row,
            "col": col,
            "axial_mm": axial,
            "angle_deg": angle,
            "force_n": force,
            "force_g": float(newtons_to_grams(force)),
            "skew": skew,
            "peak_deflection": peak,
            "flags": int(flags),
            "flag_names": flag_names(int(flags)),
            "latency_ms": 1e3 * (time.perf_counter() - frame.arrival),
        }

    def _calibrated(self, counts: np.ndarray):
        deflection, apply_flags = self.calibration.apply(counts[None], self.sensor)
        if self._creep is not None:
            deflection = self._creep(deflection[0])[None]
        if self._keep:
            self.last_deflection = deflection[0]
        c = self._calibrated_locator.from_deflection(deflection[0])
        flags = int(c.flags) | int(np.bitwise_or.reduce(np.ravel(apply_flags)))
        return (
            c.row, c.col, c.axial_mm, c.angle_deg, c.force_n, c.skew, c.peak_deflection, flags,
        )  # fmt: skip


CONTACT_FIELDS = (
    "id",
    "x_mm",
    "y_mm",
    "z_mm",
    "row",
    "col",
    "force_n",
    "peak",
    "major_mm",
    "minor_mm",
    "orientation_deg",
    "taxels",
    "area_mm2",
    "vx_mm_s",
    "vy_mm_s",
    "vz_mm_s",
    "slip",
    "flags",
)
"""Fields of each contact in :class:`LiveContacts`' estimates (``docs/contacts.md``)."""


class LiveContacts:
    """Every contact of every frame of a stream, tracked, on any kind of array.

    The first ``baseline_frames`` frames (untouched) make the baseline, which then
    follows slow drift where taxels are untouched
    (:class:`~tactsense.estimate.contacts.baseline.DriftBaseline`, time constant ``drift_s``);
    :meth:`rezero` takes a new one from the next frames. Each frame goes through
    :func:`~tactsense.estimate.contacts.find_contacts` and a
    :class:`~tactsense.estimate.contacts.track.ContactTracker`, so ids stay with their contacts
    from frame to frame.

    Parameters
    ----------
    sensor : SensorSpec, PadSpec or PointsSpec
    baseline_frames : int
        Untouched frames that make the baseline.
    threshold : float, optional
        Smallest signal that counts as contact [-]; by default the sensor's
        (:func:`~tactsense.estimate.contacts.default_threshold`).
    frame_period_s : float, optional
        Time between frames [s]; default the sensor's scan period.
    baseline : array_like, shape (rows, cols), optional
        The untouched readings [counts], known in advance (no frames spent on it).
    keep_deflection : bool
        Keep the signal of the last frame in :attr:`last_deflection` (for a display).
    drift_s : float or None
        Time constant of the drift-following baseline [s]; None keeps it fixed.
    max_contacts : int
        At most this many contacts per frame (1-64).
    method : str
        How positions are found (:data:`~tactsense.estimate.contacts.METHODS`).
    calibration : ArrayCalibration, optional
        The array's calibration: its baseline (no frames are spent on one), gains, dead
        taxels and force curve apply from the first frame.
    """

    def __init__(
        self,
        sensor,
        *,
        baseline_frames: int = 5,
        threshold: float | None = None,
        frame_period_s: float | None = None,
        baseline=None,
        keep_deflection: bool = False,
        drift_s: float | None = 2.0,
        max_contacts: int = 8,
        method: str = "interpolate",
        calibration=None,
    ):
        from tactsense.estimate.contacts import default_threshold, find_contacts
        from tactsense.estimate.contacts.array_calibration import ArrayCalibration
        from tactsense.estimate.contacts.track import ContactTracker

        if calibration is not None:
            if not isinstance(calibration, ArrayCalibration):
                raise TactsenseInputError(
                    f"a finger's calibration does not apply to {sensor.name!r}, "
                    f"a {kind_of(sensor).label}: "
                    "calibrate it with 'tactsense calibrate' on its own recording"
                )
            calibration.check_sensor(sensor)
        self.calibration = calibration
        self.sensor = sensor
        if threshold is None:  # a weight curve's own threshold, else the sensor's
            threshold = getattr(calibration, "contact_threshold", None)
        if threshold is None:  # over the noise the creep compensation leaves
            from tactsense.estimate.creep import described_compensation

            creep = described_compensation(sensor)[0]
            threshold = default_threshold(sensor, creep=creep, frame_period_s=frame_period_s)
        self.threshold = float(threshold)
        self.frame_period_s = float(frame_period_s or sensor.scan_period_s)
        self._baseline_frames = max(1, int(baseline_frames))
        self._drift_s = drift_s
        self._keep = bool(keep_deflection)
        self._options = {"max_contacts": max_contacts, "method": method,
                         "threshold": self.threshold}  # fmt: skip
        self._collected: list[np.ndarray] = []
        self._drift = None
        self._tracker = ContactTracker(self.frame_period_s)
        self._serial = 0
        self.last_deflection: np.ndarray | None = None
        """The signal of the last frame [-] (with ``keep_deflection``)."""
        # compile (or load from Numba's cache) now, not while frames queue up
        find_contacts(np.zeros((1, *sensor.shape)), sensor, counts=False, **self._options)
        if calibration is not None:
            self._set_baseline(np.asarray(calibration.baseline, dtype=float))
        elif baseline is not None:
            self._set_baseline(np.asarray(baseline, dtype=float))
        self._warm_up()

    def _warm_up(self) -> None:
        """Run the per-frame path (contacts, force, tracking) on a synthetic touch
        (:func:`warm_frames`), so that nothing compiles or loads at the first real frame
        or the first contact (``--method fit`` stalled 1.7 s there); then forget it."""
        saved = (self._drift, list(self._collected), self.last_deflection)
        frames = warm_frames(self.sensor, None if self._drift is None else self._drift.baseline)
        if self._drift is None:  # the baseline's frames too, as a run begins
            frames = [frames[-1]] * self._baseline_frames + frames
        else:
            self._drift = copy.deepcopy(self._drift)  # the warm frames move it: a copy
        for frame in frames:
            self(frame)
        self._drift, self._collected, self.last_deflection = saved
        self.reset()

    def _set_baseline(self, baseline: np.ndarray) -> None:
        from tactsense.estimate.contacts.baseline import DriftBaseline
        from tactsense.estimate.creep import described_compensation

        creep, stiffening = described_compensation(self.sensor)  # as 'locate' (docs/contacts.md)
        self._drift = DriftBaseline(
            baseline, self.sensor, frame_period_s=self.frame_period_s,
            threshold=self.threshold,
            time_constant_s=float("inf") if self._drift_s is None else self._drift_s,
            rezero_frames=self._baseline_frames, creep=creep, stiffening=stiffening,
        )  # fmt: skip

    @property
    def ready(self) -> bool:
        """True once estimates come out (the baseline is known)."""
        return self._drift is not None

    @property
    def baseline(self) -> np.ndarray | None:
        """The current baseline [counts] (None while it is being collected)."""
        return None if self._drift is None else self._drift.baseline

    @property
    def below_frames(self) -> int:
        """Frames so far with a taxel below the baseline by more than the threshold."""
        return 0 if self._drift is None else self._drift.below_frames

    def reset(self) -> None:
        """Forget the tracks (after a jump in time, e.g. a seek in a recording)."""
        from tactsense.estimate.contacts.track import ContactTracker

        self._tracker = ContactTracker(self.frame_period_s)
        self._serial = 0

    def rezero(self) -> None:
        """Take the baseline anew from the next ``baseline_frames`` frames (untouched)."""
        if self._drift is None:
            self._collected = []
        else:
            self._drift.rezero()

    def __call__(self, frame: StreamFrame) -> dict | None:
        """The contacts of one frame, or None while the baseline is being collected.

        Returns
        -------
        dict
            ``sequence``, ``device_time_s``, ``host_time_s``, ``n_contacts``, ``force_n``
            (their sum [N]), ``flags`` (of the frame), ``flag_names``, ``rezeroing``,
            ``latency_ms`` and ``contacts``: a list of dicts of :data:`CONTACT_FIELDS`.
        """
        from tactsense.estimate.contacts import find_contacts

        counts = np.asarray(frame.counts)
        if self._drift is None:
            self._collected.append(np.asarray(counts, dtype=float))
            if len(self._collected) >= self._baseline_frames:
                collected = np.stack(self._collected)
                self._set_baseline(np.nanmedian(collected, axis=0))
                # the baseline's frames pass through it as they do in a recording's
                # locate (batch.contacts_file): live and batch give the same numbers
                self._drift.signal(collected)
                self._collected = []
            return None
        table = find_contacts(counts[None], self.sensor, baseline=self._drift,
                              calibration=self.calibration, **self._options)  # fmt: skip
        table.frame[:] = self._serial
        tracked, _ = self._tracker.update(table, first_frame=self._serial)
        self._serial += 1
        if self._keep:  # the signal the estimate used (the calibration's gains applied)
            self.last_deflection = self._drift.last_signal[-1].copy()
        columns = tracked.columns()
        contacts = [
            {name: _plain(columns[name][k]) for name in CONTACT_FIELDS if name in columns}
            for k in range(len(tracked))
        ]
        flags = int(np.bitwise_or.reduce(tracked.flags)) if len(tracked) else int(Flag.NO_CONTACT)
        return {
            "sequence": frame.sequence,
            "device_time_s": frame.device_time_s,
            "host_time_s": frame.host_time_s,
            "n_contacts": len(contacts),
            "force_n": float(np.nansum(tracked.force_n)) if len(tracked) else 0.0,
            "flags": flags,
            "flag_names": flag_names(flags),
            "rezeroing": self._drift.rezeroing,
            "contacts": contacts,
            "latency_ms": 1e3 * (time.perf_counter() - frame.arrival),
        }


def _plain(value):
    """A NumPy scalar as the Python number JSON writers expect."""
    if isinstance(value, np.bool_ | bool):
        return bool(value)
    if isinstance(value, np.integer):
        return int(value)
    return float(value)
