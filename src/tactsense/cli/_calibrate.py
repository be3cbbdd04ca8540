"""``tactsense calibrate``: the calibration a sensor's kind takes, from recordings: the
paper's finger (a probe swept along every column, creep steps, a knife edge) or an
array's (a probe on every taxel, a uniform press, known weights)."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import numpy as np
import typer
from rich.console import Console
from rich.table import Table

from tactsense._validation import TactsenseInputError
from tactsense.cli._common import atomic_output, check_output, fail
from tactsense.io.recording import read_recording
from tactsense.kinds import kind_of, kinds


def calibrate(
    sweep: Annotated[
        Path,
        typer.Argument(
            help="Recording starting with untouched frames: a finger's probe swept along "
            "every column (section 3.1); a pad's or point set's sweep over every taxel, a "
            "uniform press (--press), or the weights placed one at a time (with "
            "--force-log WEIGHTS.csv and no sweep)."
        ),
    ],
    out: Annotated[
        Path, typer.Option("--out", "-o", help="Calibration JSON file to write.")
    ] = Path("calibration.json"),
    probe_g: Annotated[
        float,
        typer.Option(
            min=1e-3,
            max=1e5,
            help="Load of the sweeping probe in grams-force, for the "
            "sensitivity thresholds of Fig. 8.",
        ),
    ] = 50.0,
    baseline_frames: Annotated[
        int,
        typer.Option(min=1, max=1_000_000, help="Untouched frames at the start of each recording."),
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
            "fit and store depth and Poisson's ratio. The edge positions come from the "
            "recording's scenario (a simulation) or from --knife-log."
        ),
    ] = None,
    knife_log: Annotated[
        Path | None,
        typer.Option(
            "--knife-log",
            help="The lab's stage log of the --knife recording: a CSV with time_s [s, the "
            "recording's clock], position_mm [mm, the edge along the finger] and force_n "
            "[N]; each press is the frames where the force is on, its position the "
            "logged one at its last frame.",
        ),
    ] = None,
    row: Annotated[
        int, typer.Option(min=0, max=254, help="Row of the tactel under --steps and --knife.")
    ] = 4,
    col: Annotated[
        int, typer.Option(min=0, max=254, help="Column of the tactel under --steps and --knife.")
    ] = 0,
    partial: Annotated[
        bool,
        typer.Option(
            "--partial",
            help="Accept a sweep that leaves more than 10 % of the tactels uncalibrated "
            "(they keep gain 1 and are listed in the JSON's notes).",
        ),
    ] = False,
    press: Annotated[
        bool,
        typer.Option(
            "--press",
            help="Pads and point sets: the recording is a uniform press of the whole array "
            "(a bladder, a foam block) rather than a probe on every taxel in turn.",
        ),
    ] = False,
    force_log: Annotated[
        Path | None,
        typer.Option(
            "--force-log",
            help="Pads and point sets: the known loads of the presses. A box of weights: a "
            "CSV with one row per weight placed (each placed, held and removed, in the "
            "order placed), the unit in the header: mass_g, mass_kg, force_n or force_mn "
            "(optional temperature_c [degC]); the presses are found in the recording. Or a "
            "timed log (a load cell's) with time_s [s, the recording's clock]. Gives a "
            "weight curve from the contacts' total signal with saturation flagged and a "
            "leave-one-out error per weight (docs/calibration.md); with --loads and a "
            "load cell's time_s/force_n log, the force curve of the layer model's force "
            "(docs/contacts.md).",
        ),
    ] = None,
    loads: Annotated[
        Path | None,
        typer.Option(
            "--loads",
            help="Pads and point sets: the recording --force-log was logged with (presses "
            "of varied force), SWEEP then giving the per-taxel gains (a probe on every "
            "taxel, or a uniform press with --press). Without --loads, SWEEP is the "
            "recording of the weights itself, and the gains are 1 (or from it, with "
            "--press: weights on a plate over the whole array).",
        ),
    ] = None,
    threshold: Annotated[
        float | None,
        typer.Option(
            min=1e-9,
            max=1e6,
            help="Pads and point sets with weights: the contact threshold of the total "
            "signal [-] (default: 10 counts' worth, or 5 standard deviations of the "
            "description's read noise if more). "
            "Kept in the calibration, and used by locate with it unless given there.",
        ),
    ] = None,
    force: Annotated[bool, typer.Option("--force", help="Replace OUT if it exists.")] = False,
    # ---- three-axis taxels (r8-triest) ----
    shear_sweep: Annotated[
        list[Path] | None,
        typer.Option(
            "--shear-sweep",
            help="Three-axis sensors: a recording of tangential loads under known loads "
            "(the probe pressed on the taxels and pushed along x, or along y); give it "
            "once per sweep, with SWEEP the normal sweep (a probe pressed on every taxel, "
            "simulate --scenario calibration). Every taxel's 3x3 matrix is fitted to "
            "all of them (docs/triaxial.md).",
        ),
    ] = None,
    # ---- /r8-triest ----
) -> None:
    """Build a calibration (gains, baseline, dead/weak/noisy tactels, creep, model fit).

    A sweep that misses more than 10 % of the tactels, and a creep or knife-edge fit
    that stops at a bound of its parameters or leaves a residual above 10 % of full
    scale, is an error: such a calibration would be applied without anyone knowing.

    A pad or a point set: newtons from known weights alone (--force-log WEIGHTS.csv,
    one row per weight placed, held and removed, the unit in the header): a curve from
    the contacts' total signal, saturation flagged, a leave-one-out error per weight,
    hysteresis and temperature where the log has them (docs/calibration.md). Per-taxel
    gains on top from a probe on every taxel in turn (simulate --scenario calibration)
    or a uniform press (--press), given first with the weights as --loads. Applied by
    locate, live and view with --calibration.
    """
    from tactsense.estimate.finger import calibrate as cal

    try:
        check_output(out, force, inputs=[sweep, steps, knife, force_log, loads, knife_log])
        from tactsense.io.recording import RecordingReader

        with RecordingReader(sweep) as reader:
            kind = reader.sensor.kind
            # ---- three-axis taxels (r8-triest) ----
            sensor = reader.sensor
        from tactsense.cli import _triaxial

        if _triaxial.vector_taxels(sensor):
            given = (("--steps", steps), ("--knife", knife), ("--knife-log", knife_log),
                     ("--force-log", force_log), ("--loads", loads),
                     ("--press", press or None), ("--threshold", threshold))  # fmt: skip
            for name, value in given:
                if value is not None:
                    raise TactsenseInputError(
                        f"{name} is not for three-axis sensors; {sweep} holds one: give the "
                        "normal sweep and --shear-sweep recordings"
                    )
            check_output(out, force, inputs=[sweep, *(shear_sweep or [])])
            _triaxial.calibrate_shear(sweep, out, sensor=sensor, shear_sweeps=shear_sweep or [],
                                      baseline_frames=baseline_frames)  # fmt: skip
            return
        if shear_sweep:
            raise TactsenseInputError(
                f"--shear-sweep is for three-axis sensors; {sweep} holds a {kind_of(kind).label}"
            )
        # ---- /r8-triest ----
        if kind_of(kind).array_calibration:  # else the paper's finger calibration
            for name, value in (("--steps", steps), ("--knife", knife), ("--knife-log", knife_log)):
                if value is not None:
                    raise TactsenseInputError(
                        f"{name} is for fingers; {sweep} holds a {kind_of(kind).label}"
                    )
            if loads is not None and force_log is None:
                raise TactsenseInputError("--loads goes with --force-log (the load cell's log)")
            _calibrate_array(sweep, out, press=press, force_log=force_log, loads=loads,
                             baseline_frames=baseline_frames, partial=partial,
                             threshold=threshold)  # fmt: skip
            return
        for name, value in (("--press", press or None), ("--force-log", force_log),
                            ("--loads", loads), ("--threshold", threshold)):  # fmt: skip
            if value is not None:
                arrays = " and ".join(k.plural for k in kinds().values() if k.array_calibration)
                raise TactsenseInputError(
                    f"{name} is for {arrays}; {sweep} holds a {kind_of(kind).label}"
                )
        # the sweep is read in pieces: any length fits in memory
        with RecordingReader(sweep) as reader:
            sensor = reader.sensor
            calibration = cal.calibrate_sweep(
                (frames for _, frames, _ in reader.chunks()),
                sensor,
                baseline_frames=baseline_frames,
                probe_grams=probe_g,
            )
        uncalibrated = calibration.notes["uncalibrated_tactels"]
        wired = int(np.prod(sensor.shape))
        if len(uncalibrated) > 0.1 * wired and not partial:
            raise TactsenseInputError(
                f"the sweep reached only {wired - len(uncalibrated)} of {wired} tactels "
                f"({len(uncalibrated)} never deflected 1 %): sweep the probe along every "
                "column (simulate --scenario calibration), or pass --partial to keep gain 1 "
                "for the rest"
            )
        if steps is not None:
            calibration.viscoelastic = _fit_steps(
                read_recording(steps), sensor, row, col, baseline_frames
            )
        if knife_log is not None and knife is None:
            raise TactsenseInputError("--knife-log goes with --knife (the recording it logs)")
        if knife is not None:
            calibration.model_fit, compensated = _fit_knife(
                read_recording(knife),
                sensor,
                row,
                col,
                baseline_frames,
                creep=calibration.viscoelastic,
                log=knife_log,
            )
            calibration.notes["knife_fit_creep_compensated"] = compensated
        with atomic_output(out) as temporary:
            calibration.save(temporary)
    except (TactsenseInputError, FileExistsError) as error:
        fail(str(error))
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
    missed = calibration.notes["uncalibrated_tactels"]
    table.add_row(
        "uncalibrated (gain 1)",
        f"[bold red]{len(missed)} of {gains.size}: the sweep did not reach them[/]"
        if missed
        else "none",
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
            f"RMS {m.rms_percent:.2f} % of full scale"
            + (
                " (creep compensated)"
                if calibration.notes.get("knife_fit_creep_compensated")
                else " (creep not compensated: "
                + (
                    "the fit was better without)"
                    if calibration.viscoelastic is not None
                    else "give --steps)"
                )
            ),
        )
    Console(stderr=True).print(table)


def _calibrate_array(recording, out, *, press, force_log, loads, baseline_frames, partial,
                     threshold=None):  # fmt: skip
    """``calibrate`` on a pad or a point set (tactsense.estimate.contacts.array_calibration)."""
    from tactsense.estimate.contacts.array_calibration import calibrate_array, read_weights_log
    from tactsense.io.recording import RecordingReader

    log = read_weights_log(force_log) if force_log is not None else None
    # a load cell's time_s/force_n log of a --loads recording: the model-force curve
    cell = log is not None and loads is not None and log.time_s is not None
    cell = cell and log.column == "force_n" and log.temperature_c is None and threshold is None
    rec = read_recording(recording)
    load_path = recording if loads is None else loads
    load_rec = rec if loads is None else read_recording(loads)
    if load_rec.sensor != rec.sensor:
        raise TactsenseInputError(f"{loads} comes from another sensor than {recording}")
    method = "press" if press else "sweep"
    options = {}
    if log is not None and not cell:
        if loads is None and not press:
            method = "none"  # the weights alone: no per-taxel gains
        with RecordingReader(load_path) as reader:
            attrs = dict(reader.attrs)
        options = dict(weights=log, threshold=threshold, attrs=attrs)
    elif log is not None:
        options = dict(force_log=(log.time_s, log.force_n))
    calibration = calibrate_array(
        rec.frames, rec.sensor, method=method, baseline_frames=baseline_frames,
        loads=(load_rec.frames, load_rec.time_s), partial=partial, **options,
    )  # fmt: skip
    with atomic_output(out) as temporary:
        calibration.save(temporary)
    table = Table(title=f"wrote {out}", show_header=False)
    gains, dead = calibration.gains, calibration.dead
    used = gains[~dead]
    table.add_row("gains from", calibration.notes["method"])
    table.add_row("gain spread (max/min)", f"{used.max() / used.min():.2f}")
    table.add_row("dead taxels", f"{int(dead.sum())} of {dead.size}")
    console_err = Console(stderr=True)
    if calibration.curve_input == "signal_total":
        _print_weight_curve(calibration, table, console_err)
        return
    if calibration.force_curve is not None:
        x, y = calibration.force_curve
        table.add_row(
            "force curve",
            f"{len(x)} knots from {calibration.notes['force_pairs']} frames, "
            f"{x[0]:.3g}-{x[-1]:.3g} N estimated -> {y[0]:.3g}-{y[-1]:.3g} N measured",
        )
        notes = calibration.notes
        table.add_row(
            "force log checked",
            f"positive; {notes['force_log_scale']:.3g} x the model's force; rank "
            f"correlation {notes['force_log_rank_correlation']:.2f}",
        )
    console_err.print(table)


LOO_GOAL_PERCENT = 5.0
"""A held-out weight predicted further off than this [%] gets a hint to add weights."""

PLAUSIBLE_PRESSURE_PA = 1.0e6
"""A weight heavier than this pressure over the whole array's area [Pa] is taken for a
unit mistake (1 MPa: four times the Young's modulus of the presets' rubber, a strain
that tears a skin; grams under ``mass_kg`` read 1000 times heavier)."""


def _array_area_mm2(sensor) -> float | None:
    """The area the array's taxels cover [mm^2]: a pad's rows x cols cells, a point
    set's taxel areas; None on a finger."""
    grid = getattr(sensor, "grid", None)
    if grid is not None:
        return float(grid.rows * grid.cols * grid.row_pitch_mm * grid.col_pitch_mm)
    areas = getattr(sensor, "areas_mm2", None)  # a point set's, one per taxel
    if areas is None:
        return None
    return float(np.sum(areas() if callable(areas) else areas))


