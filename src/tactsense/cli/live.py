"""The live system on the command line: ``emulate``, ``record``, ``live`` and ``view``.

Where the frames come from is :mod:`tactsense.cli._live_sources`; what is written,
:mod:`tactsense.cli._live_outputs`.
"""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Annotated

import numpy as np
import typer
from rich.progress import Progress, TextColumn

from tactsense._signals import stopped_by
from tactsense._validation import TactsenseInputError
from tactsense.cli import _robot_live as robot  # r7-capture
from tactsense.cli import _scenario as shear_options  # r8-fixc8: simulate's
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
from tactsense.cli._live_outputs import (
    FOXGLOVE_HELP,
    LiveFormat,
    Outlets,
    RecordFormat,
    _check_record_suffix,
    _check_ros2_options,
    _listen_for_rezero,
    bind_foxglove,
    check_foxglove,
    close_foxglove,
    serve_foxglove,
    write_estimates,
)
from tactsense.cli._live_sources import (
    DurationLimit,
    FramesLimit,
    StreamSensorOption,
    TimeoutOption,
    _check_duration,
    _note_narrow_samples,
    _open_reader,
    _refuse_recording_source,
    _source_file,
    _stream_and_locator,
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
from tactsense.cli._view_command import view
from tactsense.cli._wire_components import (  # r8-triwire
    ComponentsOption,
    format_with_components,
    refuse_with_skin,
    source_with_components,
)
from tactsense.estimate.contacts.array_calibration import load_calibration
from tactsense.kinds import kind_of
from tactsense.sensor import load_sensor

app = new_group("The live system: an emulated finger, recording and live estimates.")

RATE = dict(min=0.0, max=1.0)

SCENARIO_PARAMETERS = (
    "sensor", "scenario", "row", "col", "force_g", "increment", "dwell_s", "lift_s",
    "repeats", "x_mm", "y_mm", "separation_mm", "indenter", "size_mm", "speed_mm_s",
    "angle_deg", "forces_g", "shear_ratio", "shear_angle_deg", "friction", "ramp_s",
    "flaws", "seed",
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
    shear_ratio: shear_options.ShearRatioOption = None,  # r8-fixc8: simulate's shear options
    shear_angle_deg: shear_options.ShearAngleOption = None,
    friction: shear_options.FrictionOption = None,
    ramp_s: shear_options.RampOption = None,
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
    # ---- robot skin (r7-capture) ----
    skin: robot.SkinOption = None,
    drift_ppm: robot.DriftOption = None,
    clock_offset_s: robot.ClockOffsetOption = None,
    # ---- /r7-capture ----
    components: ComponentsOption = None,  # r8-triwire
) -> None:
    """Play a sensor as a device: frames of the twin (a finger, a pad or a point set) in the
    wire protocol on a pty or TCP; with --skin, a device per board of a robot skin, each on
    its own pty or TCP port (--port P: P, P+1, ...), printed as DEVICE=URL (docs/robot.md).

    Prints where to connect on standard output (a pty path, or socket://127.0.0.1:PORT)
    and serves until Ctrl-C. The device streams after a host sends START
    (docs/protocol.md); 'tactsense record' and 'tactsense live' do.
    """
    from tactsense.io.recording import read_recording
    from tactsense.stream import Emulator, FaultRates
    from tactsense.stream.sources import parse_format

    if (skin, drift_ppm, clock_offset_s) != (None, None, None):  # r7-capture
        return robot.emulate_skin(ctx, locals())
    wire_format = format_with_components(wire_format, components)  # r8-triwire
    if not 0 < speed <= 1e6:
        fail(f"--speed must be more than 0 and at most 1e6 (a multiple of the scan rate); "
             f"got {speed:g}; 1e6 sends as fast as the line takes them")  # fmt: skip
    if recording is not None and robot.is_robot_folder(recording):  # r7-fixc
        fail(f"--recording {recording} is a robot recording (a folder): add --skin SKIN")
    if recording is not None:
        given = [
            "--" + name.replace("_", "-")
            for name in SCENARIO_PARAMETERS
            if getattr(ctx.get_parameter_source(name), "name", "") == "COMMANDLINE"
        ]
        if given:
            fail(f"--recording excludes {', '.join(given)}: the recording brings its own "
                 "sensor and frames")  # fmt: skip
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
                shear=dict(shear_ratio=shear_ratio, shear_angle_deg=shear_angle_deg,
                           friction=friction, ramp_s=ramp_s),  # r8-fixc8
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
    injected = ("garbage", "bitflip", "drop", "truncate", "stall")
    console.print(f"sent {log.frames} frames ({log.delivered_intact} intact); injected: "
                  + ", ".join(f"{k} {getattr(log, k)}" for k in injected))  # fmt: skip


@app.command()
def record(
    source: robot.SourcesArgument,  # r7-capture: several with --skin
    out: Annotated[
        Path,
        typer.Option(
            "--out",
            "-o",
            help="New recording: HDF5 (crash-safe), or MCAP (see --format); with --skin a new "
            "folder, required.",
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
    skin: robot.SkinOption = None,  # ---- r7-capture ----
    dropout_s: robot.DropoutOption = 2.0,  # ---- /r7-capture ----
    components: ComponentsOption = None,  # r8-triwire
) -> None:
    """Record a device's frames as they arrive, until --frames, --duration or Ctrl-C;
    with --skin, several devices into a robot recording (a folder; docs/robot.md).

    HDF5 is flushed at least once a second: if the recorder is killed, every frame up
    to the last flush is readable. Losses (bad check, gaps, timeouts...) are counted
    and stored with the frames.
    """
    from tactsense.stream import StreamError
    from tactsense.stream import record as run_record

    refuse_with_skin(skin, components)  # r8-triwire
    if skin is not None:  # r7-capture
        return robot.record_skin(locals())
    source = robot.one_source(source, dropout_s)  # r7-capture
    source = source_with_components(source, components)  # r8-triwire
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


@app.command()
def live(
    source: robot.SourcesArgument,  # r7-capture: several with --skin
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
            "('interpolate', 'cop', 'fit' or 'joint')."
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
    # ---- foxglove live (r6-fox) ----
    foxglove: Annotated[
        str | None, typer.Option("--foxglove", metavar="[HOST:]PORT", help=FOXGLOVE_HELP)
    ] = None,
    # ---- /foxglove live (r6-fox) ----
    # ---- ROS 2 topics (r6-ros2) ----
    ros2: Annotated[
        bool,
        typer.Option(
            "--ros2",
            help="Also publish every frame as ROS 2 topics over DDS, without ROS 2: "
            "TactileState, TactileContacts, sensor_msgs/Image and geometry_msgs/"
            "WrenchStamped under --namespace, best effort, keep last 5 (docs/ros2.md). "
            "DDS stays on 127.0.0.1 unless --ros2-config or CYCLONEDDS_URI says otherwise.",
        ),
    ] = False,
    namespace: Annotated[
        str | None,
        typer.Option(
            "--namespace",
            help="--ros2: the node's ROS 2 namespace, '/' or /name/... of letters, digits "
            "and _ (no trailing /; at most 232 characters); as ROS 2 does with a node's "
            "namespace, a relative one gets a leading / (foo: /foo; '': /) "
            "[default: /<sensor name>].",
        ),
    ] = None,
    ros2_config: Annotated[
        str | None,
        typer.Option(
            "--ros2-config",
            help="--ros2: a Cyclone DDS configuration (an XML file, file://PATH or XML) "
            "for a network other than the loopback [default: CYCLONEDDS_URI, else "
            "127.0.0.1 only, multicast off].",
        ),
    ] = None,
    # ---- /ROS 2 topics (r6-ros2) ----
    skin: robot.SkinOption = None,  # ---- r7-capture ----
    dropout_s: robot.DropoutOption = 2.0,  # ---- /r7-capture ----
    components: ComponentsOption = None,  # r8-triwire
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

    refuse_with_skin(skin, components)  # r8-triwire
    if skin is not None:  # r7-capture
        return robot.live_skin(locals())
    source = robot.one_source(source, dropout_s)  # r7-capture
    source = source_with_components(source, components)  # r8-triwire
    _check_duration(duration)
    foxglove_address = check_foxglove(foxglove)  # r6-fox
    if out is not None:
        check_output(out, force, inputs=[calibration, *sensor_file(sensor), *_source_file(source)])
    _check_ros2_options(ros2, namespace, ros2_config)  # r6-ros2
    foxglove_server = bind_foxglove(foxglove_address)  # r6-fox: before the source opens
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
        # ---- foxglove live (r6-fox) ----
        serve_foxglove(foxglove_server, reader.sensor)
        if foxglove_server is not None:
            outlets = Outlets(outlets, foxglove_server)
        # ---- /foxglove live (r6-fox) ----
        publisher = None  # ---- r6-ros2 ----
        if ros2:
            from tactsense.interop.ros2 import Ros2Publisher

            publisher = Ros2Publisher(reader.sensor, namespace=namespace, config=ros2_config)
            publisher.wait_for_subscribers(1.0)  # those already listening get the first frame
            outlets = Outlets(outlets, publisher)
        reader.start()
    except BaseException as error:
        if foxglove_server is not None:  # r6-fox: bound before the source; nothing sent
            foxglove_server.close()
        if isinstance(error, TactsenseInputError):
            fail(str(error))
        raise
    latencies: list[float] = []
    used = [0]  # frames given to the locator
    multi = kind_of(reader.sensor).multi_contact
    rezero = threading.Event()
    _listen_for_rezero(rezero, signal)

    def run(stream) -> None:
        write_estimates(
            stream, reader, locator, output_format=output_format, multi=multi, frames=frames,
            duration=duration, rezero=rezero, outlets=outlets, latencies=latencies, used=used,
        )  # fmt: skip

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
    finally:
        close_foxglove(foxglove_server)  # r6-fox
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
    if publisher is not None:  # r6-ros2
        console.print(publisher.summary())
        publisher.close()


app.command()(view)  # registered last, as it always was
