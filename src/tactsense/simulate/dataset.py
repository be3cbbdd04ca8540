"""Labelled episodes for data sets: presses, slides and grasps on a sensor's surface,
their frames and their ground truth.

An episode is ``frames`` frames at the sensor's scan rate of up to
:data:`MAX_CONTACTS` sphere contacts, drawn from the plan (:class:`DatasetPlan`) and the
episode's own random stream (``SeedSequence([seed, episode])``: an episode is the same
whichever worker makes it and in whatever order). Three tasks:

``press``
    One sphere pressed and lifted: the normal force rises (raised cosine) to a peak
    force, holds and falls; no shear, no slip.
``slide``
    One sphere pressed, then dragged across the surface: the tangential force (along the
    motion) grows while the contact sticks (slip 0) to the static friction limit
    ``mu_s * N``, then the contact slides at a constant speed with kinetic friction
    ``0.8 * mu_s * N`` (slip 1) until it is lifted.
``grasp``
    One to three contact patches of a held object share a grip force that rises, holds
    and falls; while held, a load along the surface (the object's weight as it is
    lifted) grows to a peak drawn on either side of the friction limit
    ``mu_s * grip``: where it reaches the limit the object slips (slip 1, every patch
    moving together at a constant speed, kinetic friction), else it is held (slip 0).

Labels per frame and contact slot (``(frames, MAX_CONTACTS)``): position [mm] in the
kind's surface coordinates (a pad: x along rows, y along columns), normal force [N],
tangential force [N] (x, y), sphere radius [mm], slip (1: the contact slides during the
frame, it is ``speed * period`` further on in the next) and the contact's id (its
slot, stable over the episode; -1 where the slot carries no force). The frames come
from :func:`tactsense.simulate.contact_frames.frames_from_contacts` with the plan's flaws
(its per-frame flaws; the memory flaws need a sequence and are not applied there).
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, field

import numpy as np

from tactsense._validation import TactsenseInputError
from tactsense.kinds import kind_of

MAX_CONTACTS = 3
"""Contact slots of an episode's labels: a grasp has one to three patches [-]."""

TASKS = ("press", "slide", "grasp")
"""The episode kinds, in the order of their ``task_index``."""

KINETIC_RATIO = 0.8
"""Kinetic over static friction coefficient of a sliding contact [-]."""


def _per_frame_flaws() -> tuple[str, ...]:
    from tactsense.physics.flaws import FLAW_NAMES
    from tactsense.simulate.contact_frames import LEFT_OUT_FLAWS

    return tuple(name for name in FLAW_NAMES if name not in LEFT_OUT_FLAWS)


PER_FRAME_FLAWS = _per_frame_flaws()
"""The flaws a data set's frames can have (``--flaws all``: all of these)."""


class DatasetError(TactsenseInputError):
    """A data set plan that cannot be generated."""


@dataclass(frozen=True)
class DatasetPlan:
    """What a data set holds: how many episodes of which tasks, their ranges, the seed.

    Forces are drawn uniformly in ``force_n`` (a press's or a slide's peak, a grasp's
    grip), radii in ``radius_mm``, slide and slip speeds in ``speed_mm_s``, static
    friction coefficients in ``friction``.
    """

    episodes: int = 100
    frames: int = 200
    tasks: tuple[str, ...] = TASKS
    force_n: tuple[float, float] = (0.05, 0.8)
    radius_mm: tuple[float, float] = (1.0, 3.0)
    speed_mm_s: tuple[float, float] = (2.0, 20.0)
    friction: tuple[float, float] = (0.3, 1.0)
    seed: int = 0
    flaws: str = "all"
    extra: dict = field(default_factory=dict)

    def __post_init__(self) -> None:
        if not 1 <= self.episodes <= 10**7:
            raise DatasetError(f"episodes must be 1 to 10,000,000; got {self.episodes}")
        if not 10 <= self.frames <= 10**6:
            raise DatasetError(f"frames per episode must be 10 to 1,000,000; got {self.frames}")
        tasks = tuple(self.tasks)
        unknown = [t for t in tasks if t not in TASKS]
        if not tasks or unknown:
            raise DatasetError(
                f"unknown task(s) {', '.join(unknown) or '(none given)'}; choose from "
                f"{', '.join(TASKS)}"
            )
        object.__setattr__(self, "tasks", tasks)
        from tactsense.simulate.contact_frames import named_left_out_flaws, resolve_flaws

        left_out = named_left_out_flaws(self.flaws)
        if left_out:
            raise DatasetError(
                f"flaw(s) {', '.join(left_out)} need the frame sequence (memory or jitter); "
                "a data set's frames take the per-frame flaws only "
                f"({', '.join(PER_FRAME_FLAWS)})"
            )
        resolve_flaws(self.flaws)  # an unknown name: a one-line error
        for name, low_limit, high_limit, unit in (
            ("force_n", 1e-4, 1e3, "N"),
            ("radius_mm", 0.05, 100.0, "mm"),
            ("speed_mm_s", 0.0, 1e4, "mm/s"),
            ("friction", 0.01, 10.0, "-"),
        ):
            low, high = (float(v) for v in getattr(self, name))
            if not (
                np.isfinite(low) and np.isfinite(high) and low_limit <= low <= high <= high_limit
            ):
                raise DatasetError(
                    f"{name} range ({low:g}, {high:g}) [{unit}]: need {low_limit:g} <= low <= "
                    f"high <= {high_limit:g}"
                )
            object.__setattr__(self, name, (low, high))

    @property
    def total_frames(self) -> int:
        return self.episodes * self.frames

    def to_dict(self) -> dict:
        return {k: (list(v) if isinstance(v, tuple) else v) for k, v in asdict(self).items()}


