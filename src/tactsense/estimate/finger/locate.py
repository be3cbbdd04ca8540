"""One call from frames to contacts: position, peak deflection, force, skew, flags."""

from __future__ import annotations

from dataclasses import fields
from pathlib import Path

import numpy as np

from tactsense._signals import deferred_interrupts
from tactsense._validation import TactsenseInputError, check_frames
from tactsense.estimate._kind import kind_or_none
from tactsense.estimate.finger._fast import locate_into, place_tip_gap, prepare_frames
from tactsense.estimate.finger.force import force_per_deflection
from tactsense.estimate.finger.localize import MAX_ITERATIONS, MAX_STEP, TOLERANCE
from tactsense.estimate.output import EstimatesWriter
from tactsense.estimate.results import Estimates, Flag
from tactsense.geometry import tactel_to_surface
from tactsense.sensor import SensorSpec

CONTACT_THRESHOLD = 0.005  # fractional deflection: 10 counts at 2000, about 5 g on the probe


def locate(
    frames,
    sensor: SensorSpec,
    *,
    baseline=None,
    counts: bool = True,
    dead=None,
    threshold: float = CONTACT_THRESHOLD,
    second_contact: float = 0.3,
    calibration=None,
    frame_period_s: float | None = None,
    compensator=None,
    workers: int = 1,
) -> Estimates:
    """Locate the contact in every frame of a batch.

    Parameters
    ----------
    frames : array_like, shape (..., rows, cols)
        A/D readings [counts] (``counts=True``, the default) or fractional
        deflections [-] (``counts=False``).
    sensor : SensorSpec
        The finger the frames come from.
    baseline : array_like, shape (rows, cols)
        Undeflected readings [counts]; required with counts (see
        :func:`~tactsense.estimate.finger.deflection.baseline_from`).
    dead : array_like of bool, shape (rows, cols), optional
        Tactels to ignore.
    threshold : float
        Smallest peak tactel deflection that counts as a contact [-].
    second_contact : float
        A separate local maximum larger than this share of the largest sets
        the MULTIPLE flag [-].
    calibration : Calibration, optional
        Applied to counts before estimation (its baseline replaces
        ``baseline``; gains, nonlinearity, excluded tactels, and creep
        compensation when ``frame_period_s`` is given for frames in time order).
    workers : int
        Threads for the compiled passes (the frames are split among them; the
        kernels release the GIL). 1 (the default) runs in the calling thread.
    compensator : CreepCompensator, optional
        With ``calibration``: the creep state carried from the previous piece of the
        same recording (:meth:`Calibration.compensator`), for chunked processing.

    Returns
    -------
    Estimates
        Positions, force and skew per frame; NaN and NO_CONTACT where no
        tactel passes the threshold. Frames with unusable tactels are
        processed with those tactels ignored, and flagged.
    """
    kind = kind_or_none(sensor)
    if kind is not None and kind.multi_contact:
        raise TactsenseInputError(
            f"this works on fingers; {sensor.name!r} is a {kind.label}: its contacts come from "
            "'tactsense locate' (the long table), 'live', 'view' and the export to MCAP "
            "(tactsense.estimate.find_contacts)"
        )
    if kind is None or not kind.describes(sensor):  # the finger's description
        raise TactsenseInputError(f"sensor must be a SensorSpec; got {type(sensor).__name__}")
    frames = check_frames(frames, sensor.shape)
    if calibration is not None and not counts:
        raise TactsenseInputError("a calibration applies to counts, not to deflections")
    if workers < 1:
        raise TactsenseInputError(f"workers must be at least 1; got {workers}")
    if calibration is None and counts:
        if baseline is None:
            raise TactsenseInputError(
                "counts need a baseline (the untouched readings): pass baseline=, e.g. "
                "tactsense.estimate.baseline_from(frames), or counts=False for deflections"
            )
        baseline = check_frames(baseline, sensor.shape, "baseline").astype(float)
        if baseline.ndim != 2:
            raise TactsenseInputError(
                f"baseline has shape {baseline.shape}; expected {sensor.shape}"
            )
        unusable = ~np.isfinite(baseline) | (baseline <= 0)
        if dead is not None:
            unusable = unusable | np.asarray(dead, dtype=bool)
        lead = frames.shape[:-2]
        # counts as recorded (uint16, or float with NaN): no float64 copy of the input
        source = _as_kernel_input(frames).reshape(-1, *sensor.shape)
        shared = (
            np.where(unusable, 1.0, baseline),
            unusable,
            float(2**sensor.electronics.adc_bits - 1),
            int(Flag.NAN_INPUT),
            int(Flag.SATURATED),
            int(Flag.DEAD_TACTEL),
        )
        geometry = (
            sensor.closes_circumference,
            1 if sensor.array.tip_row else 0,
            TOLERANCE,
            MAX_ITERATIONS,
            MAX_STEP,
        )

        n = source.shape[0]
        flags = np.empty(n, np.int64)
        touched = np.empty(n, np.bool_)
        outputs = _kernel_outputs(n)

        def block(lo: int, hi: int) -> None:
            # eq. 4 and Newton on one cache-sized block: the deflection of BLOCK frames
            # is made and used while it is hot, never for the whole recording; the
            # results go straight into the recording's outputs
            deflection, flags[lo:hi], peak = prepare_frames(source[lo:hi], *shared)
            touched[lo:hi] = peak >= threshold
            locate_into(deflection, touched[lo:hi], *geometry, *(a[lo:hi] for a in outputs))
            if sensor.array.tip_row:  # a pass of its own: the Newton kernel as it was
                place_tip_gap(deflection, sensor.closes_circumference, *_row_col(outputs, lo, hi))

        _for_blocks(block, n, workers)
        row, col, value, iterations, converged, summed, skew, second = outputs
        periodic = sensor.closes_circumference
        rows, cols = sensor.shape
        flags[~touched] |= int(Flag.NO_CONTACT)
    else:
        if calibration is not None:
            deflection, flags = calibration.apply(
                frames, sensor, frame_period_s=frame_period_s, compensator=compensator
            )
        else:
            deflection = np.asarray(frames, dtype=float)
            bad = ~np.isfinite(deflection)
            flags = np.where(bad.any(axis=(-2, -1)), int(Flag.NAN_INPUT), 0).astype(np.int64)
            deflection = np.where(bad, 0.0, deflection)
            if dead is not None:
                deflection = np.where(np.asarray(dead, bool), 0.0, deflection)
        lead = deflection.shape[:-2]
        rows, cols = sensor.shape
        flat = np.ascontiguousarray(deflection.reshape(-1, rows, cols), dtype=np.float64)
        flags = flags.reshape(-1).copy()
        periodic = sensor.closes_circumference
        touched = flat.reshape(flat.shape[0], -1).max(axis=1) >= threshold
        flags[~touched] |= int(Flag.NO_CONTACT)
        geometry = (periodic, 1 if sensor.array.tip_row else 0, TOLERANCE, MAX_ITERATIONS, MAX_STEP)
        outputs = _kernel_outputs(flat.shape[0])

        def flat_block(lo: int, hi: int) -> None:
            locate_into(flat[lo:hi], touched[lo:hi], *geometry, *(a[lo:hi] for a in outputs))
            if sensor.array.tip_row:
                place_tip_gap(flat[lo:hi], periodic, *_row_col(outputs, lo, hi))

        _for_blocks(flat_block, flat.shape[0], workers)
        row, col, value, iterations, converged, summed, skew, second = outputs
    force = force_per_deflection(sensor) * summed
    # a clipped reading understates its tactel's deflection, so the sum is only a lower
    # bound: no number rather than a wrong one (the position is kept, flagged)
    force[(flags & int(Flag.SATURATED)) != 0] = np.nan
    # more tension than compression around a contact: no force rather than a negative one
    negative = touched & (summed <= 0.0)
    flags[negative] |= int(Flag.NEGATIVE_FORCE)
    force[negative] = np.nan
    flags[touched & ~converged] |= int(Flag.NOT_CONVERGED)
    with np.errstate(invalid="ignore"):
        edge = (row < 0.5) | (row > rows - 1.5)
        if not periodic:
            edge |= (col < 0.5) | (col > cols - 1.5)
        flags[touched & edge] |= int(Flag.EDGE)
        if sensor.array.tip_row:
            flags[touched & (row < 1.0)] |= int(Flag.TIP)
    flags[touched & (second >= second_contact)] |= int(Flag.MULTIPLE)
    axial, angle = tactel_to_surface(sensor, np.nan_to_num(row), np.nan_to_num(col))
    axial = np.where(touched, axial, np.nan)
    angle = np.where(touched, angle, np.nan)
    shaped = [
        a.reshape(lead)
        for a in (row, col, axial, angle, value, force, skew, iterations, converged, flags)
    ]
    return Estimates(*shaped)


