"""The ``tactsense`` command line: thin wrappers around the public functions."""

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
from tactsense.io.recording import read_recording, write_recording
from tactsense.physics.contact import grams_force
from tactsense.physics.flaws import FLAW_NAMES
from tactsense.sensor import SensorSpec, load_sensor

app = typer.Typer(
    no_args_is_help=True,
    add_completion=False,
    rich_markup_mode=None,
    help="tactsense: digital twin and analysis of the capacitive tactile finger of Fearing (1990).",
)
sensor_app = typer.Typer(
    no_args_is_help=True, rich_markup_mode=None, help="Show, export and check sensor descriptions."
)
app.add_typer(sensor_app, name="sensor")
design_app = typer.Typer(
    no_args_is_help=True,
    rich_markup_mode=None,
    help="Design questions: capacitor gain in the skin, aliasing, the Cramer-Rao bound.",
)
app.add_typer(design_app, name="design")

console = Console(stderr=True)

SensorOption = Annotated[
    str,
    typer.Option(
        "--sensor",
        help="Built-in finger ('initial': 3.8 mm x 45 deg, 'improved': 3.3 mm x 18 deg) "
        "or the path of a sensor TOML file.",
    ),
]


class ScenarioKind(StrEnum):
    sweep_axial = "sweep-axial"
    sweep_around = "sweep-around"
    repeated = "repeated"
    calibration = "calibration"
    knife = "knife-edge"


def _fail(message: str) -> None:
    console.print(f"[bold red]error:[/] {message}")
    raise typer.Exit(code=2)


@app.command()
def reproduce(
    out: Annotated[
        Path,
        typer.Option(
            "--out",
            "-o",
            help="New directory for the figures, report.md, report.html and results.json.",
        ),
    ] = Path("paper-report"),
    quick: Annotated[
        bool,
        typer.Option(
            help="Fewer positions and repetitions: a reduced run for tests and a first look."
        ),
    ] = False,
    sensor: SensorOption = "initial",
    force: Annotated[
        bool,
        typer.Option(
            "--force",
            help="Write into OUT even if it exists (its report files "
            "are replaced; nothing else in it is touched).",
        ),
    ] = False,
) -> None:
    """Run the paper's experiments on the digital twin and write the claims report."""
    from tactsense.reproduce import reproduce as run_reproduce

    try:
        spec = load_sensor(sensor)
        if out.exists() and not force:
            _fail(f"{out} exists; pass --force to write into it, or choose another directory")
        with Progress(
            TextColumn("{task.description:<36}"),
            BarColumn(),
            MofNCompleteColumn(),
            TimeRemainingColumn(),
            console=console,
            disable=None,
        ) as bar:
            task = bar.add_task("experiments", total=None)

            def update(name: str, done: int, total: int) -> None:
                bar.update(task, description=name, completed=done, total=total)

            result = run_reproduce(out, quick=quick, force=force, sensor=spec, progress=update)
    except (TactsenseInputError, FileExistsError) as error:
        _fail(str(error))
    claims = result["claims"].values()
    agree = sum(claim.verdict == "agrees" for claim in claims)
    table = Table(title=f"{len(result['figures'])} figures and {len(claims)} claims in {out}")
    for column in ("claim", "paper", "tactsense", "unit", "verdict"):
        table.add_column(column)
    for claim in claims:
        table.add_row(
            claim.id,
            "-" if claim.paper is None else f"{claim.paper:.4g}",
            f"{claim.computed:.4g}",
            claim.unit,
            claim.verdict,
        )
    Console().print(table)
    console.print(
        f"{agree} of {len(claims)} claims agree; open {out / 'report.html'} for the "
        "figures and the reasons behind each difference"
    )


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
                _fail(f"{target} exists; pass --force to replace it, or choose another name")
        if plot is not None and scenario not in (
            ScenarioKind.sweep_axial,
            ScenarioKind.sweep_around,
        ):
            _fail("--plot draws the sweeps along or around; not available for this scenario")
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
        _fail(str(error))