@dataclass
class Episode:
    """One episode: its frames [counts] and labels, ``(frames, ...)`` arrays."""

    index: int
    task: str
    frames: np.ndarray  # (T, rows, cols) [counts]
    position_mm: np.ndarray  # (T, K, 2) [mm]
    normal_force_n: np.ndarray  # (T, K) [N]
    tangential_force_n: np.ndarray  # (T, K, 2) [N]
    radius_mm: np.ndarray  # (T, K) [mm]
    slip: np.ndarray  # (T, K) uint8, 1 where the contact slides
    contact_id: np.ndarray  # (T, K) int32, -1 where the slot carries no force

    @property
    def present(self) -> np.ndarray:
        return self.normal_force_n > 0


def surface_area(spec) -> tuple[tuple[float, float], tuple[float, float]]:
    """Where contacts are placed: ``((x_low, x_high), (y_low, y_high))`` [mm], the outer
    taxels' centres (a contact's centre stays on the taxel grid)."""
    grid = kind_of(spec).surface_grid(spec)
    if grid is None:
        raise DatasetError(
            f"data sets place contacts on a taxel grid; the {kind_of(spec).label} "
            f"{spec.name!r} has none (use a pad)"
        )
    (row_pitch, rows), (col_pitch, cols) = grid
    return (0.0, (rows - 1) * row_pitch), (0.0, (cols - 1) * col_pitch)


def _envelope(t: np.ndarray, on: float, rise: float, off: float, fall: float) -> np.ndarray:
    """0 before ``on``, a raised-cosine rise over ``rise``, 1 until ``off``, a fall over
    ``fall`` [-] (times as fractions of the episode)."""
    up = np.clip((t - on) / rise, 0.0, 1.0)
    down = np.clip((t - off) / fall, 0.0, 1.0)
    return 0.5 * (1 - np.cos(np.pi * up)) * 0.5 * (1 + np.cos(np.pi * down))


def _fit_speed(start, direction, speed, duration, area) -> float:
    """The speed [mm/s] at most ``speed`` at which every point of ``start`` (k, 2)
    moving along ``direction`` for ``duration`` [s] stays in ``area``."""
    if duration <= 0:
        return 0.0
    room = np.inf
    for axis in range(2):
        d = direction[axis]
        low, high = area[axis]
        if d > 1e-12:
            room = min(room, float(np.min((high - start[:, axis]) / d)))
        elif d < -1e-12:
            room = min(room, float(np.min((low - start[:, axis]) / d)))
    return float(min(speed, max(0.0, room) / duration))


def _spread_points(rng, k: int, area, min_gap: float) -> np.ndarray:
    """``k`` points in ``area`` at least ``min_gap`` [mm] apart where it allows (a few
    tries, then the best draw)."""
    lows = np.array([area[0][0], area[1][0]])
    highs = np.array([area[0][1], area[1][1]])
    best, best_gap = None, -1.0
    for _ in range(20):
        points = rng.uniform(lows, highs, size=(k, 2))
        gap = (
            np.inf
            if k == 1
            else min(
                float(np.linalg.norm(points[i] - points[j])) for i in range(k) for j in range(i)
            )
        )
        if gap >= min_gap:
            return points
        if gap > best_gap:
            best, best_gap = points, gap
    return best


