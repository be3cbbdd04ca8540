"""Other tools' formats on the command line: ``export`` (MCAP for ROS 2 and Foxglove, Rerun)."""

from __future__ import annotations

from enum import StrEnum
from pathlib import Path
from typing import Annotated

import typer

from tactsense._validation import TactsenseInputError
from tactsense.cli._common import (
    BaselineFramesOption,
    CalibrationOption,
    ContactThresholdOption,
    atomic_output,
    check_output,
    console,
    fail,
    new_group,
    progress_bar,
    remove_stale_partials,
)
from tactsense.estimate.contacts.array_calibration import load_calibration
from tactsense.kinds import kind_of

app = new_group("Other tools' formats: MCAP (ROS 2, Foxglove) and Rerun.")


class ExportFormat(StrEnum):
    mcap = "mcap"
    rerun = "rerun"
    lerobot = "lerobot"
    csv = "csv"


DEFAULT_FRAME_ID = "finger"
"""``--frame-id``'s default: the URDF link 'tactsense sensor export --urdf' names (a link's
name, not a sensor kind's)."""

SUFFIXES = {ExportFormat.mcap: ".mcap", ExportFormat.rerun: ".rrd", ExportFormat.csv: ".csv"}


@app.command()
def export(
    recording: Annotated[Path, typer.Argument(help="HDF5 recording to export.")],
    out: Annotated[
        Path,
        typer.Option(
            "--out",
            "-o",
            help="New file: .mcap for --format mcap, .rrd for --format rerun, .csv for "
            "--format csv; a new folder for --format lerobot.",
        ),
    ],
    export_format: Annotated[
        ExportFormat | None,
        typer.Option(
            "--format",
            help="mcap: tactile_msgs/TactileState, TactileContact and TactileContacts "
            "messages (ROS 2 CDR) for ROS 2 and Foxglove; rerun: heat map, contact and force "
            "for the Rerun viewer; "
            "lerobot: a LeRobot v3 dataset folder; csv: the frames, one a row, as "
            "'tactsense import' reads them. "
            "Default: from the extension of OUT.",
        ),
    ] = None,
    episode_split: Annotated[
        int | None,
        typer.Option(
            "--episode-split",
            min=1,
            help="lerobot: one episode per this many frames (default: one per recording).",
        ),
    ] = None,
    frame_id: Annotated[
        str,
        typer.Option(
            "--frame-id",
            help="mcap: the frame_id of every header, the URDF link the sensor is mounted on "
            "(the link 'tactsense sensor export --urdf --link' wrote; default finger).",
        ),
    ] = DEFAULT_FRAME_ID,
    start_time: Annotated[
        float | None,
        typer.Option(
            "--start-time",
            min=0.0,
            max=4.2e9,
            help="mcap: Unix time of the first frame [s] for a recording without host times "
            "(a simulation); a recorded stream is stamped with its host times (default: 0).",
        ),
    ] = None,
    calibration: CalibrationOption = None,
    baseline_frames: BaselineFramesOption = 5,
    threshold: ContactThresholdOption = None,
    quiet: Annotated[bool, typer.Option("--quiet", "-q", help="No progress bar.")] = False,
    force: Annotated[bool, typer.Option("--force", help="Replace OUT if it exists.")] = False,
    # ---- a robot recording (r7-handio) ----
    fps: Annotated[
        int | None,
        typer.Option(
            "--fps",
            min=1,
            max=10_000,
            help="lerobot, a robot recording: rows per second [Hz], 1-10000 (default: the "
            "fastest patch's scan rate); each row holds every patch's latest frame.",
        ),
    ] = None,
    # ---- /a robot recording (r7-handio) ----
) -> None:
    """Export a recording's frames and contacts to another tool's format (docs/interop.md).

    Frames and contacts are estimated a piece at a time, as 'locate' does; the file is
    written to a temporary name and moved into place when complete. A robot recording
    (a folder, docs/robot.md) exports to mcap or lerobot.
    """
    # ---- a robot recording (r7-handio) ----
    from tactsense.io.robot_recording import is_robot_recording

    if is_robot_recording(recording):
        from tactsense.cli._robot_io import export_robot

        export_robot(
            recording, out, export_format, frame_id_given=frame_id != DEFAULT_FRAME_ID,
            calibration=calibration, start_time=start_time, baseline_frames=baseline_frames,
            threshold=threshold, episode_split=episode_split, fps=fps, quiet=quiet, force=force,
        )  # fmt: skip
        return
    if fps is not None:
        fail("--fps applies to a robot recording's --format lerobot only")
    # ---- /a robot recording (r7-handio) ----

    if export_format is None:
        by_suffix = {suffix: kind for kind, suffix in SUFFIXES.items()}
        export_format = by_suffix.get(out.suffix.lower())
        if export_format is None:
            fail(
                f"{out}: say --format mcap or rerun (or csv for the frames, lerobot for a "
                "dataset folder), or use the extension .mcap, .rrd or .csv"
            )
    else:  # an extension that names another format is a mistake, never a file name
        named = {suffix: kind for kind, suffix in SUFFIXES.items()}.get(out.suffix.lower())
        if named is not None and named is not export_format:
            fail(
                f"--out {out}: the extension {out.suffix} is for --format {named.value}, "
                f"not --format {export_format.value}; name the output "
                + (
                    "a folder without an extension"
                    if export_format is ExportFormat.lerobot
                    else f"with {SUFFIXES[export_format]}"
                )
            )
    if export_format is ExportFormat.lerobot:
        _export_lerobot(recording, out, calibration, baseline_frames, threshold, episode_split)
        return
    if episode_split is not None:
        fail("--episode-split applies to --format lerobot only")
    if export_format is ExportFormat.csv:
        if calibration is not None or threshold is not None:
            fail("--calibration and --threshold apply to contacts; a CSV export holds the frames")
        if frame_id != DEFAULT_FRAME_ID or start_time is not None:
            fail("--frame-id and --start-time apply to --format mcap only")
        _export_csv(recording, out, force, quiet)
        return
    if export_format is not ExportFormat.mcap and (
        frame_id != DEFAULT_FRAME_ID or start_time is not None
    ):
        fail("--frame-id and --start-time apply to --format mcap only")
    if not frame_id.strip() or any(c.isspace() for c in frame_id):
        fail(f"--frame-id {frame_id!r}: give a link name without spaces")
    check_output(out, force, inputs=[recording, calibration])
    try:
        cal = None if calibration is None else load_calibration(calibration)
        if export_format is ExportFormat.mcap:
            from tactsense.interop.mcap import _writer_class
            from tactsense.interop.mcap import export_mcap as run

            _writer_class()
        else:
            from tactsense.interop.rerun import _rerun
            from tactsense.interop.rerun import export_rerun as run

            _rerun()
        with progress_bar("exporting", unit="frames", quiet=quiet) as bar:
            task = bar.add_task("frames", total=None)

            def update(done: int, total: int) -> None:
                bar.update(task, completed=done, total=total)

            extra = (
                {"frame_id": frame_id, "start_time_s": start_time}
                if export_format is ExportFormat.mcap
                else {}
            )
            with atomic_output(out) as temporary:
                counts = run(
                    recording, temporary, calibration=cal, baseline_frames=baseline_frames,
                    threshold=threshold, progress=update, **extra,
                )  # fmt: skip
    except (TactsenseInputError, FileExistsError) as error:
        fail(str(error))
    clock = f", {counts['clock']} clock" if "clock" in counts else ""
    if counts.get("contacts", 0) is None:  # ---- frames only (r8-triinterop) ----
        console.print(
            f"wrote {out}: {counts['frames']} frames, no contacts (sensor kind "
            f"{counts['kind']!r} has no contact estimator; {export_format.value}{clock})"
        )
        return
    if kind_of(counts.get("kind", "finger")).multi_contact:  # every contact of every frame
        what = (
            "one TactileContact per contact per frame, named <sensor>/<id>; "
            if export_format is ExportFormat.mcap
            else "tracked, labelled with their ids; "
        )
        console.print(
            f"wrote {out}: {counts['frames']} frames, {counts['contacts']} contacts "
            f"({what}{export_format.value}{clock})"
        )
        return
    console.print(
        f"wrote {out}: {counts['frames']} frames, {counts['contacts']} with a contact "
        f"({export_format.value}{clock})"
    )


