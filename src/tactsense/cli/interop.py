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
    ThresholdOption,
    atomic_output,
    check_output,
    console,
    fail,
    new_group,
    progress_bar,
    remove_stale_partials,
)

app = new_group("Other tools' formats: MCAP (ROS 2, Foxglove) and Rerun.")


class ExportFormat(StrEnum):
    mcap = "mcap"
    rerun = "rerun"
    lerobot = "lerobot"


SUFFIXES = {ExportFormat.mcap: ".mcap", ExportFormat.rerun: ".rrd"}


@app.command()
def export(
    recording: Annotated[Path, typer.Argument(help="HDF5 recording to export.")],
    out: Annotated[
        Path,
        typer.Option(
            "--out", "-o", help="New file: .mcap for --format mcap, .rrd for --format rerun."
        ),
    ],
    export_format: Annotated[
        ExportFormat | None,
        typer.Option(
            "--format",
            help="mcap: tactile_msgs/TactileState and TactileContact messages (ROS 2 CDR) for "
            "ROS 2 and Foxglove; rerun: heat map, contact and force for the Rerun viewer; "
            "lerobot: a LeRobot v3 dataset folder. "
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
    calibration: CalibrationOption = None,
    baseline_frames: BaselineFramesOption = 5,
    threshold: ThresholdOption = 0.005,
    quiet: Annotated[bool, typer.Option("--quiet", "-q", help="No progress bar.")] = False,
    force: Annotated[bool, typer.Option("--force", help="Replace OUT if it exists.")] = False,
) -> None:
    """Export a recording's frames and contacts to another tool's format (docs/interop.md).

    Frames and contacts are estimated a piece at a time, as 'locate' does; the file is
    written to a temporary name and moved into place when complete.
    """
    from tactsense.estimate import Calibration

    if export_format is None:
        by_suffix = {suffix: kind for kind, suffix in SUFFIXES.items()}
        export_format = by_suffix.get(out.suffix.lower())
        if export_format is None:
            fail(
                f"{out}: say --format mcap or rerun (or lerobot, for a dataset folder), or use "
                "the extension .mcap or .rrd"
            )
    if export_format is ExportFormat.lerobot:
        _export_lerobot(recording, out, calibration, baseline_frames, threshold, episode_split)
        return
    if episode_split is not None:
        fail("--episode-split applies to --format lerobot only")
    check_output(out, force, inputs=[recording, calibration])
    try:
        cal = None if calibration is None else Calibration.load(calibration)
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

            with atomic_output(out) as temporary:
                counts = run(
                    recording, temporary, calibration=cal, baseline_frames=baseline_frames,
                    threshold=threshold, progress=update,
                )  # fmt: skip
    except (TactsenseInputError, FileExistsError) as error:
        fail(str(error))
    console.print(
        f"wrote {out}: {counts['frames']} frames, {counts['contacts']} with a contact "
        f"({export_format.value})"
    )


def _export_lerobot(recording, out, calibration, baseline_frames, threshold, episode_split):
    """``export --format lerobot``: a new dataset folder (tactsense.interop.lerobot)."""
    from tactsense.estimate import Calibration
    from tactsense.interop.lerobot import export_lerobot

    if out.exists():
        fail(f"{out} exists; a LeRobot dataset goes into a new folder")
    check_output(out, False, what="dataset folder", inputs=[recording, calibration])
    remove_stale_partials(out.parent)  # left by a run killed outright
    cal = None if calibration is None else Calibration.load(calibration)
    counts = export_lerobot(
        recording, out, calibration=cal, baseline_frames=baseline_frames,
        threshold=threshold, episode_split=episode_split,
    )  # fmt: skip
    console.print(
        f"wrote {out}: {counts['frames']} frames in {counts['episodes']} episodes at "
        f"{counts['fps']} fps, {counts['contacts']} with a contact (lerobot)"
    )
