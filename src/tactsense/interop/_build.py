"""What every importer shares: its error and the recording it builds from frames and
stamps. The importers (:mod:`tactsense.interop.importers`, :mod:`~tactsense.interop.
lerobot`, :mod:`~tactsense.interop.icub_grasp`) import it; it imports none of them."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from tactsense._validation import TactsenseInputError
from tactsense.sensor import SensorSpecError, load_sensor
from tactsense.sensor.common import SpecBase

UNIX_EPOCH_THRESHOLD_S = 1e9
"""Stamps at or after this [s] (September 2001) are read as Unix times (host clock)."""


class ImportError_(TactsenseInputError):
    """A source that cannot be imported (named, with what was expected)."""


def _sensor(sensor, source: Path, what: str) -> SpecBase:
    if sensor is None:
        raise ImportError_(f"{source}: {what} does not describe its sensor; pass --sensor")
    try:
        return load_sensor(sensor)
    except SensorSpecError as error:
        raise ImportError_(f"--sensor: {error}") from None


def _frames_array(values: list, sensor: SpecBase) -> np.ndarray:
    frames = np.asarray(values, dtype=np.float64).reshape(-1, *sensor.frame_shape)
    whole = np.all(np.isfinite(frames)) and np.all(frames == np.rint(frames))
    if whole and frames.size and frames.min() >= 0 and frames.max() <= 65535:
        return frames.astype(np.uint16)
    return frames


def build_recording(
    sensor: SpecBase,
    frames: list,
    stamps_s,
    *,
    source: str,
    description: str,
    losses: dict | None = None,
):
    """A :class:`~tactsense.io.recording.Recording` of imported frames and their stamps."""
    from tactsense.io.recording import Recording
    from tactsense.physics.transduction import sample_offsets

    stamps = np.asarray(stamps_s, dtype=np.float64)
    if len(frames) == 0:
        raise ImportError_(f"{source}: no frames to import")
    if not np.all(np.isfinite(stamps)):
        raise ImportError_(f"{source}: a time stamp is not a finite number")
    host = None
    times = stamps
    if stamps[0] >= UNIX_EPOCH_THRESHOLD_S:
        host, times = stamps, stamps - stamps[0]
    return Recording(
        frames=_frames_array(frames, sensor),
        time_s=times,
        sample_offset_s=sample_offsets(sensor),
        sensor=sensor,
        scenario={"description": description},
        host_time_s=host,
        losses=dict(losses or {}),
        source=source,
    )
