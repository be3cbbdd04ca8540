"""``tactsense design``: the paper's design questions (section 5 and 6)."""

from __future__ import annotations

from enum import StrEnum
from pathlib import Path
from typing import Annotated

import numpy as np
import typer
from rich.table import Table

from tactsense._validation import TactsenseInputError
from tactsense.cli._common import (
    SensorOption,
    fail,
    new_group,
    print_table,
    progress_bar,
    same_file,
)
from tactsense.kinds import KindNotSupported, kind_of, kinds
from tactsense.physics.contact import grams_force
from tactsense.sensor import load_sensor

app = new_group("Design questions: capacitor gain in the skin, aliasing, the Cramer-Rao bound.")


@app.command("aliasing")
def design_aliasing(
    depth: Annotated[
        float, typer.Option(min=1e-3, max=1e3, help="Sensor depth d below the surface, in mm.")
    ] = 3.8,
    spacing: Annotated[
        float, typer.Option(min=1e-3, max=1e3, help="Sensor spacing b, in mm.")
    ] = 3.8,
    poisson: Annotated[
        float,
        typer.Option(
            min=-0.999,
            max=0.5,
            help="Poisson's ratio of the plane-stress model (the paper's fit: "
            "0.4; the rubber: 0.5).",
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
        fail(str(error))
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
    print_table(table)


@app.command("bound")
def design_bound(
    axial: Annotated[
        float | None,
        typer.Option(
            min=-1e3,
            max=1e3,
            help="Fingers: probe position along the finger, arc length from the "
            "junction of tip and cylinder, in mm [default: 12.5].",
        ),
    ] = None,
    angle: Annotated[
        float | None,
        typer.Option(
            min=-360.0,
            max=360.0,
            help="Fingers: probe angle around the finger, in deg [default: 0].",
        ),
    ] = None,
    x_mm: Annotated[
        float | None,
        typer.Option(
            "--x-mm",
            min=-1e4,
            max=1e4,
            help="Pads: where the probe presses, along x (the rows) [mm] [default: the middle].",
        ),
    ] = None,
    y_mm: Annotated[
        float | None,
        typer.Option(
            "--y-mm",
            min=-1e4,
            max=1e4,
            help="Pads: where the probe presses, along y (the columns) [mm] [default: the middle].",
        ),
    ] = None,
    force_g: Annotated[
        float, typer.Option(min=1e-3, max=1e5, help="Probe load in grams-force.")
    ] = 50.0,
    diameter: Annotated[
        float | None,
        typer.Option(
            min=1e-3,
            max=100.0,
            help="Fingers: contact diameter of the hemispherical probe, in mm [default: 3]; "
            "pads: the sphere's diameter, in mm [default: 3.2, the paper's probe].",
        ),
    ] = None,
    sensor: SensorOption = "initial",
    as_json: Annotated[
        bool, typer.Option("--json", help="Print the result as JSON instead of a table.")
    ] = False,
    noise_fs: Annotated[
        float | None,
        typer.Option(
            "--noise-fs",
            min=0.001,
            max=50.0,
            help="Pads: the realistic read noise the bounds are also given at, in % of the "
            "converter's full scale, 0.001-50 [default: 1, the lower end of 1-2 % for "
            "piezoresistive arrays; Interlink FSR 400 data sheet: +-2 % repeatability].",
        ),
    ] = None,
) -> None:
    """Cramer-Rao lower bound on contact position and force at the sensor's reading noise
    (a finger, or a pad: a sphere at --x-mm, --y-mm; pads also give the censored
    (one-sided) bound and the Bayesian bound over the taxel cell, at the preset's noise
    and at --noise-fs)."""
    try:
        spec = load_sensor(sensor)
        kind = kind_of(spec)
        if kind.design_model == "layer":  # the layer model's bound: a sphere at (x, y)
            for flag, value in (("--axial", axial), ("--angle", angle)):
                if value is not None:
                    fail(f"{flag} is for fingers; {spec.name!r} is a {kind.label}: give "
                         "--x-mm, --y-mm")  # fmt: skip
            _pad_bound(spec, x_mm, y_mm, force_g, 3.2 if diameter is None else diameter,
                       as_json, 1.0 if noise_fs is None else noise_fs)  # fmt: skip
            return
        if kind.design_model != "paper":
            bounded = " and ".join(f"{k.name} sensors" for k in kinds().values() if k.design_model)
            raise KindNotSupported(f"design bound works on {bounded}; {spec.name!r} is a "
                                   f"{kind.label}")  # fmt: skip
        for flag, value in (("--x-mm", x_mm), ("--y-mm", y_mm), ("--noise-fs", noise_fs)):
            if value is not None:
                fail(f"{flag} is for pads; {spec.name!r} is a {kind.label}: give --axial, --angle")
    except TactsenseInputError as error:
        fail(str(error))
    _finger_bound(
        spec,
        12.5 if axial is None else axial,
        0.0 if angle is None else angle,
        force_g,
        3.0 if diameter is None else diameter,
        as_json,
    )


def _finger_bound(spec, axial, angle, force_g, diameter, as_json) -> None:
    import json

    from tactsense.analysis.bound import cramer_rao_bound, noise_variance

    try:
        bound = cramer_rao_bound(
            spec, axial, angle, grams_force(force_g), contact_diameter_mm=diameter
        )
    except TactsenseInputError as error:
        fail(str(error))
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
    print_table(table)


def _pad_bound(spec, x_mm, y_mm, force_g, diameter, as_json, noise_fs=1.0) -> None:
    """``design bound`` on a pad: a sphere of ``diameter`` mm at (x_mm, y_mm)."""
    import json

    from tactsense.analysis.pad_bound import cramer_rao_bound, noise_variance
    from tactsense.flat_scenarios import centre_mm

    kind = kind_of(spec)
    (row_pitch, rows), (col_pitch, cols) = kind.surface_grid(spec)
    cx, cy = centre_mm(spec)
    x = cx if x_mm is None else x_mm
    y = cy if y_mm is None else y_mm
    for flag, value, pitch, n, axis in (
        ("--x-mm", x, row_pitch, rows, "x"),
        ("--y-mm", y, col_pitch, cols, "y"),
    ):
        low, high = -0.5 * pitch, (n - 0.5) * pitch
        if not low <= value <= high:
            fail(f"{flag} {value:g} is off the {rows}x{cols} {kind.label} {spec.name!r}: "
                 f"{axis} runs from {low:g} to {high:g} mm")  # fmt: skip
    force = grams_force(force_g)
    try:
        bound = cramer_rao_bound(spec, x, y, force, radius_mm=0.5 * diameter)
    except TactsenseInputError:
        bound = None  # singular: the censored and Bayesian bounds below say more
    from tactsense.cli._pad_bounds import pad_bound_rows

    try:
        rows = pad_bound_rows(spec, x, y, force, 0.5 * diameter, noise_fs)
    except TactsenseInputError as error:
        fail(str(error))
    noise = float(np.sqrt(noise_variance(spec)))
    if as_json:
        inputs = {"x_mm": x, "y_mm": y, "force_n": force, "probe_diameter_mm": diameter,
                  "sensor": spec.name, "noise_counts": noise, "noise_fs_pct": noise_fs}  # fmt: skip
        finite = [  # strict JSON: a singular bound's infinities as null
            {k: (None if isinstance(v, float) and not np.isfinite(v) else v) for k, v in r.items()}
            for r in rows
        ]
        typer.echo(json.dumps({"inputs": inputs, "bound": bound, "bounds": finite}, indent=2))
        return
    table = Table(
        title=f"Cramer-Rao bound, {force_g:g} g ({diameter:g}-mm sphere) at ({x:g}, {y:g}) mm "
        f"on {spec.name}",
        show_header=False,
    )
    table.add_row("reading noise", f"{noise:.3f} counts RMS (read noise and quantization)")
    if bound is None:
        table.add_row("classic bound", "singular Fisher information (see the rank test below)")
    else:
        table.add_row("along x", f"{1e3 * bound['x_mm']:.3g} um ({bound['x_pitch']:.3g} pitch)")
        table.add_row("along y", f"{1e3 * bound['y_mm']:.3g} um ({bound['y_pitch']:.3g} pitch)")
        table.add_row(
            "force", f"{1e3 * bound['force_n']:.3g} mN ({100 * bound['force_relative']:.3g} %)"
        )
    print_table(table)
    from tactsense.cli._pad_bounds import bounds_table

    print_table(bounds_table(rows, spec.name))


class ElasticModel(StrEnum):
    plane_stress = "plane_stress"
    plane_strain = "plane_strain"


@app.command("strip")
def design_strip(
    thickness: Annotated[
        float,
        typer.Option(
            min=1e-3,
            max=1e3,
            help="Depth of the bottom capacitor plate below the skin surface "
            "(the skin thickness when the plate sits on the core), in mm.",
        ),
    ] = 3.8,
    separation: Annotated[
        float,
        typer.Option(
            min=1e-4,
            max=1e3,
            help="Nominal plate separation d_o, in mm; the top plate lies this "
            "far above the bottom one.",
        ),
    ] = 0.5,
    load: Annotated[
        float,
        typer.Option(
            min=1e-6,
            max=1e7,
            help="Load per unit length of the finger slab, in N/m (the paper: "
            "about 200 N/m for its calibration probe).",
        ),
    ] = 200.0,
    width: Annotated[
        float,
        typer.Option(
            min=1e-3,
            max=1e3,
            help="Width of the parabolic contact pressure, in mm (the paper's probe: 3 mm).",
        ),
    ] = 3.0,
    backing: Annotated[
        float,
        typer.Option(
            min=0.0,
            max=1e3,
            help="Elastic layer between the bottom plate and the rigid core, "
            "in mm (0: the plate sits on the core).",
        ),
    ] = 0.0,
    modulus: Annotated[
        float, typer.Option(min=1.0, max=1e12, help="Young's modulus of the skin, in Pa.")
    ] = 2.5e5,
    poisson: Annotated[
        float, typer.Option(min=-0.999, max=0.5, help="Poisson's ratio of the skin material.")
    ] = 0.5,
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
        fail(str(error))
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
    print_table(table)


def _grid(text: str, option: str, *, low: float, high: float) -> list[float]:
    """'START:STOP:COUNT' (evenly spaced, inclusive) or 'A,B,C' -> values within range."""
    try:
        if ":" in text:
            start, stop, count = text.split(":")
            n = int(count)
            if n < 1 or n > 10_000:
                raise ValueError
            values = np.linspace(float(start), float(stop), n).tolist()
        else:
            values = [float(v) for v in text.split(",") if v.strip()]
    except ValueError:
        fail(f"{option} {text!r}: expected START:STOP:COUNT (COUNT 1-10000) or A,B,C")
    if not values or not all(np.isfinite(v) and low <= v <= high for v in values):
        fail(f"{option} {text!r}: every value must lie in [{low:g}, {high:g}]")
    return values


@app.command("sweep")
def design_sweep_command(
    out: Annotated[
        Path,
        typer.Option(
            "--out", "-o", help="The map as NetCDF (an xarray Dataset; open with xarray)."
        ),
    ] = Path("design_map.nc"),
    depth: Annotated[
        str | None,
        typer.Option(
            help="Effective depths of a finger, or sensing depths of a pad (its layer's "
            "thickness scales with it) [mm]: START:STOP:COUNT or A,B,C (0.5-20) "
            "[default: 2:6:9 for a finger, 0.5:4:8 for a pad]."
        ),
    ] = None,
    spacing: Annotated[
        str | None,
        typer.Option(
            help="Tactel spacings along a finger, or a pad's pitch along both axes (its "
            "electrodes scale with it) [mm]: as --depth (0.5-20) [default: 2:3.8:7 for a "
            "finger, 1.5:5:8 for a pad]."
        ),
    ] = None,
    poisson: Annotated[
        str | None,
        typer.Option(
            help="Poisson's ratios: a finger's effective one, a pad's layer's: A,B,C (0-0.5) "
            "[default: 0.4 for a finger (the paper's fit), 0.5 for a pad (rubber)]."
        ),
    ] = None,
    force_g: Annotated[str, typer.Option(help="Probe loads [g]: A,B,C (0.1-10000).")] = "50",
    sensor: SensorOption = "initial",
    plot: Annotated[
        Path | None, typer.Option(help="Also draw the map (first ratio and load) to this PNG.")
    ] = None,
    workers: Annotated[
        int,
        typer.Option(
            min=0, max=256, help="Local Dask worker processes (0: compute here, one core)."
        ),
    ] = 0,
    force: Annotated[bool, typer.Option("--force", help="Replace OUT and PLOT.")] = False,
) -> None:
    """Map what section 6 trades off over a grid of designs: sensitivity, aliasing,
    interpolation ripple and the Cramer-Rao bound on position and force. The paper's
    two fingers are marked on the plot; for a pad (--sensor pad16), sensing depth x pitch
    with the pad presets marked."""

    from tactsense.analysis.sweep import design_map, design_sweep, plot_map
    from tactsense.cli._common import atomic_output, check_output, console, sensor_file

    check_output(out, force, inputs=sensor_file(sensor))
    if plot is not None:
        from tactsense.plotting import check_plot_format

        check_output(plot, force, what="plot", inputs=sensor_file(sensor))
        if same_file(plot, out):
            fail(f"--plot {plot} and --out {out} are the same file; choose two names")
        check_plot_format(plot)
    spec = load_sensor(sensor)
    try:
        mapped = design_map(spec)  # the kind's map; another kind has none
    except TactsenseInputError as error:
        fail(str(error))
    grid = mapped.grid
    depths = _grid(depth or grid["depth"], "--depth", low=0.5, high=20.0)
    spacings = _grid(spacing or grid["spacing"], "--spacing", low=0.5, high=20.0)
    ratios = _grid(poisson or grid["poisson"], "--poisson", low=0.0, high=0.5)
    loads = _grid(force_g, "--force-g", low=0.1, high=10_000.0)
    client = cluster = None
    if workers > 0:
        import logging

        from dask.distributed import Client, LocalCluster

        cluster = LocalCluster(
            n_workers=workers,
            threads_per_worker=1,
            dashboard_address="127.0.0.1:0",
            silence_logs=logging.ERROR,
        )
        client = Client(cluster)
        console.print(f"Dask dashboard: {client.dashboard_link}")
    try:
        with progress_bar("depths", eta=False) as bar:
            task = bar.add_task("sweep", total=len(depths))
            dataset = design_sweep(
                spec,
                depths,
                spacings,
                poisson_ratios=ratios,
                grams=loads,
                client=client,
                progress=lambda done, total: bar.update(task, completed=done, total=total),
            )
    finally:
        if client is not None:
            client.close()
            cluster.close()
    with atomic_output(out) as temporary:
        dataset.to_netcdf(temporary, engine="scipy")
    if plot is not None:
        designs, note = mapped.marks(spec, ratios[0])
        with atomic_output(plot) as temporary:
            plot_map(dataset, temporary, designs=designs, note=note)
    n = len(depths) * len(spacings) * len(ratios) * len(loads)
    fits = int(np.isfinite(dataset["xi"].values).sum())
    console.print(
        f"wrote {out}: {n} designs ({n - fits} do not fit the {kind_of(spec).label}: NaN)"
    )