def _print_weight_curve(calibration, table, console) -> None:
    """The weight curve's summary and its leave-one-out table, as kept in the notes."""
    notes = calibration.notes
    x, y = calibration.force_curve
    weights = notes["weights"]
    table.add_row(
        "weights",
        f"{len(notes['presses'])} presses of {len(weights)} weights ({notes['weights_column']} "
        f"in {notes['weights_log']}); threshold {notes['threshold']:.4g}",
    )
    table.add_row(
        "weight curve",
        f"{len(x)} knots, 0-{y[-1]:.4g} N (total signal up to {calibration.curve_top:.4g}; "
        "beyond: force NaN, flag BEYOND_CALIBRATION)",
    )
    saturation = notes["saturation"]
    table.add_row(
        "saturation",
        f"[bold]from {saturation['from_n']:.4g} N[/]: {saturation['reason']}"
        if saturation
        else f"none up to the heaviest weight, {weights[-1]['force_n']:.4g} N",
    )
    loo, lightest = notes["loo_max_error_percent"], notes["loo_lightest_error_percent"]
    said = [] if loo is None else [f"largest error {loo:.1f} % (weights between two others)"]
    if lightest is not None:
        said.append(f"the lightest {lightest:+.1f} % (from the origin)")
    disorder = notes.get("out_of_order") or []
    pooled = {f for pair in disorder for f in pair}
    bends = [w["force_n"] for w in weights if w.get("loo_between") and w["force_n"] not in pooled
             and abs(w["loo_error_percent"]) > LOO_GOAL_PERCENT]  # fmt: skip
    if disorder:
        said.append(
            "[bold]the totals fall from "
            + ", ".join(f"{a:.3g} N to {b:.3g} N" for a, b in disorder)
            + ": is the log in the order the weights were placed, one row per placing?[/]"
        )
    if bends:
        said.append(
            f"[bold]above {LOO_GOAL_PERCENT:g} % at {', '.join(f'{f:.3g}' for f in bends)} N: "
            "add weights there, where the curve bends[/]"
        )
    table.add_row("leave-one-out", "; ".join(said) or "no weight could be held out")
    table.add_row(
        "holds for",
        "loads placed and shaped as the weights were: a cell whose reading is not linear "
        "in its load (an FSR's divider) sums otherwise when a load is shared between "
        "taxels, and a sparse array reads less between taxels; place each weight at "
        "several spots (one row each) to take their median (docs/calibration.md)",
    )
    area_mm2 = _array_area_mm2(calibration.sensor)
    heaviest = max(w["force_n"] for w in weights)
    if area_mm2 and heaviest / (area_mm2 * 1e-6) > PLAUSIBLE_PRESSURE_PA:
        console.print(
            f"warning: the heaviest weight, {heaviest:.4g} N, over the whole array "
            f"({area_mm2:.4g} mm^2) is {heaviest / area_mm2:.3g} MPa, more than a rubber "
            f"skin bears: is {notes['weights_column']!r} the unit of the numbers in "
            f"{notes['weights_log']} (grams written under mass_kg or force_n)?"
        )
    hysteresis = notes["hysteresis"]
    table.add_row(
        "hysteresis",
        f"{hysteresis['max_difference_n']:.4g} N, {hysteresis['percent_of_full_scale']:.1f} % "
        f"of full scale ({hysteresis['full_scale_n']:.4g} N)"
        if hysteresis["measured"]
        else f"not measured: {hysteresis['why']}",
    )
    temperature = notes["temperature"]
    table.add_row(
        "temperature",
        f"{100 * temperature['coefficient_per_c']:+.3g} % of the total per degC about "
        f"{temperature['reference_c']:.3g} degC (not applied by locate)"
        if temperature["calibrated"]
        else f"not calibrated: {temperature['why']}",
    )
    console.print(table)
    loo_table = Table(title="each weight held out, predicted from the others' curve")
    for name in ("load [N]", "presses", "total signal", "predicted [N]", "error [%]"):
        loo_table.add_column(name, justify="right")
    for w in weights:
        if w["saturated"]:
            predicted, error = "saturated", "flagged"
        elif w.get("loo_n") is None:
            predicted, error = "beyond the others", "not extrapolated"
        else:
            predicted, error = f"{w['loo_n']:.4g}", f"{w['loo_error_percent']:+.1f}"
        loo_table.add_row(f"{w['force_n']:.4g}", str(w["presses"]),
                          f"{w['signal_total']:.4g}", predicted, error)  # fmt: skip
    console.print(loo_table)


