"""Commands on the model: ``simulate``, ``info`` and ``sensor show|check``."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import numpy as np
import typer
from rich.table import Table

from tactsense._validation import TactsenseInputError
from tactsense.cli import _robot_sensor  # r7-skin
from tactsense.cli import _scenario as scenario_options  # r8-triphys: the shear options
from tactsense.cli._common import (
    SensorOption,
    atomic_output,
    check_output,
    checked_sensor,
    console,
    fail,
    frame_text,
    new_group,
    print_table,
    rest_warnings,
    same_file,
    sensor_file,
    threshold_rule,
)
from tactsense.cli._scenario import (
    AngleOption,
    ColOption,
    DwellOption,
    FlawsOption,
    ForceGOption,
    ForcesGOption,
    IncrementOption,
    IndenterOption,
    LiftOption,
    RepeatsOption,
    RowOption,
    ScenarioKind,
    ScenarioOption,
    SeedOption,
    SeparationOption,
    SizeOption,
    SpeedOption,
    XOption,
    YOption,
    build_scenario,
    resolve_scenario,
    run_scenario,
)
from tactsense.io.recording import read_recording
from tactsense.kinds import kind_of
from tactsense.sensor import load_sensor

app = new_group("Simulate the finger and describe recordings.")
sensor_app = new_group("Show, export and check sensor descriptions.")


@app.command()
def simulate(
    out: Annotated[Path, typer.Option("--out", "-o", help="HDF5 recording to write.")] = Path(
        "sweep.h5"
    ),
    sensor: SensorOption = "initial",
    scenario: ScenarioOption = None,
    row: RowOption = None,
    col: ColOption = None,
    force_g: ForceGOption = None,
    increment: IncrementOption = None,
    dwell_s: DwellOption = None,
    lift_s: LiftOption = None,
    repeats: RepeatsOption = None,
    x_mm: XOption = None,
    y_mm: YOption = None,
    separation_mm: SeparationOption = None,
    indenter: IndenterOption = None,
    size_mm: SizeOption = None,
    speed_mm_s: SpeedOption = None,
    angle_deg: AngleOption = None,
    forces_g: ForcesGOption = None,
    shear_ratio: scenario_options.ShearRatioOption = None,  # r8-triphys
    shear_angle_deg: scenario_options.ShearAngleOption = None,  # r8-triphys
    friction: scenario_options.FrictionOption = None,  # r8-triphys
    ramp_s: scenario_options.RampOption = None,  # r8-triphys
    flaws: FlawsOption = "all",
    seed: SeedOption = 0,
    forward: Annotated[
        str,
        typer.Option(
            "--forward",
            metavar="[twin|finger3d|finger3d-foam]",
            help="The finger's elastic model. 'twin': the paper's (plane stress along the "
            "finger, ring spreading around), what the estimators assume. 'finger3d': the "
            "solid 3-D skin with its hemispherical tip (finite elements, tabulated, with the "
            "twin's rings), which reads far less than the twin: to test estimators on a skin "
            "structurally unlike the one they assume. 'finger3d-foam': the same "
            "skin on the paper's foam dielectric, which reads more and is the closest to the "
            "paper's finger. The two 3-D models take probes and the knife edge only, on "
            "fingers only (docs/model.md, sections 3b-3d; docs/accuracy.md).",
        ),
    ] = "twin",
    plot: Annotated[
        Path | None,
        typer.Option(help="Also draw the swept tactels' responses to this PNG (sweeps only)."),
    ] = None,
    force_log: Annotated[
        Path | None,
        typer.Option(
            "--force-log",
            help="Also write the force applied in each frame (jitter included) as a load "
            "cell's log: a CSV of time_s [s, the recording's clock] and force_n [N], the "
            "file 'calibrate --force-log' reads (with --scenario loads: the force curve's "
            "data). Extension .csv.",
        ),
    ] = None,
    force: Annotated[
        bool,
        typer.Option("--force", help="Replace OUT, PLOT and FORCE_LOG if they already exist."),
    ] = False,
) -> None:
    """Simulate a sensor (a finger, a pad or a point set) under a scenario and write an
    HDF5 recording of A/D frames."""
    from tactsense.plotting import check_plot_format, plot_sweep

    try:
        spec = load_sensor(sensor)
        for target in (out, plot, force_log):
            if target is not None:
                check_output(target, force, inputs=sensor_file(sensor))
        if plot is not None and same_file(plot, out):
            fail(f"--plot {plot} and --out {out} are the same file; choose two names")
        if force_log is not None:
            if same_file(force_log, out) or (plot is not None and same_file(force_log, plot)):
                fail(f"--force-log {force_log} is the same file as --out or --plot; "
                     "choose another name")  # fmt: skip
            if force_log.suffix.lower() != ".csv":
                fail(f"--force-log {force_log}: the load cell's log is a CSV file; use the "
                     "extension .csv")  # fmt: skip
        if plot is not None:
            check_plot_format(plot)
        kind_of(spec).check_forward(spec, forward)
        scenario = resolve_scenario(spec, scenario)
        if plot is not None and scenario not in (
            ScenarioKind.sweep_axial,
            ScenarioKind.sweep_around,
        ):
            fail(
                "--plot draws a finger's sweeps along or around; not available for "
                f"--scenario {scenario.value} (view a pad's recording with 'tactsense view')"
            )
        scene = build_scenario(
            spec, scenario, row=row, col=col, force_g=force_g, increment=increment,
            dwell_s=dwell_s, lift_s=lift_s, repeats=repeats, x_mm=x_mm, y_mm=y_mm,
            separation_mm=separation_mm, indenter=indenter, size_mm=size_mm,
            speed_mm_s=speed_mm_s, angle_deg=angle_deg, forces_g=forces_g,
            shear=dict(shear_ratio=shear_ratio, shear_angle_deg=shear_angle_deg,
                       friction=friction, ramp_s=ramp_s),  # r8-triphys
        )  # fmt: skip
        if out.suffix.lower() not in (".h5", ".hdf5"):
            fail(
                f"--out {out}: a recording is an HDF5 file; use the extension .h5 (or "
                ".hdf5). Other formats come from 'tactsense export' or 'locate'"
            )
        for warning in rest_warnings(spec):  # trial8 (r8-fixa8): a rest reading on the rail
            console.print(f"warning: {warning}", soft_wrap=True, markup=False, highlight=False)
        # frames go to the file as they are made: memory stays flat however long
        with atomic_output(out) as temporary:
            written = run_scenario(spec, scene, flaws=flaws, seed=seed, path=temporary,
                                   forward=forward)  # fmt: skip
        model = {
            "finger3d": ", the 3-D skin's response",
            "finger3d-foam": ", the 3-D skin on the foam dielectric",
        }.get(forward, "")
        console.print(
            f"wrote {out}: {written} frames of {frame_text(spec)} counts at "
            f"{spec.electronics.scan_rate_hz:g} Hz ({spec.name}{model})"
        )
        if force_log is not None:
            with atomic_output(force_log) as temporary:
                rows = write_force_log(out, temporary)
            console.print(f"wrote {force_log}: the applied force of {rows} frames")
        if plot is not None:  # a sweep: a few hundred frames, read back whole
            with atomic_output(plot) as temporary:
                plot_sweep(read_recording(out), temporary)
            console.print(f"wrote {plot}")
    except (TactsenseInputError, FileExistsError) as error:
        fail(str(error))


def write_force_log(recording: Path, path: Path, chunk: int = 65_536) -> int:
    """Write a simulated recording's applied force per frame as a load cell's CSV log.

    Columns ``time_s`` (the frame's time on the recording's clock [s]) and ``force_n``
    (the total force of the step the frame reads, jitter included [N]), the format
    :func:`tactsense.estimate.contacts.array_calibration.read_force_log` reads; read from the
    file's truth in pieces (memory stays flat). Returns the number of rows.
    """
    import csv

    import h5py

    with h5py.File(recording, "r") as h5:
        force = np.asarray(h5["truth/step_force_n"][()], dtype=float)
        steps, times = h5["truth/frame_step"], h5["time"]
        with open(path, "w", newline="", encoding="utf-8") as stream:
            writer = csv.writer(stream)
            writer.writerow(["time_s", "force_n"])
            for start in range(0, len(times), chunk):
                t = times[start : start + chunk]
                f = np.nan_to_num(force[steps[start : start + chunk]])
                writer.writerows(zip((f"{v:.9g}" for v in t), (f"{v:.9g}" for v in f),
                                     strict=True))  # fmt: skip
        return len(times)


@app.command()
def info(
    recording: Annotated[
        Path, typer.Argument(help="HDF5 recording, or a robot recording (a folder), to describe.")
    ],
) -> None:
    """Describe a recording: sensor, scenario, frames and their range."""
    import json

    from tactsense.cli._info_components import ComponentRanges  # r8-triwire
    from tactsense.io.recording import RecordingReader
    from tactsense.io.robot_recording import is_robot_recording  # r7-fixc

    if is_robot_recording(recording):  # r7-fixc: a robot recording (a folder)
        from tactsense.cli._robot_io import robot_info

        return robot_info(recording)
    try:
        # streamed in blocks of the file's chunks: memory stays flat however long it is
        with RecordingReader(recording) as reader:
            n, spec = reader.n_frames, reader.sensor
            low, high, bad, finite_seen = np.inf, -np.inf, 0, False
            for _, frames, _ in (ranges := ComponentRanges(spec)).watch(reader.chunks()):
                if frames.dtype.kind == "f":
                    finite = np.isfinite(frames)
                    bad += int(np.count_nonzero(~finite.reshape(len(frames), -1).all(axis=1)))
                    frames = frames[finite]
                if frames.size:
                    finite_seen = True
                    low, high = min(low, frames.min()), max(high, frames.max())
            last = reader.time_s(n - 1, n) if n else np.zeros(0)
            first = reader.time_s(0, 1) if n else np.zeros(0)  # r7-fixc
            attrs = reader.attrs
            losses = reader.losses
            closed_cleanly = reader.closed_cleanly
    except TactsenseInputError as error:
        fail(str(error))
    try:
        scenario = json.loads(str(attrs.get("scenario_json", "{}")))
    except json.JSONDecodeError as error:
        fail(f"{recording}: scenario metadata is not valid JSON ({error})")
    source = str(attrs.get("source", ""))
    flaws = [f for f in str(attrs.get("flaws", "")).split(",") if f]
    table = Table(title=str(recording), show_header=False)
    table.add_row("sensor", spec.name)
    table.add_row("frames", f"{n} x {' x '.join(map(str, spec.frame_shape))} counts")  # r8-triwire
    # r7-fixc: from the first frame (a device clock need not start at 0)
    duration = float(last[-1] - first[0]) + spec.scan_period_s if n else 0.0
    table.add_row("duration", f"{duration:.3f} s at {spec.electronics.scan_rate_hz:g} Hz")
    if finite_seen:
        counts = f"{low:g} .. {high:g}"
        if bad:
            counts += f" ({bad} frames hold NaN or infinite readings)"
    else:
        counts = "none (no frames)" if n == 0 else "none finite"
    table.add_row("counts", counts)
    ranges.add_rows(table)  # r8-triwire: the components per taxel and each one's range
    if source:
        table.add_row("source", source)
    if losses:
        lost = ", ".join(f"{k} {v}" for k, v in losses.items() if v) or "none"
        table.add_row("losses", lost)
    if not closed_cleanly:
        table.add_row("state", "not closed by its writer (killed?): frames up to its last flush")
    table.add_row("scenario", str(scenario.get("description", "")))
    # a simulation lists the flaws it switched on; a device's flaws are not known
    table.add_row("flaws", ", ".join(flaws) or ("unknown (a device)" if source else "none"))
    print_table(table)


@sensor_app.command("show")
def sensor_show(
    what: _robot_sensor.WhatArgument = None,  # r7-skin
    sensor: _robot_sensor.SkinOrSensorOption = "initial",  # r7-skin
    out: Annotated[
        Path | None, typer.Option("--out", "-o", help="Write the TOML here instead of printing it.")
    ] = None,
    force: Annotated[bool, typer.Option("--force", help="Replace OUT if it exists.")] = False,
) -> None:
    """Print a sensor description as TOML: a starting point for describing your own finger.

    A robot skin (a skin preset such as hand4, a skin TOML or a URDF with several sensors):
    its patches (link, pose: xyz [mm], rpy [deg], kind, taxels, rate, device), totals and
    moving joints with limits; --out writes its TOML. 'sensor show hand4' = --sensor hand4."""
    # ---- robot skins (r7-skin) ----
    sensor = _robot_sensor.one_sensor(what, sensor)
    if _robot_sensor.is_skin(sensor):
        return _robot_sensor.show_skin(sensor, out, force)
    # ---- /r7-skin ----
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


def _preset_row(name: str, spec) -> tuple[str, str, str, str, str]:
    """(name, kind, size, pitch, one-line description) of a preset, for ``sensor list``."""
    size, pitch = kind_of(spec).size_text(spec)
    first = spec.description.split(". ")[0].rstrip(".")
    return name, spec.kind, size, pitch, first


@sensor_app.command("list")
def sensor_list() -> None:
    """List the built-in presets: name, kind, size, pitch and what each is."""
    from tactsense.sensor import PRESETS

    table = Table(title="built-in sensors (tactsense sensor show --sensor NAME prints one as TOML)")
    for column in ("name", "kind", "size", "pitch", "description"):
        table.add_column(column)
    for name, make in PRESETS.items():
        table.add_row(*_preset_row(name, make()))
    print_table(table)
    # ---- robot skins (r7-skin) ----
    print_table(_robot_sensor.skin_list_table())
    # ---- /r7-skin ----


@sensor_app.command("check")
def sensor_check(
    path: Annotated[
        Path,
        typer.Argument(
            help="Sensor TOML file to validate, or a robot skin (a skin preset such as hand4, "
            "a skin TOML or a URDF with several sensors)."
        ),
    ],
    probe_g: Annotated[
        float | None,
        typer.Option(
            "--probe-g",
            min=1e-3,
            max=1e5,
            help="Pads: the load of the 3.2-mm sphere probe the blind-spot check presses "
            "everywhere on the pad [g] [default: 50].",
        ),
    ] = None,
) -> None:
    """Validate a sensor TOML file (finger, pad or point set) and print its derived
    quantities; on a pad, warn of blind spots: places where a --probe-g press moves no
    taxel's reading by more than three times its noise (read noise and quantization).
    A robot skin: the skin's problems and each sensor's, then warnings (a board reading
    patches at different rates, taxels of two patches on top of each other)."""
    # ---- robot skins (r7-skin) ----
    if _robot_sensor.is_skin(path):
        if probe_g is not None:
            fail("--probe-g maps the blind spots of one pad; give a pad, not a robot skin")
        return _robot_sensor.check_skin(path)
    # ---- /r7-skin ----
    try:
        spec = checked_sensor(path)  # a preset's name too, as 'sensor show' (trial 8)
    except TactsenseInputError as error:
        fail(str(error))
    table = Table(title=f"{spec.name}: valid", show_header=False)
    for label, value in spec.summary():
        table.add_row(label, value)
    warnings = []
    kind = kind_of(spec)
    layer = kind.design_model == "layer"  # blind spots are mapped with the layer model
    if not layer and probe_g is not None:
        fail(f"--probe-g maps the blind spots of a pad; {spec.name!r} is a {kind.label}")
    if kind.multi_contact and kind.contact_estimation:  # locate's threshold (r8-triphys)
        from tactsense.estimate.contacts import default_threshold, threshold_counts

        table.add_row(
            "contact threshold",
            f"{threshold_counts(spec):.3g} counts from the rest, signal "
            f"{default_threshold(spec):.3g} (locate's default: {threshold_rule(spec)})",
        )
    if layer:
        label, value, warnings = _blind_spot_report(spec, 50.0 if probe_g is None else probe_g)
        table.add_row(label, value)
    warnings += rest_warnings(spec)  # trial8 (r8-fixa8): a rest reading on the rail
    print_table(table)
    for warning in warnings:
        console.print(
            f"warning: {warning}", soft_wrap=True, markup=False, highlight=False, emoji=False
        )


def _blind_spot_report(spec, probe_g: float) -> tuple[str, str, list[str]]:
    """A pad's blind spots for a ``probe_g`` press: (table label, value, warnings)."""
    from tactsense.analysis.pad_bound import blind_spots, signal_map
    from tactsense.estimate.contacts import default_threshold
    from tactsense.physics.contact import grams_force

    force = grams_force(probe_g)
    found = blind_spots(spec, force)
    threshold = found["threshold_counts"]
    label = f"blind spots ({probe_g:g}-g probe)"
    warnings = []
    if not found["regions"]:
        value = (
            f"none: every place moves a taxel by at least {found['weakest_change_counts']:.3g} "
            f"counts (threshold {threshold:.3g}, 3 x the reading noise)"
        )
    else:
        regions = found["regions"]
        biggest = regions[0]
        value = (
            f"{100 * found['blind_fraction']:.1f} % of the pad ({found['blind_area_mm2']:.3g} "
            f"mm^2) in {len(regions)} regions"
        )
        where = "; ".join(
            f"({r['centre_mm'][0]:.3g}, {r['centre_mm'][1]:.3g}) mm" for r in regions[:6]
        ) + ("; and more" if len(regions) > 6 else "")
        warnings.append(
            f"{spec.name!r} does not see a {probe_g:g}-g press (3.2-mm sphere) on "
            f"{100 * found['blind_fraction']:.1f} % of its area ({found['blind_area_mm2']:.3g} "
            f"mm^2): there no taxel's reading moves by more than {threshold:.3g} counts "
            f"(3 x its noise). {len(regions)} blind regions, the largest "
            f"{biggest['area_mm2']:.3g} mm^2 ({biggest['extent_mm'][0]:.3g} x "
            f"{biggest['extent_mm'][1]:.3g} mm), centred at {where}. A finer pitch closes "
            "them ('tactsense design sweep' maps depth against pitch)"
        )
    # what locate needs: a rise above its contact threshold
    _, _, _, rise = signal_map(spec, force)
    level = default_threshold(spec)
    if spec.transduction.kind != "capacitive":
        needed = level * spec.transduction.counts_per_strain
    else:  # the signal is (V - V_o) / V: a rise of level V_o / (1 - level)
        needed = level * spec.electronics.nominal_counts / (1.0 - level)
    weak = float(np.mean(rise < needed))
    if weak > found["blind_fraction"] + 1e-9:
        warnings.append(
            f"on {100 * weak:.1f} % of {spec.name!r} a {probe_g:g}-g press raises no taxel "
            f"above locate's contact threshold ({needed:.3g} counts): it is seen but not "
            "found as a contact"
        )
    return label, value, warnings


