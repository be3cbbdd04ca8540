"""``tactsense view``: the sensor in a web browser (registered in the live group, after
``live``)."""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Annotated

import typer

from tactsense._validation import TactsenseInputError
from tactsense.cli._common import (
    BaselineFramesOption,
    CalibrationOption,
    ContactThresholdOption,
    console,
    fail,
)
from tactsense.cli._live_outputs import (
    FOXGLOVE_HELP,
    RECORDING_SUFFIXES,
    bind_foxglove,
    check_foxglove,
    close_foxglove,
    serve_foxglove,
)
from tactsense.cli._live_sources import (
    LSL_PREFIX,
    StreamSensorOption,
    TimeoutOption,
    _open_reader,
)
from tactsense.cli._robot_view import (  # r7-hand3d
    ROBOT_JOINTS_CSV_HELP,
    ROBOT_JOINTS_HELP,
    ROBOT_SKIN_HELP,
    is_robot_view,
    view_robot,
)
from tactsense.estimate.contacts.array_calibration import load_calibration
from tactsense.sensor import load_sensor


def view(
    source: Annotated[
        list[str],  # r7-hand3d: several sources with --skin (a hand's devices)
        typer.Argument(
            help="A recording (.h5 from 'tactsense record' or 'simulate') to play back, or "
            "a device: a serial port, a pty path, socket://127.0.0.1:PORT or any pyserial "
            "URL; or lsl:NAME, a Lab Streaming Layer frames outlet; or FORMAT:URL for a "
            "device speaking text lines, marker-framed bytes or JustFloat (docs/devices.md). "
            "A robot recording (a folder), or with --skin the skin's devices "
            "(docs/robot.md)."
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
    # ---- foxglove live (r6-fox) ----
    foxglove: Annotated[
        str | None, typer.Option("--foxglove", metavar="[HOST:]PORT", help=FOXGLOVE_HELP)
    ] = None,
    # ---- /foxglove live (r6-fox) ----
    # ---- robot view (r7-hand3d) ----
    skin: Annotated[str | None, typer.Option("--skin", help=ROBOT_SKIN_HELP)] = None,
    joints: Annotated[
        str | None, typer.Option("--joints", metavar="NAME=RAD,...", help=ROBOT_JOINTS_HELP)
    ] = None,
    joints_csv: Annotated[
        Path | None, typer.Option("--joints-csv", metavar="FILE", help=ROBOT_JOINTS_CSV_HELP)
    ] = None,
    # ---- /robot view (r7-hand3d) ----
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

    from tactsense.view import LiveFeed, RecordingFeed, ViewServer, view_locator
    from tactsense.view.server import is_loopback
    from tactsense.view.vectors import baseline_of  # r8-triview: any frame shape

    # ---- robot view (r7-hand3d): a robot recording or a skin's devices, in 3-D ----
    if is_robot_view(source, skin):
        view_robot(
            source, skin=skin, joints=joints, joints_csv=joints_csv, port=port, host=host,
            open_browser=open_browser,
            speed=speed, baseline_frames=baseline_frames, threshold=threshold, timeout=timeout,
            refused={"--calibration": calibration is not None, "--sensor": sensor is not None,
                     "--foxglove": foxglove is not None},
        )  # fmt: skip
        return
    if joints is not None or joints_csv is not None:
        fail(
            "--joints and --joints-csv apply to a robot skin's view (a robot recording, or --skin)"
        )
    if len(source) != 1:
        fail("several sources are a robot skin's devices: give --skin SKIN")
    source = source[0]
    if Path(source).is_dir():  # r7-fixc: a folder is no device nor recording
        fail(
            f"{source} is a folder; give a recording (.h5), a robot recording (the folder "
            "holding robot.json), or a device"
        )
    # ---- /robot view (r7-hand3d) ----
    foxglove_address = check_foxglove(foxglove)  # r6-fox
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
    foxglove_server = bind_foxglove(foxglove_address)  # r6-fox: before the source opens
    try:
        cal = None if calibration is None else load_calibration(calibration)
        if is_recording:

            def locator_for(spec, file):
                if cal is not None:
                    return view_locator(spec, calibration=cal, threshold=threshold)
                start = file.frames(0, baseline_frames)
                base = baseline_of(start, min(baseline_frames, len(start)))  # r8-triview
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
    except BaseException as error:
        if foxglove_server is not None:  # r6-fox: bound before the source; nothing sent
            foxglove_server.close()
        if isinstance(error, TactsenseInputError):
            fail(str(error))
        raise
    try:
        server = ViewServer(feed, host=listen, port=port)
    except OSError as error:
        feed.stop()
        if foxglove_server is not None:  # r6-fox
            foxglove_server.close()
        fail(f"cannot listen on {listen}:{port}: {error.strerror or error}")
    # ---- foxglove live (r6-fox): the page's frames and estimates, to Foxglove too ----
    serve_foxglove(foxglove_server, feed.sensor)
    if foxglove_server is not None:
        from tactsense.interop.foxglove_live import PublishingLocator

        feed.locator = PublishingLocator(feed.locator, foxglove_server)
    # ---- /foxglove live (r6-fox) ----
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
    finally:
        close_foxglove(foxglove_server)  # r6-fox
    console.print(f"stopped: {feed.frames_in} frames shown")
