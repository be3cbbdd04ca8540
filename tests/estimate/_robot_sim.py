"""Simulated hand frames for the robot estimator's tests and benchmark (tests may
simulate; the estimator never does)."""

from __future__ import annotations

import numpy as np

from tactsense.kinds import kind_of
from tactsense.simulate import ContactBatch, frames_from_contacts


def patch_frames(patch, n, rng, *, touched=0.6, max_contacts=2, force_n=(0.3, 1.5)):
    """(n, rows, cols) counts of one patch under random sphere contacts (some frames
    untouched), its rest frames' median as baseline, and the contacts (n, k, 2) [mm],
    (n, k) [N]."""
    sensor = patch.sensor
    rows, cols = sensor.shape
    positions = np.asarray(sensor.taxel_positions_mm(), float)
    k = max_contacts
    pos = np.zeros((n, k, 2))
    force = np.zeros((n, k))
    lo, hi = positions[:, :2].min(axis=0), positions[:, :2].max(axis=0)
    for f in range(n):
        if rng.random() > touched:
            continue
        m = rng.integers(1, k + 1) if kind_of(sensor).image_grid else 1
        for j in range(m):
            pos[f, j] = rng.uniform(lo + 0.2 * (hi - lo), hi - 0.2 * (hi - lo))
            force[f, j] = rng.uniform(*force_n)
    frames = frames_from_contacts(sensor, ContactBatch(pos, force), rng=rng)
    rest = frames_from_contacts(
        sensor, ContactBatch(np.zeros((5, 1, 2)), np.zeros((5, 1))), rng=rng
    )
    baseline = np.median(rest, axis=0).reshape(rows, cols)
    return frames.reshape(n, rows, cols), baseline, pos, force


def hand_frames(skin, n, seed=0, **options):
    """Per patch (frames, baseline, positions, forces) of ``n`` hand frames."""
    rng = np.random.default_rng(seed)
    return {p.name: patch_frames(p, n, rng, **options) for p in skin.patches}


def write_pressed_recording(path, skin, *, frames: int = 30, period_s: float = 0.01, seed=0):
    """A robot recording (folder) of ``skin``: every patch untouched for its first 5
    frames, then its first patch pressed at the middle of its taxels by 1 N."""
    from tactsense.io._layout import Recording
    from tactsense.io.robot_recording import RobotRecording, write_robot_recording

    rng = np.random.default_rng(seed)
    streams = {}
    for index, patch in enumerate(skin.patches):
        force = np.zeros((frames, 1))
        position = np.zeros((frames, 1, 2))
        if index == 0:
            force[5:] = 1.0
            position[:] = np.asarray(patch.sensor.taxel_positions_mm())[:, :2].mean(axis=0)
        counts = frames_from_contacts(patch.sensor, ContactBatch(position, force), rng=rng)
        streams[patch.name] = Recording(
            frames=counts.reshape(frames, *patch.sensor.shape),
            time_s=np.arange(frames) * period_s,
            sample_offset_s=np.zeros(patch.sensor.shape),
            sensor=patch.sensor,
        )
    return write_robot_recording(path, RobotRecording(skin=skin, streams=streams))
