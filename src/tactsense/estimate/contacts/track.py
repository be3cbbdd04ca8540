"""Contacts over time: stable ids, births, deaths, merges and splits, velocity and slip.

:class:`ContactTracker` takes the :class:`~tactsense.estimate.contacts.ContactTable` of a
piece of a recording at a time and returns it with ``id``, ``vx_mm_s``, ``vy_mm_s``,
``vz_mm_s`` and ``slip`` set, and the events of the piece. Its state (the live tracks and
the next frame number) carries over from one piece to the next, so a recording tracked
in pieces gives the same result as tracked whole.

Each frame, the live tracks are matched to the frame's contacts by the assignment of
least total cost (the Hungarian method, compiled; the tests hold it to
:func:`scipy.optimize.linear_sum_assignment`)::

    cost(track, contact) = |predicted position - position| [mm]
                           + force_weight_mm_per_n * |force - track's force| [N]

where the prediction moves the track by its velocity over the frames since it was last
seen. A pair further apart than ``gate_mm`` is never matched.

Events (:class:`TrackEvent`):

- ``birth``: a contact matched to no track gets a new id;
- ``split``: ... and it lies within ``gate_mm`` of a track matched to another contact
  (the track is its ``parent``: ``others = (parent,)``);
- ``death``: a track unmatched for more than ``max_missing`` frames ends;
- ``merge``: ... and when it went unmatched its prediction lay within ``gate_mm`` of a
  contact matched to another track (``others = (survivor,)``); a merge ends the track
  at once.

A contact larger than the gate (a flat stamp) is matched within :data:`EXTENT_GATE`
times its extent along its major axis instead (``major_mm``): its centre jumps when its
rim first reads in part, and it keeps its id. Merges and splits are told within the
gate.

Velocity: the displacement since the track was last seen over the time elapsed,
smoothed exponentially (``smoothing`` is the weight of the new value). Slip: a contact
moving faster than ``slip_speed_mm_s`` while its force changes by less than
``slip_force_rate`` of itself per second (a contact that moves under a steady load: a
sliding finger, an object slipping out of a grasp; a press or release changes the force
quickly and is not slip).
"""

from __future__ import annotations

import dataclasses
import math
from typing import NamedTuple

import numpy as np

from tactsense._validation import TactsenseInputError
from tactsense.estimate.results import ContactTable

_FAR = 1e9
"""The cost of a forbidden pair [mm]: far above any real cost, small enough that sums
with it keep the real costs' digits."""
_KINDS = ("birth", "death", "merge", "split")


class TrackEvent(NamedTuple):
    """A change in the set of tracked contacts."""

    frame: int
    """Frame at which it happened [-]."""
    kind: str
    """``birth``, ``death``, ``merge`` or ``split``."""
    id: int
    """The id born, dead, merged away, or split off."""
    others: tuple
    """``merge``: (the id it merged into,); ``split``: (the parent id,); else ()."""


class _Track:
    __slots__ = ("dforce", "force", "id", "last", "missing", "near", "pos", "vel")

    def __init__(self, id_, pos, force, frame):
        self.id = id_
        self.pos = pos
        self.vel = np.zeros(3)
        self.force = force
        self.dforce = 0.0
        self.last = frame
        self.missing = 0
        self.near = -1  # id of the track whose contact it fell into when it went unseen


def assign(cost: np.ndarray, limit: float) -> list[tuple[int, int]]:
    """Pairs (row, col) of least total cost, none at or above ``limit`` (a row may stay
    unmatched rather than take such a pair): the compiled Hungarian method
    (:func:`~tactsense.estimate.contacts._fast.hungarian`)."""
    from tactsense.estimate.contacts._fast import hungarian

    cost = np.asarray(cost, dtype=float)
    if cost.shape[0] == 0 or cost.shape[1] == 0:
        return []
    capped = np.where(cost < limit, cost, _FAR)
    match = hungarian(capped, _FAR)
    return [(i, int(j)) for i, j in enumerate(match) if j >= 0]


EXTENT_GATE = 3.0
"""A contact larger than the gate is matched within this many of its extents along its
major axis (``major_mm``, a standard deviation) [-]: a flat stamp's centre (or the peak
of a rim that reaches the array's edge) moves by more than the gate from frame to
frame, and keeps its id. Three standard deviations of a uniform footprint are 0.87 of
its side."""