@app.command()
def locate(
    recording: Annotated[Path, typer.Argument(help="HDF5 recording to analyse.")],
    out: Annotated[
        Path, typer.Option("--out", "-o", help="CSV file to write, one row per frame.")
    ] = Path("estimates.csv"),
    baseline_frames: Annotated[
        int,
        typer.Option(
            help="Number of untouched frames at the start of the recording "
            "whose median is the undeflected reading V_o of eq. 4."
        ),
    ] = 5,
    threshold: Annotated[
        float,
        typer.Option(
            help="Smallest tactel deflection that counts as a contact, as a "
            "fraction (0.005 = 0.5 %, about 10 counts at 2000)."
        ),
    ] = 0.005,
    calibration: Annotated[
        Path | None,
        typer.Option(
            help="Calibration JSON from 'tactsense calibrate': its baseline, gains, "
            "excluded tactels and creep model are applied."
        ),
    ] = None,
    force: Annotated[bool, typer.Option("--force", help="Replace OUT if it exists.")] = False,
) -> None:
    """Locate the contact in every frame: position, force, skew and quality flags to CSV."""
    from tactsense.estimate import baseline_from, write_estimates_csv
    from tactsense.estimate import locate as run_locate

    try:
        if out.exists() and not force:
            _fail(f"{out} exists; pass --force to replace it, or choose another name")
        rec = read_recording(recording)
        if calibration is not None:
            from tactsense.estimate import Calibration

            calibrated = Calibration.load(calibration, rec.sensor)
            estimates = run_locate(
                rec.frames,
                rec.sensor,
                calibration=calibrated,
                frame_period_s=rec.sensor.scan_period_s,
                threshold=threshold,
            )
        else:
            baseline = baseline_from(rec.frames, baseline_frames)
            estimates = run_locate(rec.frames, rec.sensor, baseline=baseline, threshold=threshold)
        write_estimates_csv(out, estimates, rec.time_s, overwrite=force)
    except (TactsenseInputError, FileExistsError) as error:
        _fail(str(error))
    touched = int(np.count_nonzero(np.isfinite(estimates.row)))
    console.print(f"wrote {out}: {len(estimates)} frames, {touched} with a contact")


@app.command()
def calibrate(
    sweep: Annotated[
        Path,
        typer.Argument(
            help="Recording of a probe swept along every column (section 3.1), "
            "starting with untouched frames."
        ),
    ],
    out: Annotated[
        Path, typer.Option("--out", "-o", help="Calibration JSON file to write.")
    ] = Path("calibration.json"),
    probe_g: Annotated[
        float,
        typer.Option(
            help="Load of the sweeping probe in grams-force, for the "
            "sensitivity thresholds of Fig. 8."
        ),
    ] = 50.0,
    baseline_frames: Annotated[
        int, typer.Option(help="Untouched frames at the start of each recording.")
    ] = 5,
    steps: Annotated[
        Path | None,
        typer.Option(
            help="Recording of force steps on one tactel (Fig. 12): fit and store the "
            "creep model. Needs the recording's scenario (simulated) or clear on/off "
            "steps, which are then detected."
        ),
    ] = None,
    knife: Annotated[
        Path | None,
        typer.Option(
            help="Recording of a knife edge stepped past one tactel (section 4.1): "
            "fit and store depth and Poisson's ratio. Needs the recording's scenario "
            "for the edge positions."
        ),
    ] = None,
    row: Annotated[int, typer.Option(help="Row of the tactel under --steps and --knife.")] = 4,
    col: Annotated[int, typer.Option(help="Column of the tactel under --steps and --knife.")] = 0,
    force: Annotated[bool, typer.Option("--force", help="Replace OUT if it exists.")] = False,
) -> None:
    """Build a calibration (gains, baseline, dead/weak/noisy tactels, creep, model fit)."""
    from tactsense.estimate import calibrate as cal

    try:
        if out.exists() and not force:
            _fail(f"{out} exists; pass --force to replace it, or choose another name")
        rec = read_recording(sweep)
        calibration = cal.calibrate_sweep(
            rec.frames, rec.sensor, baseline_frames=baseline_frames, probe_grams=probe_g
        )
        if steps is not None:
            calibration.viscoelastic = _fit_steps(
                read_recording(steps), rec.sensor, row, col, baseline_frames
            )
        if knife is not None:
            calibration.model_fit = _fit_knife(
                read_recording(knife), rec.sensor, row, col, baseline_frames
            )
        calibration.save(out, overwrite=force)
    except (TactsenseInputError, FileExistsError) as error:
        _fail(str(error))
    table = Table(title=f"wrote {out}", show_header=False)
    gains = calibration.gains
    table.add_row("gain spread (max/min)", f"{gains.max() / gains.min():.2f}")
    finite = calibration.threshold_g[np.isfinite(calibration.threshold_g)]
    table.add_row(
        "threshold per A/D unit",
        f"mean {finite.mean():.2f} g, {finite.min():.2f}-{finite.max():.2f} g",
    )
    table.add_row(
        "dead / weak / noisy",
        f"{calibration.dead.sum()} / {calibration.weak.sum()} / {calibration.noisy.sum()}",
    )
    if calibration.viscoelastic is not None:
        v = calibration.viscoelastic
        table.add_row(
            "creep model",
            f"delayed {v.delayed_fraction:.3f} x "
            f"{1e3 * v.delayed_time_constant_s:.1f} ms, creep {v.creep_fraction:.3f} "
            f"x {v.creep_time_constant_s:.1f} s",
        )
    if calibration.model_fit is not None:
        m = calibration.model_fit
        table.add_row(
            "plane-stress fit",
            f"depth {m.depth_mm:.2f} mm, nu {m.poisson_ratio:.3f}, "
            f"RMS {m.rms_percent:.2f} % of full scale",
        )
    Console(stderr=True).print(table)


