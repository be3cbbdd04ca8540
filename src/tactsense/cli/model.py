"""Commands on the model: ``simulate``, ``info`` and ``sensor show|check``."""

from __future__ import annotations

from enum import StrEnum
from pathlib import Path
from typing import Annotated

import numpy as np
import typer
from rich.console import Console
from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeRemainingColumn
from rich.table import Table

from tactsense._validation import TactsenseInputError
from tactsense.cli._common import SensorOption, console, fail, new_group
from tactsense.io.recording import read_recording, write_recording
from tactsense.physics.contact import grams_force
from tactsense.physics.flaws import FLAW_NAMES
from tactsense.sensor import SensorSpec, load_sensor

app = new_group("Simulate the finger and describe recordings.")
sensor_app = new_group("Show, export and check sensor descriptions.")


class ScenarioKind(StrEnum):
    sweep_axial = "sweep-axial"
    sweep_around = "sweep-around"
    repeated = "repeated"
    calibration = "calibration"
    knife = "knife-edge"


@app.command()
def simulate(
    out: Annotated[Path, typer.Option("--out", "-o", help="HDF5 recording to write.")] = Path(
        "sweep.h5"
    ),
    sensor: SensorOption = "initial",
    scenario: Annotated[
        ScenarioKind,
        typer.Option(
            help="What touches the finger: 'sweep-axial' steps a probe along the finger "
            "(Fig. 7), 'sweep-around' steps it around (Fig. 13), 'repeated' applies it "
            "again and again above one tactel (Figs. 10-12; also the force steps for "
            "'calibrate --steps'), 'calibration' sweeps the probe along every column "
            "(section 3.1, for 'calibrate'), 'knife-edge' steps a 0.5-N knife edge past "
            "tactel (row, col) (section 4.1, for 'calibrate --knife')."
        ),
    ] = ScenarioKind.sweep_axial,
    row: Annotated[
        int,
        typer.Option(
            help="Row of the tactel: fixes the axial position of a sweep "
            "around, or the tactel loaded by 'repeated' (0 = tip row)."
        ),
    ] = 4,
    col: Annotated[
        int,
        typer.Option(
            help="Column of the tactel: fixes the angle of a sweep along the "
            "finger, or the tactel loaded by 'repeated'."
        ),
    ] = 0,
    force_g: Annotated[
        float, typer.Option(help="Probe load in grams-force (the paper's unit) [g].")
    ] = 50.0,
    increment: Annotated[
        float | None,
        typer.Option(
            help="Step between probe positions: mm for sweep-axial (default 0.6), "
            "deg for sweep-around (default 3)."
        ),
    ] = None,
    dwell_s: Annotated[
        float, typer.Option(help="Time the probe is held at each position or application [s].")
    ] = 0.5,
    lift_s: Annotated[
        float,
        typer.Option(
            help="Time the probe is lifted between positions or applications "
            "(0 = it slides from one to the next in a sweep) [s]."
        ),
    ] = 0.0,
    repeats: Annotated[int, typer.Option(help="Applications for 'repeated'.")] = 100,
    flaws: Annotated[
        str,
        typer.Option(
            help="Flaws to switch on: 'all', 'none' or a comma list of "
            + ", ".join(FLAW_NAMES)
            + ". Their sizes come from the sensor description."
        ),
    ] = "all",
    seed: Annotated[
        int | None, typer.Option(help="Seed of every random draw, for a repeatable run.")
    ] = 0,
    plot: Annotated[
        Path | None,
        typer.Option(help="Also draw the swept tactels' responses to this PNG (sweeps only)."),
    ] = None,
    force: Annotated[
        bool, typer.Option("--force", help="Replace OUT and PLOT if they already exist.")
    ] = False,
) -> None:
    """Simulate the finger under a scenario and write an HDF5 recording of A/D frames."""
    from tactsense.plotting import plot_sweep
    from tactsense.simulate import (
        calibration_sweep,
        knife_edge_sweep,
        probe_sweep,
        repeated_load,
    )
    from tactsense.simulate import simulate as run_simulation

    try:
        spec = load_sensor(sensor)
        for target in (out, plot):
            if target is not None and target.exists() and not force:
                fail(f"{target} exists; pass --force to replace it, or choose another name")
        if plot is not None and scenario not in (
            ScenarioKind.sweep_axial,
            ScenarioKind.sweep_around,
        ):
            fail("--plot draws the sweeps along or around; not available for this scenario")
        force_n = grams_force(force_g)
        if scenario is ScenarioKind.calibration:
            scene = calibration_sweep(spec, force_n=force_n, increment=increment or 0.6)
        elif scenario is ScenarioKind.knife:
            scene = knife_edge_sweep(spec, row=row, col=col, increment=increment or 0.6)
        elif scenario is ScenarioKind.repeated:
            scene = repeated_load(
                spec,
                row=row,
                col=col,
                force_n=force_n,
                repeats=repeats,
                on_s=dwell_s,
                off_s=max(lift_s, dwell_s),
            )
        else:
            along = "axial" if scenario is ScenarioKind.sweep_axial else "around"
            scene = probe_sweep(
                spec,
                along=along,
                row=row,
                col=col,
                increment=increment,
                force_n=force_n,
                dwell_s=dwell_s,
                lift_s=lift_s,
            )
        with Progress(
            TextColumn("simulating"),
            BarColumn(),
            MofNCompleteColumn(),
            TextColumn("frames"),
            TimeRemainingColumn(),
            console=console,
            disable=None,
        ) as bar:
            task = bar.add_task("frames", total=None)

            def update(done: int, total: int) -> None:
                bar.update(task, completed=done, total=total)

            recording = run_simulation(spec, scene, flaws=flaws, rng=seed, progress=update)
        write_recording(out, recording, overwrite=force)
        console.print(
            f"wrote {out}: {len(recording)} frames of {spec.shape[0]}x{spec.shape[1]} "
            f"counts at {spec.electronics.scan_rate_hz:g} Hz ({spec.name})"
        )
        if plot is not None:
            plot_sweep(recording, plot, overwrite=force)
            console.print(f"wrote {plot}")
    except (TactsenseInputError, FileExistsError) as error:
        fail(str(error))