def episode_labels(spec, plan: DatasetPlan, index: int) -> Episode:
    """The labels of episode ``index`` (its frames empty): deterministic in
    ``(plan.seed, index)``."""
    rng = np.random.default_rng(np.random.SeedSequence([plan.seed, index, 0]))
    area = surface_area(spec)
    pitch = min(area[0][1] / max(1, spec.shape[0] - 1), area[1][1] / max(1, spec.shape[1] - 1))
    n = plan.frames
    period = spec.scan_period_s
    t = np.arange(n) / n  # fraction of the episode
    task = plan.tasks[int(rng.integers(len(plan.tasks)))]
    k = 1 if task != "grasp" else int(rng.integers(1, MAX_CONTACTS + 1))
    position = np.zeros((n, MAX_CONTACTS, 2))
    normal = np.zeros((n, MAX_CONTACTS))
    tangential = np.zeros((n, MAX_CONTACTS, 2))
    slip = np.zeros((n, MAX_CONTACTS), dtype=np.uint8)
    radius = np.full((n, MAX_CONTACTS), float(np.mean(plan.radius_mm)))
    radius[:, :k] = rng.uniform(*plan.radius_mm, size=k)
    on, rise = rng.uniform(0.02, 0.15), rng.uniform(0.08, 0.2)
    fall = rng.uniform(0.08, 0.15)
    off = rng.uniform(max(on + rise + 0.3, 0.6), 0.98 - fall)
    envelope = _envelope(t, on, rise, off, fall)
    force = rng.uniform(*plan.force_n)
    mu = rng.uniform(*plan.friction)
    start = _spread_points(rng, k, area, 2.0 * pitch)
    centre = np.array([np.mean(area[0]), np.mean(area[1])])
    towards = centre - start.mean(axis=0)  # a drag or a slip heads inwards, give or take 60 deg
    angle = np.arctan2(towards[1], towards[0]) + rng.uniform(-np.pi / 3, np.pi / 3)
    direction = np.array([np.cos(angle), np.sin(angle)])
    position[:, :k] = start
    if task == "press":
        normal[:, 0] = force * envelope
    elif task == "slide":
        normal[:, 0] = force * envelope
        held = on + rise  # loaded: the drag starts
        stick = rng.uniform(0.03, 0.08)  # fraction of the episode the contact sticks
        moving = (t >= held + stick) & (t < off)
        build = np.clip((t - held) / stick, 0.0, 1.0) * (t < held + stick) * (t >= held)
        duration = moving.sum() * period
        speed = _fit_speed(start, direction, rng.uniform(*plan.speed_mm_s), duration, area)
        speed = speed if moving.any() else 0.0
        travel = np.concatenate([[0.0], np.cumsum(moving[:-1])]) * period * speed
        position[:, 0] = start[0] + travel[:, None] * direction
        drag = np.where(moving, KINETIC_RATIO * mu, build * mu) * normal[:, 0]
        tangential[:, 0] = drag[:, None] * direction
        slip[:, 0] = moving & (speed > 0)
    else:  # grasp: the patches share the grip, the load along the surface grows
        weights = rng.dirichlet(np.ones(k)) * 0.6 + 0.4 / k  # no patch nearly unloaded
        grip = force * envelope
        normal[:, :k] = grip[:, None] * weights
        held = on + rise
        lift = rng.uniform(0.15, 0.3)  # the load's rise, fraction of the episode
        peak = rng.uniform(0.5, 1.5) * mu * force  # either side of the friction limit
        load = peak * np.clip((t - held) / lift, 0.0, 1.0) * (t >= held) * (envelope > 0)
        slipping = (load >= mu * grip) & (t >= held) & (t < off)
        duration = slipping.sum() * period
        speed = _fit_speed(start, direction, rng.uniform(*plan.speed_mm_s), duration, area)
        slid = np.concatenate([[0.0], np.cumsum(slipping[:-1])]) * period * speed
        position[:, :k] = start[None] + slid[:, None, None] * direction
        drag = np.where(slipping, KINETIC_RATIO * mu * grip, np.minimum(load, mu * grip))
        tangential[:, :k] = (drag[:, None] * weights)[..., None] * direction
        slip[:, :k] = (slipping & (speed > 0))[:, None]
    present = normal > 0
    contact_id = np.where(present, np.arange(MAX_CONTACTS, dtype=np.int32), -1).astype(np.int32)
    slip = (slip * present).astype(np.uint8)
    return Episode(
        index=index,
        task=task,
        frames=np.zeros((0, *spec.frame_shape)),
        position_mm=position,
        normal_force_n=normal,
        tangential_force_n=tangential * present[..., None],
        radius_mm=radius,
        slip=slip,
        contact_id=contact_id,
    )


def episode(spec, plan: DatasetPlan, index: int, *, gains=None) -> Episode:
    """Episode ``index`` with its frames [counts], ``(frames, *spec.frame_shape)``.

    The frames' random draws (noise) come from the episode's own stream, so the data set
    is the same however its episodes are shared out.
    """
    from tactsense.simulate.contact_frames import ContactBatch, frames_from_contacts

    labelled = episode_labels(spec, plan, index)
    shear = labelled.tangential_force_n if kind_of(spec).senses_shear else None
    contacts = ContactBatch(
        position_mm=labelled.position_mm,
        normal_force_n=labelled.normal_force_n,
        tangential_force_n=shear,  # a kind that takes normal pressure only: a label alone
        radius_mm=labelled.radius_mm,
        shape="sphere",
    )
    rng = np.random.default_rng(np.random.SeedSequence([plan.seed, index, 1]))
    frames = frames_from_contacts(spec, contacts, flaws=plan.flaws, rng=rng, gains=gains)
    labelled.frames = np.asarray(frames).reshape(plan.frames, *spec.frame_shape)
    return labelled


def episodes(spec, plan: DatasetPlan, first: int, count: int, *, gains=None) -> list[Episode]:
    """Episodes ``first`` to ``first + count`` (exclusive; one Dask task's share)."""
    stop = min(plan.episodes, first + count)
    return [episode(spec, plan, i, gains=gains) for i in range(first, stop)]