def _as_kernel_input(frames: np.ndarray) -> np.ndarray:
    """Frames in a type the compiled pass takes without copying (uint16, int, float64)."""
    if frames.dtype in (np.uint16, np.int32, np.int64, np.float64):
        return np.ascontiguousarray(frames)
    return np.ascontiguousarray(frames, dtype=np.float64)


BLOCK = 4096
"""Frames per block of the compiled passes: the deflection of a block (2 MB for 8 x 8)
stays in cache between the two passes."""


def _kernel_outputs(n: int) -> tuple[np.ndarray, ...]:
    """The per-frame arrays :func:`locate_into` fills: row, col, value, iterations,
    converged, summed, skew, second."""
    return (
        *(np.empty(n) for _ in range(3)),
        np.empty(n, np.int64),
        np.empty(n, np.bool_),
        *(np.empty(n) for _ in range(3)),
    )


def _row_col(outputs, lo: int, hi: int) -> tuple[np.ndarray, np.ndarray]:
    """The row and column slices of :func:`_kernel_outputs` for frames ``lo:hi``."""
    return outputs[0][lo:hi], outputs[1][lo:hi]


def _for_blocks(work, n: int, workers: int) -> None:
    """``work(lo, hi)`` over consecutive blocks of ``n`` frames, on ``workers`` threads
    (each block writes its own slice of the outputs).

    A Ctrl-C is held back meanwhile and raised once the blocks are done
    (:mod:`tactsense._signals`: a Ctrl-C inside compiled code can crash the interpreter).
    """
    spans = [(lo, min(lo + BLOCK, n)) for lo in range(0, n, BLOCK)] or [(0, 0)]
    with deferred_interrupts():
        if workers == 1 or len(spans) == 1:
            for lo, hi in spans:
                work(lo, hi)
        else:
            from concurrent.futures import ThreadPoolExecutor

            with ThreadPoolExecutor(max_workers=workers) as pool:
                list(pool.map(lambda span: work(*span), spans))


def write_estimates_csv(
    path: str | Path, estimates: Estimates, time_s=None, *, overwrite: bool = False
) -> Path:
    """Write one row per frame, units in the column names (full precision)."""

    path = Path(path)
    if path.exists() and not overwrite:
        raise FileExistsError(f"{path} exists; pass --force to replace it")
    times = np.full(len(estimates), np.nan) if time_s is None else np.ravel(time_s)
    flat = Estimates(*(np.ravel(getattr(estimates, f.name)) for f in fields(Estimates)))
    with EstimatesWriter(path, format="csv") as out:
        out.write(0, times, flat)
    return path
