"""Commands on the model: ``simulate``, ``info`` and ``sensor show|check``."""

from __future__ import annotations

from enum import StrEnum
from pathlib import Path
from typing import Annotated

import numpy as np
import typer
from rich.console import Console
from rich.table import Table

from tactsense._validation import TactsenseInputError
from tactsense.cli._common import (
    SensorOption,
    atomic_output,
    check_output,
    console,
    fail,
    new_group,
    same_file,
    sensor_file,
)
from tactsense.cli._scenario import (
    ColOption,
    DwellOption,
    FlawsOption,
    ForceGOption,
    IncrementOption,
    LiftOption,
    RepeatsOption,
    RowOption,
    ScenarioKind,
    ScenarioOption,
    SeedOption,
    build_scenario,
    run_scenario,
)
from tactsense.io.recording import read_recording, write_recording
from tactsense.sensor import SensorSpec, load_sensor

app = new_group("Simulate the finger and describe recordings.")
sensor_app = new_group("Show, export and check sensor descriptions.")


@app.command()
def simulate(
    out: Annotated[Path, typer.Option("--out", "-o", help="HDF5 recording to write.")] = Path(
        "sweep.h5"
    ),
    sensor: SensorOption = "initial",
    scenario: ScenarioOption = ScenarioKind.sweep_axial,
    row: RowOption = None,
    col: ColOption = None,
    force_g: ForceGOption = None,
    increment: IncrementOption = None,
    dwell_s: DwellOption = None,
    lift_s: LiftOption = None,
    repeats: RepeatsOption = None,
    flaws: FlawsOption = "all",
    seed: SeedOption = 0,
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

    try:
        spec = load_sensor(sensor)
        for target in (out, plot):
            if target is not None:
                check_output(target, force, inputs=sensor_file(sensor))
        if plot is not None and same_file(plot, out):
            fail(f"--plot {plot} and --out {out} are the same file; choose two names")
        if plot is not None and scenario not in (
            ScenarioKind.sweep_axial,
            ScenarioKind.sweep_around,
        ):
            fail("--plot draws the sweeps along or around; not available for this scenario")
        scene = build_scenario(
            spec,
            scenario,
            row=row,
            col=col,
            force_g=force_g,
            increment=increment,
            dwell_s=dwell_s,
            lift_s=lift_s,
            repeats=repeats,
        )
        recording = run_scenario(spec, scene, flaws=flaws, seed=seed)
        with atomic_output(out) as temporary:
            write_recording(temporary, recording)
        console.print(
            f"wrote {out}: {len(recording)} frames of {spec.shape[0]}x{spec.shape[1]} "
            f"counts at {spec.electronics.scan_rate_hz:g} Hz ({spec.name})"
        )
        if plot is not None:
            with atomic_output(plot) as temporary:
                plot_sweep(recording, temporary)
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
    finite = np.isfinite(frames) if frames.dtype.kind == "f" else np.ones(frames.shape, bool)
    if finite.any():
        counts = f"{frames[finite].min():g} .. {frames[finite].max():g}"
        bad = int(np.count_nonzero(~finite.all(axis=(1, 2))))
        if bad:
            counts += f" ({bad} frames hold NaN or infinite readings)"
    else:
        counts = "none (no frames)" if frames.size == 0 else "none finite"
    table.add_row("counts", counts)
    if rec.source:
        table.add_row("source", rec.source)
    if rec.losses:
        lost = ", ".join(f"{k} {v}" for k, v in rec.losses.items() if v) or "none"
        table.add_row("losses", lost)
    if not rec.closed_cleanly:
        table.add_row("state", "not closed by its writer (killed?): frames up to its last flush")
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
            check_output(out, force, inputs=sensor_file(sensor))
            with atomic_output(out) as temporary:
                spec.to_toml(temporary)
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


class BasePreset(StrEnum):
    initial = "initial"
    improved = "improved"


@sensor_app.command("import")
def sensor_import(
    path: Annotated[
        Path, typer.Argument(help="URDF file with a tactile toolbox <sensor><tactile><array>.")
    ],
    out: Annotated[
        Path | None,
        typer.Option("--out", "-o", help="Write the sensor TOML here instead of printing it."),
    ] = None,
    name: Annotated[
        str | None,
        typer.Option(help="The <sensor name=...> to take when the file describes several."),
    ] = None,
    extends: Annotated[
        BasePreset,
        typer.Option(
            help="Preset giving what the array does not say: body, skin, electronics, flaws, "
            "and whether data row 0 is a tip row."
        ),
    ] = BasePreset.initial,
    force: Annotated[bool, typer.Option("--force", help="Replace OUT if it exists.")] = False,
) -> None:
    """Read a URDF tactile array (ROS tactile toolbox) into a sensor description (TOML).

    The array gives rows, columns, both spacings (along the finger; around it as the arc
    at the skin's surface), the taxel size and the update rate; the rest comes from the
    preset named by --extends.
    """
    from tactsense.interop.urdf import sensor_from_urdf

    if out is not None:
        check_output(out, force, inputs=[path])
    try:
        spec = sensor_from_urdf(path, name=name, extends=extends.value)
        if out is None:
            typer.echo(spec.to_toml_string())
        else:
            with atomic_output(out) as temporary:
                spec.to_toml(temporary)
            console.print(
                f"wrote {out}: {spec.name}, {spec.shape[0]} x {spec.shape[1]} tactels, "
                f"{spec.array.spacing_axial_mm:g} mm x {spec.array.spacing_angle_deg:.4g} deg"
            )
    except (TactsenseInputError, FileExistsError) as error:
        fail(str(error))


@sensor_app.command("export")
def sensor_export(
    sensor: SensorOption = "initial",
    urdf: Annotated[
        bool,
        typer.Option(
            "--urdf", help="Write the URDF tactile array (the only format so far; required)."
        ),
    ] = False,
    out: Annotated[
        Path | None,
        typer.Option("--out", "-o", help="Write the URDF here instead of printing it."),
    ] = None,
    link: Annotated[str, typer.Option(help="Name of the link the sensor is mounted on.")] = (
        "finger"
    ),
    force: Annotated[bool, typer.Option("--force", help="Replace OUT if it exists.")] = False,
) -> None:
    """Write a sensor's array as a URDF tactile description for ROS (RViz's tactile display).

    Rows along the finger, columns around it, spacings and sizes in metres (the arc at
    the skin's surface around); the data vector is a tactsense frame, row-major.
    """
    from tactsense.interop.urdf import sensor_to_urdf

    if not urdf:
        fail("say which format: --urdf (for TOML use 'tactsense sensor show')")
    if not link.strip():
        fail("--link is empty; give the name of the link the sensor is mounted on")
    if out is not None:
        check_output(out, force, inputs=sensor_file(sensor))
    try:
        text = sensor_to_urdf(load_sensor(sensor), link=link.strip())
        if out is None:
            typer.echo(text, nl=False)
        else:
            with atomic_output(out) as temporary:
                Path(temporary).write_text(text, encoding="utf-8")
            console.print(f"wrote {out}")
    except (TactsenseInputError, FileExistsError) as error:
        fail(str(error))
