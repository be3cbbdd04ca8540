"""A robot recording's contacts, patch by patch, in each patch's link frame.

The exports of a robot recording (:mod:`tactsense.interop.robot_mcap`) take their
contacts from :func:`iter_patch_contacts`, the ONE place that estimates them: today the
single-array estimator of each patch (``locate``'s, as ``tactsense export`` uses for one
array: a pad's or a point set's contacts found and tracked, a finger's one contact per
frame), moved into the patch's link frame with the patch's ``origin``
(``p_link = R p_sensor + t``, ``n_link = R n_sensor``). A whole-robot estimator can
replace the body of this function without the exports changing.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass

import numpy as np

from tactsense.kinds import kind_of
from tactsense.robot import Patch, rotation_matrix


@dataclass(frozen=True)
class PatchPiece:
    """Consecutive frames of one patch and their contacts, in the patch's link frame.

    Attributes
    ----------
    start : int
        Index of the first frame in the patch's stream [-].
    frames : (n, rows, cols) ndarray
        The frames [counts], as recorded.
    time_s : (n,) ndarray
        Their times in the stream [s].
    frame : (k,) int ndarray
        Each contact's frame, an index into this piece (non-decreasing).
    names : list of k str
        Each contact's unique name: ``<patch>/<tracked id>`` (a finger's one contact:
        ``<patch>``).
    points_m : (k, 3) ndarray
        Contact points [m] in the link frame.
    normals : (k, 3) ndarray
        Outward unit normals of the skin there, in the link frame.
    force_n : (k,) ndarray
        Normal force [N], pressing inward (finite: contacts without a force are left out).
    """

    start: int
    frames: np.ndarray
    time_s: np.ndarray
    frame: np.ndarray
    names: list[str]
    points_m: np.ndarray
    normals: np.ndarray
    force_n: np.ndarray


def sensor_to_link(patch: Patch, points_m, normals) -> tuple[np.ndarray, np.ndarray]:
    """Points [m] and unit normals in a patch's sensor frame, moved into its link frame."""
    rotation = rotation_matrix(patch.origin.rpy_rad)
    points = np.asarray(points_m, dtype=float).reshape(-1, 3)
    normals = np.asarray(normals, dtype=float).reshape(-1, 3)
    return points @ rotation.T + np.asarray(patch.origin.xyz_m), normals @ rotation.T


def iter_patch_contacts(
    reader,
    patch: Patch,
    *,
    baseline_frames: int = 5,
    threshold: float | None = None,
    drift_s: float | None = 2.0,
) -> Iterator[PatchPiece]:
    """A patch's stream a piece at a time, with its contacts in the link frame.

    Parameters
    ----------
    reader : RecordingReader
        The patch's stream (open).
    patch : Patch
        The patch (its sensor, link and origin).
    baseline_frames : int
        Untouched frames at the start of the stream for the baseline [-].
    threshold : float, optional
        Contact threshold (the kind's default when None), as ``locate``'s.
    drift_s : float, optional
        Time constant of the baseline following drift [s] (pads and point sets).
    """
    sensor = reader.sensor
    if kind_of(sensor).multi_contact:  # every contact, tracked
        from tactsense.batch import iter_contacts

        positions = sensor.taxel_positions_mm()
        taxel_normals = sensor.taxel_normals()
        pieces = iter_contacts(
            reader, baseline_frames=baseline_frames, threshold=threshold, drift_s=drift_s
        )
        for start, n, time_s, table, _ in pieces:
            xyz = np.column_stack([table.x_mm, table.y_mm, table.z_mm])
            keep = np.isfinite(xyz).all(axis=1) & np.isfinite(table.force_n)
            xyz = xyz[keep]
            # the normal of the taxel nearest each contact (+z everywhere on a pad)
            nearest = (
                np.argmin(((xyz[:, None, :] - positions[None, :, :]) ** 2).sum(axis=-1), axis=1)
                if len(xyz)
                else np.zeros(0, int)
            )
            points, normals = sensor_to_link(patch, xyz * 1e-3, taxel_normals[nearest])
            yield PatchPiece(
                start=start,
                frames=reader.frames(start, start + n),
                time_s=np.asarray(time_s, float),
                frame=np.asarray(table.frame[keep], np.int64) - start,
                names=[f"{patch.name}/{i}" for i in table.id[keep]],
                points_m=points,
                normals=normals,
                force_n=np.asarray(table.force_n[keep], float),
            )
        return
    from tactsense.batch import iter_locate
    from tactsense.estimate import Flag
    from tactsense.estimate.finger.locate import CONTACT_THRESHOLD
    from tactsense.interop.ros import contact_geometry

    pieces = iter_locate(
        reader,
        baseline_frames=baseline_frames,
        threshold=CONTACT_THRESHOLD if threshold is None else threshold,
    )
    for start, time_s, est in pieces:
        touching = ((est.flags & int(Flag.NO_CONTACT)) == 0) & np.isfinite(est.force_n)
        chosen = np.flatnonzero(touching)
        points, normals = contact_geometry(
            sensor, np.asarray(est.axial_mm)[chosen], np.asarray(est.angle_deg)[chosen]
        )
        points, normals = sensor_to_link(patch, points, normals)
        yield PatchPiece(
            start=start,
            frames=reader.frames(start, start + len(time_s)),
            time_s=np.asarray(time_s, float),
            frame=chosen.astype(np.int64),
            names=[patch.name] * len(chosen),
            points_m=points,
            normals=normals,
            force_n=np.asarray(est.force_n, float)[chosen],
        )
