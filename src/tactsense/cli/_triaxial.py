"""``locate`` and ``calibrate`` on three-axis recordings (r8-triest):
:mod:`tactsense.estimate.triaxial` behind the commands' options."""

from __future__ import annotations

from contextlib import ExitStack
from pathlib import Path

from tactsense._validation import TactsenseInputError
from tactsense.cli._common import atomic_output, check_output, console, progress_bar


def vector_taxels(sensor) -> bool:
    """Whether ``sensor``'s taxels read several components (its frames end with a
    component axis)."""
    from tactsense.estimate.triaxial.fit import vector_taxels as vector

    return vector(sensor)


FRICTION_HELP = (
    "Three-axis sensors: the coefficient of friction between the skin and what touches "
    "it [-] (0.05-5), for the slip states (gross slip at the tangential/normal force "
    "ratio mu, Cattaneo-Mindlin's stick ratio below it) [default: found per contact where "
    "its ratio stops rising and it slides]."
)


# ---- the indenter's radius (r9-mjslip2) ----
RADIUS_HELP = (
    "Three-axis sensors: the radius of the sphere that touches the skin [mm] (0.2-50); "
    "the estimator fits the kind's response for it (docs/triaxial.md) [default: the "
    "kind's probe, a 1.6-mm sphere]."
)
# ---- /r9-mjslip2 ----


def locate_shear(recording: Path, out: Path, force: bool, quiet: bool, *, sensor,
                 calibration, threshold, baseline_frames: int, max_contacts: int,
                 chunk_frames, friction, method: str,
                 radius_mm: float | None = None) -> None:  # fmt: skip
    """``locate`` on a three-axis recording: the long table with shear and slip."""
    from tactsense.batch import shear_contacts_file
    from tactsense.estimate.output import events_sidecar, output_format
    from tactsense.estimate.triaxial.calibration import TriaxialCalibration
    from tactsense.estimate.triaxial.locate import check_friction

    check_friction(friction)
    if radius_mm is not None:  # r9-mjslip2: checked before any work
        from tactsense.estimate.triaxial.response import check_radius_mm

        try:
            check_radius_mm(radius_mm)
        except TactsenseInputError as error:
            raise TactsenseInputError(f"--indenter-radius: {error}") from None
    if method != "interpolate":
        raise TactsenseInputError(
            f"--method {method} is for pads; a three-axis sensor's contacts are fitted with "
            "its response to normal and tangential loads"
        )
    if calibration is not None and not isinstance(calibration, TriaxialCalibration):
        raise TactsenseInputError(
            f"the calibration is not a three-axis one; {sensor.name!r} reads three "
            "components a taxel: calibrate it with 'tactsense calibrate' on its own sweeps"
        )
    from tactsense.estimate.triaxial.locate import threshold_counts_of  # r8-fixb8

    threshold_counts = threshold_counts_of(sensor, threshold)
    sidecar = events_sidecar(out) if output_format(out) == "csv" else None
    if sidecar is not None:
        check_output(sidecar, force, inputs=[recording])
    with ExitStack() as stack:
        bar = stack.enter_context(progress_bar("locating contacts", unit="frames", quiet=quiet))
        temporary = stack.enter_context(atomic_output(out))
        events_temporary = stack.enter_context(atomic_output(sidecar)) if sidecar else None
        task = bar.add_task("frames", total=None)
        summary = shear_contacts_file(
            recording, temporary, baseline_frames=baseline_frames, calibration=calibration,
            threshold_counts=threshold_counts, friction=friction, max_contacts=max_contacts,
            chunk_frames=chunk_frames, events_path=events_temporary,
            progress=lambda done, total: bar.update(task, completed=done, total=total),
            radius_mm=radius_mm,
        )  # fmt: skip
    also = f" (events in {sidecar})" if sidecar is not None else ""
    # ---- no "nan N" when nothing was touched (r8-fixb8) ----
    if summary["rows"] == 0:
        from tactsense.estimate.triaxial.fit import default_threshold_counts

        counts = default_threshold_counts(sensor) if threshold is None else threshold_counts
        given = "default" if threshold is None else f"{threshold:g} of full scale"
        console.print(
            f"wrote {out}{also}: {summary['frames']} frames, no contact found (threshold "
            f"{given} = {counts:.0f} counts of field change)"
        )
        return
    # ---- /r8-fixb8 ----
    console.print(
        f"wrote {out}{also}: {summary['frames']} frames, {summary['rows']} contact rows in "
        f"{summary['frames_with_contact']} frames (at most {summary['most']} at once), "
        f"{summary['ids']} tracked ids; largest normal force {summary['force_max_n']:.3g} N, "
        f"largest tangential {summary['shear_max_n']:.3g} N; {summary['gross_slips']} "
        f"contact{'' if summary['gross_slips'] == 1 else 's'} slipped (gross slip)"
    )


def calibrate_shear(sweep: Path, out: Path, *, sensor, shear_sweeps: list[Path],
                    baseline_frames: int) -> None:  # fmt: skip
    """``calibrate`` on three-axis sweeps: every taxel's 3x3 matrix."""
    import json

    from tactsense.estimate.triaxial.calibration import calibrate_triaxial
    from tactsense.io.recording import read_recording

    loaded = []
    for path in [sweep, *shear_sweeps]:
        recording = read_recording(path)
        if tuple(recording.sensor.frame_shape) != tuple(sensor.frame_shape):
            raise TactsenseInputError(
                f"{path} holds frames of {recording.sensor.frame_shape}; {sweep} of "
                f"{sensor.frame_shape}: the sweeps must be of one sensor"
            )
        truth = recording.truth or {}
        if "step_contacts_json" not in truth or "frame_step" not in truth:
            raise TactsenseInputError(
                f"{path} has no known loads (the truth's step_contacts_json): a three-axis "
                "calibration needs the load of every frame (simulate --scenario "
                "calibration, or a sweep whose loads were logged)"
            )
        loaded.append(
            (recording.frames, truth["frame_step"], json.loads(truth["step_contacts_json"]))
        )
    calibration = calibrate_triaxial(loaded, sensor, baseline_frames=baseline_frames)
    with atomic_output(out) as temporary:
        calibration.save(temporary)
    notes = calibration.notes
    console.print(
        f"wrote {out}: a 3x3 matrix for each of {sensor.n_taxels} taxels from "
        f"{notes['frames']} loaded frames of {1 + len(shear_sweeps)} sweep(s); residual "
        f"{notes['rms_before_counts']:.3g} -> {notes['rms_after_counts']:.3g} counts rms"
        + (
            f"; {len(notes['weak_taxels'])} taxels saw little load (kept near the identity)"
            if notes["weak_taxels"]
            else ""
        )
    )
