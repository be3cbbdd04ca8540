"""The live system on the command line: ``emulate``, ``record`` and ``live``."""

from __future__ import annotations

import csv
import json
import sys
from enum import StrEnum
from pathlib import Path
from typing import Annotated

import numpy as np
import typer
from rich.progress import Progress, TextColumn

from tactsense._signals import stopped_by
from tactsense._validation import TactsenseInputError
from tactsense.cli._common import (
    BaselineFramesOption,
    CalibrationOption,
    ContactThresholdOption,
    SensorOption,
    atomic_output,
    check_output,
    console,
    fail,
    new_group,
    sensor_file,
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
    ScenarioOption,
    SeedOption,
    SeparationOption,
    SizeOption,
    SpeedOption,
    XOption,
    YOption,
    build_scenario,
    run_scenario,
)
from tactsense.estimate.array_calibration import load_calibration
from tactsense.sensor import load_sensor

app = new_group("The live system: an emulated finger, recording and live estimates.")

RATE = dict(min=0.0, max=1.0)

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


class RecordFormat(StrEnum):
    h5 = "h5"
    mcap = "mcap"


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
    """The compiled, warmed locator of a sensor: :class:`LiveLocator` for a finger,
    :class:`LiveContacts` (every contact, tracked) for a pad or a point set."""
    from tactsense.stream import LiveLocator
    from tactsense.stream.live import LiveContacts

    if spec.kind != "finger":
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
            f"an array's calibration does not apply to {spec.name!r}, a finger: "
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


SCENARIO_PARAMETERS = (
    "sensor", "scenario", "row", "col", "force_g", "increment", "dwell_s", "lift_s",
    "repeats", "x_mm", "y_mm", "separation_mm", "indenter", "size_mm", "speed_mm_s",
    "angle_deg", "forces_g", "flaws", "seed",
)  # fmt: skip
"""emulate's options that build a scenario: a --recording brings its own frames."""


