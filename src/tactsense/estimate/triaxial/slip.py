"""Slip of each tracked contact from its tangential/normal force ratio over time.

Cattaneo-Mindlin (Johnson 1985, section 7.2): a sphere pressed with ``P`` and loaded
tangentially with ``Q < mu P`` sticks over a central disc of radius
``c = a (1 - Q / (mu P))^(1/3)`` and slips on the annulus outside it (incipient slip,
spreading in from the edge as ``Q`` grows); at ``Q = mu P`` the stick disc vanishes and
the whole contact slides (gross slip), the tangential force staying at ``mu P``.

What the taxels show of it is the ratio ``Q / P`` a contact carries. With the friction
coefficient known (``friction``), the state follows from the ratio: ``stick`` below
:data:`PARTIAL_RATIO` (no tangential load worth the name; once in partial slip, below
:data:`STICK_RATIO`: a dead band), ``partial`` up to ``mu`` less a
margin, ``gross`` beyond it for :data:`CONFIRM` frames running (the onset dated to the
first frame of the ramp's line at ``mu``: below); the stick ratio ``c/a`` is
Cattaneo-Mindlin's. Without it, a
contact's gross slip is found where its ratio stops rising while it carries a tangential
load and the contact starts to move along its tangential force: the ratio has stayed
within :data:`FLAT` since a frame (the plateau at ``mu``) before which it rose by more than
:data:`RISE` a frame, and the contact has moved more than :data:`SLIDE_MM` along the
tangential force since the plateau began (a hold below ``mu``
is a plateau too, but nothing slides). The onset is dated back (below), and from then on
the contact's ``mu`` is the ratio there (the plateau's median). The detection itself
comes at least :data:`PLATEAU_FRAMES` frames after the onset it dates (the
``slip_detected_s`` column says when).

The onset's date (r9-mjslip2): the ratio climbs a ramp while the tangential load grows and
holds at ``mu`` once the contact slides. Called from the first frame within
:data:`MARGIN` of ``mu`` (or the plateau's knee), the onset comes early by the margin
over the ramp's slope (2-3 frames on the MuJoCo example: ``docs/mujoco.md``). At the
detection the straight line through the ramp's last :data:`RAMP_FRAMES` frames below
the plateau (:func:`ramp_crossing`, frames known then: causal) is crossed with ``mu``
(given, or the plateau's median when found) and the onset dated to the first frame at or
after the crossing, kept from the first frame near ``mu`` on; with ``mu`` given the call
waits (up to :data:`RAMP_WAIT` frames) while the line reaches ``mu`` after the present
frame. With fewer than :data:`RAMP_MIN_POINTS` ramp frames (a jerk into slip) the first
frame near ``mu``.
"""

from __future__ import annotations

import math
from collections import deque

import numpy as np

SLIP_STATES = ("stick", "partial", "gross")
"""The slip of a contact: no tangential load; incipient (partial) slip; gross slip."""

STICK_RATIO = 0.03
"""Tangential/normal force ratio below which a contact counts as sticking [-] (the
noise of the ratio on the twin is about 0.01)."""

# ---- a dead band between stick and partial; a stick row's c/a (r8-fixb8) ----
PARTIAL_RATIO = 0.05
"""Ratio from which a sticking contact counts as in partial slip [-]; once there, it
counts as sticking again only below :data:`STICK_RATIO`: a dead band (hysteresis), so the
ratio's noise under a press alone (up to 0.035 on the uncalibrated twin, straddling
:data:`STICK_RATIO`) does not flip a contact between ``stick`` and ``partial``. A
``stick`` row's stick ratio c/a is 1 (no tangential load: no slip annulus), whether
``mu`` is known or not."""
# ---- /r8-fixb8 ----

MARGIN = 0.04
"""A ratio within this share of ``mu`` of it counts as gross slip [-]."""

RISE = 0.004
"""Least rise of the ratio per frame [-/frame] over the :data:`RISE_FRAMES` frames
before a plateau."""

RISE_FRAMES = 6
"""Frames over which the rise before a plateau is measured [frames]."""

FLAT = 0.04
"""Largest spread of the ratio over a plateau [-] (about four times its noise on the
twin)."""

PLATEAU_FRAMES = 3
"""Least frames of a plateau that declare gross slip (the detection's delay) [frames]."""

SLIDE_MM = 0.06
"""Movement along the tangential force that tells a slide from a hold [mm]."""

CONFIRM = 2
"""Consecutive frames at ``mu`` that declare gross slip when ``mu`` is known (one frame
alone is a glitch: a lift's last frame under the layer's memory fits as any load)
[frames]."""

