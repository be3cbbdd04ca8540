"""An iCub grasp trial (Soh et al., 2012) as ONE robot recording of the iCub hand.

``tactsense import book_8.txt --format icub-grasp --skin icub_hand --out RUN``: the five
fingertips of a trial (:mod:`tactsense.interop.icub_grasp` reads the file) go to the
skin's patches ``<finger>_tip`` (thumb, index, middle, ring, little), one stream each,
every frame the file's line for that fingertip in that slice. The files carry no times:
slice ``k`` is at ``k x period_s`` (default 1 s: frame times are slice numbers).

The 9 joint encoders of each slice (the hand's joints 7-15 of iCub's arm, in degrees,
:data:`ICUB_ENCODERS`) are kept whole in ``icub_encoders.csv`` in the recording's folder
(``time_s`` then one column per encoder [deg]). Those whose joint the skin has are also
written, in radians, to ``joint_states.csv`` (``time_s`` then one column per joint of the
skin [rad]), the joint-state table of the robot's frame (:data:`ENCODER_JOINTS` says which
encoder drives which joints: a joint of the skin named as the encoder, with or without a
side prefix ``r_``/``l_`` and a ``_joint`` suffix; the ``pinky`` encoder drives the ring's
and the little finger's distal joints, coupled on iCub). iCub's coupled distal joints
(one motor and encoder for two phalanges) are not split between the phalanges: the
encoder's angle is given to each joint it drives.
"""

from __future__ import annotations

import csv
import math
import os
import shutil
from pathlib import Path

import numpy as np

from tactsense.interop._build import ImportError_, build_recording
from tactsense.interop.icub_grasp import DEFAULT_PERIOD_S, FINGERS, GraspTrial, IcubGraspError
from tactsense.robot import RobotSkin, RobotSkinError, load_skin

ICUB_ENCODERS = (
    "hand_finger",
    "thumb_oppose",
    "thumb_proximal",
    "thumb_distal",
    "index_proximal",
    "index_distal",
    "middle_proximal",
    "middle_distal",
    "pinky",
)
"""The 9 encoders of a slice: iCub's arm joints 7 to 15 (iCub's joint names)."""

ENCODER_JOINTS = {
    "thumb_distal": ("thumb_distal",),
    "index_distal": ("index_distal",),
    "middle_distal": ("middle_distal",),
    "pinky": ("pinky", "ring_distal", "little_distal"),
}
"""Joint names (without side prefix and ``_joint`` suffix) other than the encoder's own
that an encoder drives."""

ENCODERS_FILE = "icub_encoders.csv"
JOINT_STATES_FILE = "joint_states.csv"


def _bare(joint: str) -> str:
    name = joint.removesuffix("_joint")
    for side in ("r_", "l_"):
        name = name.removeprefix(side)
    return name


def encoder_joints(skin: RobotSkin) -> dict[str, list[str]]:
    """Which of the skin's movable joints each iCub encoder drives (empty lists left out)."""
    out: dict[str, list[str]] = {}
    movable = skin.movable_joints
    for encoder in ICUB_ENCODERS:
        names = {encoder, *ENCODER_JOINTS.get(encoder, ())}
        joints = [j for j in movable if _bare(j) in names]
        if joints:
            out[encoder] = joints
    return out


