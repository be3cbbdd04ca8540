"""``tactsense import``: other tools' files into a tactsense recording (docs/interop.md)."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import numpy as np
import typer

from tactsense.cli._common import atomic_output, check_output, console, new_group, sensor_file

app = new_group("Other tools' files into tactsense recordings.")


RATE_MISMATCH = 20.0
"""Imported frames further apart (or closer) than this many times the sensor's scan period
get a warning: a time column in milliseconds reads 1000 times too slow."""


@app.command("import")
def import_(
    source: Annotated[
        Path,
        typer.Argument(
            help="MCAP (.mcap), rosbag2 bag (folder or .db3), XDF (.xdf), CSV (.csv), a "
            "LeRobot dataset folder, or an iCub grasp trial (.txt)."
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
    format: Annotated[
        str,
        typer.Option(
            "--format",
            help="'auto' (by extension; a .txt by its first line) or 'icub-grasp' (a trial "
            "of the iCub grasp dataset, docs/interop.md).",
        ),
    ] = "auto",
    finger: Annotated[
        str | None,
        typer.Option(
            "--finger",
            help="iCub grasp trial: the fingertip to import (thumb, index, middle, ring, "
            "little); its sensor is the icub_fingertip preset unless --sensor.",
        ),
    ] = None,
    period: Annotated[
        float | None,
        typer.Option(
            "--period",
            min=1e-6,
            max=1e6,
            help="iCub grasp trial: time between slices [s]. The files carry no times: "
            "without it a slice counts 1 s (frame times are slice numbers).",
        ),
    ] = None,
    force: Annotated[bool, typer.Option("--force", help="Replace OUT if it exists.")] = False,
    # ---- a robot recording (r7-handio) ----
    skin: Annotated[
        str | None,
        typer.Option(
            "--skin",
            help="Import into a robot recording (OUT a new folder) for this robot skin (a "
            "preset or a skin TOML): a bag's TactileState topics go to the patches they "
            "name; an iCub grasp trial's five fingertips to icub_hand's (docs/robot.md). A "
            "robot MCAP that tactsense wrote needs none.",
        ),
    ] = None,
    patch_map: Annotated[
        list[str] | None,
        typer.Option(
            "--map",
            help="With --skin, a bag: NAME=PATCH sends the channel named NAME (or the one "
            "channel of the topic NAME) to the skin's patch PATCH; repeat for several.",
        ),
    ] = None,
    # ---- /a robot recording (r7-handio) ----
) -> None:
    """Import frames and their times from another tool's file into a recording.

    TactileState messages (ROS 2) from MCAP or rosbag2, one stream of an XDF file
    (LabRecorder), one frame per CSV row, a LeRobot dataset of one sensor written by
    tactsense, or one fingertip of an iCub grasp trial.
    """
    # ---- a robot recording (r7-handio) ----
    from tactsense.cli._robot_io import refuse_robot_lerobot  # r7-fixc
    from tactsense.interop.robot_bag import is_robot_mcap

    refuse_robot_lerobot(source)  # r7-fixc: a robot LeRobot export: say what import reads

    if skin is not None or (topic is None and is_robot_mcap(source)):
        from tactsense.cli._robot_io import import_robot

        others = {"--sensor": sensor, "--topic": topic, "--stream": stream, "--finger": finger,
                  "--time-column": time_column != "time"}  # fmt: skip
        import_robot(source, out, skin=skin, format=format, period=period, others=others,
                     force=force, mapping=patch_map)  # fmt: skip
        return
    if patch_map:
        from tactsense.cli._common import fail

        fail("--map applies to a robot import (--skin)")
    # ---- /a robot recording (r7-handio) ----
    from tactsense.interop.importers import read_source
    from tactsense.io.recording import write_recording

    sensor_input = [] if sensor is None else sensor_file(sensor)
    check_output(out, force, inputs=[source, *sensor_input])
    recording = read_source(
        source, sensor=sensor, time_column=time_column, topic=topic, stream=stream,
        format=format, finger=finger, period_s=period,
    )  # fmt: skip
    with atomic_output(out) as temporary:
        write_recording(temporary, recording)
    parts = recording.sensor.components  # r8-triinterop: components a taxel, when several
    console.print(
        f"wrote {out}: {len(recording)} frames of {recording.sensor.name} "
        f"({recording.sensor.shape[0]} x {recording.sensor.shape[1]}"
        + (f" x {parts} components" if parts > 1 else "")
        + ")"
    )
    times = np.asarray(recording.time_s, dtype=float)
    no_times = "the file carries no times" in recording.scenario.get("description", "")
    if len(times) > 2 and not no_times:
        step = float(np.median(np.diff(times)))
        period = recording.sensor.scan_period_s
        if step > RATE_MISMATCH * period or step < period / RATE_MISMATCH:
            console.print(
                f"warning: the frames are {step:.4g} s apart (median), "
                f"{step / period:.3g} times the period of {recording.sensor.name!r} "
                f"({period:.4g} s, its scan_rate_hz): are the times in seconds (not ms or "
                "us)? Otherwise set \\[electronics] scan_rate_hz in the sensor's description"
            )
    if no_times:
        console.print(
            "note: the iCub grasp trial carries no times; frame times are slice numbers "
            "(1 s apart): give --period S if the slices' period is known"
        )