MIN_FORCE_N = 0.02
"""Normal force below which a contact's ratio means nothing (a lift's last frames, where
noise over a vanishing force reads as any ratio): it counts as unloaded [N]."""

HISTORY = 24
"""Frames of each contact's ratio kept [frames]."""

RAMP_FRAMES = 8
"""Frames of the ramp (the last ones below the plateau) its line is fitted to [frames]."""

RAMP_BAND = (0.3, 0.97)
"""Ratios, as shares of ``mu`` (or of the plateau's level), that count as the ramp [-]:
above a press's own, below the plateau's noise (the ratio's noise at ``mu`` is about
0.6 % of it on the calibrated twin)."""

RAMP_MIN_POINTS = 3
"""Least ramp frames that date an onset by the ramp's line [frames]."""


def ramp_crossing(ratios, frames, level: float) -> float | None:
    """Fractional frame where the ramp of ``ratios`` (a contact's tangential/normal
    ratio [-] at ``frames``) reaches ``level`` [-]: the least-squares line through the
    last :data:`RAMP_FRAMES` frames whose ratio is within :data:`RAMP_BAND` of
    ``level``, crossed with it. None where fewer than :data:`RAMP_MIN_POINTS` frames are
    on the ramp or the line does not rise by :data:`RISE` a frame."""
    r, f = np.asarray(ratios, dtype=float), np.asarray(frames, dtype=float)
    low, high = RAMP_BAND
    ramp = np.flatnonzero((r > low * level) & (r < high * level))[-RAMP_FRAMES:]
    if len(ramp) < RAMP_MIN_POINTS:
        return None
    slope, intercept = np.polyfit(f[ramp], r[ramp], 1)
    if not slope > RISE:
        return None
    return float((level - intercept) / slope)


RAMP_WAIT = 3
"""Frames a call of gross slip (``mu`` given) may wait, after the first frame near ``mu``,
for the ramp's line to reach ``mu`` [frames]."""


def _dated_onset(ratios, frames, level: float, first: int, last: int) -> int | None:
    """The onset frame: the first frame at or after :func:`ramp_crossing` at ``level``,
    kept from ``first`` (the first frame near the plateau) on; ``first`` without a ramp.
    None while the line reaches ``level`` after ``last`` (the present frame) and
    ``last`` is less than :data:`RAMP_WAIT` frames after ``first``: not yet."""
    crossing = ramp_crossing(ratios, frames, level)
    if crossing is None:
        return first
    onset = max(math.ceil(crossing - 1e-9), first)
    if onset > last:
        return None if last - first < RAMP_WAIT else last
    return int(onset)