def _export_csv(recording, out, force, quiet) -> None:
    """``export --format csv``: the frames, one a row (tactsense.interop.csvfile)."""
    from tactsense.interop.csvfile import export_csv

    check_output(out, force, inputs=[recording])
    try:
        with progress_bar("exporting", unit="frames", quiet=quiet) as bar:
            task = bar.add_task("frames", total=None)
            with atomic_output(out) as temporary:
                counts = export_csv(
                    recording, temporary,
                    progress=lambda done, total: bar.update(task, completed=done, total=total),
                )  # fmt: skip
    except (TactsenseInputError, FileExistsError) as error:
        fail(str(error))
    host = ", with host times" if counts["host_time"] else ""
    console.print(
        f"wrote {out}: {counts['frames']} frames{host} (csv; 'tactsense import {out.name} "
        "--sensor S' reads it back)"
    )


def _export_lerobot(recording, out, calibration, baseline_frames, threshold, episode_split):
    """``export --format lerobot``: a new dataset folder (tactsense.interop.lerobot)."""
    from tactsense.interop.lerobot import export_lerobot

    if out.exists():
        fail(
            f"{out} exists; a LeRobot dataset goes into a new folder (--force never replaces "
            "a folder): remove it or choose another name"
        )
    check_output(out, False, what="dataset folder", inputs=[recording, calibration])
    remove_stale_partials(out.parent)  # left by a run killed outright
    try:  # a finger's calibration or a pad's (an array calibration)
        cal = None if calibration is None else load_calibration(calibration)
    except TactsenseInputError as error:
        fail(str(error))
    counts = export_lerobot(
        recording, out, calibration=cal, baseline_frames=baseline_frames,
        threshold=threshold, episode_split=episode_split,
    )  # fmt: skip
    contacts = (
        f"{counts['contacts']} with a contact"
        if not kind_of(counts.get("kind", "finger")).multi_contact
        else f"{counts['contacts']} contacts"
    )
    if counts.get("contacts", 0) is None:  # ---- frames only (r8-triinterop) ----
        contacts = f"no contacts (sensor kind {counts['kind']!r} has no contact estimator)"
    console.print(
        f"wrote {out}: {counts['frames']} frames in {counts['episodes']} "
        f"{'episode' if counts['episodes'] == 1 else 'episodes'} at "  # trial8 (r8-fixa8)
        f"{counts['fps']} fps, {contacts} (lerobot)"
    )
