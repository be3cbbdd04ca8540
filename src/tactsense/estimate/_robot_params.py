"""Each patch's settings for the hand's compiled call (:mod:`._robot_kernel`): the
single-array estimator's constants and tables, per kind."""

from __future__ import annotations

import math

import numpy as np

from tactsense.estimate import _robot_kernel as K
from tactsense.robot import RobotSkin


def _pad_parameters(sensor, threshold: float) -> tuple[np.ndarray, tuple]:
    from tactsense.estimate.contacts.pad import (
        FIT_STEPS,
        _kernel_max,
        _kernel_total,
        pad_force_kernel,
        point_reach,
        point_taxels,
    )
    from tactsense.estimate.contacts.segment import RING_RATIO, SADDLE_RATIO, WEAK_SHARE, dip_floor
    from tactsense.estimate.reading import signal_noise_variance

    noise_var = signal_noise_variance(sensor)
    resistive = sensor.transduction.kind != "capacitive"
    param = np.zeros(K.N_PARAM)
    param[K.P_THRESHOLD] = threshold
    param[K.P_SADDLE] = SADDLE_RATIO
    param[K.P_FLOOR] = dip_floor(sensor, threshold)
    param[K.P_RING] = RING_RATIO
    param[K.P_WEAK] = WEAK_SHARE * threshold
    param[K.P_FAR] = point_reach(sensor)
    param[K.P_COVER] = point_taxels(sensor)
    param[K.P_NOISE_VAR] = noise_var
    param[K.P_MERGE_FLOOR] = 3.0 * math.sqrt(noise_var) if resistive else -math.inf
    param[K.P_KERNEL_TOTAL] = _kernel_total(sensor)
    param[K.P_ROW_PITCH] = sensor.grid.row_pitch_mm
    param[K.P_COL_PITCH] = sensor.grid.col_pitch_mm
    amp, amp_step, _ = pad_force_kernel(sensor)
    sig, sig_step, _ = pad_force_kernel(sensor, FIT_STEPS, signed=True)
    return param, (amp, amp_step, sig, sig_step, _kernel_max(sensor))


def _points_parameters(sensor, threshold: float):
    from tactsense.estimate.contacts.points import _points_geometry, points_force_kernel
    from tactsense.estimate.contacts.segment import SADDLE_RATIO, dip_floor

    param = np.zeros(K.N_PARAM)
    param[K.P_THRESHOLD] = threshold
    param[K.P_SADDLE] = SADDLE_RATIO
    param[K.P_FLOOR] = dip_floor(sensor, threshold)
    positions, _, neighbours = _points_geometry(sensor)
    return param, positions, neighbours, np.asarray(points_force_kernel(sensor), float)


def locate_robot_reference(skin: RobotSkin, frames, baselines, *, joints=None, threshold=None):
    """The straightforward path: :func:`~tactsense.estimate.contacts.find_contacts` on
    each patch's frames (n, rows, cols), each contact placed with
    :meth:`~tactsense.robot.RobotSkin.link_poses` (a fixed pose) and the patch's origin;
    the same contact columns as :meth:`HandLocator.locate` (without the wrenches)."""
    from tactsense.estimate.contacts import default_threshold, find_contacts

    poses = skin.link_poses(joints)
    rows = {key: [] for key in ("frame", "patch", "link", "contact", "sensor", "link_xyz",
                                "base_xyz", "force_n")}  # fmt: skip
    for patch in skin.patches:
        value = threshold if threshold is not None else default_threshold(patch.sensor)
        table = find_contacts(
            frames[patch.name], patch.sensor, baseline=baselines[patch.name], threshold=value
        )
        point = np.column_stack([table.x_mm, table.y_mm, table.z_mm])
        origin = patch.origin.matrix()
        in_link = point @ origin[:3, :3].T + 1e3 * origin[:3, 3]
        pose = poses[patch.link]
        in_base = in_link @ pose[:3, :3].T + 1e3 * pose[:3, 3]
        rows["frame"].append(table.frame)
        rows["patch"].append(np.full(len(table.frame), patch.name, dtype=object))
        rows["link"].append(np.full(len(table.frame), patch.link, dtype=object))
        rows["contact"].append(table.contact)
        rows["sensor"].append(point)
        rows["link_xyz"].append(in_link)
        rows["base_xyz"].append(in_base)
        rows["force_n"].append(table.force_n)
    return {key: np.concatenate(value) for key, value in rows.items()}
