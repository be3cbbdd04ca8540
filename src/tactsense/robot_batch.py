"""A robot recording's contacts and wrenches, read block by block: the folder (or a
:class:`~tactsense.io.robot_recording.RobotRecording` in memory) through
:class:`~tactsense.estimate.robot.HandLocator`.

It reads recordings, so it sits above both :mod:`tactsense.io` and
:mod:`tactsense.estimate` (estimation takes arrays, never files).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping

import numpy as np

from tactsense._validation import TactsenseInputError
from tactsense.estimate._robot_joints import JointStates
from tactsense.estimate._robot_tables import RobotContacts
from tactsense.estimate.robot import HandLocator


class _Streams:
    """Each patch's frame times [s] and frames, from a robot recording in memory
    (:class:`~tactsense.io.robot_recording.RobotRecording`) or its folder (read block by
    block: only the times are read whole)."""

    def __init__(self, source):
        from tactsense.io.robot_recording import RobotRecording

        self._readers: dict = {}
        self.times: dict[str, np.ndarray] = {}
        if isinstance(source, RobotRecording):
            self.skin = source.skin
            self._memory = {k: v for k, v in source.streams.items() if len(v.frames)}
            self.times = {k: np.asarray(v.time_s, float) for k, v in self._memory.items()}
            return
        from tactsense.io import robot_recording as layout
        from tactsense.io.recording import RecordingReader

        self._memory = {}
        self.skin = layout.read_robot_skin(source)
        content = layout.read_manifest(source)
        clocks = [d.get("clock") for d in content.get("devices", {}).values()]
        aligned = getattr(layout, "aligned_times", None)  # a capture's host-aligned times
        use_aligned = aligned is not None and clocks and all(clocks)
        try:
            for name in content.get("streams", []):
                self.skin.patch(name)
                path = layout.stream_path(source, name)
                if not path.exists():
                    continue
                reader = RecordingReader(path)
                self._readers[name] = reader
                if reader.n_frames == 0:
                    continue
                times = aligned(source, name) if use_aligned else reader.time_s(0, reader.n_frames)
                self.times[name] = np.asarray(times, float)
        except BaseException:
            self.close()
            raise

    def frames(self, name: str, start: int, stop: int) -> np.ndarray:
        if name in self._memory:
            return np.asarray(self._memory[name].frames[start:stop])
        return np.asarray(self._readers[name].frames(start, stop))

    def close(self) -> None:
        for reader in self._readers.values():
            reader.close()
        self._readers = {}


def iter_robot_blocks(
    recording,
    *,
    joints: JointStates | Mapping[str, float] | None = None,
    baseline_frames: int = 5,
    threshold: float | None = None,
    max_contacts: int = 8,
    method: str = "interpolate",
    block_frames: int = 4096,
    progress: Callable[[int, int], None] | None = None,
    warnings: list[str] | None = None,
):
    """:func:`locate_robot_recording` block by block: yields a :class:`RobotContacts` per
    ``block_frames`` hand frames (memory bounded by the block, whatever the length; a
    folder's frames are read a block at a time). ``method``: a pad patch's estimator,
    ``"interpolate"`` or ``"joint"`` (:class:`HandLocator`)."""
    if not (isinstance(baseline_frames, int) and baseline_frames >= 1):
        raise TactsenseInputError(
            f"baseline_frames must be a positive integer; got {baseline_frames!r}"
        )
    if not (isinstance(block_frames, int) and block_frames >= 1):
        raise TactsenseInputError(f"block_frames must be a positive integer; got {block_frames!r}")
    streams = _Streams(recording)
    try:
        skin = streams.skin
        names = [p.name for p in skin.patches]
        baselines = {}
        for patch in skin.patches:
            if patch.name not in streams.times:
                baselines[patch.name] = np.full(patch.sensor.shape, np.nan)
                if warnings is not None:
                    warnings.append(f"patch {patch.name!r} has no frames: no contacts from it")
                continue
            first = streams.frames(patch.name, 0, baseline_frames).astype(float)
            baselines[patch.name] = np.nanmedian(first, axis=0)
        locator = HandLocator(
            skin, baselines, threshold=threshold, max_contacts=max_contacts, method=method
        )
        if isinstance(joints, Mapping):
            locator.joint_array(joints, 1)
        present = [name for name in names if name in streams.times]
        if not present:
            raise TactsenseInputError("the recording holds no frames of the skin's patches")
        lead = max(present, key=lambda name: len(streams.times[name]))
        times = streams.times[lead]
        n = len(times)
        previous = np.full(len(names), -1, np.int64)
        for lo in range(0, n, block_frames):
            hi = min(lo + block_frames, n)
            block_times = times[lo:hi]
            counts = np.empty((hi - lo, locator.n_taxels))
            own_time = np.zeros((hi - lo, len(names)))
            fresh = np.zeros((hi - lo, len(names)), np.bool_)
            for p, name in enumerate(names):
                off = locator._offset[p]
                size = skin.patches[p].n_taxels
                if name not in streams.times:
                    counts[:, off : off + size] = locator._baseline[off : off + size]
                    continue
                own = streams.times[name]
                index = np.searchsorted(own, block_times, side="right") - 1
                before = np.concatenate([[previous[p]], index[:-1]])
                fresh[:, p] = (index >= 0) & (index != before)
                previous[p] = index[-1]
                rows = np.maximum(index, 0)
                low, high = int(rows.min()), int(rows.max()) + 1
                frames = streams.frames(name, low, high).reshape(high - low, size)
                counts[:, off : off + size] = frames[rows - low]
                own_time[:, p] = own[rows]
            if isinstance(joints, JointStates):
                q = joints.at(block_times, locator.joint_names)
            else:
                q = locator.joint_array(joints, hi - lo)
            yield locator.locate(counts, q, fresh=fresh, time_s=block_times,
                                 patch_time_s=own_time, first_frame=lo)  # fmt: skip
            if progress is not None:
                progress(hi, n)
        if isinstance(joints, JointStates) and warnings is not None:
            warnings.extend(joints.coverage_warnings(times))
    finally:
        streams.close()


def locate_robot_recording(recording, **options) -> RobotContacts:
    """Contacts and wrenches of a whole robot recording, in memory
    (:class:`~tactsense.io.robot_recording.RobotRecording`) or its folder.

    Each patch's baseline is the median of its stream's first ``baseline_frames`` frames
    (untouched). ``joints``: a fixed pose (joint name -> position [rad or m]), a
    :class:`JointStates` interpolated to the hand frames' times, or None (all at 0).
    Times: the streams' ``time_s`` [s] (a captured folder whose devices all have a clock
    fit: their frames' times on the host clock, Unix time). Options as
    :func:`iter_robot_blocks`.
    """
    warnings: list[str] = []
    parts = list(iter_robot_blocks(recording, warnings=warnings, **options))
    if not parts:
        raise TactsenseInputError("the recording holds no frames of the skin's patches")
    result = RobotContacts.concatenate(parts)
    result.warnings.extend(warnings)
    return result


__all__ = ["iter_robot_blocks", "locate_robot_recording"]