@app.command()
def emulate(
    ctx: typer.Context,
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
    flaws: FlawsOption = "all",
    seed: SeedOption = 0,
    recording: Annotated[
        Path | None,
        typer.Option(help="Play the frames of this recording instead of simulating a scenario."),
    ] = None,
    port: Annotated[
        int | None,
        typer.Option(
            min=0,
            max=65535,
            help="Serve on this TCP port of 127.0.0.1 (0: a free port) instead of a new "
            "pseudo-terminal.",
        ),
    ] = None,
    speed: Annotated[
        float,
        typer.Option(
            help="Send frames at this multiple of the sensor's scan rate (more than 0, at "
            "most 1e6; 1e6 sends as fast as the line takes them).",
        ),
    ] = 1.0,
    loop: Annotated[
        bool, typer.Option("--loop", help="Start the frames over when they run out.")
    ] = False,
    garbage: Annotated[
        float, typer.Option(**RATE, help="Rate of bursts of random bytes [per frame].")
    ] = 0.0,
    bitflip: Annotated[
        float, typer.Option(**RATE, help="Rate of frames with one bit inverted [per frame].")
    ] = 0.0,
    drop: Annotated[float, typer.Option(**RATE, help="Rate of frames not sent [per frame].")] = 0.0,
    truncate: Annotated[
        float, typer.Option(**RATE, help="Rate of frames cut short [per frame].")
    ] = 0.0,
    stall: Annotated[
        float, typer.Option(**RATE, help="Rate of pauses before a frame [per frame].")
    ] = 0.0,
    stall_s: Annotated[
        float, typer.Option(min=0.0, max=60.0, help="Length of each pause [s].")
    ] = 0.5,
    fault_seed: Annotated[
        int, typer.Option(min=0, help="Seed of the fault draws, for a repeatable line.")
    ] = 0,
    wire_format: Annotated[
        str | None,
        typer.Option(
            "--format",
            help="Speak another wire format instead of tactsense's: text, marker or "
            "justfloat, with options (e.g. text,sep=tab; marker,start=AA55,width=16,"
            "order=big; docs/devices.md). The address printed names it; the device "
            "streams as soon as a host connects.",
        ),
    ] = None,
) -> None:
    """Play a sensor as a device: frames of the twin (a finger, a pad or a point set) in the
    wire protocol on a pty or TCP.

    Prints where to connect on standard output (a pty path, or socket://127.0.0.1:PORT)
    and serves until Ctrl-C. The device streams after a host sends START
    (docs/protocol.md); 'tactsense record' and 'tactsense live' do.
    """
    from tactsense.io.recording import read_recording
    from tactsense.stream import Emulator, FaultRates
    from tactsense.stream.sources import parse_format

    if not 0 < speed <= 1e6:
        fail(
            f"--speed must be more than 0 and at most 1e6 (a multiple of the scan rate); "
            f"got {speed:g}; 1e6 sends as fast as the line takes them"
        )
    if recording is not None:
        given = [
            "--" + name.replace("_", "-")
            for name in SCENARIO_PARAMETERS
            if getattr(ctx.get_parameter_source(name), "name", "") == "COMMANDLINE"
        ]
        if given:
            fail(
                f"--recording excludes {', '.join(given)}: the recording brings its own "
                "sensor and frames"
            )
    try:
        faults = FaultRates(garbage, bitflip, drop, truncate, stall, stall_s)
        fmt = None if wire_format is None else parse_format(wire_format)
        prefix = "" if fmt is None else fmt.spec() + ":"
        if recording is not None:
            source = read_recording(recording)
        else:
            spec = load_sensor(sensor)
            scene = build_scenario(
                spec, scenario, row=row, col=col, force_g=force_g, increment=increment,
                dwell_s=dwell_s, lift_s=lift_s, repeats=repeats, x_mm=x_mm, y_mm=y_mm,
                separation_mm=separation_mm, indenter=indenter, size_mm=size_mm,
                speed_mm_s=speed_mm_s, angle_deg=angle_deg, forces_g=forces_g,
            )  # fmt: skip
            source = run_scenario(spec, scene, flaws=flaws, seed=seed)
        emulator = Emulator.from_recording(
            source, speed=speed, faults=faults, repeat=loop, rng=fault_seed, wire_format=fmt
        )
    except TactsenseInputError as error:
        fail(str(error))
    _note_narrow_samples(fmt, source.sensor)
    try:
        if port is None:
            # the protocol's twin keeps the slave open (no EIO); another format's closes
            # it, to see when a host opens the line
            master, _slave, path = emulator.open_pty()
            typer.echo(prefix + path)
            sys.stdout.flush()
            console.print(
                f"emulating {source.sensor.name} on {path}: {len(source)} frames at "
                f"{emulator.frame_rate_hz or float('inf'):g} frames/s; Ctrl-C stops"
            )
            emulator.serve_pty(master)
        else:

            def ready(chosen: int) -> None:
                typer.echo(f"{prefix}socket://127.0.0.1:{chosen}")
                sys.stdout.flush()
                console.print(
                    f"emulating {source.sensor.name} on 127.0.0.1:{chosen}: {len(source)} "
                    f"frames at {emulator.frame_rate_hz or float('inf'):g} frames/s; "
                    "Ctrl-C stops"
                )

            emulator.serve_tcp(port, ready=ready)
    except KeyboardInterrupt:
        pass
    except OSError as error:
        fail(f"cannot serve: {error.strerror or error}")
    log = emulator.log
    console.print(
        f"sent {log.frames} frames ({log.delivered_intact} intact); injected: "
        + ", ".join(
            f"{k} {getattr(log, k)}" for k in ("garbage", "bitflip", "drop", "truncate", "stall")
        )
    )


RECORD_SUFFIXES = {".h5": RecordFormat.h5, ".hdf5": RecordFormat.h5, ".mcap": RecordFormat.mcap}
"""What ``record`` writes, by the extension of ``--out`` (without ``--format``)."""
OTHER_SUFFIXES = (".csv", ".jsonl", ".json", ".txt", ".rrd", ".xdf", ".db3", ".toml", ".npy")
"""Extensions of files of other kinds: ``record`` never writes a recording under them."""


def _check_record_suffix(out: Path, record_format: RecordFormat | None) -> None:
    """Refuse an output whose name says another kind of file than the one written."""
    suffix = out.suffix.lower()
    kind = RECORD_SUFFIXES.get(suffix)
    if record_format is None and kind is None:
        fail(
            f"--out {out}: record writes HDF5 (.h5, .hdf5) or MCAP (.mcap); use one of "
            "these extensions or say --format h5 or mcap. For estimates as CSV or JSON "
            "lines use 'tactsense live --out'"
        )
    if record_format is not None and (
        suffix in OTHER_SUFFIXES or (kind is not None and kind is not record_format)
    ):
        fail(
            f"--out {out}: the extension {suffix} says another kind of file than "
            f"--format {record_format.value}; use .h5 for h5, .mcap for mcap"
        )