def _deflection_of(rec, row, col, baseline_frames):
    from tactsense.estimate import baseline_from
    from tactsense.physics.transduction import fractional_deflection

    rec.sensor.check_tactel(row, col)
    base = baseline_from(rec.frames, baseline_frames)
    return fractional_deflection(rec.frames.astype(float), base)[:, row, col]


def _fit_steps(rec, sensor, row, col, baseline_frames):
    from tactsense.estimate.finger import calibrate as cal

    if rec.sensor != sensor:
        raise TactsenseInputError("the steps recording comes from another sensor than the sweep")
    rec.sensor.check_tactel(row, col)
    model, _, rms = cal.fit_viscoelastic_recording(rec, row, col, baseline_frames=baseline_frames)
    problems = cal.check_viscoelastic_fit(model, rms, rec.sensor.scan_period_s)
    if problems:
        raise TactsenseInputError(
            f"the creep fit to tactel ({row}, {col}) of the --steps recording cannot be trusted: "
            f"{'; '.join(problems)}. Is it a recording of force steps on that tactel "
            "(simulate --scenario repeated)? Check --row and --col."
        )
    return model


def _fit_knife(rec, sensor, row, col, baseline_frames, *, creep=None, log=None):
    """The plane-stress fit to the knife-edge recording; with a creep model (from
    --steps), the fit to the readings compensated for creep is kept when it is sound and
    its residual smaller: a knife held 0.5 s and lifted 0.5 s leaves the rubber's memory
    in every reading, which otherwise bends the fit (depth 4.07 mm and nu 0.228 for the
    twin's 3.8 mm and 0.4). Returns (fit, whether it is the compensated one)."""
    from tactsense.estimate.finger import calibrate as cal

    if rec.sensor != sensor:
        raise TactsenseInputError("the knife recording comes from another sensor than the sweep")
    if log is None and "step_axial_mm" not in rec.truth:
        raise TactsenseInputError(
            "the knife-edge fit needs the edge position of every step: this recording has no "
            "scenario truth; give the stage's log with --knife-log"
        )
    signal = _deflection_of(rec, row, col, baseline_frames)
    if log is not None:
        from tactsense.estimate.contacts.array_calibration import presses_from_log, read_stage_log

        # the tactel reads at its own moment of each scan: the log at those times
        sampled = np.asarray(rec.time_s) + float(np.asarray(rec.sample_offset_s)[row, col])
        last, positions, _ = presses_from_log(sampled, read_stage_log(log))
    else:
        last, steps = rec.last_loaded_frames(row, col)
        positions = np.asarray(rec.truth["step_axial_mm"])[steps]
    # distinct to 0.1 mm: the positions carry the probe's placement jitter
    distinct = np.unique(np.round(positions[np.isfinite(positions)], 1)).size
    if distinct < 6:
        raise TactsenseInputError(
            f"the --knife recording loads the finger at {distinct} distinct position(s); a "
            "knife-edge fit needs the edge stepped past the tactel (simulate --scenario "
            "knife-edge)"
        )
    fit = cal.fit_plane_stress(positions, signal[last])
    compensated = False
    if creep is not None:
        # the creep model is only as good as the --steps recording: the compensated fit
        # is kept when it is sound and fits better than the raw one
        fixed = cal.compensate_viscoelastic(signal, rec.sensor.scan_period_s, creep)
        other = cal.fit_plane_stress(positions, fixed[last])
        if not cal.check_model_fit(other) and other.rms_percent < fit.rms_percent:
            fit, compensated = other, True
    problems = cal.check_model_fit(fit)
    if problems:
        raise TactsenseInputError(
            f"the knife-edge fit to tactel ({row}, {col}) cannot be trusted (depth "
            f"{fit.depth_mm:.2f} mm, nu {fit.poisson_ratio:.3f}): {'; '.join(problems)}. "
            "Is the edge stepped past that tactel? Check --row and --col. (A finger the "
            "plane-stress model does not describe, such as --forward finger3d's solid skin, "
            "gives such fits too: docs/model.md, section 3d.)"
        )
    return fit, compensated
