"""Where the live commands' frames come from: a device (a serial port, a pty, a socket,
a Lab Streaming Layer outlet or another wire format) and the compiled locator that
estimates its frames, the estimator the sensor's kind names."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from tactsense._validation import TactsenseInputError
from tactsense.cli._common import console, fail
from tactsense.kinds import kind_of
from tactsense.sensor import load_sensor

SourceArgument = Annotated[
    str,
    typer.Argument(
        help="The device: a serial port (/dev/ttyUSB0), a pty path printed by 'tactsense "
        "emulate', socket://127.0.0.1:PORT, or any other pyserial URL; or lsl:NAME, a Lab "
        "Streaming Layer frames outlet (its name or source_id); or FORMAT:URL for a device "
        "that speaks text lines, marker-framed bytes or JustFloat (text:/dev/ttyACM0, "
        "marker,start=AA55,width=16:URL, justfloat:URL; docs/devices.md; --sensor needed)."
    ),
]
StreamSensorOption = Annotated[
    str | None,
    typer.Option(
        "--sensor",
        help="The sensor on the line: a preset ('initial', 'improved', 'pad16', ...; "
        "for text, byte or float formats the rows x cols) or a TOML file. Default: ask "
        "the device (IDENTIFY) for its sensor description.",
    ),
]
TimeoutOption = Annotated[
    float | None,
    typer.Option(
        min=0.001,
        max=3600.0,
        help="A frame later than this after the previous one counts as a timeout [s] "
        "(default: 3 frame periods + 0.05 s).",
    ),
]
FramesLimit = Annotated[
    int | None, typer.Option("--frames", min=1, help="Stop after this many frames.")
]
DurationLimit = Annotated[
    float | None,
    typer.Option("--duration", help="Stop after this long [s] (more than 0, at most 1e7)."),
]


def _note_narrow_samples(fmt, spec) -> None:
    """Say so when a format's samples carry fewer bits than the sensor's converter: the
    emulator sends the top bits, which a reader takes only under a description of them."""
    bits, width = int(spec.electronics.adc_bits), getattr(fmt, "sample_bits", None)
    if width is not None and bits > width:
        nominal = spec.electronics.nominal_counts / 2 ** (bits - width)
        console.print(
            f"note: {width}-bit samples carry the top {width} of {spec.name}'s {bits} bits "
            f"(counts >> {bits - width}); read them as a sensor with [electronics] adc_bits "
            f"= {width}, nominal_counts = {nominal:g} (docs/devices.md)"
        )


def _check_duration(duration: float | None) -> None:
    """Refuse a --duration that would record nothing (0), or is not a number [s]."""
    if duration is not None and not 0 < duration <= 1e7:
        fail(f"--duration must be more than 0 s and at most 1e7 s; got {duration:g} s")


LSL_PREFIX = "lsl:"


def _source_file(source: str) -> list[Path]:
    """A source that names a file or device (not an address): an input no output replaces."""
    from tactsense.stream.sources import split_source

    if not source.startswith(LSL_PREFIX):
        try:
            source = split_source(source)[1]
        except TactsenseInputError as error:
            fail(str(error))
    return [] if "://" in source or source.startswith(LSL_PREFIX) else [Path(source)]


def _refuse_recording_source(source: str) -> None:
    """A recording given where a device is expected: say what reads it."""
    if source.lower().endswith((".h5", ".hdf5")) and Path(source).is_file():
        fail(
            f"{source} is a recording; this command reads a device. For a recording use "
            "'tactsense locate' (or 'view' to play it back), or play it as a device with "
            f"'tactsense emulate --recording {source} --port 0'"
        )


def _open_reader(source: str, sensor: str | None, timeout: float | None, *, start: bool = True):
    from tactsense.stream.sources import open_source

    _refuse_recording_source(source)
    spec = None if sensor is None else load_sensor(sensor)
    if source.startswith(LSL_PREFIX):
        from tactsense.interop.lsl import LslReader

        name = source[len(LSL_PREFIX) :].strip()
        if not name:
            fail("lsl: needs an outlet name or source_id, e.g. lsl:fearing1990_initial-frames")
        return LslReader(name, sensor=spec, timeout_s=timeout or 5.0)
    return open_source(source, sensor=spec, timeout_s=timeout, start=start)


def _stream_and_locator(
    source,
    sensor,
    timeout,
    calibration,
    baseline_frames,
    threshold,
    *,
    keep_deflection=False,
    contact_options: dict | None = None,
):
    """The device, opened but not started, and a compiled locator for it: the finger's
    :class:`LiveLocator`, or :class:`LiveContacts` (every contact, tracked) for a pad or a
    point set.

    The calibration was checked before the line was opened; whether it belongs to the
    device's sensor can only be checked once the device has said which.
    """
    from tactsense.stream.sources import split_source

    try:
        wire_format = None if source.startswith(LSL_PREFIX) else split_source(source)[0]
    except TactsenseInputError as error:
        fail(str(error))
    if wire_format is not None and sensor is not None:
        spec = load_sensor(sensor)
        try:  # refused before the estimator compiles, not after
            wire_format.check_converter(spec)
        except TactsenseInputError as error:
            fail(str(error))
        # a device of another format streams once the line opens (it has no START):
        # compile and warm the estimator first, or the first frames queue behind it
        locator = _locator_for(
            spec, calibration, baseline_frames, threshold,
            keep_deflection=keep_deflection, contact_options=contact_options,
        )  # fmt: skip
        return _open_reader(source, sensor, timeout, start=False), locator
    reader = _open_reader(source, sensor, timeout, start=False)
    try:
        locator = _locator_for(
            reader.sensor, calibration, baseline_frames, threshold,
            keep_deflection=keep_deflection, contact_options=contact_options,
        )  # fmt: skip
    except BaseException:
        reader.close()
        raise
    return reader, locator


def _locator_for(
    spec, calibration, baseline_frames, threshold, *, keep_deflection, contact_options
):
    """The compiled, warmed locator of a sensor, as its kind says: :class:`LiveContacts`
    (every contact, tracked) where it has many a frame (a pad, a point set), else
    :class:`LiveLocator` (the finger's one contact)."""
    from tactsense.stream import LiveLocator
    from tactsense.stream.live import LiveContacts

    kind = kind_of(spec)
    if not kind.contact_estimation:
        raise kind.unsupported(spec, "live contact estimation")
    # ---- taxels of several components (r8-triview): contacts with shear and slip ----
    if int(getattr(spec, "components", 1)) > 1:
        from tactsense.estimate.triaxial import LiveShearContacts
        from tactsense.estimate.triaxial.locate import threshold_counts_of  # r8-fixb8

        options = contact_options or {}
        if options.get("method", "interpolate") != "interpolate":
            raise TactsenseInputError(
                f"--method {options['method']!r} applies to scalar pads; the contacts of "
                f"{spec.name!r} are fitted with their shear (leave --method out)"
            )
        from tactsense.view.vectors import warmed

        warmed(LiveShearContacts, spec)  # its tables built before the line opens
        return LiveShearContacts(
            spec,
            baseline_frames=baseline_frames,
            calibration=calibration,
            threshold_counts=threshold_counts_of(spec, threshold),  # locate's rule (r8-fixb8)
            max_contacts=options.get("max_contacts", 8),
            keep_deflection=keep_deflection,
        )
    # ---- /taxels of several components (r8-triview) ----
    if kind.multi_contact:
        return LiveContacts(
            spec,
            baseline_frames=baseline_frames,
            threshold=threshold,
            frame_period_s=None,  # the sensor's scan period: device time, not the wire's
            keep_deflection=keep_deflection,
            calibration=calibration,
            **(contact_options or {}),
        )
    if calibration is not None and not hasattr(calibration, "apply"):
        raise TactsenseInputError(
            f"an array's calibration does not apply to {spec.name!r}, a {kind_of(spec).label}: "
            "calibrate it with 'tactsense calibrate' on a probe sweep of the finger"
        )
    if threshold is None:
        threshold = 0.005
    if calibration is not None:
        calibration.check_sensor(spec)
    return LiveLocator(
        spec,
        calibration=calibration,
        baseline_frames=baseline_frames,
        threshold=threshold,
        frame_period_s=None,  # the sensor's scan period: device time, not the wire's
        keep_deflection=keep_deflection,
    )