@sensor_app.command("import")
def sensor_import(
    path: Annotated[
        Path,
        typer.Argument(
            help="URDF file with a tactile toolbox <sensor><tactile> (an <array> or a <taxel> "
            'list), or a JSON list of taxels [{"xyz": [x, y, z], "normal": [nx, ny, nz], '
            '"area": a}] in mm and mm^2.'
        ),
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
        str | None,
        typer.Option(
            help="Preset giving what the file does not say (the elastic layer, electronics, "
            "flaws, ...), and the kind: a finger preset (initial, improved; row 0 a tip row) "
            "or a pad preset (pad4, pad16, pad12x32) for an <array>; a point-set preset "
            "(dome12) for a <taxel> list or JSON. Default: initial for an <array>, dome12 "
            "for taxels."
        ),
    ] = None,
    force: Annotated[bool, typer.Option("--force", help="Replace OUT if it exists.")] = False,
) -> None:
    """Read a URDF tactile sensor (ROS tactile toolbox) or a JSON taxel list into a sensor
    description (TOML).

    An <array> gives rows, columns, both spacings, the taxel size and the update rate (a
    finger: along it and the arc around it at the skin's surface; a pad: along x and y); a
    <taxel idx xyz rpy> list or a JSON list gives each taxel's position, normal and area
    (a point set). The rest comes from the preset named by --extends.
    """
    from tactsense.interop.urdf import sensor_from_urdf_any
    from tactsense.sensor import PRESETS, preset, sensor_from_dict, taxels_from_json

    if out is not None:
        check_output(out, force, inputs=[path])
    try:
        if extends is not None and extends.removeprefix("fearing1990_") not in PRESETS:
            fail(f"--extends {extends!r} is not a preset; available: {', '.join(PRESETS)}")
        if path.suffix.lower() == ".json":
            base = preset(extends or "dome12")
            if "taxels" not in base.SECTIONS:  # a kind described taxel by taxel
                fail(
                    f"--extends {extends} is a {kind_of(base).label}; a JSON taxel list is a "
                    "point set"
                )
            data = base.to_dict()
            taxels = taxels_from_json(path)
            data["name"] = name or path.stem
            data["description"] = f"imported from {path.name} (JSON taxel list), on {base.name}"
            data["taxels"] = {
                "positions_mm": [list(p) for p in taxels.positions_mm],
                "normals": [list(n) for n in taxels.normals],
                "area_mm2": list(taxels.area_mm2),
            }
            spec = sensor_from_dict(data, source=str(path))
        else:
            spec = sensor_from_urdf_any(path, name=name, extends=extends)
        if out is None:
            typer.echo(spec.to_toml_string())
        else:
            with atomic_output(out) as temporary:
                spec.to_toml(temporary)
            console.print(f"wrote {out}: {spec.name}, {spec.kind}, frames of {spec.frame_shape}")
    except (TactsenseInputError, FileExistsError) as error:
        fail(str(error))