@app.command()
def record(
    source: SourceArgument,
    out: Annotated[
        Path,
        typer.Option(
            "--out",
            "-o",
            help="New recording: HDF5 (crash-safe), or MCAP (see --format).",
        ),
    ] = Path("recording.h5"),
    record_format: Annotated[
        RecordFormat | None,
        typer.Option(
            "--format",
            help="h5: HDF5, crash-safe, losses stored; mcap: tactile_msgs/TactileState "
            "messages for ROS 2 and Foxglove (docs/interop.md). Default: mcap if OUT ends "
            "in .mcap, else h5.",
        ),
    ] = None,
    frames: FramesLimit = None,
    duration: DurationLimit = None,
    sensor: StreamSensorOption = None,
    timeout: TimeoutOption = None,
    frame_id: Annotated[
        str | None,
        typer.Option(
            "--frame-id",
            help="mcap: the frame_id of every header, the URDF link the sensor is mounted "
            "on [default: finger].",
        ),
    ] = None,
    quiet: Annotated[bool, typer.Option("--quiet", help="No live status line.")] = False,
    force: Annotated[bool, typer.Option("--force", help="Replace OUT if it exists.")] = False,
) -> None:
    """Record a device's frames as they arrive, until --frames, --duration or Ctrl-C.

    HDF5 is flushed at least once a second: if the recorder is killed, every frame up
    to the last flush is readable. Losses (bad check, gaps, timeouts...) are counted
    and stored with the frames.
    """
    from tactsense.stream import StreamError
    from tactsense.stream import record as run_record

    _check_duration(duration)
    if record_format is None:
        mcap = out.suffix.lower() == ".mcap"
    else:
        mcap = record_format is RecordFormat.mcap
    if frame_id is not None and not mcap:
        fail("--frame-id applies to MCAP recordings (--out X.mcap or --format mcap)")
    if frame_id is not None and (not frame_id.strip() or any(c.isspace() for c in frame_id)):
        fail(f"--frame-id {frame_id!r}: give a link name without spaces")
    extra = {"frame_id": frame_id} if frame_id is not None else {}
    if mcap:
        from tactsense.interop.mcap import _writer_class
        from tactsense.interop.mcap import record_mcap as run_record

        try:
            _writer_class()
        except TactsenseInputError as error:
            fail(str(error))
    check_output(out, force, inputs=[*sensor_file(sensor), *_source_file(source)])
    _refuse_recording_source(source)
    _check_record_suffix(out, record_format)
    try:
        reader = _open_reader(source, sensor, timeout)
    except TactsenseInputError as error:
        fail(str(error))
    with Progress(
        TextColumn("{task.description}"),
        console=console,
        disable=quiet or not console.is_terminal,
    ) as bar:
        task = bar.add_task(f"recording {source}")

        kept = [0]  # frames in the file, as the recorder last reported

        def update(count: int, stats, rate: float) -> None:
            kept[0] = count
            bar.update(task, description=f"{out}: {rate:7.1f} frames/s, {stats.summary(count)}")

        interrupted = False
        try:
            with reader:
                run_record(
                    reader, out, max_frames=frames, duration_s=duration, overwrite=force,
                    progress=update, **extra,
                )  # fmt: skip
        except KeyboardInterrupt:
            interrupted = True
        except (StreamError, TactsenseInputError, FileExistsError) as error:
            if kept[0] and out.exists():
                losses = reader.stats.summary(kept[0]).partition(", ")[2]
                fail(
                    f"{error}; kept {kept[0]} frames in {out}" + (f" ({losses})" if losses else "")
                )
            fail(f"{error}; no frame was recorded, nothing written")
    if interrupted:
        stopped = f" (stopped by {stopped_by()})"
        if not kept[0] and not out.exists():
            console.print(f"stopped by {stopped_by()} before any frame arrived; nothing written")
            raise typer.Exit(0)
    else:
        stopped = ""
    console.print(f"wrote {out}{stopped}: {reader.stats.summary(kept[0])}")


class LiveFormat(StrEnum):
    jsonl = "jsonl"
    csv = "csv"