def _columns(table: ContactTable):
    """What both trackers read and write: positions (contiguous) [mm], forces (NaN as 0)
    [N], and the id, velocity and slip columns to fill."""
    n = len(table)
    pos = np.ascontiguousarray(np.column_stack([table.x_mm, table.y_mm, table.z_mm]), float)
    force = np.nan_to_num(np.asarray(table.force_n, dtype=float))
    return pos, force, np.full(n, -1, np.int64), np.zeros((n, 3)), np.zeros(n, bool)


def _reach(table: ContactTable, gate_mm: float) -> np.ndarray:
    """Each row's gate [mm]: ``gate_mm``, or :data:`EXTENT_GATE` times its extent."""
    major = np.nan_to_num(np.asarray(table.major_mm, dtype=float))
    return np.ascontiguousarray(np.maximum(gate_mm, EXTENT_GATE * major))


def _tracked(table: ContactTable, ids, vel, slip) -> ContactTable:
    """A copy of ``table`` with the tracker's columns set."""
    return dataclasses.replace(
        table, id=ids, vx_mm_s=vel[:, 0], vy_mm_s=vel[:, 1], vz_mm_s=vel[:, 2], slip=slip,
        extra=dict(table.extra),
    )  # fmt: skip


class ReferenceTracker:
    """The tracker's rules in plain Python with :func:`scipy.optimize.linear_sum_assignment`
    each frame: the readable reference of :class:`ContactTracker` (the tests hold the two
    equal; ``benchmarks/bench_contacts.py`` times both).

    Parameters
    ----------
    frame_period_s : float
        Time between frames [s].
    gate_mm : float
        Farthest a contact may lie from a track's prediction and still continue it [mm].
    force_weight_mm_per_n : float
        How much a force difference counts against a match [mm/N].
    max_missing : int
        Frames a track survives unseen before it dies (a contact that flickers below
        the threshold keeps its id).
    smoothing : float
        Weight of the newest velocity in its exponential average, in (0, 1].
    slip_speed_mm_s : float
        Speed above which a contact under a steady force slips [mm/s].
    slip_force_rate : float
        Largest relative force change per second of a steady force [1/s].
    """

    def __init__(
        self,
        frame_period_s: float,
        *,
        gate_mm: float = 5.0,
        force_weight_mm_per_n: float = 2.0,
        max_missing: int = 2,
        smoothing: float = 0.3,
        slip_speed_mm_s: float = 2.0,
        slip_force_rate: float = 0.5,
    ):
        checks = {
            "frame_period_s": frame_period_s,
            "gate_mm": gate_mm,
            "smoothing": smoothing,
            "slip_speed_mm_s": slip_speed_mm_s,
            "slip_force_rate": slip_force_rate,
        }
        for name, value in checks.items():
            if not (isinstance(value, int | float) and math.isfinite(value) and value > 0):
                raise TactsenseInputError(f"{name} must be a positive number; got {value!r}")
        if smoothing > 1:
            raise TactsenseInputError(f"smoothing must be in (0, 1]; got {smoothing!r}")
        if not (isinstance(force_weight_mm_per_n, int | float) and force_weight_mm_per_n >= 0):
            raise TactsenseInputError(
                f"force_weight_mm_per_n must be 0 or more; got {force_weight_mm_per_n!r}"
            )
        if not (isinstance(max_missing, int) and max_missing >= 0):
            raise TactsenseInputError(f"max_missing must be 0 or more; got {max_missing!r}")
        self.frame_period_s = float(frame_period_s)
        self.gate_mm = float(gate_mm)
        self.force_weight = float(force_weight_mm_per_n)
        self.max_missing = max_missing
        self.smoothing = float(smoothing)
        self.slip_speed = float(slip_speed_mm_s)
        self.slip_force_rate = float(slip_force_rate)
        self.next_frame = 0
        self.next_id = 0
        self.tracks: list[_Track] = []

    def update(
        self, table: ContactTable, first_frame: int | None = None
    ) -> tuple[ContactTable, list[TrackEvent]]:
        """Track the contacts of the next ``table.n_frames`` frames.

        Parameters
        ----------
        table : ContactTable
            Its ``frame`` column holds frame numbers from ``first_frame`` on.
        first_frame : int, optional
            The first frame the table covers; by default the frame after the previous
            piece (0 for the first).

        Returns
        -------
        table, events
            The table with ``id``, velocity and ``slip`` set (a copy), and the events.
        """
        start, end, frames = self._check(table, first_frame)
        pos, force, ids, vel, slip = _columns(table)
        reach = _reach(table, self.gate_mm)
        events: list[TrackEvent] = []
        bounds = np.searchsorted(frames, np.arange(start, end + 1))
        # frames without contacts only age the tracks: jump over runs of them
        busy = np.unique(frames)
        for f in busy:
            lo, hi = bounds[f - start], bounds[f - start + 1]
            self._frame(int(f), pos[lo:hi], force[lo:hi], ids[lo:hi], vel[lo:hi], slip[lo:hi],
                        events, reach[lo:hi])  # fmt: skip
        self._age_until(end, events)
        self.next_frame = end
        return _tracked(table, ids, vel, slip), events

    def _check(self, table, first_frame):
        """The first and end frame a table covers, and its frame column, checked."""
        if not isinstance(table, ContactTable):
            raise TactsenseInputError(f"expected a ContactTable; got {type(table).__name__}")
        start = self.next_frame if first_frame is None else int(first_frame)
        if start < self.next_frame:
            raise TactsenseInputError(
                f"frames go backwards: this piece starts at frame {start}, the tracker is "
                f"at frame {self.next_frame}"
            )
        frames = np.asarray(table.frame, dtype=np.int64)
        end = start + int(table.n_frames)
        if len(frames) and (frames.min() < start or frames.max() >= end):
            raise TactsenseInputError(
                f"the table's frames {frames.min()}-{frames.max()} lie outside the "
                f"{table.n_frames} frames from {start} that it says it covers (n_frames)"
            )
        if len(frames) and np.any(np.diff(frames) < 0):
            raise TactsenseInputError("the table's rows are not in frame order")
        return start, end, frames

    def _age_until(self, frame: int, events: list[TrackEvent]) -> None:
        """End the tracks unseen for more than max_missing frames before ``frame``."""
        alive = []
        for track in self.tracks:
            unseen = frame - 1 - track.last
            if unseen > self.max_missing:
                death = track.last + self.max_missing + 1
                events.append(TrackEvent(death, "death", track.id, ()))
            else:
                alive.append(track)
        self.tracks = alive

    def _frame(self, f, pos, force, ids, vel, slip, events, reach=None) -> None:
        self._age_until(f, events)
        tracks = self.tracks
        dt = self.frame_period_s
        n_t, n_c = len(tracks), len(pos)
        gate = np.full(n_c, self.gate_mm) if reach is None else reach
        if n_t:
            predicted = np.array([t.pos + t.vel * dt * (f - t.last) for t in tracks])
            distance = np.linalg.norm(predicted[:, None, :] - pos[None, :, :], axis=-1)
            cost = distance + self.force_weight * np.abs(
                np.array([t.force for t in tracks])[:, None] - force[None, :]
            )
            cost = np.where(distance <= gate[None, :], cost, _FAR)
            from scipy.optimize import linear_sum_assignment

            rows, cols = linear_sum_assignment(cost)
            pairs = [(int(i), int(j)) for i, j in zip(rows, cols, strict=True) if cost[i, j] < _FAR]
        else:
            distance = np.zeros((0, n_c))
            pairs = []
        matched_t = {i for i, _ in pairs}
        matched_c = {j for _, j in pairs}
        owner = {j: tracks[i] for i, j in pairs}
        for i, j in pairs:
            track = tracks[i]
            elapsed = dt * (f - track.last)
            step = (pos[j] - track.pos) / elapsed
            track.vel = self.smoothing * step + (1 - self.smoothing) * track.vel
            rate = (force[j] - track.force) / elapsed
            track.dforce = self.smoothing * rate + (1 - self.smoothing) * track.dforce
            track.pos, track.force, track.last, track.missing = pos[j], force[j], f, 0
            ids[j] = track.id
            vel[j] = track.vel
            speed = float(np.linalg.norm(track.vel))
            steady = abs(track.dforce) <= self.slip_force_rate * max(abs(track.force), 1e-12)
            slip[j] = speed > self.slip_speed and steady
        # tracks not seen: a merge when they fell into another track's contact
        survivors = []
        for i, track in enumerate(tracks):
            if i in matched_t:
                survivors.append(track)
                continue
            into = [j for j in matched_c if distance[i, j] <= self.gate_mm]
            if into:
                j = min(into, key=lambda j: distance[i, j])
                events.append(TrackEvent(f, "merge", track.id, (owner[j].id,)))
                continue
            survivors.append(track)
        self.tracks = survivors
        # contacts not matched: births, or splits off a track matched nearby
        for j in range(n_c):
            if j in matched_c:
                continue
            track = _Track(self.next_id, pos[j], force[j], f)
            self.next_id += 1
            near = [i for i in matched_t if distance[i, j] <= self.gate_mm]
            if near:
                parent = tracks[min(near, key=lambda i: distance[i, j])]
                events.append(TrackEvent(f, "split", track.id, (parent.id,)))
            else:
                events.append(TrackEvent(f, "birth", track.id, ()))
            self.tracks.append(track)
            ids[j] = track.id


