"""``tactsense locate RUN/`` on a robot recording: every patch's contacts in the link and
base frames, the wrench per link and the grasp's total (:mod:`tactsense.estimate.robot`).

``cli/estimate.py``'s ``locate`` hands a robot recording's folder here (a short marked
block); its options for the joint state are declared there and checked here.
"""

from __future__ import annotations

from pathlib import Path

from tactsense._validation import TactsenseInputError
from tactsense.cli._common import atomic_output, check_output, console, fail, inside, progress_bar

OUTPUT_FORMATS = (".parquet", ".csv")

JOINTS_HELP = (
    "Robot recordings: a fixed joint state, NAME=POSITION,... [rad for revolute joints, m "
    "for prismatic ones], each within the joint's limits; joints not named are at 0."
)
JOINTS_CSV_HELP = (
    "Robot recordings: joint states over time, a CSV with a time_s column [s, the "
    "recording's clock] and one column per joint [rad or m], linearly interpolated to the "
    "frames' times (held at the ends, with a warning)."
)
JOINTS_BAG_HELP = (
    "Robot recordings: joint states from a sensor_msgs/JointState topic of a rosbag2 bag "
    "(folder or one of its files; header stamps [s] on the recording's clock), "
    "interpolated as --joints-csv."
)
JOINTS_TOPIC_HELP = "With --joints-bag: the JointState topic [default: the bag's only one]."
WRENCHES_HELP = (
    "Robot recordings: file for the wrench table (per frame, per link: force [N] and "
    "torque [N mm] about the link origin in its frame; and the grasp's total in the base "
    "frame) [default: OUT's name + _wrenches, same format]."
)


def robot_only_options(joints, joints_csv, joints_bag, joints_topic, wrenches) -> list[str]:
    """The robot recordings' options given (for a single recording's refusal)."""
    given = {"--joints": joints, "--joints-csv": joints_csv, "--joints-bag": joints_bag,
             "--joints-topic": joints_topic, "--wrenches": wrenches}  # fmt: skip
    return [name for name, value in given.items() if value is not None]


def _joint_source(skin, joints, joints_csv, joints_bag, joints_topic):
    from tactsense.estimate._robot_joints import parse_joints, read_joint_bag, read_joint_csv

    chosen = [v for v in (joints, joints_csv, joints_bag) if v is not None]
    if len(chosen) > 1:
        raise TactsenseInputError("give one of --joints, --joints-csv and --joints-bag")
    if joints_topic is not None and joints_bag is None:
        raise TactsenseInputError("--joints-topic names a topic of --joints-bag; add --joints-bag")
    if joints is not None:
        fixed = parse_joints(joints)
        skin.link_poses(fixed)  # names, values, limits
        return fixed
    if joints_csv is not None:
        states = read_joint_csv(joints_csv)
    elif joints_bag is not None:
        states = read_joint_bag(joints_bag, joints_topic)
    else:
        return None
    states.check(skin)
    return states


def _write(table, path: Path) -> None:
    if path.suffix.lower() == ".csv":
        import pyarrow.csv

        pyarrow.csv.write_csv(table, path)
    else:
        import pyarrow.parquet

        pyarrow.parquet.write_table(table, path)


def run_robot_locate(
    recording: Path,
    out: Path,
    *,
    force: bool,
    quiet: bool,
    joints: str | None,
    joints_csv: Path | None,
    joints_bag: Path | None,
    joints_topic: str | None,
    wrenches: Path | None,
    baseline_frames: int,
    threshold: float | None,
    max_contacts: int,
    single_array_options: dict,
) -> None:
    """Locate a robot recording's contacts and write the contacts and wrench tables."""
    from tactsense.estimate.robot import locate_robot_recording
    from tactsense.io.robot_recording import read_robot_recording

    try:
        unused = [name for name, value in single_array_options.items() if value]
        if unused:
            raise TactsenseInputError(
                f"{', '.join(unused)} apply to a single array's recording; the hand's "
                "estimator uses 'interpolate' with each stream's first frames as baseline"
            )
        if out.suffix.lower() not in OUTPUT_FORMATS:
            raise TactsenseInputError(
                f"--out {out}: a robot recording's contacts go to .parquet or .csv"
            )
        wrenches = wrenches or out.with_name(f"{out.stem}_wrenches{out.suffix}")
        if wrenches.suffix.lower() not in OUTPUT_FORMATS:
            raise TactsenseInputError(f"--wrenches {wrenches}: expected .parquet or .csv")
        for path, what in ((out, "--out"), (wrenches, "--wrenches")):
            if inside(path, recording):
                raise TactsenseInputError(
                    f"{what} {path} lies inside the robot recording {recording}; an output "
                    "never goes into an input: choose another folder"
                )
            check_output(path, force, what=what, inputs=[recording])
        if Path(wrenches).resolve() == Path(out).resolve():
            raise TactsenseInputError("--wrenches names the same file as --out")
        data = read_robot_recording(recording)
        source = _joint_source(data.skin, joints, joints_csv, joints_bag, joints_topic)
        with progress_bar("locating the hand", unit="hand frames", quiet=quiet) as bar:
            task = bar.add_task("frames", total=None)
            result = locate_robot_recording(
                data, joints=source, baseline_frames=baseline_frames, threshold=threshold,
                max_contacts=max_contacts,
                progress=lambda done, total: bar.update(task, completed=done, total=total),
            )  # fmt: skip
        with atomic_output(out) as temporary_contacts, atomic_output(wrenches) as temporary:
            _write(result.contacts_table(), temporary_contacts)
            _write(result.wrenches_table(), temporary)
    except (TactsenseInputError, FileExistsError) as error:
        fail(str(error))
    contacts = result.contacts
    links = sorted(set(contacts["link"]))
    console.print(
        f"wrote {out}: {len(contacts['frame'])} contact rows over {result.n_frames} hand "
        f"frames, {len(set(contacts['patch']))} of {len(data.skin.patches)} patches touched, "
        f"on links {', '.join(links) or '(none)'}; wrenches in {wrenches}",
        soft_wrap=True, markup=False, highlight=False, emoji=False,
    )  # fmt: skip
    for line in result.warnings:
        console.print(f"warning: {line}", soft_wrap=True, markup=False, highlight=False)
