"""Several contacts per frame, on any array: the long table every multi-contact tool shares.

A :class:`ContactTable` holds one row per contact per frame (a "long" table): the
segmentation (:func:`find_contacts`) fills the geometric columns, the tracker
(:mod:`tactsense.estimate.contacts.track`) the identity and motion columns. Frames without any
contact have no row; ``n_frames`` says how many frames the table covers, so that empty
frames are known.

Positions are in the sensor's own frame [mm] for every kind of array: a pad's taxel
``(r, c)`` sits at ``x = r * row_pitch_mm``, ``y = c * col_pitch_mm``, ``z = 0``; a point
set's and a finger's positions are points of the surface (``taxel_positions_mm``).
"""

from __future__ import annotations

import math

import numpy as np

from tactsense._validation import TactsenseInputError, check_frames
from tactsense.estimate._kind import kind_or_none
from tactsense.estimate.contacts.pad import (
    _kernel_total,
    pad_contact_force,
    pad_fit,
    pad_merged_force,
    point_reach,
    point_taxels,
)
from tactsense.estimate.contacts.points import _points_contacts
from tactsense.estimate.contacts.segment import (
    BLOCK,
    METHODS,
    RING_RATIO,
    SADDLE_RATIO,
    _extent,
    _segment,
    dip_floor,
)
from tactsense.estimate.reading import at_rail, default_threshold, signal_from_counts
from tactsense.estimate.results import ContactTable, Flag
from tactsense.geometry import tactel_to_surface
from tactsense.kinds import kind_of


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
    :func:`~tactsense.estimate.finger.locate`'s force). On a point set, the amplitude of the
    response to a load at the nearest taxel.

    Parameters
    ----------
    frames : array_like, shape (N, rows, cols) or (rows, cols)
        A/D readings [counts] (``counts=True``) or the signal [-] (``counts=False``:
        fractional deflection for capacitive taxels, strain for resistive ones).
    sensor : SensorSpec, PadSpec or PointsSpec
    baseline : array_like, shape (rows, cols), or DriftBaseline
        Untouched readings [counts]; required with counts unless ``calibration``. A
        :class:`~tactsense.estimate.contacts.baseline.DriftBaseline` follows slow drift where taxels
        are untouched (it moves on with every frame given).
    dead : array_like of bool, shape (rows, cols), optional
        Taxels to ignore.
    threshold : float, optional
        Smallest signal that counts as contact [-]; :func:`default_threshold`.
    calibration : Calibration or ArrayCalibration, optional
        A finger's calibration (its baseline, gains, nonlinearity, creep), or a pad's or
        point set's (:class:`~tactsense.estimate.contacts.array_calibration.ArrayCalibration`:
        baseline, gains, dead taxels, force curve); ``baseline`` may then be a
        :class:`~tactsense.estimate.contacts.baseline.DriftBaseline` started from its baseline.
    max_contacts : int
        At most this many contacts per frame, the largest kept (1-64).
    method : {"interpolate", "cop", "fit", "joint"}
        How a contact's position is found (:data:`METHODS`); ``"joint"`` (pads): every
        contact of a frame fitted jointly with its size, contacts added by a likelihood
        criterion, each with its standard errors from the Fisher matrix at the fit
        (extras ``x_sd_mm``, ``y_sd_mm`` [mm], ``force_sd_n`` [N]; NaN where the frame
        does not determine the contact) (docs/contacts.md).
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
    kind = kind_or_none(sensor)
    if kind is None:
        raise TactsenseInputError(
            f"sensor must be a finger, pad or point set; got {type(sensor).__name__}"
        )
    if method not in METHODS:
        raise TactsenseInputError(f"method {method!r}: expected one of {', '.join(METHODS)}")
    if method in ("fit", "joint") and not (kind.image_grid and kind.response_fit):
        raise TactsenseInputError(  # r10 trial: a point set took it silently
            f"method {method!r} works on pads; {sensor.name!r} is a {kind.label}"
        )
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
    from tactsense.estimate.contacts.calibration import ArrayCalibration

    array_calibration = isinstance(calibration, ArrayCalibration)
    if calibration is not None and not counts:
        raise TactsenseInputError("a calibration applies to counts, not to the signal")
    if array_calibration:
        if not kind.array_calibration:
            raise TactsenseInputError(
                f"{sensor.name!r} is a {kind.label}: calibrate it with 'tactsense calibrate' (a "
                "finger's calibration), not with an array calibration"
            )
        calibration.check_sensor(sensor)
        signal, flags = calibration.signal(frames, sensor, baseline=baseline)
    elif calibration is not None:
        if kind.array_calibration:
            raise TactsenseInputError(
                f"a finger's calibration does not apply to {sensor.name!r}, a {kind.name}: "
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
    if not kind.image_grid:
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


def _grid_contacts(
    signal, sensor, threshold, saddle, max_contacts, method, ring=RING_RATIO
) -> ContactTable:
    kind = kind_of(sensor)
    if method in ("fit", "joint") and not kind.response_fit:
        raise TactsenseInputError(
            f"method {method!r} works on pads; {sensor.name!r} is a {kind.label}"
        )
    periodic = kind.periodic(sensor)
    refine = method == "interpolate" and kind.response_fit
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
    if kind.multi_contact:  # an array's grid: positions from its pitches
        g = sensor.grid
        row, col = seg["row"], seg["col"]
        x = row * g.row_pitch_mm
        y = col * g.col_pitch_mm
        z = np.zeros(n)
        peak = seg["value"]
        if method in ("fit", "joint"):
            row, col, force = pad_fit(signal, labels, seg, sensor)
            model = kind.contact_model(sensor) if method == "joint" else None
            if model is not None:  # each contact's size; more contacts (r6-padfit)
                from tactsense.estimate.contacts._joint import fit_sizes
                from tactsense.estimate.contacts._joint_errors import standard_errors

                seg, row, col, force, radius, flat = fit_sizes(
                    signal, seg, row, col, force, sensor, model, max_contacts
                )
                extra["contact_radius_mm"], extra["flat_share"] = radius, flat
                sd = standard_errors(
                    signal, seg["frame"], row, col, force, radius, flat, sensor, model
                )
                extra["x_sd_mm"], extra["y_sd_mm"], extra["force_sd_n"] = sd.T
                n = len(seg["frame"])
                flags, z, peak = np.zeros(n, np.int64), np.zeros(n), seg["value"]
            x = row * g.row_pitch_mm
            y = col * g.col_pitch_mm
        else:
            force = pad_contact_force(signal, labels, seg, sensor)
        if "contact_radius_mm" not in extra:  # the joint fit sizes each contact itself
            pad_merged_force(signal, labels, seg, row, col, sensor, threshold, force)
        if seg["wide"].any() and "contact_radius_mm" not in extra:
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
    else:  # one contact per frame by its kind's estimator: the paper's locate, per contact
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
    """Each contact of a finger frame located by :func:`~tactsense.estimate.finger.locate` on
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
