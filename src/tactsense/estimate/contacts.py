"""Several contacts per frame, on any array: the long table every multi-contact tool shares.

A :class:`ContactTable` holds one row per contact per frame (a "long" table): the
segmentation (:func:`find_contacts`) fills the geometric columns, the tracker
(:mod:`tactsense.estimate.track`) the identity and motion columns. Frames without any
contact have no row; ``n_frames`` says how many frames the table covers, so that empty
frames are known.

Positions are in the sensor's own frame [mm] for every kind of array: a pad's taxel
``(r, c)`` sits at ``x = r * row_pitch_mm``, ``y = c * col_pitch_mm``, ``z = 0``; a point
set's and a finger's positions are points of the surface (``taxel_positions_mm``).
"""

from __future__ import annotations

import dataclasses
import functools
import math
from dataclasses import dataclass, field, fields
from typing import ClassVar

import numpy as np

from tactsense._signals import deferred_interrupts
from tactsense._validation import TactsenseInputError, check_frames
from tactsense.estimate.finger.deflection import Flag
from tactsense.geometry import tactel_to_surface

_INT_COLUMNS = ("frame", "contact", "id", "taxels", "flags")


@dataclass
class ContactTable:
    """Contacts of a batch of frames, one row per contact per frame (long format).

    Every column is a 1-D array of the same length (the number of contacts found);
    rows are sorted by ``frame``, then by ``contact``.
    """

    frame: np.ndarray
    """Index of the frame in the batch (or recording) [-], int64."""
    contact: np.ndarray
    """Rank of the contact within its frame, 0 for the largest force [-], int32."""
    x_mm: np.ndarray
    """Position in the sensor frame [mm]."""
    y_mm: np.ndarray
    """[mm]"""
    z_mm: np.ndarray
    """[mm] (0 on a pad)."""
    row: np.ndarray
    """Fractional row of the peak [taxel] on grids (pads, fingers); NaN on point sets."""
    col: np.ndarray
    """Fractional column of the peak [taxel]; NaN on point sets."""
    force_n: np.ndarray
    """Normal force carried by the contact [N]; NaN when a taxel of it saturated or
    without a force calibration where one is needed."""
    peak: np.ndarray
    """Interpolated peak deflection (capacitive) or strain (resistive) [-]."""
    major_mm: np.ndarray
    """Extent: square root of the larger eigenvalue of the second moment of the
    contact's readings about its centre [mm] (a standard deviation, not a radius)."""
    minor_mm: np.ndarray
    """Extent along the other principal axis [mm]."""
    orientation_deg: np.ndarray
    """Angle of the major axis from the x axis, in (-90, 90] [deg]."""
    taxels: np.ndarray
    """Taxels in the contact's region [-], int32."""
    flags: np.ndarray
    """:class:`~tactsense.estimate.deflection.Flag` bits of the contact, int64."""
    n_frames: int = 0
    """Frames the table covers (frames with no contact have no row)."""
    id: np.ndarray | None = None
    """Stable identity across frames (set by the tracker) [-], int64; None before."""
    vx_mm_s: np.ndarray | None = None
    """Velocity of the tracked contact [mm/s] (set by the tracker)."""
    vy_mm_s: np.ndarray | None = None
    """[mm/s]"""
    vz_mm_s: np.ndarray | None = None
    """[mm/s]"""
    slip: np.ndarray | None = None
    """True where the contact moves under a roughly constant force (tracker), bool."""
    area_mm2: np.ndarray | None = None
    """Area of the contact's taxels, each its cell of the grid (a pad's row pitch times
    column pitch; a finger's axial step times its arc) [mm^2]; NaN on point sets (set
    by :func:`find_contacts`; None in a table made otherwise)."""
    extra: dict = field(default_factory=dict)
    """Further per-row columns (name -> 1-D array), e.g. ``axial_mm`` on a finger."""

    UNITS: ClassVar[dict[str, str]] = {
        "frame": "1",
        "contact": "1",
        "id": "1",
        "x_mm": "mm",
        "y_mm": "mm",
        "z_mm": "mm",
        "row": "taxel",
        "col": "taxel",
        "force_n": "N",
        "peak": "1",
        "major_mm": "mm",
        "minor_mm": "mm",
        "orientation_deg": "deg",
        "taxels": "1",
        "area_mm2": "mm2",
        "flags": "bits",
        "vx_mm_s": "mm/s",
        "vy_mm_s": "mm/s",
        "vz_mm_s": "mm/s",
        "slip": "bool",
    }

    def __len__(self) -> int:
        return int(np.size(self.frame))

    def columns(self) -> dict[str, np.ndarray]:
        """Every column that is set, in a fixed order (``extra`` last)."""
        out = {}
        for f in fields(self):
            if f.name in ("n_frames", "extra"):
                continue
            value = getattr(self, f.name)
            if value is None and f.name == "area_mm2":  # a table made without it
                value = np.full(len(self.frame), np.nan)
            if value is not None:
                out[f.name] = np.asarray(value)
        out.update({k: np.asarray(v) for k, v in self.extra.items()})
        return out

    def per_frame_counts(self) -> np.ndarray:
        """Number of contacts in each of the ``n_frames`` frames [-]."""
        return np.bincount(np.asarray(self.frame, dtype=np.int64), minlength=self.n_frames)

    @classmethod
    def concatenate(cls, tables) -> ContactTable:
        """The tables of consecutive pieces as one: rows joined, ``n_frames`` summed
        (every piece's ``frame`` column is already numbered for the whole)."""
        tables = list(tables)
        if not tables:
            return cls.empty(0)
        kw = {}
        for f in fields(cls):
            if f.name in ("n_frames", "extra"):
                continue
            values = [getattr(t, f.name) for t in tables]
            kw[f.name] = None if any(v is None for v in values) else np.concatenate(values)
        extra = {
            key: np.concatenate([t.extra[key] for t in tables])
            for key in tables[0].extra
            if all(key in t.extra for t in tables)
        }
        return cls(**kw, n_frames=sum(t.n_frames for t in tables), extra=extra)

    @classmethod
    def empty(cls, n_frames: int = 0) -> ContactTable:
        """A table with no contact over ``n_frames`` frames."""
        kw = {}
        for f in fields(cls):
            if f.name in ("n_frames", "extra", "id", "vx_mm_s", "vy_mm_s", "vz_mm_s", "slip"):
                continue
            dtype = np.int64 if f.name in _INT_COLUMNS else float
            kw[f.name] = np.zeros(0, dtype=dtype)
        return cls(**kw, n_frames=n_frames)