def _deflection_of(rec, row, col, baseline_frames):
    from tactsense.estimate import baseline_from
    from tactsense.physics.transduction import fractional_deflection

    rec.sensor.check_tactel(row, col)
    base = baseline_from(rec.frames, baseline_frames)
    return fractional_deflection(rec.frames.astype(float), base)[:, row, col]


def _fit_steps(rec, sensor, row, col, baseline_frames):
    from tactsense.estimate import calibrate as cal

    if rec.sensor != sensor:
        raise TactsenseInputError("the steps recording comes from another sensor than the sweep")
    rec.sensor.check_tactel(row, col)
    model, _, _ = cal.fit_viscoelastic_recording(rec, row, col, baseline_frames=baseline_frames)
    return model


def _fit_knife(rec, sensor, row, col, baseline_frames):
    from tactsense.estimate import calibrate as cal

    if rec.sensor != sensor:
        raise TactsenseInputError("the knife recording comes from another sensor than the sweep")
    if "step_axial_mm" not in rec.truth:
        raise TactsenseInputError(
            "the knife-edge fit needs the edge position of every step: this recording has no "
            "scenario truth"
        )
    signal = _deflection_of(rec, row, col, baseline_frames)
    last, steps = rec.last_loaded_frames(row, col)
    return cal.fit_plane_stress(rec.truth["step_axial_mm"][steps], signal[last])


@app.command()
def info(recording: Annotated[Path, typer.Argument(help="HDF5 recording to describe.")]) -> None:
    """Describe a recording: sensor, scenario, frames and their range."""
    try:
        rec = read_recording(recording)
    except TactsenseInputError as error:
        _fail(str(error))
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
        _fail(str(error))


@sensor_app.command("check")
def sensor_check(
    path: Annotated[Path, typer.Argument(help="Sensor TOML file to validate.")],
) -> None:
    """Validate a sensor TOML file and print its derived quantities."""
    try:
        spec = SensorSpec.from_toml(path)
    except TactsenseInputError as error:
        _fail(str(error))
    table = Table(title=f"{spec.name}: valid", show_header=False)
    table.add_row("frame shape (rows, cols)", f"{spec.shape}")
    table.add_row("closes the circumference", str(spec.closes_circumference))
    table.add_row("junction capacitance", f"{spec.junction_capacitance_f * 1e12:.3f} pF")
    table.add_row("ring flexural length", f"{spec.ring_flexural_length_mm:.3f} mm")
    Console().print(table)