class ContactTracker(ReferenceTracker):
    """Stable ids for the contacts of consecutive frames (compiled).

    The rules of the module's docstring; parameters as :class:`ReferenceTracker`. The
    state (the live tracks, the next id and frame) carries over from one
    :meth:`update` to the next.

    Examples
    --------
    >>> tracker = ContactTracker(0.01)                         # doctest: +SKIP
    >>> for start, frames in pieces:                           # doctest: +SKIP
    ...     table = find_contacts(frames, sensor, baseline=b, first_frame=start)
    ...     tracked, events = tracker.update(table)
    """

    def __init__(self, frame_period_s: float, **options):
        super().__init__(frame_period_s, **options)
        self._grow(64)
        self._alive = 0

    def _grow(self, capacity: int) -> None:
        old = getattr(self, "_t_id", None)
        n = 0 if old is None else self._alive
        arrays = {
            "_t_pos": np.zeros((capacity, 3)),
            "_t_vel": np.zeros((capacity, 3)),
            "_t_force": np.zeros(capacity),
            "_t_dforce": np.zeros(capacity),
            "_t_last": np.zeros(capacity, np.int64),
            "_t_id": np.zeros(capacity, np.int64),
        }
        for name, array in arrays.items():
            if old is not None:
                array[:n] = getattr(self, name)[:n]
            setattr(self, name, array)

    def update(
        self, table: ContactTable, first_frame: int | None = None
    ) -> tuple[ContactTable, list[TrackEvent]]:
        """Track the contacts of the next ``table.n_frames`` frames.

        Parameters
        ----------
        table : ContactTable
            Its ``frame`` column holds frame numbers from ``first_frame`` on.
        first_frame : int, optional
            The first frame the table covers; by default the frame after the previous
            piece (0 for the first).

        Returns
        -------
        table, events
            The table with ``id``, velocity and ``slip`` set (a copy), and the events.
        """
        from tactsense._signals import deferred_interrupts
        from tactsense.estimate.contacts._fast import track_into

        start, end, frames = self._check(table, first_frame)
        n = len(frames)
        pos, force, ids, vel, slip = _columns(table)
        most = int(np.bincount(frames - start).max(initial=0)) if n else 0
        need = self._alive + (self.max_missing + 2) * most + 8
        if need > len(self._t_id):
            self._grow(need)
        cap_ev = 2 * n + self._alive + 8
        ev = [np.empty(cap_ev, np.int64) for _ in range(4)]
        counters = np.array([self._alive, self.next_id, 0], np.int64)
        with deferred_interrupts():
            status = track_into(
                frames, pos, force, start, end, self._t_pos, self._t_vel, self._t_force,
                self._t_dforce, self._t_last, self._t_id, counters, self.frame_period_s,
                self.gate_mm, self.force_weight, self.max_missing, self.smoothing,
                self.slip_speed, self.slip_force_rate, _FAR, _reach(table, self.gate_mm), ids,
                vel, slip, *ev,
            )  # fmt: skip
        if status != 0:  # pragma: no cover - the capacities above are upper bounds
            raise RuntimeError("tracker capacity exceeded")
        self._alive, self.next_id = int(counters[0]), int(counters[1])
        self.next_frame = end
        k = int(counters[2])
        events = [
            TrackEvent(int(f), _KINDS[kind], int(i), () if other < 0 else (int(other),))
            for f, kind, i, other in zip(*(e[:k] for e in ev), strict=True)
        ]
        return _tracked(table, ids, vel, slip), events


def track(table: ContactTable, frame_period_s: float, **options):
    """Track a whole table at once: :meth:`ContactTracker.update` on a new tracker.

    Returns
    -------
    table, events
    """
    return ContactTracker(frame_period_s, **options).update(table, first_frame=0)