@sensor_app.command("export")
def sensor_export(
    sensor: _robot_sensor.SkinOrSensorOption = "initial",  # r7-skin: lists skin presets
    urdf: Annotated[
        bool,
        typer.Option(
            "--urdf", help="Write the URDF tactile array (as --format urdf; one is required)."
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
    # ---- robot skins (r7-skin) ----
    fmt: Annotated[
        str | None,
        typer.Option(
            "--format",
            help="What to write: 'urdf' (as --urdf) or, for a robot skin (a skin preset such "
            "as hand4, a skin TOML or a URDF), 'toml' (the skin's TOML, every sensor whole) or "
            "'urdf' (every link, joint and sensor). Required for a robot skin.",
        ),
    ] = None,
    # ---- /r7-skin ----
) -> None:
    """Write a sensor as a URDF tactile description for ROS (RViz's tactile display).

    A pad as an <array> (rows along x, columns along y); a finger or a point set as a
    <taxel idx xyz rpy> list, each taxel on the skin at its real position and normal (a
    finger: x along it); metres; the data vector is a tactsense frame, row-major. A robot
    skin: --format toml or urdf (its links, joints and every sensor).
    """
    from tactsense.interop.urdf import sensor_to_urdf

    # ---- robot skins (r7-skin) ----
    if _robot_sensor.is_skin(sensor):
        return _robot_sensor.export_skin(
            sensor, "urdf" if urdf and fmt is None else fmt, out, force
        )
    if fmt is not None and fmt != "urdf":
        fail(
            f"--format {fmt!r}: one sensor is exported as urdf ('tactsense sensor show' "
            "prints its TOML)"
        )
    urdf = urdf or fmt == "urdf"
    # ---- /r7-skin ----
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
