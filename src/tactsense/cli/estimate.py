"""Commands that estimate from recordings: ``locate``, ``calibrate`` and ``batch``.

``calibrate`` is :mod:`tactsense.cli._calibrate`'s, ``batch`` :mod:`tactsense.cli._batch`'s;
they are registered here, in this order.
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from tactsense._validation import TactsenseInputError
from tactsense.cli import _robot_locate as _robot  # r7-handloc: robot recordings
from tactsense.cli import _triaxial  # r8-triest: three-axis taxels
from tactsense.cli._batch import batch
from tactsense.cli._calibrate import calibrate
from tactsense.cli._common import (
    BaselineFramesOption,
    CalibrationOption,
    ContactThresholdOption,
    atomic_output,
    check_output,
    console,
    fail,
    new_group,
    progress_bar,
)
from tactsense.kinds import kind_of

app = new_group("Estimate contacts and calibrations from recordings.")

# ---- locate's --threshold states the three-axis rule too (r8-fixb8) ----
_THRESHOLD = ContactThresholdOption.__metadata__[0]
LocateThresholdOption = Annotated[
    float | None,
    typer.Option(
        "--threshold",
        callback=_THRESHOLD.callback,
        help=_THRESHOLD.help + " Three-axis taxels (the same rule in locate, export, live "
        "and view): a fraction of the converter's full scale (2**adc_bits - 1 counts) that "
        "the length of a taxel's field change (x, y, z) must exceed [default: 8 times the "
        "description's read_noise_counts times sqrt(3), at least 10 counts].",
    ),
]
# ---- /r8-fixb8 ----


def _locate_contacts(recording, out, force, quiet, **options) -> None:
    """``locate`` writing the long table of tracked contacts (pads, point sets,
    ``--contacts``)."""
    from tactsense.batch import contacts_file
    from tactsense.estimate.output import events_sidecar, output_format

    sidecar = events_sidecar(out) if output_format(out) == "csv" else None
    if sidecar is not None:
        check_output(sidecar, force, inputs=[recording])
    from contextlib import ExitStack

    with ExitStack() as stack:
        bar = stack.enter_context(progress_bar("locating contacts", unit="frames", quiet=quiet))
        temporary = stack.enter_context(atomic_output(out))
        events_temporary = stack.enter_context(atomic_output(sidecar)) if sidecar else None
        task = bar.add_task("frames", total=None)
        summary = contacts_file(
            recording, temporary, events_path=events_temporary,
            progress=lambda done, total: bar.update(task, completed=done, total=total),
            **options,
        )  # fmt: skip
    also = f" (events in {sidecar})" if sidecar is not None else ""
    console.print(
        f"wrote {out}{also}: {summary['frames']} frames, {summary['rows']} contact rows in "
        f"{summary['frames_with_contact']} frames (at most {summary['most']} at once), "
        f"{summary['ids']} tracked ids; {summary['births']} births, {summary['deaths']} "
        f"deaths, {summary['merges']} merges, {summary['splits']} splits; "
        f"creep: {summary['creep']}"
    )
    if summary.get("beyond_calibration"):
        console.print(
            f"warning: {summary['beyond_calibration']} contacts read beyond the calibrated "
            "range (flag BEYOND_CALIBRATION): heavier than the heaviest unsaturated weight, "
            "their force is NaN, not extrapolated"
        )
    for line in (summary.get("unusable"), summary.get("movement")):
        if line:
            console.print(
                f"warning: {line}", soft_wrap=True, markup=False, highlight=False, emoji=False
            )
    below, first = summary["below_baseline"], summary.get("below_first_baseline", 0)
    if below and first:
        console.print(
            f"warning: {below} frames read below the baseline by more than the threshold "
            f"(flag BELOW_BASELINE; {first} below the first frames' own): the first "
            "frames, which make the baseline, were probably touched; record untouched "
            "frames first"
        )
    elif below:  # below a baseline that moved, never below the first frames'
        console.print(
            f"warning: {below} frames read below the baseline by more than the threshold "
            "(flag BELOW_BASELINE), none below the first frames' own: the baseline "
            "followed a falling reading it took for the creep after a lift (a slow "
            "unload, or a contact sliding off the taxel) and the reading fell further; "
            "the forces there read low"
        )


@app.command()
def locate(
    recording: Annotated[
        Path,
        typer.Argument(
            help="HDF5 recording to analyse, or a robot recording's folder (docs/robot.md)."
        ),
    ],
    out: Annotated[
        Path,
        typer.Option(
            "--out",
            "-o",
            help="File to write, one row per frame (on a pad, a point set or with "
            "--contacts: one row per contact per frame); the extension sets the format: .csv "
            "(units in the column names: _s, _mm, _deg, _n; flags as bits and by name), "
            ".parquet or .h5 (flags as bits).",
        ),
    ] = Path("estimates.csv"),
    baseline_frames: BaselineFramesOption = 5,
    threshold: LocateThresholdOption = None,  # r8-fixb8
    calibration: CalibrationOption = None,
    contacts: Annotated[
        bool,
        typer.Option(
            "--contacts",
            help="On a finger: write every contact, tracked, as a long table (one row per "
            "contact per frame, docs/contacts.md) instead of one row per frame. Pads and "
            "point sets always get the long table.",
        ),
    ] = False,
    max_contacts: Annotated[
        int,
        typer.Option(
            min=1,
            max=64,
            help="Long table: at most this many contacts per frame (the largest by force).",
        ),
    ] = 8,
    method: Annotated[
        str,
        typer.Option(
            help="Long table: how a contact's position is found: 'interpolate' (the "
            "paper's windowed sinc and Newton, on the grid), 'cop' (centre of pressure) or "
            "'fit' (pads: maximum likelihood on the layer's response, the most accurate, "
            "about 300 us a contact; docs/accuracy.md) or 'joint' (pads: every contact of "
            "a frame fitted jointly with its size and indenter shape, contacts added by a "
            "likelihood criterion, each with its standard errors; milliseconds a frame on "
            "pad4, tens to hundreds on pad16 and larger pads, about a second on a large "
            "contact over many taxels; docs/contacts.md, docs/performance.md)."
            + _robot.METHOD_HELP  # r10-handjoint
        ),
    ] = "interpolate",
    drift_s: Annotated[
        float,
        typer.Option(
            "--drift-s",
            min=0.0,
            max=1e6,
            help="Long table: time constant [s] with which the baseline follows slow "
            "drift where taxels are untouched (held while touched, as iCub's skin does; "
            "docs/contacts.md); 0 keeps the first frames' baseline (a measured "
            "recording's taxel is still re-zeroed after a lift, for the creep it may "
            "carry; a simulated or MuJoCo recording without memory flaws never is). "
            "With a pad's "
            "--calibration it starts from the calibration's baseline; not used with a "
            "finger's.",
        ),
    ] = 2.0,
    chunk_frames: Annotated[
        int | None,
        typer.Option(
            min=1,
            max=10_000_000,
            help="Frames read and estimated at a time (memory is about 1 kB per frame "
            "of 8 x 8) [default: the recording's HDF5 chunk, near 65,536].",
        ),
    ] = None,
    workers: Annotated[
        int,
        typer.Option(
            min=1,
            max=256,
            help="Threads for the estimation (the compiled passes release the GIL; "
            "2 gives about 1.7x on 2 cores).",
        ),
    ] = 1,
    quiet: Annotated[
        bool, typer.Option("--quiet", "-q", help="No progress bar, only the summary line.")
    ] = False,
    force: Annotated[bool, typer.Option("--force", help="Replace OUT if it exists.")] = False,
    # ---- contacts in the robot's frame (r7-handloc) ----
    joints: Annotated[str | None, typer.Option("--joints", help=_robot.JOINTS_HELP)] = None,
    joints_csv: Annotated[
        Path | None, typer.Option("--joints-csv", help=_robot.JOINTS_CSV_HELP)
    ] = None,
    joints_bag: Annotated[
        Path | None, typer.Option("--joints-bag", help=_robot.JOINTS_BAG_HELP)
    ] = None,
    joints_topic: Annotated[
        str | None, typer.Option("--joints-topic", help=_robot.JOINTS_TOPIC_HELP)
    ] = None,
    wrenches: Annotated[Path | None, typer.Option("--wrenches", help=_robot.WRENCHES_HELP)] = None,
    # ---- /r7-handloc ----
    # ---- three-axis taxels (r8-triest) ----
    friction: Annotated[
        float | None, typer.Option("--friction", help=_triaxial.FRICTION_HELP)
    ] = None,
    # ---- /r8-triest ----
    # ---- the indenter's radius on three-axis taxels (r9-mjslip2) ----
    indenter_radius_mm: Annotated[
        float | None, typer.Option("--indenter-radius", help=_triaxial.RADIUS_HELP)
    ] = None,
    # ---- /r9-mjslip2 ----
) -> None:
    """Locate the contact in every frame: position, force, skew and quality flags.

    The recording is read and the estimates written piece by piece, so memory stays
    bounded whatever its length; a progress bar shows on a terminal. A robot recording's
    folder (docs/robot.md): every patch's contacts in its link's and the base frame, and
    the wrench per link.
    """
    # ---- a robot recording's folder (r7-handloc) ----
    from tactsense.io.robot_recording import is_robot_recording

    robot_options = _robot.robot_only_options(joints, joints_csv, joints_bag, joints_topic,
                                              wrenches)  # fmt: skip
    if is_robot_recording(recording):
        single = {"--calibration": calibration is not None, "--contacts": contacts,
                  "--method": method not in _robot.HAND_METHODS,  # r10-handjoint
                  "--chunk-frames": chunk_frames is not None,
                  "--workers": workers != 1, "--drift-s": drift_s != 2.0,
                  "--friction": friction is not None,  # r10: three-axis options
                  "--indenter-radius": indenter_radius_mm is not None}  # fmt: skip
        _robot.run_robot_locate(
            recording, out, force=force, quiet=quiet, joints=joints, joints_csv=joints_csv,
            joints_bag=joints_bag, joints_topic=joints_topic, wrenches=wrenches,
            baseline_frames=baseline_frames, threshold=threshold, max_contacts=max_contacts,
            single_array_options=single, method=method,  # r10-handjoint: --method joint
        )  # fmt: skip
        return
    if robot_options:
        fail(
            f"{', '.join(robot_options)} apply to a robot recording's folder; "
            f"{recording} is not one"
        )
    # ---- /r7-handloc ----

    from tactsense.batch import locate_file, output_format
    from tactsense.estimate.contacts import METHODS
    from tactsense.io.recording import RecordingReader

    try:
        check_output(out, force, inputs=[recording, calibration])
        output_format(out)
        if method not in METHODS:
            raise TactsenseInputError(f"--method {method!r}: expected one of {', '.join(METHODS)}")
        with RecordingReader(recording) as reader:
            sensor = reader.sensor
        # ---- three-axis taxels (r8-triest) ----
        if _triaxial.vector_taxels(sensor):
            calibrated = None
            if calibration is not None:
                from tactsense.estimate.contacts.array_calibration import load_calibration

                calibrated = load_calibration(calibration, sensor)
            _triaxial.locate_shear(
                recording, out, force, quiet, sensor=sensor, calibration=calibrated,
                threshold=threshold, baseline_frames=baseline_frames,
                max_contacts=max_contacts, chunk_frames=chunk_frames, friction=friction,
                method=method, radius_mm=indenter_radius_mm,
            )  # fmt: skip
            return
        if friction is not None:
            raise TactsenseInputError(
                f"--friction applies to three-axis sensors; {sensor.name!r} reads one "
                "component a taxel"
            )
        if indenter_radius_mm is not None:  # r9-mjslip2
            raise TactsenseInputError(
                f"--indenter-radius applies to three-axis sensors; {sensor.name!r} reads one "
                "component a taxel"
            )
        # ---- /r8-triest ----
        calibrated = None
        if calibration is not None:
            from tactsense.estimate.contacts.array_calibration import load_calibration

            calibrated = load_calibration(calibration, sensor)
        many = kind_of(sensor).multi_contact  # a pad's, a point set's: the long table
        if not contacts and not many:
            changed = (("--method", method != "interpolate"), ("--max-contacts", max_contacts != 8))
            given = [name for name, value in changed if value]
            if given:
                raise TactsenseInputError(
                    f"{' and '.join(given)} apply to the long table of contacts: add "
                    "--contacts (a finger's one-row-per-frame table has one contact)"
                )
        if contacts or many:
            _locate_contacts(
                recording, out, force, quiet, baseline_frames=baseline_frames,
                calibration=calibrated, threshold=threshold, max_contacts=max_contacts,
                method=method, chunk_frames=chunk_frames,
                drift_s=drift_s if drift_s > 0 else None,
            )  # fmt: skip
            return
        if threshold is None:
            threshold = 0.005
        with (
            progress_bar("locating", unit="frames", quiet=quiet) as bar,
            atomic_output(out) as temporary,
        ):
            task = bar.add_task("frames", total=None)
            summary = locate_file(
                recording,
                temporary,
                baseline_frames=baseline_frames,
                calibration=calibrated,
                threshold=threshold,
                chunk_frames=chunk_frames,
                workers=workers,
                progress=lambda done, total: bar.update(task, completed=done, total=total),
            )
    except (TactsenseInputError, FileExistsError) as error:
        fail(str(error))
    note = f", {summary['saturated']} saturated (force NaN)" if summary["saturated"] else ""
    console.print(
        f"wrote {out}: {summary['frames']} frames, {summary['contacts']} with a contact{note}"
    )
    if summary.get("movement"):
        console.print(
            f"warning: {summary['movement']}",
            soft_wrap=True, markup=False, highlight=False, emoji=False,
        )  # fmt: skip


app.command()(calibrate)
app.command()(batch)
