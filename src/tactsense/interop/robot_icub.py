"""An iCub grasp trial (Soh et al., 2012) as ONE robot recording of the iCub hand.

``tactsense import book_8.txt --format icub-grasp --skin icub_hand --out RUN``: the five
fingertips of a trial (:mod:`tactsense.interop.icub_grasp` reads the file) go to the
skin's patches ``<finger>_tip`` (thumb, index, middle, ring, little), one stream each,
every frame the file's line for that fingertip in that slice. The files carry no times:
slice ``k`` is at ``k x period_s`` (default 1 s: frame times are slice numbers).

The 9 joint encoders of each slice (the hand's joints 7-15 of iCub's arm, in degrees,
:data:`ICUB_ENCODERS`) are kept whole in ``icub_encoders.csv`` in the recording's folder
(``time_s`` then one column per encoder [deg]). The joints of the skin they drive get
their angles, in radians, in ``joint_states.csv`` (``time_s`` then one column per joint
[rad]), the joint-state table of the robot's frame. Which joints: :data:`ICUB_COUPLING`,
iCub's coupling of its hand as the iCub simulator's control board undoes it
(robotology/gazebo-yarp-plugins, ``plugins/controlboard/src/ControlBoardDriverCoupling.
cpp``, commit 01796a2787784eb220b69dfd850cb21b1be54cde: ``ThumbCouplingHandler``,
``IndexCouplingHandler``, ``MiddleCouplingHandler``, ``PinkyCouplingHandler``,
``decoupleRefPos``): an opposition or proximal encoder drives its one joint, a distal
encoder the finger's two distal joints by half its angle each, ``pinky`` the ring's and
the little finger's three flexion joints by a third each. The joints are found by the
names of icub-models (``r_hand_thumb_0_joint`` ... ``r_hand_little_3_joint``; a ``l_``
hand too). ``hand_finger`` (the abduction of the fingers) is kept in the encoders' file
only: its coupling in the simulator depends on a configuration this does not read.
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

ICUB_COUPLING = {
    "thumb_oppose": (("thumb_0", 1.0),),
    "thumb_proximal": (("thumb_1", 1.0),),
    "thumb_distal": (("thumb_2", 0.5), ("thumb_3", 0.5)),
    "index_proximal": (("index_1", 1.0),),
    "index_distal": (("index_2", 0.5), ("index_3", 0.5)),
    "middle_proximal": (("middle_1", 1.0),),
    "middle_distal": (("middle_2", 0.5), ("middle_3", 0.5)),
    "pinky": tuple(
        (f"{finger}_{k}", 1.0 / 3.0) for finger in ("ring", "little") for k in (1, 2, 3)
    ),
}
"""Per encoder, the joints it drives (icub-models' names without ``r_hand_``/``l_hand_``
and ``_joint``) and the share of its angle each takes [-]."""

ENCODERS_FILE = "icub_encoders.csv"
JOINT_STATES_FILE = "joint_states.csv"


def _bare(joint: str) -> str:
    name = joint.removesuffix("_joint")
    for side in ("r_hand_", "l_hand_"):
        name = name.removeprefix(side)
    return name


def encoder_joints(skin: RobotSkin) -> dict[str, list[tuple[str, float]]]:
    """Which of the skin's movable joints each iCub encoder drives, and by what share of
    its angle (:data:`ICUB_COUPLING`); encoders that drive none are left out."""
    by_bare: dict[str, list[str]] = {}
    for joint in skin.movable_joints:
        by_bare.setdefault(_bare(joint), []).append(joint)
    out: dict[str, list[tuple[str, float]]] = {}
    for encoder, driven in ICUB_COUPLING.items():
        joints = [(j, share) for bare, share in driven for j in by_bare.get(bare, [])]
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
        for joint, share in joints:
            positions[joint] = share * angle
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
