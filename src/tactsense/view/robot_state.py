"""What the hand's view holds between frames: every patch's latest signal and contacts,
each patch through its own single-array estimator (:class:`HandState`), and the message
that shows them. :mod:`tactsense.view.robot_estimator` holds the robot estimator's
variant."""

from __future__ import annotations

import math
from collections.abc import Mapping

import numpy as np

from tactsense.robot import RobotSkin
from tactsense.stream.reader import StreamFrame
from tactsense.view.locators import view_locator
from tactsense.view.robot_scene import contacts_by_link, contacts_in_base, link_poses_message


def _signal(locator) -> list | None:
    deflection = getattr(locator, "last_deflection", None)
    if deflection is None:
        return None
    values = np.nan_to_num(np.asarray(deflection, dtype=float).reshape(-1), nan=0.0)
    return np.round(values, 5).tolist()


class HandState:
    """The latest frame, signal and contacts of every patch, and the message that shows them.

    ``contacts_of`` turns one patch's estimate into contacts in the base frame
    (:func:`~tactsense.view.robot_scene.contacts_in_base` by default: the one place
    to swap in the robot estimator).
    """

    def __init__(
        self,
        skin: RobotSkin,
        joint_positions: Mapping[str, float] | None = None,
        *,
        baseline_frames: int = 5,
        threshold: float | None = None,
        frame_period_s: float | None = None,
        baselines: Mapping[str, np.ndarray] | None = None,
        contacts_of=contacts_in_base,
    ):
        self._start(skin, joint_positions)
        self.contacts_of = contacts_of
        baselines = baselines or {}
        self.locators = {
            patch.name: view_locator(
                patch.sensor,
                baseline_frames=baseline_frames,
                threshold=threshold,
                frame_period_s=frame_period_s,
                baseline=baselines.get(patch.name),
            )
            for patch in skin.patches
        }

    def _start(self, skin: RobotSkin, joint_positions) -> None:
        self.skin = skin
        self.joints = dict(joint_positions or {})
        self.poses = skin.link_poses(self.joints)
        self.signals: dict[str, list | None] = {p.name: None for p in skin.patches}
        self.contacts: dict[str, list[dict]] = {p.name: [] for p in skin.patches}
        self.frame_times: dict[str, float | None] = {p.name: None for p in skin.patches}
        self.frames_seen: dict[str, int] = {p.name: 0 for p in skin.patches}

    def set_joints(self, joint_positions: Mapping[str, float]) -> None:
        """Move the hand to a new joint state [rad or m] (contacts found from now on are
        placed with it)."""
        self.poses = self.skin.link_poses(joint_positions)
        self.joints = dict(joint_positions)

    estimator = "each patch's own (single-array, tracked)"
    """What the contacts come from, as the page says it."""

    def update_all(self, frames: Mapping[str, StreamFrame]) -> None:
        """The new frames of a tick (patch -> frame), each through its estimator."""
        for patch, frame in frames.items():
            self.update(patch, frame)

    def links_table(self, contacts: list[dict]) -> list[dict]:
        """The contacts per link (:func:`~tactsense.view.robot_scene.contacts_by_link`)."""
        return contacts_by_link(self.skin, contacts)

    def update(self, patch: str, frame: StreamFrame) -> None:
        """Run ``patch``'s estimator on ``frame`` and keep its signal and contacts."""
        estimate = self.locators[patch](frame)
        self.signals[patch] = _signal(self.locators[patch])
        self.contacts[patch] = self.contacts_of(self.skin, self.poses, patch, estimate)
        self.frame_times[patch] = float(frame.device_time_s)
        self.frames_seen[patch] += 1

    @property
    def signal_floor(self) -> float:
        """The smallest signal the page's colour scale tops at [-]: twice the largest
        contact threshold of the patches (noise alone stays dark)."""
        thresholds = [getattr(loc, "threshold", None) for loc in self.locators.values()]
        thresholds = [float(t) for t in thresholds if t is not None and math.isfinite(t)]
        return 2.0 * max(thresholds) if thresholds else 0.01

    def reset(self) -> None:
        """Forget the tracks (a jump in time)."""
        for locator in self.locators.values():
            locator.reset()

    def message(self, serial: int, time_s: float, extra: dict | None = None) -> dict:
        contacts = [c for p in self.skin.patches for c in self.contacts[p.name]]
        message = {
            "type": "robot_frame",
            "serial": serial,
            "time_s": round(float(time_s), 6),
            "signals": self.signals,
            "frame_times_s": self.frame_times,
            "contacts": contacts,
            "links": self.links_table(contacts),
            "frame_counts": self.frames_seen,
            "estimator": self.estimator,
            "joints": {name: round(float(v), 9) for name, v in self.joints.items()},
            "link_poses": link_poses_message(self.poses),
        }
        if extra:
            message.update(extra)
        return message
