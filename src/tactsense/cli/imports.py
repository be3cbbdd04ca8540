"""``tactsense import``: other tools' files into a tactsense recording (docs/interop.md)."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from tactsense.cli._common import atomic_output, check_output, console, new_group, sensor_file

app = new_group("Other tools' files into tactsense recordings.")


@app.command("import")
def import_(
    source: Annotated[
        Path,
        typer.Argument(
            help="MCAP (.mcap), rosbag2 bag (folder or .db3), XDF (.xdf), CSV (.csv) or a "
            "LeRobot dataset folder."
        ),
    ],
    out: Annotated[Path, typer.Option("--out", "-o", help="New HDF5 recording.")],
    sensor: Annotated[
        str | None,
        typer.Option(
            "--sensor",
            help="The sensor (preset or TOML) for sources that do not describe theirs: CSV, "
            "an XDF stream not from tactsense, a TactileState whose sensor name is not a preset.",
        ),
    ] = None,
    time_column: Annotated[
        str, typer.Option("--time-column", help="CSV: the column of frame times [s].")
    ] = "time",
    topic: Annotated[
        str | None,
        typer.Option("--topic", help="MCAP/rosbag2: the TactileState topic, if several."),
    ] = None,
    stream: Annotated[
        str | None,
        typer.Option("--stream", help="XDF: the stream's name or source_id, if several."),
    ] = None,
    force: Annotated[bool, typer.Option("--force", help="Replace OUT if it exists.")] = False,
) -> None:
    """Import frames and their times from another tool's file into a recording.

    TactileState messages (ROS 2) from MCAP or rosbag2, one stream of an XDF file
    (LabRecorder), one frame per CSV row, or a LeRobot dataset written by tactsense.
    """
    from tactsense.interop.importers import read_source
    from tactsense.io.recording import write_recording

    sensor_input = [] if sensor is None else sensor_file(sensor)
    check_output(out, force, inputs=[source, *sensor_input])
    recording = read_source(
        source, sensor=sensor, time_column=time_column, topic=topic, stream=stream
    )
    with atomic_output(out) as temporary:
        write_recording(temporary, recording)
    console.print(
        f"wrote {out}: {len(recording)} frames of {recording.sensor.name} "
        f"({recording.sensor.shape[0]} x {recording.sensor.shape[1]})"
    )