def icub_hand_recording(trial: GraspTrial, skin="icub_hand", *, period_s: float | None = None):
    """A trial's five fingertips as a robot recording, and its joint states.

    Returns
    -------
    recording : RobotRecording
        A stream per fingertip patch ``<finger>_tip``.
    joints : dict
        ``time_s`` (T,), ``encoders_deg`` (T, 9), ``mapping`` (encoder -> joints of the
        skin) and ``positions_rad`` (joint -> (T,) [rad]).
    """
    from tactsense.io.robot_recording import RobotRecording

    try:
        skin = load_skin(skin)
    except RobotSkinError as error:
        raise ImportError_(f"--skin: {error}") from None
    period = DEFAULT_PERIOD_S if period_s is None else float(period_s)
    if not (math.isfinite(period) and period > 0):
        raise IcubGraspError(f"the period between slices must be positive; got {period_s!r}")
    names = {p.name for p in skin.patches}
    missing = [f"{finger}_tip" for finger in FINGERS if f"{finger}_tip" not in names]
    if missing:
        raise ImportError_(
            f"skin {skin.name!r} has no patch {', '.join(missing)}; an iCub grasp trial fills "
            "the patches thumb_tip, index_tip, middle_tip, ring_tip and little_tip"
        )
    time_s = np.arange(len(trial)) * period
    timing = (
        f"slices {period:g} s apart (as given)"
        if period_s is not None
        else "frame times are slice numbers (the file carries no times)"
    )
    streams = {}
    for k, finger in enumerate(FINGERS):
        patch = skin.patch(f"{finger}_tip")
        if patch.sensor.n_taxels != trial.taxels_counts.shape[-1]:
            raise ImportError_(
                f"patch {patch.name!r} has {patch.sensor.n_taxels} taxels; an iCub fingertip "
                f"has {trial.taxels_counts.shape[-1]}"
            )
        frames = trial.taxels_counts[:, k, :].reshape(-1, *patch.sensor.shape)
        streams[patch.name] = build_recording(
            patch.sensor, list(frames), time_s, source=trial.source,
            description=f"iCub grasp trial {trial.source}, {finger} fingertip; {timing}",
        )  # fmt: skip
    mapping = encoder_joints(skin)
    positions = {}
    for encoder, joints in mapping.items():
        angle = np.deg2rad(trial.encoders_deg[:, ICUB_ENCODERS.index(encoder)])
        for joint in joints:
            positions[joint] = angle
    recording = RobotRecording(
        skin=skin,
        streams=streams,
        description=f"iCub grasp trial {trial.source}: five fingertips; {timing}",
    )
    joints = {
        "time_s": time_s,
        "encoders_deg": trial.encoders_deg,
        "mapping": mapping,
        "positions_rad": positions,
    }
    return recording, joints


def outside_limits(skin: RobotSkin, positions_rad: dict) -> dict[str, int]:
    """Per joint, how many of its positions lie outside its limits [-]."""
    by_name = {j.name: j for j in skin.joints}
    out = {}
    for name, values in positions_rad.items():
        joint = by_name[name]
        bad = int(np.count_nonzero((values < joint.lower) | (values > joint.upper)))
        if bad:
            out[name] = bad
    return out


def _write_csv(path: Path, header: list[str], columns: list[np.ndarray]) -> None:
    with open(path, "w", newline="", encoding="utf-8") as stream:
        writer = csv.writer(stream)
        writer.writerow(header)
        for row in zip(*columns, strict=True):
            writer.writerow([repr(float(v)) for v in row])


def write_icub_hand(path: str | Path, recording, joints: dict, *, overwrite: bool = False) -> Path:
    """Write the robot recording with ``icub_encoders.csv`` and ``joint_states.csv`` in its
    folder, all or nothing (a temporary folder moved into place). An existing folder is
    replaced only with ``overwrite`` and only if it is a robot recording."""
    from tactsense.io.robot_recording import is_robot_recording, write_robot_recording

    path = Path(path)
    if path.exists():
        if not overwrite:
            raise FileExistsError(f"{path} exists; pass --force to replace it")
        if not is_robot_recording(path):
            raise ImportError_(
                f"{path} exists and is not a robot recording; it is not replaced, whatever "
                "--force says"
            )
    temporary = path.with_name(f".{path.name}.{os.getpid()}.partial")
    shutil.rmtree(temporary, ignore_errors=True)
    try:
        write_robot_recording(temporary, recording)
        time_s = joints["time_s"]
        encoders = joints["encoders_deg"]
        _write_csv(
            temporary / ENCODERS_FILE,
            ["time_s", *(f"{name}_deg" for name in ICUB_ENCODERS)],
            [time_s, *encoders.T],
        )
        positions = joints["positions_rad"]
        if positions:
            _write_csv(
                temporary / JOINT_STATES_FILE,
                ["time_s", *positions],
                [time_s, *positions.values()],
            )
        if path.exists():
            shutil.rmtree(path)
        os.replace(temporary, path)
    except BaseException:
        shutil.rmtree(temporary, ignore_errors=True)
        raise
    return path
