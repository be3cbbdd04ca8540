"""``tactsense locate RUN/`` on a robot recording: every patch's contacts in the link and
base frames, the wrench per link and the grasp's total (:mod:`tactsense.estimate.robot`).

``cli/estimate.py``'s ``locate`` hands a robot recording's folder here (a short marked
block); its options for the joint state are declared there and checked here.
"""

from __future__ import annotations

from pathlib import Path

from tactsense._validation import TactsenseInputError
from tactsense.cli._common import atomic_output, check_output, console, fail, inside, progress_bar
from tactsense.estimate._robot_tables import HAND_METHODS

OUTPUT_FORMATS = (".parquet", ".csv")

SINGLE_METHODS = ("interpolate", "cop", "fit", "joint")
"""The single array's methods (``find_contacts``'): one the hand does not take is
refused as not applying, any other name as unknown."""

JOINTS_HELP = (
    "Robot recordings: a fixed joint state, NAME=POSITION,... [rad for revolute joints, m "
    "for prismatic ones], each within the joint's limits; joints not named are at 0. "
    "Default (no joint option): the recording's own joint_states.csv, else the joint state "
    "a simulated grasp wrote, else every joint at 0 (or at its nearer limit when 0 is outside "
    "its limits)."
)
JOINTS_CSV_HELP = (
    "Robot recordings: joint states over time, a CSV with a time_s column [s, the "
    "recording's clock: a capture's are Unix seconds on the host clock, a simulation's "
    "start at 0] and one column per joint [rad or m], linearly interpolated to the "
    "frames' times (held at the ends, with a warning)."
)
JOINTS_BAG_HELP = (
    "Robot recordings: joint states from a sensor_msgs/JointState topic of a rosbag2 bag "
    "(folder or one of its files) or a plain MCAP file (header stamps [s] on the "
    "recording's clock), interpolated as --joints-csv."
)
JOINTS_TOPIC_HELP = "With --joints-bag: the JointState topic [default: the bag's only one]."
WRENCHES_HELP = (
    "Robot recordings: file for the wrench table (per frame, per link: force [N] and "
    "torque [N mm] about the link origin in its frame; and the grasp's total in the base "
    "frame) [default: OUT's name + _wrenches, same format]."
)

FORCE_CAVEAT = (
    "note: force_n [N] is the amplitude of a 1.6-mm probe's response ('interpolate'): a "
    "broad contact (a large object) reads low; for pad patches' forces fitted with each "
    "contact's size, add --method joint (slower; docs/robot.md gives the figures, "
    "docs/contacts.md says where the fit can and cannot tell force)"
)
JOINT_CAVEAT = (
    "note: --method joint fitted each pad patch's contacts with their size "
    "(contact_radius_mm, flat_share); point-set patches keep their own estimator (no "
    "size-aware fit; NaN in those columns); a pad that reads too few taxels per contact "
    "cannot tell size from force (docs/contacts.md)"
)
METHOD_HELP = (
    " On a robot recording's folder: 'interpolate' (default) or 'joint' (each pad patch's "
    "contacts fitted jointly with their size, then placed and summed into wrenches; "
    "point-set patches keep their estimator; 1-4 s per hand frame with a broad contact "
    "on a pad: docs/robot.md)."
)


def robot_only_options(joints, joints_csv, joints_bag, joints_topic, wrenches) -> list[str]:
    """The robot recordings' options given (for a single recording's refusal)."""
    given = {"--joints": joints, "--joints-csv": joints_csv, "--joints-bag": joints_bag,
             "--joints-topic": joints_topic, "--wrenches": wrenches}  # fmt: skip
    return [name for name, value in given.items() if value is not None]


def _joint_source(skin, joints, joints_csv, joints_bag, joints_topic, recording=None):
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
    else:  # none given: the recording's own (its joint_states.csv, a simulation's state)
        from tactsense.io.robot_recording import recorded_joint_state

        what, value = recorded_joint_state(recording) if recording is not None else ("none", None)
        if what == "fixed":
            skin.link_poses(value)
            return value
        if what != "csv":
            return skin.rest_joint_positions()
        states = read_joint_csv(value)
    states.check(skin)
    return states