# ---- finding the contacts of a batch of frames ---------------------------------------

SADDLE_RATIO = 0.8
"""Two maxima of a frame are two contacts only if the signal between them dips below
this share of the lower one (and by more than the contact threshold) [-]; otherwise the
lower is a bump on the same contact and the two regions are merged."""

NOISE_DIP = 3.0
"""... and only if that dip exceeds this many standard deviations of the difference of
two taxels' read noise (``NOISE_DIP * sqrt(2) * sigma``, sigma from the sensor's
``read_noise_counts``; :func:`signal_noise_variance`) [-]: a noisy plateau's bumps are
not contacts."""

RING_RATIO = 0.1
"""Maxima joined by ridges (saddles of at least this share of the lower one) into a
group of three or more are one contact [-]: a flat stamp on a layer reads its rim
(its corners highest), a punch its ring, each split into bumps by the taxels' gains;
two probes make two maxima, and stay two. 0 switches the rule off."""

WEAK_SHARE = 0.4
"""Taxels above this share of the threshold (but below it) that touch two regions join
them for :data:`RING_RATIO`'s ridges (a rim broken by a low-gain taxel) [-]; they stay
out of every contact's taxels."""

PAIR_RIDGE = 0.15
"""Two maxima farther apart than two point loads' tails reach (:func:`point_reach`) that
are joined by a ridge of at least this share of their summed heights are one contact
[-] (a cylinder lying across a pad reads its two ends highest; the tails of two loads
that far apart read less than 0.1 of each one's peak between them, 0.15 with a taxel's
gain half as high again)."""

METHODS = ("interpolate", "cop", "fit")
"""``interpolate``: the paper's method on the grid (Hann-windowed sinc over 3 taxels on
each side of the maximum, Newton to 0.01 taxel); ``cop``: the centre of pressure (the
signal-weighted mean position of the contact's taxels); ``fit`` (pads): the maximum-
likelihood position and force under white noise, fitting the layer's tabulated response
(:func:`pad_force_kernel`) to the taxels around the contact."""