@app.command()
def live(
    source: SourceArgument,
    calibration: CalibrationOption = None,
    output_format: Annotated[
        LiveFormat, typer.Option("--format", help="One JSON object per line, or CSV.")
    ] = LiveFormat.jsonl,
    out: Annotated[
        Path | None,
        typer.Option("--out", "-o", help="Write the estimates here instead of standard output."),
    ] = None,
    frames: FramesLimit = None,
    duration: DurationLimit = None,
    baseline_frames: BaselineFramesOption = 5,
    threshold: ContactThresholdOption = None,
    sensor: StreamSensorOption = None,
    timeout: TimeoutOption = None,
    lsl: Annotated[
        bool,
        typer.Option(
            "--lsl",
            help="Also publish the frames and the estimates on two Lab Streaming Layer "
            "outlets (<sensor>-frames, <sensor>-contacts; docs/interop.md).",
        ),
    ] = False,
    method: Annotated[
        str,
        typer.Option(
            help="Pads and point sets: how a contact's position is found, as for 'locate' "
            "('interpolate', 'cop' or 'fit')."
        ),
    ] = "interpolate",
    max_contacts: Annotated[
        int,
        typer.Option(
            min=1, max=64, help="Pads and point sets: at most this many contacts a frame."
        ),
    ] = 8,
    drift_s: Annotated[
        float,
        typer.Option(
            "--drift-s",
            min=0.0,
            max=1e6,
            help="Pads and point sets: time constant [s] with which the baseline follows "
            "slow drift where taxels are untouched; 0 keeps it fixed (as 'locate').",
        ),
    ] = 2.0,
    force: Annotated[bool, typer.Option("--force", help="Replace OUT if it exists.")] = False,
) -> None:
    """Estimate the contact of every frame as it arrives: position, force, skew, flags and
    latency (from the frame's last byte to its estimate), until --frames, --duration,
    the end of the stream or Ctrl-C.

    A pad or a point set gets every contact of every frame, tracked (ids, velocity,
    slip; docs/contacts.md): one JSON object per frame with a "contacts" list, or with
    --format csv one row per contact (a frame without contact: one row, n_contacts 0).
    The baseline follows slow drift where taxels are untouched. Re-zero (take the
    baseline anew from the next frames, the sensor untouched): type z and Enter on a
    terminal, or send SIGUSR1 (kill -USR1 PID).
    """
    import signal
    import threading

    from tactsense.stream import StreamError
    from tactsense.stream.live import CONTACT_FIELDS, FIELDS

    _check_duration(duration)
    if out is not None:
        check_output(out, force, inputs=[calibration, *sensor_file(sensor), *_source_file(source)])
    try:
        cal = None if calibration is None else load_calibration(calibration)
        from tactsense.estimate.contacts import METHODS

        if method not in METHODS:
            raise TactsenseInputError(f"--method {method!r}: expected one of {', '.join(METHODS)}")
        reader, locator = _stream_and_locator(
            source, sensor, timeout, cal, baseline_frames, threshold,
            contact_options={"method": method, "max_contacts": max_contacts,
                             "drift_s": drift_s if drift_s > 0 else None},
        )  # fmt: skip
        outlets = None
        if lsl:
            from tactsense.interop.lsl import LslOutlets

            rate = 1.0 / reader.frame_period_s if reader.frame_period_s else 0.0
            outlets = LslOutlets(reader.sensor, reader.identity, rate)
        reader.start()
    except TactsenseInputError as error:
        fail(str(error))
    latencies: list[float] = []
    used = [0]  # frames given to the locator
    multi = reader.sensor.kind != "finger"
    rezero = threading.Event()
    _listen_for_rezero(rezero, signal)

    def run(stream) -> None:
        writer = None
        if output_format is LiveFormat.csv:
            fields = LIVE_CONTACT_COLUMNS if multi else FIELDS
            writer = csv.DictWriter(stream, fieldnames=fields, lineterminator="\n")
            writer.writeheader()
        for frame in reader.frames(max_frames=frames, duration_s=duration):
            used[0] += 1
            if rezero.is_set():
                rezero.clear()
                locator.rezero()
                print("re-zeroing: the baseline from the next frames", file=sys.stderr)
            estimate = locator(frame)
            if outlets is not None:
                outlets.push(frame, estimate)
            if estimate is None:
                continue
            latencies.append(estimate["latency_ms"])
            if writer is None:
                clean = {
                    k: (None if isinstance(v, float) and not np.isfinite(v) else v)
                    for k, v in estimate.items()
                }
                stream.write(json.dumps(clean) + "\n")
            elif multi:
                for row in _contact_rows(estimate, CONTACT_FIELDS):
                    writer.writerow(row)
            else:
                writer.writerow(
                    {k: repr(v) if isinstance(v, float) else v for k, v in estimate.items()}
                )
            stream.flush()

    interrupted = False
    try:
        with reader:
            try:
                if out is None:
                    run(sys.stdout)
                else:
                    with (
                        atomic_output(out) as temporary,
                        open(temporary, "w", newline="") as stream,
                    ):
                        try:
                            run(stream)
                        except KeyboardInterrupt:
                            interrupted = True  # what was estimated so far is complete
            finally:
                if hasattr(reader, "stop"):
                    reader.stop(wait_s=0.5)  # END settles the last frames' losses
    except KeyboardInterrupt:
        interrupted = True
    except (StreamError, TactsenseInputError) as error:
        fail(str(error))
    except BrokenPipeError:
        sys.stderr.close()
        return
    warmup = used[0] - len(latencies)
    summary = reader.stats.summary(used[0])
    if warmup:  # after "N frames"
        head, _, rest = summary.partition(", ")
        summary = f"{head} ({warmup} for the baseline)" + (f", {rest}" if rest else "")
    if latencies:
        median, p99 = np.percentile(latencies, [50, 99])
        summary += f"; latency median {median:.3f} ms, p99 {p99:.3f} ms"
    stopped = f" (stopped by {stopped_by()})" if interrupted else ""
    console.print(f"{len(latencies)} estimates{stopped} from {summary}")