@app.command()
def info(recording: Annotated[Path, typer.Argument(help="HDF5 recording to describe.")]) -> None:
    """Describe a recording: sensor, scenario, frames and their range."""
    try:
        rec = read_recording(recording)
    except TactsenseInputError as error:
        fail(str(error))
    table = Table(title=str(recording), show_header=False)
    frames = np.asarray(rec.frames)
    table.add_row("sensor", rec.sensor.name)
    table.add_row("frames", f"{frames.shape[0]} x {frames.shape[1]} x {frames.shape[2]} counts")
    duration = rec.time_s[-1] + rec.sensor.scan_period_s if len(rec) else 0.0
    table.add_row("duration", f"{duration:.3f} s at {rec.sensor.electronics.scan_rate_hz:g} Hz")
    table.add_row("counts", f"{frames.min():g} .. {frames.max():g}")
    table.add_row("scenario", str(rec.scenario.get("description", "")))
    table.add_row("flaws", ", ".join(rec.flaws) or "none")
    Console().print(table)


@sensor_app.command("show")
def sensor_show(
    sensor: SensorOption = "initial",
    out: Annotated[
        Path | None, typer.Option("--out", "-o", help="Write the TOML here instead of printing it.")
    ] = None,
    force: Annotated[bool, typer.Option("--force", help="Replace OUT if it exists.")] = False,
) -> None:
    """Print a sensor description as TOML: a starting point for describing your own finger."""
    try:
        spec = load_sensor(sensor)
        if out is None:
            typer.echo(spec.to_toml_string())
        else:
            spec.to_toml(out, overwrite=force)
            console.print(f"wrote {out}")
    except (TactsenseInputError, FileExistsError) as error:
        fail(str(error))


@sensor_app.command("check")
def sensor_check(
    path: Annotated[Path, typer.Argument(help="Sensor TOML file to validate.")],
) -> None:
    """Validate a sensor TOML file and print its derived quantities."""
    try:
        spec = SensorSpec.from_toml(path)
    except TactsenseInputError as error:
        fail(str(error))
    table = Table(title=f"{spec.name}: valid", show_header=False)
    table.add_row("frame shape (rows, cols)", f"{spec.shape}")
    table.add_row("closes the circumference", str(spec.closes_circumference))
    table.add_row("junction capacitance", f"{spec.junction_capacitance_f * 1e12:.3f} pF")
    table.add_row("ring flexural length", f"{spec.ring_flexural_length_mm:.3f} mm")
    Console().print(table)