class SlipMonitor:
    """Slip of every tracked contact, frame after frame (its state carries across pieces).

    Parameters
    ----------
    frame_period_s : float
        Time between frames [s].
    friction : float, optional
        Coefficient of friction between the skin and what touches it [-]; None: found
        per contact at its first gross slip.
    """

    def __init__(self, frame_period_s: float, friction: float | None = None):
        self.period = float(frame_period_s)
        self.friction = None if friction is None else float(friction)
        self._tracks: dict[int, dict] = {}

    def _track(self, ident: int) -> dict:
        track = self._tracks.get(ident)
        if track is None:
            track = {"ratio": deque(maxlen=HISTORY), "frames": deque(maxlen=HISTORY),
                     "xy": deque(maxlen=HISTORY),
                     "mu": self.friction, "gross": False, "partial": False,
                     "onset": math.nan,
                     "detected": math.nan}  # fmt: skip
            self._tracks[ident] = track
        return track

    def update(self, frame, ids, ratio, x_mm, y_mm, angle_deg, force_n) -> dict[str, np.ndarray]:
        """The slip columns of a tracked table's rows (in frame order): each row's
        frame, id, tangential/normal ratio [-], position [mm], tangential force's
        direction [deg] and normal force [N] (below :data:`MIN_FORCE_N` the contact
        counts as unloaded).

        Returns ``slip_state`` (one of :data:`SLIP_STATES`), ``stick_ratio`` (c/a [-]:
        1 in stick, 0 in gross slip, NaN in partial slip where ``mu`` is not known yet),
        ``friction`` (the ``mu`` used [-], NaN if unknown), ``slip_onset_s`` (time of the
        contact's latest gross-slip onset [s], dated back to its first frame at ``mu``,
        NaN before any), ``slip_detected_s`` (when that onset was detected [s]: the time
        of the first ``gross`` row). The state is causal (what was known at that frame,
        as ``live`` gives it): the rows from the onset up to its detection stay
        ``partial``.
        """
        n = len(ids)
        state = np.empty(n, dtype=object)
        stick, mu_out = np.full(n, np.nan), np.full(n, np.nan)
        onset, detected = np.full(n, np.nan), np.full(n, np.nan)
        for k in range(n):
            track = self._track(int(ids[k]))
            loaded = np.isfinite(ratio[k]) and force_n[k] >= MIN_FORCE_N
            rho = float(ratio[k]) if loaded else 0.0
            f = int(frame[k])
            if track["frames"] and f != track["frames"][-1] + 1:  # a gap: start over
                track["ratio"].clear()
                track["frames"].clear()
                track["xy"].clear()
            track["ratio"].append(rho)
            track["frames"].append(f)
            track["xy"].append((float(x_mm[k]), float(y_mm[k])))
            mu = track["mu"]
            if mu is None:
                start = self._plateau(track["ratio"], track["xy"], float(angle_deg[k]))
                if start is not None:
                    plateau = list(track["ratio"])[start:]
                    # the median: the knee's first frames may still be on the ramp
                    track["mu"] = mu = float(np.median(plateau))
                    track["gross"] = True
                    first = _dated_onset(list(track["ratio"])[:start],
                                         list(track["frames"])[:start], mu,
                                         track["frames"][start], f)  # fmt: skip
                    track["onset"] = (f if first is None else first) * self.period
                    track["detected"] = f * self.period
            else:
                at_mu = [r >= mu * (1.0 - MARGIN) for r in list(track["ratio"])[-CONFIRM:]]
                gross = len(at_mu) == CONFIRM and all(at_mu)
                if gross and not track["gross"]:  # dated by the ramp's line at mu
                    ratios = list(track["ratio"])
                    j = len(ratios) - CONFIRM
                    while j > 0 and ratios[j - 1] >= mu * (1.0 - MARGIN):
                        j -= 1  # the run near mu began before (a call that waited)
                    near = track["frames"][j]  # the history's frames run without a gap
                    first = _dated_onset(ratios, track["frames"], mu, near, f)
                    if first is None:
                        gross = False  # the ramp reaches mu after this frame: not yet
                    else:
                        track["onset"] = first * self.period
                        track["detected"] = f * self.period
                if not gross and track["gross"] and rho >= mu * (1.0 - 3 * MARGIN):
                    gross = True  # hysteresis: noise about mu does not end a slide
                track["gross"] = gross
            # r8-fixb8: partial from PARTIAL_RATIO up, stick again only below STICK_RATIO
            track["partial"] = rho >= (STICK_RATIO if track["partial"] else PARTIAL_RATIO)
            if track["gross"]:
                state[k] = "gross"
            elif track["partial"]:
                state[k] = "partial"
            else:
                state[k] = "stick"
                stick[k] = 1.0  # no tangential load: c = a (r8-fixb8)
            if mu is not None:
                mu_out[k] = mu
                if state[k] != "stick":
                    stick[k] = 0.0 if track["gross"] else (1.0 - min(rho / mu, 1.0)) ** (1 / 3)
            onset[k], detected[k] = track["onset"], track["detected"]
        return {"slip_state": state, "stick_ratio": stick, "friction": mu_out,
                "slip_onset_s": onset, "slip_detected_s": detected}  # fmt: skip

    @staticmethod
    def _plateau(ratios, xy, angle_deg: float) -> int | None:
        """Index in ``ratios`` where a plateau after a rise begins (the knee), along
        which the contact slid, or None."""
        r = np.asarray(ratios, dtype=float)
        if len(r) < RISE_FRAMES + PLATEAU_FRAMES + 1 or r[-1] < 2 * STICK_RATIO:
            return None
        knee = None
        for start in range(len(r) - 1 - PLATEAU_FRAMES, RISE_FRAMES - 1, -1):
            if np.ptp(r[start:]) > FLAT:
                break
            knee = start  # flat from here on: move the knee back while it stays flat
        if knee is None:
            return None
        if (r[knee] - r[knee - RISE_FRAMES]) / RISE_FRAMES <= RISE:
            return None  # no rise before it: a hold, not a slip
        along = np.array([math.cos(math.radians(angle_deg)), math.sin(math.radians(angle_deg))])
        moved = np.asarray(xy, dtype=float) @ along
        if moved[-1] - moved[knee] <= SLIDE_MM:
            return None
        return knee

    def forget(self, alive_ids) -> None:
        """Drop the tracks of contacts no longer alive."""
        alive = {int(i) for i in alive_ids}
        for ident in list(self._tracks):
            if ident not in alive:
                del self._tracks[ident]
