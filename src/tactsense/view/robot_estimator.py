"""The hand's view with the robot estimator: every patch's contacts and every link's
wrench from :class:`~tactsense.estimate.robot.HandLocator`, one compiled call a display
tick for all the patches with a new frame.

The robot estimator places the contacts of pads and point sets with a fixed baseline per
patch; a skin holding another kind, or a recording missing a patch's stream (no
baseline), is shown with each patch's own estimator instead
(:class:`~tactsense.view.robot_state.HandState`): :func:`hand_state` chooses.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from tactsense._validation import TactsenseInputError
from tactsense.robot import RobotSkin
from tactsense.stream.reader import StreamFrame
from tactsense.view.locators import DEFLECTION
from tactsense.view.robot_scene import contacts_by_link
from tactsense.view.robot_state import HandState


def _column(rows: Mapping[str, np.ndarray], names, i: int) -> list:
    return [round(float(rows[name][i]), 4) for name in names]


class HandEstimatorState(HandState):
    """:class:`~tactsense.view.robot_state.HandState` whose contacts and wrenches come from
    the robot estimator (:class:`~tactsense.estimate.robot.HandLocator`).

    Parameters
    ----------
    skin : RobotSkin
    joint_positions : mapping, optional
        The joint state [rad or m].
    baselines : mapping of patch -> (rows, cols) array
        Every patch's untouched readings [counts].
    threshold : float, optional
        Smallest signal that counts as contact [-]; default each sensor's.
    """

    estimator = "the robot estimator (estimate.robot.HandLocator: one call a tick)"

    def __init__(
        self,
        skin: RobotSkin,
        joint_positions: Mapping[str, float] | None = None,
        *,
        baselines: Mapping[str, np.ndarray],
        threshold: float | None = None,
    ):
        from tactsense.estimate.contacts import default_threshold
        from tactsense.estimate.robot import HandLocator

        self._start(skin, joint_positions)
        self.hand = HandLocator(skin, baselines, threshold=threshold)
        self.baselines = {name: np.asarray(b, dtype=float) for name, b in baselines.items()}
        thresholds = [threshold] if threshold is not None else [
            default_threshold(p.sensor) for p in skin.patches
        ]  # fmt: skip
        self._floor = 2.0 * float(max(thresholds))
        self._wrenches: dict[str, dict] = {}

    @property
    def signal_floor(self) -> float:
        """Twice the largest contact threshold of the patches [-] (noise stays dark)."""
        return self._floor

    def update(self, patch: str, frame: StreamFrame) -> None:
        self.update_all({patch: frame})

    def update_all(self, frames: Mapping[str, StreamFrame]) -> None:
        """One compiled call for every patch with a new frame; the others' wrenches held."""
        if not frames:
            return
        counts = {}
        for patch, frame in frames.items():
            sensor = self.skin.patch(patch).sensor
            counts[patch] = np.asarray(frame.counts, dtype=float)
            signal = DEFLECTION[sensor.transduction.kind](
                counts[patch], self.baselines[patch], sensor
            )
            values = np.nan_to_num(np.asarray(signal, dtype=float).reshape(-1), nan=0.0)
            self.signals[patch] = np.round(values, 5).tolist()
            self.frame_times[patch] = float(frame.device_time_s)
            self.frames_seen[patch] += 1
        found = self.hand.update(counts, self.joints or None)
        rows = found.contacts
        for patch in frames:
            self.contacts[patch] = []
        for i in range(len(rows["patch"])):
            force = float(rows["force_n"][i])
            self.contacts[rows["patch"][i]].append(
                {
                    "patch": rows["patch"][i],
                    "link": rows["link"][i],
                    "id": int(rows["contact"][i]),
                    "position_mm": _column(rows, ("x_base_mm", "y_base_mm", "z_base_mm"), i),
                    "position_link_mm": _column(rows, ("x_link_mm", "y_link_mm", "z_link_mm"), i),
                    "normal": [
                        round(float(rows[n][i]), 6) for n in ("nx_base", "ny_base", "nz_base")
                    ],
                    "force_n": round(force, 6),
                    "force_vector_n": [
                        round(float(rows[n][i]), 6) for n in ("fx_base_n", "fy_base_n", "fz_base_n")
                    ],
                }
            )
        w = found.wrenches
        self._wrenches = {
            w["link"][i]: {
                "force_link_n": [round(float(w[f"force_{a}_n"][i]), 6) for a in "xyz"],
                "torque_link_n_mm": [round(float(w[f"torque_{a}_n_mm"][i]), 6) for a in "xyz"],
            }
            for i in range(len(w["link"]))
            if w["what"][i] == "link"
        }

    def links_table(self, contacts: list[dict]) -> list[dict]:
        """The contacts per link, with each link's wrench (force [N] and torque about the
        link's origin [N mm], in the link's frame) from the robot estimator."""
        rows = contacts_by_link(self.skin, contacts)
        for row in rows:
            row.update(self._wrenches.get(row["link"], {}))
        return rows

    def reset(self) -> None:
        """Forget the held wrenches (a jump in time)."""
        self.hand.reset()


def hand_state(
    skin: RobotSkin,
    joint_positions: Mapping[str, float] | None,
    *,
    baselines: Mapping[str, np.ndarray],
    baseline_frames: int = 5,
    threshold: float | None = None,
    frame_period_s: float | None = None,
) -> HandState:
    """The robot estimator's state where it takes the skin and every patch has a
    baseline, else each patch's own estimator."""
    if all(p.name in baselines for p in skin.patches):
        try:
            return HandEstimatorState(
                skin, joint_positions, baselines=baselines, threshold=threshold
            )
        except TactsenseInputError:  # a kind the robot estimator does not place
            pass
    return HandState(
        skin,
        joint_positions,
        baseline_frames=baseline_frames,
        threshold=threshold,
        frame_period_s=frame_period_s,
        baselines=baselines,
    )