class _TableWriter:
    """A table written block by block: Parquet or CSV by the extension."""

    def __init__(self, path: Path):
        self.path = path
        self._writer = None

    def write(self, table) -> None:
        if self._writer is None:
            if self.path.suffix.lower() == ".csv":
                import pyarrow.csv

                self._writer = pyarrow.csv.CSVWriter(self.path, table.schema)
            else:
                import pyarrow.parquet

                self._writer = pyarrow.parquet.ParquetWriter(self.path, table.schema)
        self._writer.write_table(table)

    def close(self) -> None:
        if self._writer is not None:
            self._writer.close()


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
    method: str = "interpolate",
) -> None:
    """Locate a robot recording's contacts and write the contacts and wrench tables.

    ``single_array_options`` maps each single-array option to whether it was given (a
    ``--method`` other than :data:`HAND_METHODS` counts as one)."""
    from tactsense.io.robot_recording import read_robot_skin
    from tactsense.robot_batch import iter_robot_blocks

    try:
        if method not in HAND_METHODS and method not in SINGLE_METHODS:
            raise TactsenseInputError(
                f"--method {method!r} is not a method; a robot recording takes "
                f"{' or '.join(HAND_METHODS)}"
            )
        unused = [name for name, value in single_array_options.items() if value]
        if unused:
            verb = "applies" if len(unused) == 1 else "apply"
            raise TactsenseInputError(
                f"{', '.join(unused)} {verb} to a single array's recording; the hand's "
                f"estimator takes --method {' or '.join(HAND_METHODS)}, with each stream's "
                "first frames as baseline (locate RUN/streams/PATCH.h5 for the others)"
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
            for source in (joints_csv, joints_bag):  # a bag may be a folder: nothing in it
                if source is not None and Path(source).is_dir() and inside(path, source):
                    raise TactsenseInputError(
                        f"{what} {path} lies inside the input {source}; an output never "
                        "goes into an input: choose another folder"
                    )
            check_output(path, force, what=what, inputs=[recording, joints_csv, joints_bag])
        if Path(wrenches).resolve() == Path(out).resolve():
            raise TactsenseInputError("--wrenches names the same file as --out")
        skin = read_robot_skin(recording)
        source = _joint_source(skin, joints, joints_csv, joints_bag, joints_topic, recording)
        warnings: list[str] = []
        rows, frames, patches, links = 0, 0, set(), set()
        with (
            progress_bar("locating the hand", unit="hand frames", quiet=quiet) as bar,
            atomic_output(out) as temporary_contacts,
            atomic_output(wrenches) as temporary_wrenches,
        ):
            task = bar.add_task("frames", total=None)
            writers = (_TableWriter(temporary_contacts), _TableWriter(temporary_wrenches))
            try:
                for part in iter_robot_blocks(
                    recording, joints=source, baseline_frames=baseline_frames,
                    threshold=threshold, max_contacts=max_contacts, method=method,
                    warnings=warnings,
                    progress=lambda done, total: bar.update(task, completed=done, total=total),
                ):  # fmt: skip
                    writers[0].write(part.contacts_table())
                    writers[1].write(part.wrenches_table())
                    rows += len(part.contacts["frame"])
                    frames += part.n_frames
                    patches.update(part.contacts["patch"])
                    links.update(part.contacts["link"])
            finally:
                for writer in writers:
                    writer.close()
    except (TactsenseInputError, FileExistsError) as error:
        fail(str(error))
    console.print(
        f"wrote {out}: {rows} contact rows over {frames} hand frames, {len(patches)} of "
        f"{len(skin.patches)} patches touched, on links {', '.join(sorted(links)) or '(none)'}"
        f"; wrenches in {wrenches}",
        soft_wrap=True, markup=False, highlight=False, emoji=False,
    )  # fmt: skip
    if rows:
        note = JOINT_CAVEAT if method == "joint" else FORCE_CAVEAT
        console.print(note, soft_wrap=True, markup=False, highlight=False, emoji=False)
    for line in warnings:
        console.print(f"warning: {line}", soft_wrap=True, markup=False, highlight=False)