LIVE_CONTACT_COLUMNS = (
    "sequence", "device_time_s", "host_time_s", "n_contacts", "id", "x_mm", "y_mm", "z_mm",
    "row", "col", "force_n", "peak", "major_mm", "minor_mm", "orientation_deg", "taxels",
    "area_mm2", "vx_mm_s", "vy_mm_s", "vz_mm_s", "slip", "flags", "flag_names", "rezeroing",
    "latency_ms",
)  # fmt: skip
"""Columns of ``live --format csv`` on a pad or a point set: one row per contact."""


def _contact_rows(estimate: dict, fields) -> list[dict]:
    """The CSV rows of one frame's contacts (one row with n_contacts 0 when none)."""
    head = {k: estimate[k] for k in ("sequence", "device_time_s", "host_time_s", "n_contacts",
                                     "flag_names", "rezeroing", "latency_ms")}  # fmt: skip
    rows = []
    for contact in estimate["contacts"] or [{}]:
        row = dict(head)
        row.update({k: contact.get(k, "") for k in fields})
        row["flags"] = contact.get("flags", estimate["flags"])
        rows.append({k: repr(v) if isinstance(v, float) else v for k, v in row.items()})
    return rows


def _listen_for_rezero(event, signal) -> None:
    """Set ``event`` on SIGUSR1, and on a line 'z' typed at a terminal."""
    import threading

    if hasattr(signal, "SIGUSR1") and threading.current_thread() is threading.main_thread():
        signal.signal(signal.SIGUSR1, lambda *_: event.set())
    if sys.stdin is not None and sys.stdin.isatty():

        def listen() -> None:
            for line in sys.stdin:
                if line.strip().lower() in ("z", "rezero", "re-zero"):
                    event.set()

        threading.Thread(target=listen, daemon=True, name="rezero-keys").start()


RECORDING_SUFFIXES = (".h5", ".hdf5")