BLOCK = 4096
"""Frames per block of the compiled passes."""


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
    :func:`~tactsense.estimate.deflection.deflection_from_counts`.

    Returns
    -------
    signal : ndarray, shape (N, rows, cols) [-]
    flags : ndarray of int64, shape (N,)
    """
    from tactsense.estimate._contacts_fast import prepare_signal

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


def find_contacts(
    frames,
    sensor,
    *,
    baseline=None,
    counts: bool = True,
    dead=None,
    threshold: float | None = None,
    calibration=None,
    max_contacts: int = 8,
    method: str = "interpolate",
    first_frame: int = 0,
    saddle: float = SADDLE_RATIO,
    frame_period_s: float | None = None,
    compensator=None,
    ring: float = RING_RATIO,
) -> ContactTable:
    """Every contact of every frame, on any kind of array.

    Each frame is segmented into contacts: the taxels above ``threshold`` are assigned
    to a local maximum by steepest ascent (a watershed on the taxel grid, or on the
    neighbour graph of a point set), and maxima separated by a shallow saddle (see
    :data:`SADDLE_RATIO`; or a dip within the read noise, :data:`NOISE_DIP`) are merged
    into one contact, and on a grid so are maxima joined by ridges into a group of three
    or more (a flat stamp's rim, :data:`RING_RATIO`). Each contact gets a position
    (``method``), the interpolated peak, its force, its extent (second moments of its
    taxels' signal) and its taxel count.

    Force: on a pad, the least-squares amplitude of the layer's response to the
    scenarios' probe (a 1.6-mm sphere, per newton; :func:`pad_force_kernel`) at the
    contact's position, fitted to the taxels around it (other contacts' taxels left
    out): the integral of the signal cannot give force, since an incompressible layer
    bonded to a rigid base has no net normal strain under a load (nu = 0.5). On the
    finger, the paper's integral (eq. 55) of the frame shared among the contacts in
    proportion to their summed deflection (one contact: exactly
    :func:`~tactsense.estimate.locate`'s force). On a point set, the amplitude of the
    response to a load at the nearest taxel.

    Parameters
    ----------
    frames : array_like, shape (N, rows, cols) or (rows, cols)
        A/D readings [counts] (``counts=True``) or the signal [-] (``counts=False``:
        fractional deflection for capacitive taxels, strain for resistive ones).
    sensor : SensorSpec, PadSpec or PointsSpec
    baseline : array_like, shape (rows, cols), or DriftBaseline
        Untouched readings [counts]; required with counts unless ``calibration``. A
        :class:`~tactsense.estimate.baseline.DriftBaseline` follows slow drift where taxels
        are untouched (it moves on with every frame given).
    dead : array_like of bool, shape (rows, cols), optional
        Taxels to ignore.
    threshold : float, optional
        Smallest signal that counts as contact [-]; :func:`default_threshold`.
    calibration : Calibration or ArrayCalibration, optional
        A finger's calibration (its baseline, gains, nonlinearity, creep), or a pad's or
        point set's (:class:`~tactsense.estimate.array_calibration.ArrayCalibration`:
        baseline, gains, dead taxels, force curve); ``baseline`` may then be a
        :class:`~tactsense.estimate.baseline.DriftBaseline` started from its baseline.
    max_contacts : int
        At most this many contacts per frame, the largest kept (1-64).
    method : {"interpolate", "cop"}
        How a contact's position is found (:data:`METHODS`).
    first_frame : int
        Added to the ``frame`` column (pieces of a longer recording).
    saddle : float
        :data:`SADDLE_RATIO`, in (0, 1].
    ring : float
        :data:`RING_RATIO`, in [0, 1) (0: off; grids only).

    Returns
    -------
    ContactTable
        One row per contact per frame; frames without contact have no row.
    """
    kind = getattr(sensor, "kind", None)
    if kind not in ("finger", "pad", "points"):
        raise TactsenseInputError(
            f"sensor must be a finger, pad or point set; got {type(sensor).__name__}"
        )
    if method not in METHODS:
        raise TactsenseInputError(f"method {method!r}: expected one of {', '.join(METHODS)}")
    if not (isinstance(max_contacts, int | np.integer) and 1 <= max_contacts <= 64):
        raise TactsenseInputError(f"max_contacts must be an integer in 1-64; got {max_contacts!r}")
    if not (isinstance(saddle, float | int) and 0.0 < saddle <= 1.0):
        raise TactsenseInputError(f"saddle must be in (0, 1]; got {saddle!r}")
    if not (isinstance(ring, float | int) and not isinstance(ring, bool) and 0.0 <= ring < 1.0):
        raise TactsenseInputError(f"ring must be in [0, 1) (0: off); got {ring!r}")
    if threshold is None:  # a weight curve's own, else the default
        threshold = getattr(calibration, "contact_threshold", None) or default_threshold(sensor)
    if not (isinstance(threshold, float | int) and math.isfinite(threshold) and threshold > 0):
        raise TactsenseInputError(f"threshold must be a positive number; got {threshold!r}")
    frames = check_frames(frames, sensor.shape)
    lead_2d = frames.ndim == 2
    frames = frames.reshape(-1, *sensor.shape)
    if len(frames) > BLOCK and (calibration is None or not hasattr(calibration, "apply")):
        # cache-sized pieces: the signal and the labels of a piece only (a calibration's
        # creep state runs through the whole batch, so it is applied in one piece)
        options = dict(baseline=baseline, counts=counts, dead=dead, threshold=threshold,
                       max_contacts=max_contacts, method=method, saddle=saddle,
                       calibration=calibration, ring=ring)  # fmt: skip
        return ContactTable.concatenate(
            find_contacts(frames[lo : lo + BLOCK], sensor, first_frame=first_frame + lo, **options)
            for lo in range(0, len(frames), BLOCK)
        )
    from tactsense.estimate.array_calibration import ArrayCalibration

    array_calibration = isinstance(calibration, ArrayCalibration)
    if calibration is not None and not counts:
        raise TactsenseInputError("a calibration applies to counts, not to the signal")
    if array_calibration:
        if kind == "finger":
            raise TactsenseInputError(
                f"{sensor.name!r} is a finger: calibrate it with 'tactsense calibrate' (a "
                "finger's calibration), not with an array calibration"
            )
        calibration.check_sensor(sensor)
        signal, flags = calibration.signal(frames, sensor, baseline=baseline)
    elif calibration is not None:
        if kind != "finger":
            raise TactsenseInputError(
                f"a finger's calibration does not apply to {sensor.name!r}, a {kind}: "
                "calibrate it with 'tactsense calibrate' on the array's own recording"
            )
        signal, flags = calibration.apply(
            frames, sensor, frame_period_s=frame_period_s, compensator=compensator
        )
        signal = np.ascontiguousarray(signal, dtype=np.float64)
    elif counts and hasattr(baseline, "signal"):  # a DriftBaseline: follows slow drift
        signal, flags = baseline.signal(frames, dead=dead)
    elif counts:
        if baseline is None:
            raise TactsenseInputError(
                "counts need a baseline (the untouched readings): pass baseline=, e.g. "
                "tactsense.estimate.baseline_from(frames), or counts=False for the signal"
            )
        signal, flags = signal_from_counts(frames, baseline, sensor, dead=dead)
    else:
        signal = np.array(frames, dtype=np.float64)
        bad = ~np.isfinite(signal)
        flags = np.where(bad.any(axis=(-2, -1)), int(Flag.NAN_INPUT), 0).astype(np.int64)
        signal[bad] = 0.0
        if dead is not None:
            signal[:, np.asarray(dead, dtype=bool)] = 0.0
    saturated = None
    if counts and (flags & int(Flag.SATURATED)).any():
        saturated = at_rail(frames, sensor)
    if kind == "points":
        table = _points_contacts(signal, sensor, threshold, saddle, max_contacts, method)
    else:
        table = _grid_contacts(signal, sensor, threshold, saddle, max_contacts, method, ring)
    table.flags |= flags[table.frame]
    if array_calibration:
        table.force_n, beyond = calibration.contact_force(table)
        table.flags[beyond] |= int(Flag.BEYOND_CALIBRATION)
    if saturated is not None:
        _mark_saturated(table, saturated, sensor)
    table.extra.pop("_labels", None)
    table.extra.pop("_root", None)
    table.extra.pop("_total", None)
    table.n_frames = 1 if lead_2d else len(signal)
    table.frame = table.frame + int(first_frame)
    return table


def _mark_saturated(table: ContactTable, saturated: np.ndarray, sensor) -> None:
    """No force for a contact holding a clipped reading (it is only a lower bound)."""
    labels = table.extra.pop("_labels", None)
    for k in np.flatnonzero(table.flags & int(Flag.SATURATED)):
        f = int(table.frame[k])
        mine = labels[f] == table.extra["_root"][k] if labels is not None else True
        if np.any(saturated[f] & mine):
            table.force_n[k] = np.nan
        else:
            table.flags[k] &= ~int(Flag.SATURATED)


def dip_floor(sensor, threshold: float) -> float:
    """Smallest dip from the lower maximum to the saddle that keeps two maxima apart
    [-]: the threshold, or :data:`NOISE_DIP` standard deviations of two taxels' read
    noise difference when that is more (pads and point sets)."""
    if getattr(sensor, "kind", None) not in ("pad", "points"):
        return float(threshold)
    noise = NOISE_DIP * math.sqrt(2.0 * signal_noise_variance(sensor))
    return max(float(threshold), noise)


@functools.lru_cache(maxsize=16)
def point_taxels(sensor) -> int:
    """Most taxels two point loads cover on a pad (inf otherwise): twice the most taxels
    reading 0.1 of a 1.6-mm probe's peak or more, over its sub-taxel positions [-]. A
    contact over more is placed at the centre of its signal, not at its peak."""
    if getattr(sensor, "kind", None) != "pad":
        return 1 << 30
    kernel, _, _ = pad_force_kernel(sensor)
    peak = kernel.max(axis=(2, 3), keepdims=True)
    return 2 * int((kernel >= 0.1 * peak).sum(axis=(2, 3)).max())


@functools.lru_cache(maxsize=16)
def point_reach(sensor) -> float:
    """Distance between two maxima beyond which two point loads cannot make a ridge
    between them [taxel] (pads; inf otherwise): twice the farthest a 1.6-mm probe's
    response reaches 0.1 of its peak (over its sub-taxel positions), plus twice the
    farthest a load lies from its peak taxel along a row or a column (half a taxel),
    plus one taxel."""
    if getattr(sensor, "kind", None) != "pad":
        return math.inf
    kernel, step, half = pad_force_kernel(sensor)
    reach = 0.0
    n = kernel.shape[0]
    offsets = np.arange(-half, half + 1, dtype=float)
    for a in range(n):
        for b in range(n):
            k = kernel[a, b]
            ii, jj = np.nonzero(k >= 0.1 * k.max())
            d = np.hypot(offsets[ii] - a * step, offsets[jj] - b * step)
            reach = max(reach, float(d.max()))
    return 2.0 * reach + 2.0


def _segment(
    signal, threshold, saddle, periodic, max_contacts, refine, floor=None, ring=0.0,
    far=math.inf, cover=1 << 30,
):  # fmt: skip
    """The compiled segmentation of (N, rows, cols) signal, block by block."""
    from tactsense.estimate._contacts_fast import segment_into
    from tactsense.estimate.finger.localize import MAX_ITERATIONS, TOLERANCE

    n, rows, cols = signal.shape
    k = max_contacts
    count = np.zeros(n, np.int64)
    peak_row = np.empty((n, k), np.int64)
    peak_col = np.empty((n, k), np.int64)
    out = {name: np.empty((n, k)) for name in ("row", "col", "value", "total", "rr", "cc", "rc")}
    taxels = np.empty((n, k), np.int64)
    converged = np.empty((n, k), np.bool_)
    root = np.empty((n, k), np.int64)
    wide = np.zeros((n, k), np.bool_)
    labels = np.empty((n, rows, cols), np.int64)
    with deferred_interrupts():
        for lo in range(0, n, BLOCK):
            hi = min(lo + BLOCK, n)
            segment_into(
                signal[lo:hi], float(threshold), float(saddle), bool(periodic), k, bool(refine),
                TOLERANCE, MAX_ITERATIONS, count[lo:hi], peak_row[lo:hi], peak_col[lo:hi],
                out["row"][lo:hi], out["col"][lo:hi], out["value"][lo:hi], out["total"][lo:hi],
                out["rr"][lo:hi], out["cc"][lo:hi], out["rc"][lo:hi], taxels[lo:hi],
                converged[lo:hi], root[lo:hi], labels[lo:hi],
                float(threshold if floor is None else floor), float(ring),
                float(WEAK_SHARE * threshold if ring > 0 else threshold), wide[lo:hi],
                float(far), PAIR_RIDGE, int(cover),
            )  # fmt: skip
    keep = np.arange(k)[np.newaxis, :] < count[:, np.newaxis]
    frame = np.broadcast_to(np.arange(n)[:, np.newaxis], (n, k))[keep]
    rank = np.broadcast_to(np.arange(k)[np.newaxis, :], (n, k))[keep]
    rows_out = {name: value[keep] for name, value in out.items()}
    rows_out.update(
        frame=frame.astype(np.int64),
        contact=rank.astype(np.int64),
        taxels=taxels[keep],
        converged=converged[keep],
        root=root[keep],
        peak_row=peak_row[keep],
        peak_col=peak_col[keep],
        wide=wide[keep],
    )
    return rows_out, labels


def _extent(rr, cc, rc, scale_r: float, scale_c: float):
    """Principal extents [mm] and the major axis' angle from the row axis [deg] of second
    moments given in taxels^2 (scaled by the pitches)."""
    a = rr * scale_r**2
    b = cc * scale_c**2
    c = rc * scale_r * scale_c
    mean = 0.5 * (a + b)
    half = np.sqrt((0.5 * (a - b)) ** 2 + c**2)
    major = np.sqrt(np.maximum(mean + half, 0.0))
    minor = np.sqrt(np.maximum(mean - half, 0.0))
    angle = 0.5 * np.degrees(np.arctan2(2.0 * c, a - b))
    angle = np.where(angle <= -90.0, angle + 180.0, angle)
    return major, minor, angle


def _grid_contacts(
    signal, sensor, threshold, saddle, max_contacts, method, ring=RING_RATIO
) -> ContactTable:
    kind = sensor.kind
    if method == "fit" and kind != "pad":
        raise TactsenseInputError(
            f"method 'fit' works on pads; {sensor.name!r} is a {sensor.kind_label}"
        )
    periodic = kind == "finger" and sensor.closes_circumference
    refine = method == "interpolate" and kind == "pad"
    floor = dip_floor(sensor, threshold)
    far = point_reach(sensor) if ring > 0 else math.inf
    cover = point_taxels(sensor) if ring > 0 else 1 << 30
    seg, labels = _segment(
        signal, threshold, saddle, periodic, max_contacts, refine, floor, ring, far, cover
    )
    n = len(seg["frame"])
    rows, cols = sensor.shape
    flags = np.zeros(n, np.int64)
    extra = {}
    if kind == "pad":
        g = sensor.grid
        row, col = seg["row"], seg["col"]
        x = row * g.row_pitch_mm
        y = col * g.col_pitch_mm
        z = np.zeros(n)
        peak = seg["value"]
        if method == "fit":
            row, col, force = pad_fit(signal, labels, seg, sensor)
            x = row * g.row_pitch_mm
            y = col * g.col_pitch_mm
        else:
            force = pad_contact_force(signal, labels, seg, sensor)
        pad_merged_force(signal, labels, seg, row, col, sensor, threshold, force)
        if seg["wide"].any():
            # an extended contact (a stamp's rim): no point load explains it; its summed
            # signal over a point load's summed response per newton
            force = np.where(seg["wide"], seg["total"] / _kernel_total(sensor), force)
        major, minor, angle = _extent(
            seg["rr"], seg["cc"], seg["rc"], g.row_pitch_mm, g.col_pitch_mm
        )
        cell_mm2 = g.row_pitch_mm * g.col_pitch_mm
        flags[(method == "interpolate") & ~seg["converged"]] |= int(Flag.NOT_CONVERGED)
        with np.errstate(invalid="ignore"):
            edge = (row < 0.5) | (row > rows - 1.5) | (col < 0.5) | (col > cols - 1.5)
        flags[edge] |= int(Flag.EDGE)
    else:
        row, col, axial, angle_deg, peak, force, finger_flags = _finger_positions(
            signal, labels, seg, sensor, threshold, method
        )
        flags |= finger_flags
        from tactsense.geometry import surface_to_xyz

        xyz = surface_to_xyz(sensor, np.nan_to_num(axial), np.nan_to_num(angle_deg))
        x, y, z = xyz[..., 0], xyz[..., 1], xyz[..., 2]
        step_axial = float(np.diff(tactel_to_surface(sensor, np.array([1.0, 2.0]), 0.0)[0])[0])
        step_arc = sensor.radius_mm * math.radians(sensor.array.spacing_angle_deg)
        major, minor, angle = _extent(seg["rr"], seg["cc"], seg["rc"], abs(step_axial), step_arc)
        cell_mm2 = abs(step_axial) * step_arc
        extra = {"axial_mm": axial, "angle_deg": angle_deg}
    extra["_root"] = seg["root"]
    extra["_labels"] = labels
    extra["_total"] = seg["total"]  # the contact's summed signal (a weight curve's input)
    table = ContactTable(
        frame=seg["frame"], contact=seg["contact"], x_mm=x, y_mm=y, z_mm=z, row=row, col=col,
        force_n=force, peak=peak, major_mm=major, minor_mm=minor, orientation_deg=angle,
        taxels=seg["taxels"], area_mm2=seg["taxels"] * cell_mm2, flags=flags,
        n_frames=len(signal), extra=extra,
    )  # fmt: skip
    return table


def _finger_positions(signal, labels, seg, sensor, threshold, method):
    """Each contact of a finger frame located by :func:`~tactsense.estimate.locate` on
    the frame with the other contacts' taxels zeroed (one contact: the frame as read,
    so that the numbers are locate's own)."""
    from tactsense.estimate.finger.force import force_per_deflection
    from tactsense.estimate.finger.locate import locate

    frame, root = seg["frame"], seg["root"]
    n = len(frame)
    if n == 0:
        empty = np.zeros(0)
        return empty, empty, empty, empty, empty, empty, np.zeros(0, np.int64)
    own = labels[frame]
    other = (own >= 0) & (own != root[:, np.newaxis, np.newaxis])
    masked = np.where(other, 0.0, signal[frame])
    est = locate(masked, sensor, counts=False, threshold=threshold)
    flags = est.flags & ~int(Flag.NO_CONTACT) & ~int(Flag.MULTIPLE)
    # the integral of the whole frame, shared in proportion to each contact's sum
    rows_sum = signal[:, 1:, :] if sensor.array.tip_row else signal
    frame_total = rows_sum.reshape(len(signal), -1).sum(axis=1)
    share = np.ones(n)
    counts_per_frame = np.bincount(frame, minlength=len(signal))
    many = counts_per_frame[frame] > 1
    if many.any():
        by_frame = np.bincount(frame, weights=seg["total"], minlength=len(signal))
        share[many] = seg["total"][many] / by_frame[frame[many]]
    force = np.where(many, force_per_deflection(sensor) * frame_total[frame] * share, est.force_n)
    force = np.where(np.isnan(est.force_n) & ~many, np.nan, force)
    # several contacts sharing a total of zero or less: no force (as one contact has none)
    withheld = many & (frame_total[frame] <= 0.0)
    force = np.where(withheld, np.nan, force)
    flags = np.where(withheld, flags | int(Flag.NEGATIVE_FORCE), flags)
    row, col = est.row, est.col
    axial, angle = est.axial_mm, est.angle_deg
    if method == "cop":
        row, col = seg["row"], seg["col"]  # the centre of the contact's deflection
        axial, angle = tactel_to_surface(sensor, row, col)
        flags &= ~int(Flag.NOT_CONVERGED)
    return row, col, axial, angle, est.peak_deflection, force, flags.astype(np.int64)


@functools.lru_cache(maxsize=16)
def pad_force_kernel(sensor, n_sub: int = 8, signed: bool = False):
    """The signal of the taxels around the scenarios' probe (1.6-mm sphere) per newton,
    for the probe at ``n_sub + 1`` sub-taxel offsets along each axis.

    ``signed``: a resistive taxel's strain before it is clipped at zero (a resistive
    taxel reads compression only), so that the responses to several loads add up (the
    tension beside one load cancels part of the compression under the next).

    Returns ``(kernel, step, half)``: ``kernel[a, b, i, j]`` is the signal [-/N] of the
    taxel at offset ``(i - half, j - half)`` from the taxel nearest below the probe, for
    the probe at ``(a, b) * step`` taxels from that taxel. Computed on a pad of the same
    pitch, electrodes, layer and transduction large enough for the window (the layer's
    response does not depend on where it is applied).
    """
    from tactsense.estimate._contacts_fast import HALF_WINDOW
    from tactsense.physics.indenters import SphereProbe
    from tactsense.physics.pad_response import pad_strain

    half = HALF_WINDOW
    size = 2 * half + 2
    grid = dataclasses.replace(sensor.grid, rows=size, cols=size)
    from tactsense.sensor.common import Flaws

    big = dataclasses.replace(sensor, grid=grid, flaws=Flaws())
    g = big.grid
    newtons = 0.49
    kernel = np.empty((n_sub + 1, n_sub + 1, 2 * half + 1, 2 * half + 1))
    step = 1.0 / n_sub
    for a in range(n_sub + 1):
        for b in range(n_sub + 1):
            probe = SphereProbe(
                (half + a * step) * g.row_pitch_mm, (half + b * step) * g.col_pitch_mm, newtons
            )
            strain = pad_strain(big, [probe])[: 2 * half + 1, : 2 * half + 1] / newtons
            if sensor.transduction.kind != "capacitive":
                kernel[a, b] = strain if signed else np.maximum(strain, 0.0)
            else:
                kernel[a, b] = sensor.transduction.strain_gain * strain
    return kernel, step, half


FIT_STEPS = 32
"""Sub-taxel positions per taxel of the model-based fit's table (1/32 taxel apart)."""


def pad_fit(signal, labels, seg, sensor):
    """Maximum-likelihood row, column [taxel] and force [N] of each contact of a pad
    (:func:`~tactsense.estimate._contacts_fast.fit_into`)."""
    from tactsense.estimate._contacts_fast import fit_into

    n = len(seg["frame"])
    row, col, force = np.empty(n), np.empty(n), np.empty(n)
    if n:
        kernel, _, half = pad_force_kernel(sensor, FIT_STEPS)
        with deferred_interrupts():
            fit_into(
                signal, labels, seg["frame"], seg["root"], seg["peak_row"], seg["peak_col"],
                kernel, half, row, col, force,
            )  # fmt: skip
    return row, col, force


def pad_contact_force(signal, labels, seg, sensor) -> np.ndarray:
    """Force of each contact of a pad [N] (see :func:`find_contacts`)."""
    from tactsense.estimate._contacts_fast import amplitude_fit

    n = len(seg["frame"])
    force = np.empty(n)
    if n == 0:
        return force
    kernel, step, half = pad_force_kernel(sensor)
    with deferred_interrupts():
        amplitude_fit(
            signal, labels, seg["frame"], seg["root"], seg["row"], seg["col"], kernel, step,
            half, force,
        )  # fmt: skip
    return force


MERGED_GAIN = 25.0
"""Two loads replace one in a contact's force only when they lower the residual by more
than this many times one taxel's noise variance (:func:`pad_merged_force`) [-]."""

MERGED_SPREAD = 0.2
"""A contact is looked at for two loads only when it is wider along its major axis
than one load would be by more than this [taxel^2] (two loads d apart add (d/2)^2)."""

MERGED_HALVES = np.arange(0.25, 2.51, 0.125)
"""Half-separations of the two loads tried along a contact's major axis [taxel]."""


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


@functools.lru_cache(maxsize=16)
def _kernel_total(sensor) -> float:
    """The summed signal of :func:`pad_force_kernel`'s window per newton, averaged over
    the load's sub-taxel positions [-/N]: an extended contact's force is its summed
    signal over this (``find_contacts``)."""
    kernel, _, _ = pad_force_kernel(sensor)
    return float(kernel.sum(axis=(2, 3)).mean())


@functools.lru_cache(maxsize=16)
def _kernel_max(sensor) -> np.ndarray:
    """The largest response of each taxel of :func:`pad_force_kernel`'s signed window
    over every tabulated load position [-/N] (for :func:`pad_merged_force`'s skip)."""
    kernel, _, _ = pad_force_kernel(sensor, FIT_STEPS, signed=True)
    return np.ascontiguousarray(kernel.max(axis=(0, 1)))


def pad_merged_force(signal, labels, seg, row, col, sensor, threshold, force) -> None:
    """A pad contact that holds two loads too close to part carries the force of both:
    ``force`` [N] is replaced in place by the two loads' summed amplitudes where two
    explain the contact's signal clearly better than one
    (:func:`~tactsense.estimate._contacts_fast.merged_force`, :data:`MERGED_GAIN`)."""
    from tactsense.estimate._contacts_fast import merged_force

    if len(force) == 0:
        return
    kernel, step, half = pad_force_kernel(sensor, FIT_STEPS, signed=True)
    noise_var = signal_noise_variance(sensor)
    # a resistive taxel's zero may hide tension: only the taxels clearly compressed
    # tell the loads' sum; a capacitive taxel reads both signs
    resistive = sensor.transduction.kind != "capacitive"
    floor = 3.0 * math.sqrt(noise_var) if resistive else -math.inf
    with deferred_interrupts():
        merged_force(
            signal, labels, seg["frame"], seg["root"], np.asarray(row, float),
            np.asarray(col, float), seg["rr"], seg["cc"], seg["rc"], kernel, step, half,
            MERGED_HALVES, noise_var, MERGED_GAIN, floor, float(threshold), MERGED_SPREAD,
            force, _kernel_max(sensor),
        )  # fmt: skip


# ---- point sets: no grid ----------------------------------------------------------------


@functools.lru_cache(maxsize=16)
def _points_geometry(sensor):
    """Positions [mm], normals, and each taxel's neighbours: the taxels closer than 1.5
    times the distance to its nearest one (at least its 3 nearest)."""
    positions = np.asarray(sensor.taxel_positions_mm(), dtype=float)
    normals = np.asarray(sensor.taxel_normals(), dtype=float)
    distance = np.linalg.norm(positions[:, None, :] - positions[None, :, :], axis=-1)
    np.fill_diagonal(distance, np.inf)
    nearest = distance.min(axis=1)
    neighbours = []
    for i in range(len(positions)):
        chosen = np.flatnonzero(distance[i] <= 1.5 * nearest[i])
        if len(chosen) < 3:
            chosen = np.argsort(distance[i])[: min(3, len(positions) - 1)]
        neighbours.append(chosen)
    # symmetric: a neighbour of a neighbour's list
    links = [set(map(int, n)) for n in neighbours]
    for i, n in enumerate(neighbours):
        for j in n:
            links[int(j)].add(i)
    return positions, normals, tuple(np.array(sorted(x), dtype=np.int64) for x in links)


@functools.lru_cache(maxsize=16)
def points_force_kernel(sensor):
    """The signal of every taxel per newton of the scenarios' probe (1.6-mm sphere)
    centred on each taxel, shape (N, N) [-/N]: row i for the probe on taxel i."""
    from tactsense.physics.indenters import SphereProbe
    from tactsense.physics.pad_response import points_strain

    newtons = 0.49
    n = sensor.shape[1]
    kernel = np.empty((n, n))
    for i in range(n):
        strain = points_strain(sensor, [SphereProbe(0.0, 0.0, newtons, at_taxel=i)])[0] / newtons
        if sensor.transduction.kind != "capacitive":
            kernel[i] = np.maximum(strain, 0.0)
        else:
            kernel[i] = sensor.transduction.strain_gain * strain
    return kernel


def _points_segment(s, threshold, saddle, neighbours, floor=None):
    """Labels (the maximum each taxel climbs to, -1 below the threshold) of one frame
    (``floor``: the smallest dip that keeps two maxima apart, :func:`dip_floor`)."""
    floor = threshold if floor is None else floor
    n = len(s)
    parent = np.full(n, -1)
    for i in range(n):
        if not s[i] > threshold:
            continue
        best, value = i, s[i]
        for j in neighbours[i]:
            if s[j] > value or (s[j] == value and j > best):
                best, value = int(j), s[j]
        parent[i] = best
    root = parent.copy()
    for i in np.flatnonzero(parent >= 0):
        q = i
        while parent[q] != q:
            q = parent[q]
        root[i] = q
    edges = []
    for i in np.flatnonzero(parent >= 0):
        for j in neighbours[i]:
            if j > i and parent[j] >= 0 and root[j] != root[i]:
                edges.append((min(s[i], s[j]), root[i], root[j]))
    final = {int(r): int(r) for r in np.unique(root[root >= 0])}

    def find(a):
        while final[a] != a:
            a = final[a]
        return a

    for value, a, b in sorted(edges, reverse=True):
        a, b = find(int(a)), find(int(b))
        if a == b:
            continue
        low = min(s[a], s[b])
        if value >= saddle * low or low - value < floor:
            if s[a] >= s[b]:
                final[b] = a
            else:
                final[a] = b
    return np.array([find(int(r)) if r >= 0 else -1 for r in root])


def _tangent_frame(normal):
    helper = np.array([0.0, 0.0, 1.0]) if abs(normal[2]) < 0.9 else np.array([1.0, 0.0, 0.0])
    t1 = np.cross(normal, helper)
    t1 /= np.linalg.norm(t1)
    return t1, np.cross(normal, t1)


def _points_peak(s, own, peak, positions, normals, neighbours):
    """Peak of a weighted quadratic fit in the tangent plane of the contact's largest
    taxel, over it and its neighbours: ``s = a + b u + c v + d u^2 + e v^2 + f u v``.

    A point set has no grid for a sinc interpolation; a quadratic through the largest
    reading and its neighbours is the smallest smooth surface with a peak (the
    two-dimensional form of the three-point parabola), and the fit needs no spacing.
    Returns the 3-D point, the fitted peak, and whether the fit had a peak within one
    neighbour distance (else the centre of the contact's signal is used)."""
    t1, t2 = _tangent_frame(normals[peak])
    around = np.concatenate([[peak], neighbours[peak]])
    around = around[own[around]]
    offsets = positions[around] - positions[peak]
    u, v = offsets @ t1, offsets @ t2
    values = s[around]
    if len(around) >= 6:
        design = np.column_stack([np.ones_like(u), u, v, u * u, v * v, u * v])
        coef, *_ = np.linalg.lstsq(design, values, rcond=None)
        _, b, c, d, e, f = coef
        hessian = np.array([[2 * d, f], [f, 2 * e]])
        if d < 0 and np.linalg.det(hessian) > 0:
            du, dv = np.linalg.solve(hessian, [-b, -c])
            reach = np.max(np.hypot(u, v))
            if math.hypot(du, dv) <= reach:
                value = coef @ [1.0, du, dv, du * du, dv * dv, du * dv]
                return positions[peak] + du * t1 + dv * t2, float(value), True
    weights = np.clip(values, 0.0, None)
    centre = weights @ positions[around] / weights.sum()
    return centre, float(s[peak]), False


def _points_contacts(signal, sensor, threshold, saddle, max_contacts, method) -> ContactTable:
    positions, normals, neighbours = _points_geometry(sensor)
    kernel = points_force_kernel(sensor)
    floor = dip_floor(sensor, threshold)
    rows = []
    labels = np.full(signal.shape, -1, dtype=np.int64)
    for f in range(len(signal)):
        s = signal[f, 0]
        label = _points_segment(s, threshold, saddle, neighbours, floor)
        labels[f, 0] = label
        found = []
        for r in np.unique(label[label >= 0]):
            own = label == r
            w = np.where(own, s, 0.0)
            total = w.sum()
            centre = w @ positions / total
            d = positions[own] - centre
            cov = (w[own, None] * d).T @ d / total
            t1, t2 = _tangent_frame(normals[r])
            plane = np.array([[t1 @ cov @ t1, t1 @ cov @ t2], [t2 @ cov @ t1, t2 @ cov @ t2]])
            major, minor, angle = _extent(plane[0, 0], plane[1, 1], plane[0, 1], 1.0, 1.0)
            ok = True
            if method == "interpolate":
                point, peak, ok = _points_peak(
                    s, own | (label < 0), r, positions, normals, neighbours
                )
            else:
                point, peak = centre, float(s[r])
            nearest = int(np.argmin(np.linalg.norm(positions - point, axis=1)))
            g = kernel[nearest]
            use = own | (label < 0)
            force = float(g[use] @ s[use] / (g[use] @ g[use]))
            flag = 0 if ok else int(Flag.NOT_CONVERGED)
            found.append(
                (total, f, point, peak, force, major, minor, angle, int(own.sum()), flag, r)
            )
        found.sort(key=lambda item: -item[0])
        for rank, item in enumerate(found[:max_contacts]):
            rows.append((rank, *item))
    if not rows:
        table = ContactTable.empty(len(signal))
        table.extra["_root"] = np.zeros(0, np.int64)
        table.extra["_labels"] = labels
        table.extra["_total"] = np.zeros(0)
        return table
    rank, total, frame, point, peak, force, major, minor, angle, taxels, flag, root = zip(
        *rows, strict=True
    )
    point = np.array(point)
    nan = np.full(len(rows), np.nan)
    return ContactTable(
        frame=np.array(frame, np.int64), contact=np.array(rank, np.int64), x_mm=point[:, 0],
        y_mm=point[:, 1], z_mm=point[:, 2], row=nan, col=nan.copy(), force_n=np.array(force),
        peak=np.array(peak), major_mm=np.array(major, float), minor_mm=np.array(minor, float),
        orientation_deg=np.array(angle, float), taxels=np.array(taxels, np.int64),
        area_mm2=np.full(len(rows), np.nan), flags=np.array(flag, np.int64), n_frames=len(signal),
        extra={"_root": np.array(root, np.int64), "_labels": labels,
               "_total": np.array(total, float)},
    )  # fmt: skip
