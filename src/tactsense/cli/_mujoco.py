"""``tactsense mujoco``: step a MuJoCo model and record a tactile sensor's frames from its
contacts (:mod:`tactsense.interop.mujoco`, docs/mujoco.md)."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from tactsense.cli._common import (
    atomic_output,
    check_output,
    console,
    fail,
    frame_text,
    new_group,
    progress_bar,
    rest_warnings,
    sensor_file,
    sensor_help,
)

app = new_group("MuJoCo in, taxel frames out.")


@app.command("mujoco")
def mujoco_command(
    model: Annotated[
        Path | None,
        typer.Argument(
            help="MuJoCo model (MJCF XML). Default: tactsense's example (--example), moved "
            "by its own --controls table (docs/mujoco.md)."
        ),
    ] = None,
    example: Annotated[
        str,
        typer.Option(
            "--example",
            metavar="[gripper|fingertip|slip]",
            help="Without MODEL, which example: 'gripper' (a gripper finger with a "
            "40 x 40 mm pad16 pressing on and sliding across a ball and a rod), "
            "'fingertip' (the paper's "
            "finger, the 'initial' preset, slid along its axis over a ball) or 'slip' "
            "(a finger with the three-axis mag4x4 pad pressed on a 2 mm ball and dragged "
            "until it slips, twice; 8 s).",
        ),
    ] = "gripper",
    out: Annotated[Path, typer.Option("--out", "-o", help="HDF5 recording to write (.h5).")] = (
        Path("mujoco.h5")
    ),
    geom: Annotated[
        str | None,
        typer.Option(
            "--geom",
            help="The geom the sensor covers: a pad's sensing face is the geom's local +z "
            "face; a finger's skin wraps a capsule or cylinder about its local z, tip at +z "
            "(default for the examples: pad, finger).",
        ),
    ] = None,
    site: Annotated[
        str | None,
        typer.Option(
            "--site",
            help="Instead of --geom: a site; the sensor covers every geom of its body, in "
            "the site's frame.",
        ),
    ] = None,
    sensor: Annotated[
        str | None,
        typer.Option(
            "--sensor",
            help="The tactile sensor. " + sensor_help() + " Default: pad16 (the fingertip "
            "example: initial; the slip example: mag4x4).",
        ),
    ] = None,
    seconds: Annotated[
        float | None,
        typer.Option(
            "--seconds",
            max=1e6,  # above 0: checked with the others (click has no open bound here)
            help="Simulated time to record [s], (0, 1e6]. Default: the controls table's "
            "last time (10 s for the example), else 1 s.",
        ),
    ] = None,
    controls: Annotated[
        Path | None,
        typer.Option(
            "--controls",
            help="CSV of actuator controls over time: a time_s column [s] and one column "
            "per actuator named as in the model (a position servo's target [m] or [rad]), "
            "linearly interpolated. Default for the example: its own motion; else none "
            "(every control 0).",
        ),
    ] = None,
    flat_radius_mm: Annotated[
        float,
        typer.Option(
            "--flat-radius-mm",
            min=0.01,
            max=1000.0,
            help="Radius of the sphere each contact point of a flat body (box, plane, mesh) "
            "stands for [mm], 0.01-1000.",
        ),
    ] = 1.6,
    flaws: Annotated[
        str,
        typer.Option(
            help="Per-frame flaws to switch on: 'all', 'none' or a comma list of "
            "gain_spread, noise, quantization, dead, crosstalk, nonlinearity (the flaws "
            "with memory need a frame sequence and are left out)."
        ),
    ] = "all",
    seed: Annotated[
        int | None, typer.Option(min=0, help="Seed of the read noise, for a repeatable run.")
    ] = 0,
    frames_path: Annotated[
        str,
        typer.Option(
            "--frames-path",
            metavar="[auto|fast|reference]",
            help="How the frames are made from the contacts: 'fast' (the kind's tabulated "
            "response: a one-off start-up per run, then many times faster), 'reference' "
            "(the kind's own model frame by frame: no start-up), or 'auto' (fast from "
            "20,000 frames on; docs/performance.md has the figures).",
        ),
    ] = "auto",
    quiet: Annotated[bool, typer.Option("--quiet", "-q", help="No progress bar.")] = False,
    force: Annotated[bool, typer.Option("--force", help="Replace OUT if it exists.")] = False,
) -> None:
    """Step a MuJoCo model and write a tactile sensor's frames, made from the model's
    contacts on a geom (or site) at the sensor's scan rate, as a recording that
    'locate', 'view' and 'export' read; MuJoCo's contacts are its truth."""
    from tactsense.interop import mujoco as adapter
    from tactsense.sensor import load_sensor

    examples = {
        "gripper": (adapter.example_model_path(), "pad", "pad16"),
        "fingertip": (adapter.fingertip_model_path(), "finger", "initial"),
    }
    # ---- the three-axis slip example (r8-mjslip) ----
    from tactsense.interop.mujoco_shear import slip_model_path

    examples["slip"] = (slip_model_path(), "pad", "mag4x4")
    # ---- /r8-mjslip ----
    if example not in examples:
        fail(f"--example {example}: expected one of {', '.join(examples)}")
    if model is None:
        model_path, mount, preset = examples[example]
        if geom is None and site is None:
            geom = mount
        if controls is None:
            controls = model_path.with_suffix(".csv")
        sensor = sensor or preset
    else:
        model_path = model
        sensor = sensor or "pad16"
    inputs = [model_path, controls, *sensor_file(sensor)]
    check_output(out, force, inputs=inputs)
    if out.suffix.lower() not in (".h5", ".hdf5"):
        fail(f"--out {out}: a recording is an HDF5 file; use the extension .h5 (or .hdf5)")
    if geom is None and site is None:
        fail("say which geom the sensor covers (--geom NAME) or its site (--site NAME)")
    if geom is not None and site is not None:
        fail("--geom and --site are two mounts; give one")
    if seconds is not None and seconds <= 0:
        fail(f"--seconds {seconds:g}: expected a time above 0 [s]")
    paths = {"auto": None, "fast": True, "reference": False}
    if frames_path not in paths:
        fail(f"--frames-path {frames_path}: expected one of {', '.join(paths)}")
    spec = load_sensor(sensor)
    mj_model = adapter.load_model(model_path)
    table = adapter.read_controls(controls, mj_model) if controls is not None else None
    mount = adapter.MujocoSensor(
        mj_model, spec, geom=geom, site=site, flat_radius_mm=flat_radius_mm
    )
    note = mount.size_note()
    if note is not None:
        console.print(f"[yellow]note:[/] {note}", soft_wrap=True, markup=True, emoji=False)
    for warning in rest_warnings(spec):  # trial8 (r8-fixa8): a rest reading on the rail
        console.print(f"warning: {warning}", soft_wrap=True, markup=False, highlight=False)
    if seconds is None:
        seconds = float(table.time_s[-1]) if table is not None and table.time_s[-1] > 0 else 1.0
    n = adapter.frame_count(spec, seconds)
    adapter.active_flaws(flaws)  # a bad name is an error before the work
    with progress_bar("stepping", unit="frames", quiet=quiet) as bar:
        task = bar.add_task("mujoco", total=n)
        with atomic_output(out) as temporary:
            written = adapter.record_mujoco(
                temporary,
                mount,
                seconds=seconds,
                controls=table,
                flaws=flaws,
                rng=seed,
                model_path=model_path,
                progress=lambda done, total: bar.update(task, completed=done),
                fast=paths[frames_path],
            )
    console.print(
        f"wrote {out}: {written} frames of {frame_text(spec)} counts at "
        f"{spec.electronics.scan_rate_hz:g} Hz ({spec.name} on "
        f"{'geom' if geom else 'site'} {geom or site} of {Path(model_path).name}, "
        f"{round(seconds / mj_model.opt.timestep)} MuJoCo steps)"
    )