@design_app.command("aliasing")
def design_aliasing(
    depth: Annotated[float, typer.Option(help="Sensor depth d below the surface, in mm.")] = 3.8,
    spacing: Annotated[float, typer.Option(help="Sensor spacing b, in mm.")] = 3.8,
    poisson: Annotated[
        float,
        typer.Option(
            help="Poisson's ratio of the plane-stress model (the paper's fit: "
            "0.4; the rubber: 0.5)."
        ),
    ] = 0.5,
    as_json: Annotated[
        bool, typer.Option("--json", help="Print the result as JSON instead of a table.")
    ] = False,
) -> None:
    """How much a sensor depth and spacing alias (section 6, eq. 45, Fig. 20)."""
    import json

    from tactsense.analysis.aliasing import aliasing_summary

    try:
        summary = aliasing_summary(depth, spacing, poisson)
    except (TactsenseInputError, ValueError) as error:
        _fail(str(error))
    if as_json:
        keys = {
            "depth": "depth_mm",
            "spacing": "spacing_mm",
            "peak_frequency": "peak_frequency_per_mm",
            "nyquist_frequency": "nyquist_frequency_per_mm",
        }
        typer.echo(json.dumps({keys.get(k, k): v for k, v in summary.items()}, indent=2))
        return
    table = Table(
        title=f"Aliasing at depth {depth:g} mm, spacing {spacing:g} mm", show_header=False
    )
    table.add_row("xi, energy lost outside the band (eq. 45)", f"{summary['xi']:.4f}")
    table.add_row("RMS amplitude error, sqrt(xi)", f"{summary['rms_amplitude_error']:.3f}")
    table.add_row("peak of H(s)", f"{summary['peak_frequency']:.4f} cycles/mm")
    table.add_row("H at the Nyquist frequency / H(0)", f"{summary['response_at_nyquist']:.3f}")
    table.add_row(
        "worst peak-position error, line load",
        f"{summary['worst_position_error_tactel']:.3f} tactel",
    )
    table.add_row(
        "worst peak-amplitude error, line load", f"{100 * summary['worst_amplitude_error']:.1f} %"
    )
    Console().print(table)


@design_app.command("bound")
def design_bound(
    axial: Annotated[
        float,
        typer.Option(
            help="Probe position along the finger, arc length from the "
            "junction of tip and cylinder, in mm."
        ),
    ] = 12.5,
    angle: Annotated[float, typer.Option(help="Probe angle around the finger, in deg.")] = 0.0,
    force_g: Annotated[float, typer.Option(help="Probe load in grams-force.")] = 50.0,
    diameter: Annotated[
        float, typer.Option(help="Contact diameter of the hemispherical probe, in mm.")
    ] = 3.0,
    sensor: SensorOption = "initial",
    as_json: Annotated[
        bool, typer.Option("--json", help="Print the result as JSON instead of a table.")
    ] = False,
) -> None:
    """Cramer-Rao lower bound on contact position and force at the sensor's reading noise."""
    import json

    from tactsense.analysis.bound import cramer_rao_bound, noise_variance

    try:
        spec = load_sensor(sensor)
        bound = cramer_rao_bound(
            spec, axial, angle, grams_force(force_g), contact_diameter_mm=diameter
        )
    except TactsenseInputError as error:
        _fail(str(error))
    if as_json:
        typer.echo(
            json.dumps(
                {
                    "inputs": {
                        "axial_mm": axial,
                        "angle_deg": angle,
                        "force_n": grams_force(force_g),
                        "sensor": spec.name,
                        "noise_counts": float(np.sqrt(noise_variance(spec))),
                    },
                    "bound": bound,
                },
                indent=2,
            )
        )
        return
    table = Table(
        title=f"Cramer-Rao bound, {force_g:g} g at ({axial:g} mm, {angle:g} deg) on {spec.name}",
        show_header=False,
    )
    table.add_row(
        "reading noise",
        f"{np.sqrt(noise_variance(spec)):.3f} counts RMS (read noise and quantization)",
    )
    table.add_row(
        "along the finger", f"{1e3 * bound['axial_mm']:.1f} um ({bound['row_tactel']:.4f} tactel)"
    )
    table.add_row(
        "around the finger",
        f"{bound['angle_deg']:.3f} deg "
        f"({bound['col_tactel']:.4f} tactel, {1e3 * bound['arc_mm']:.1f} um of arc)",
    )
    table.add_row(
        "force", f"{1e3 * bound['force_n']:.2f} mN ({100 * bound['force_relative']:.2f} %)"
    )
    Console().print(table)