@app.command()
def view(
    source: Annotated[
        str,
        typer.Argument(
            help="A recording (.h5 from 'tactsense record' or 'simulate') to play back, or "
            "a device: a serial port, a pty path, socket://127.0.0.1:PORT or any pyserial "
            "URL; or lsl:NAME, a Lab Streaming Layer frames outlet; or FORMAT:URL for a "
            "device speaking text lines, marker-framed bytes or JustFloat (docs/devices.md)."
        ),
    ],
    port: Annotated[
        int,
        typer.Option(min=0, max=65535, help="TCP port of the page (0: a free port)."),
    ] = 0,
    host: Annotated[
        str | None,
        typer.Option(
            help="Listen on this address instead of 127.0.0.1. Anyone who reaches it sees "
            "the finger and can control playback: there is no login."
        ),
    ] = None,
    open_browser: Annotated[
        bool, typer.Option("--open", help="Open the page in the default web browser.")
    ] = False,
    calibration: CalibrationOption = None,
    baseline_frames: BaselineFramesOption = 5,
    threshold: ContactThresholdOption = None,
    speed: Annotated[
        float,
        typer.Option(
            min=0.01,
            max=1000.0,
            help="Recordings: start playing at this multiple of the recorded frame rate "
            "(the page changes it).",
        ),
    ] = 1.0,
    sensor: StreamSensorOption = None,
    timeout: TimeoutOption = None,
) -> None:
    """Show the sensor in a web browser: a live stream as it arrives, or a recording played
    back (play, pause, step, seek, speed).

    The page shows a finger unwrapped (length across, circumference down, the tip row
    apart, the seam marked), a pad as a flat grid in millimetres, a point set as dots at
    their positions; the interpolated surface, the contacts with their trails (a finger's
    one contact; on pads and point sets every contact, tracked, with its id), force and
    tactel time traces, and the stream's health (frame rate, losses by kind, latency).
    A recording played to its end says "ended"; the page's speed selector shows --speed.
    The server
    listens on 127.0.0.1 only unless --host says otherwise; it prints the address and
    serves until Ctrl-C.
    """
    import webbrowser

    from tactsense.estimate.deflection import baseline_from
    from tactsense.view import LiveFeed, RecordingFeed, ViewServer, view_locator
    from tactsense.view.server import is_loopback

    listen = "127.0.0.1" if host is None else host.strip()
    if not listen:
        fail("--host is empty; give an address such as 127.0.0.1 or 0.0.0.0")
    path = Path(source)
    is_recording = path.is_file() or path.suffix.lower() in RECORDING_SUFFIXES
    if is_recording and not path.is_file():
        fail(f"no recording at {source}")
    if is_recording and sensor is not None:
        fail("--sensor applies to a device; a recording names its own sensor")
    if is_recording and timeout is not None:
        fail("--timeout applies to a device, not to a recording")
    if not is_recording and speed != 1.0:
        fail("--speed applies to recordings; a device sends at its own rate")
    try:
        cal = None if calibration is None else load_calibration(calibration)
        if is_recording:

            def locator_for(spec, file):
                if cal is not None:
                    return view_locator(spec, calibration=cal, threshold=threshold)
                start = file.frames(0, baseline_frames)
                base = baseline_from(start, min(baseline_frames, len(start)))
                return view_locator(spec, baseline=base, threshold=threshold)

            feed = RecordingFeed(path, locator_for, speed=speed)
        else:
            from tactsense.stream.sources import split_source

            def make_locator(spec):
                return view_locator(
                    spec,
                    calibration=cal,
                    baseline_frames=baseline_frames,
                    threshold=threshold,
                    frame_period_s=None,  # the sensor's scan period: device time, not the wire's
                )

            streams_at_once = not source.startswith(LSL_PREFIX) and sensor is not None
            if streams_at_once and split_source(source)[0] is not None:
                # a device of another format streams once its line opens: locator first
                spec = load_sensor(sensor)
                split_source(source)[0].check_converter(spec)  # refused before it compiles
                locator = make_locator(spec)
                reader = _open_reader(source, sensor, timeout, start=False)
            else:
                reader = _open_reader(source, sensor, timeout, start=False)
                locator = None
            try:
                if locator is None:
                    locator = make_locator(reader.sensor)
            except BaseException:
                reader.close()
                raise
            feed = LiveFeed(reader, locator)
    except TactsenseInputError as error:
        fail(str(error))
    try:
        server = ViewServer(feed, host=listen, port=port)
    except OSError as error:
        feed.stop()
        fail(f"cannot listen on {listen}:{port}: {error.strerror or error}")
    if not is_loopback(listen):
        console.print(
            f"[bold red]warning:[/] listening on {listen}, not only on this machine: anyone "
            "who can reach it sees the finger and can control playback (there is no login)."
        )
    typer.echo(server.url)
    sys.stdout.flush()
    what = f"recording {source} ({feed.n_frames} frames)" if is_recording else source
    console.print(f"showing {what} at {server.url}; Ctrl-C stops", soft_wrap=True)
    if open_browser:
        webbrowser.open(server.url)
    try:
        server.run()
    except KeyboardInterrupt:
        pass
    console.print(f"stopped: {feed.frames_in} frames shown")
