"""A pad's calibration for the joint fit, made on a MuJoCo bench (issue 38 item 2).

``tactsense calibrate --loads`` fits its force curve to the force ``find_contacts``
gives by default (the probe's least-squares amplitude); applied to the joint fit's force
(``method="joint"``: each contact's size fitted with it) that curve maps the wrong
numbers. :func:`joint_force_calibration` keeps a calibration's gains, baseline and dead
taxels and fits the force curve to the joint fit's own force instead, against the
forces of presses whose load is known (a load cell's log; on the MuJoCo bench the
model's normal force sum at each frame's instant).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from tactsense._validation import TactsenseInputError
from tactsense.estimate.contacts.calibration import ArrayCalibration
from tactsense.estimate.contacts.find import find_contacts
from tactsense.estimate.contacts.weight_curve import force_curve

JOINT_CURVE_BINS = 8
"""Knots of the force curve: medians of the pairs in this many bins of equal count."""


def joint_forces(frames, sensor, calibration: ArrayCalibration) -> np.ndarray:
    """Each frame's summed contact force [N] from the joint fit on the calibrated signal
    (the calibration's gains, baseline and dead taxels; its force curve, if any, left
    out): the layer model's force, the input of the curve."""
    bare = replace(calibration, force_curve=None, curve_input="model_force_n")
    table = find_contacts(frames, sensor, calibration=bare, method="joint")
    total = np.zeros(len(frames))
    np.add.at(total, table.frame, np.nan_to_num(table.force_n))
    return total


def joint_force_calibration(
    calibration: ArrayCalibration,
    sensor,
    frames,
    force_n,
    *,
    min_force_n: float = 0.05,
    bins: int = JOINT_CURVE_BINS,
) -> ArrayCalibration:
    """``calibration`` (gains, baseline, dead taxels) with a force curve from the joint
    fit's force [N] to the known force of presses.

    Parameters
    ----------
    calibration : ArrayCalibration
        The pad's gains and baseline (``tactsense calibrate`` on a probe sweep).
    sensor : PadSpec
    frames : (N, rows, cols) array
        A recording of presses of several forces [counts].
    force_n : (N,) array
        The known normal force at each frame [N] (frames below ``min_force_n`` are not
        used).
    """
    force_n = np.asarray(force_n, dtype=float)
    if len(force_n) != len(frames):
        raise TactsenseInputError(f"{len(force_n)} forces for {len(frames)} frames of presses")
    if not min_force_n > 0:
        raise TactsenseInputError(f"min_force_n must be > 0 [N], got {min_force_n}")
    pressed = np.flatnonzero(force_n >= min_force_n)
    estimated = joint_forces(np.asarray(frames)[pressed], sensor, calibration)
    use = estimated > 0
    curve = force_curve(estimated[use], force_n[pressed][use], bins=bins)
    notes = {**calibration.notes, "joint_force_pairs": int(use.sum())}
    return replace(calibration, force_curve=curve, curve_input="model_force_n", notes=notes)