class ElasticModel(StrEnum):
    plane_stress = "plane_stress"
    plane_strain = "plane_strain"


@design_app.command("strip")
def design_strip(
    thickness: Annotated[
        float,
        typer.Option(
            help="Depth of the bottom capacitor plate below the skin surface "
            "(the skin thickness when the plate sits on the core), in mm."
        ),
    ] = 3.8,
    separation: Annotated[
        float,
        typer.Option(
            help="Nominal plate separation d_o, in mm; the top plate lies this "
            "far above the bottom one."
        ),
    ] = 0.5,
    load: Annotated[
        float,
        typer.Option(
            help="Load per unit length of the finger slab, in N/m (the paper: "
            "about 200 N/m for its calibration probe)."
        ),
    ] = 200.0,
    width: Annotated[
        float,
        typer.Option(
            help="Width of the parabolic contact pressure, in mm (the paper's probe: 3 mm)."
        ),
    ] = 3.0,
    backing: Annotated[
        float,
        typer.Option(
            help="Elastic layer between the bottom plate and the rigid core, "
            "in mm (0: the plate sits on the core)."
        ),
    ] = 0.0,
    modulus: Annotated[float, typer.Option(help="Young's modulus of the skin, in Pa.")] = 2.5e5,
    poisson: Annotated[float, typer.Option(help="Poisson's ratio of the skin material.")] = 0.5,
    model: Annotated[
        ElasticModel,
        typer.Option(
            help="Two-dimensional elastic model; plane stress uses the "
            "paper's substitution nu/(1+nu)."
        ),
    ] = ElasticModel.plane_stress,
    as_json: Annotated[
        bool, typer.Option("--json", help="Print the result as JSON (SI units) instead of a table.")
    ] = False,
) -> None:
    """Capacitor gain of a plate pair in a skin bonded to the rigid core (section 5, Fig. 17)."""
    import json

    from tactsense.analysis import strip_capacitor_design

    try:
        result = strip_capacitor_design(
            thickness * 1e-3,
            separation * 1e-3,
            load,
            width * 1e-3,
            backing=backing * 1e-3,
            youngs_modulus=modulus,
            poisson_ratio=poisson,
            model=model.value,
        )
    except TactsenseInputError as error:
        _fail(str(error))
    values = {key: float(value) for key, value in result.items()}
    inputs = {
        "thickness_m": thickness * 1e-3,
        "separation_m": separation * 1e-3,
        "line_load_n_per_m": load,
        "width_m": width * 1e-3,
        "backing_m": backing * 1e-3,
        "youngs_modulus_pa": modulus,
        "poisson_ratio": poisson,
        "model": model.value,
    }
    if as_json:
        output = {
            "inputs": inputs,
            "gain": values["gain"],
            "top_plate_deflection_m": values["top_plate_deflection"],
            "bottom_plate_deflection_m": values["bottom_plate_deflection"],
            "surface_deflection_m": values["surface_deflection"],
            "closing_m": values["closing"],
        }
        typer.echo(json.dumps(output, indent=2))
        return
    table = Table(title="Capacitor in an elastic strip on a rigid core", show_header=False)
    table.add_row("gain dd/d_o (eq. 36)", f"{100 * values['gain']:.2f} %")
    table.add_row("plate closing dd", f"{1e6 * values['closing']:.2f} um")
    table.add_row("top plate deflection", f"{1e6 * values['top_plate_deflection']:.2f} um")
    table.add_row("bottom plate deflection", f"{1e6 * values['bottom_plate_deflection']:.2f} um")
    table.add_row("surface deflection", f"{1e6 * values['surface_deflection']:.2f} um")
    Console().print(table)


def main() -> None:
    """Entry point of the ``tactsense`` script."""
    app()
