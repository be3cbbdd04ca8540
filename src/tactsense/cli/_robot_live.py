"""``emulate``, ``record`` and ``live`` for a robot skin: several devices at once
(``docs/robot.md``, "Capture from several devices").

``cli/live.py`` hands over here when ``--skin`` is given (short marked blocks).
"""

from __future__ import annotations

import json
import os
import sys
import time
from pathlib import Path
from typing import Annotated, Any

import typer
from rich.progress import Progress, TextColumn

from tactsense._signals import stopped_by
from tactsense._validation import TactsenseInputError
from tactsense.cli._common import console, fail

SourcesArgument = Annotated[
    list[str],
    typer.Argument(
        help="The device: a serial port (/dev/ttyUSB0), a pty path printed by 'tactsense "
        "emulate', socket://127.0.0.1:PORT, or any other pyserial URL; or lsl:NAME, a Lab "
        "Streaming Layer frames outlet (its name or source_id); or FORMAT:URL for a device "
        "that speaks text lines, marker-framed bytes or JustFloat (text:/dev/ttyACM0, "
        "marker,start=AA55,width=16:URL, justfloat:URL; docs/devices.md; --sensor needed). "
        "With --skin: one source per device of the skin, as DEVICE=SOURCE (what 'tactsense "
        "emulate --skin' prints), or plain sources in the skin's device order.",
        show_default=False,
    ),
]
SkinOption = Annotated[
    str | None,
    typer.Option(
        "--skin",
        help="A robot skin (a preset: hand4, icub_hand; or a skin TOML file): one device "
        "per board of the skin, several at once (docs/robot.md).",
    ),
]
DropoutOption = Annotated[
    float,
    typer.Option(
        "--dropout-s",
        help="--skin: a device silent this long has dropped out; the others go on [s] "
        "(more than 0, at most 3600).",
    ),
]
DriftOption = Annotated[
    float | None,
    typer.Option(
        "--drift-ppm",
        help="--skin: every device's clock runs this much faster than the host's [ppm] "
        "(-1000 to 1000) [default: drawn per device with --seed, uniform in +-30 ppm].",
    ),
]
ClockOffsetOption = Annotated[
    float | None,
    typer.Option(
        "--clock-offset-s",
        help="--skin: every device's clock reads this when it first streams [s] (0 to 1e7) "
        "[default: drawn per device with --seed, uniform in 0-100 s].",
    ),
]


DEFAULT_DROPOUT_S = 2.0
"""--dropout-s's default [s]."""


def one_source(sources: list[str], dropout_s: float) -> str:
    """The single source of a command without --skin."""
    if dropout_s != DEFAULT_DROPOUT_S:
        fail("--dropout-s applies with --skin (several devices)")
    named = [s for s in sources if _names_a_device(s)]
    if named:
        fail(
            f"{named[0]}: DEVICE=SOURCE names a board of a robot skin; add --skin SKIN "
            "(a preset: hand4, icub_hand; or a skin TOML file)"
        )
    if len(sources) != 1:
        fail(
            f"{len(sources)} sources given; give one SOURCE, or several with --skin SKIN "
            "(one per device of the skin)"
        )
    return sources[0]


def _names_a_device(source: str) -> bool:
    """Whether ``source`` reads as DEVICE=SOURCE (a board's name, then a source)."""
    import re

    name, equals, rest = source.partition("=")
    return bool(equals and rest and re.fullmatch(r"[A-Za-z][\w.-]*", name))


def is_robot_folder(path) -> bool:
    """Whether ``path`` is a robot recording (a folder), for a hint to add --skin."""
    from tactsense.io.robot_recording import is_robot_recording

    return is_robot_recording(path)


def _plural(count: int, word: str) -> str:
    return f"{count} {word}{'' if count == 1 else 's'}"


def _skin(name: str):
    from tactsense.robot import load_skin

    try:
        return load_skin(name)
    except TactsenseInputError as error:
        fail(f"--skin: {error}")


def _check_robot_output(out: Path, force: bool, inputs=()) -> None:
    """A robot recording's folder: a new name, or with --force an existing robot
    recording (never anything else, never an input)."""
    from tactsense.io.robot_recording import is_robot_recording

    out = Path(out)
    parent = out.parent if str(out.parent) else Path(".")
    for source in inputs:
        if source is not None and Path(source).exists() and out.resolve() == Path(source).resolve():
            fail(f"output {out} is the input {source}; an output never replaces an input")
    if out.suffix.lower() in (".h5", ".hdf5", ".mcap"):
        fail(
            f"--out {out}: with --skin the recording is a folder (a stream per patch); "
            "give a name without the extension"
        )
    if not parent.is_dir():
        fail(f"folder {parent} of output {out} does not exist; create it first")
    if not os.access(parent, os.W_OK | os.X_OK):
        fail(f"cannot write output {out}: folder {parent} is not writable")
    if out.exists():
        if not force:
            fail(f"{out} exists; pass --force to replace it, or choose another name")
        if not is_robot_recording(out):
            fail(f"{out} exists and is not a robot recording; it is not replaced, --force or not")


def _refuse(given: dict[str, Any], defaults: dict[str, Any], why: str) -> None:
    wrong = [
        "--" + name.replace("_", "-") for name, value in defaults.items() if given[name] != value
    ]
    if wrong:
        fail(f"{', '.join(wrong)} {'does' if len(wrong) == 1 else 'do'} not apply {why}")


def _check_dropout(dropout_s: float) -> None:
    if not 0 < dropout_s <= 3600:
        fail(f"--dropout-s must be more than 0 and at most 3600 [s]; got {dropout_s:g}")


# ---- emulate --skin ---------------------------------------------------------------------
EMULATE_SKIN_OPTIONS = (
    "skin", "drift_ppm", "clock_offset_s", "recording", "port", "loop", "seed", "garbage",
    "bitflip", "drop", "truncate", "stall", "stall_s", "fault_seed",
)  # fmt: skip
"""emulate's options that apply with --skin."""


def emulate_skin(ctx: typer.Context, options: dict[str, Any]) -> None:
    """Serve a device per board of the skin, each on its own pseudo-terminal, or with
    --port on its own TCP port of 127.0.0.1 (--port P: P, P+1, ...; 0: free ones)."""
    from tactsense.io.robot_recording import is_robot_recording, read_robot_recording
    from tactsense.stream import FaultRates
    from tactsense.stream.robot_emulator import device_emulators, rest_streams

    if options["skin"] is None:
        fail("--drift-ppm and --clock-offset-s apply with --skin (a device per board)")
    given = [
        "--" + name.replace("_", "-").replace("wire-format", "format")
        for name in ctx.params
        if name not in EMULATE_SKIN_OPTIONS
        and getattr(ctx.get_parameter_source(name), "name", "") == "COMMANDLINE"
    ]
    if given:
        fail(
            f"--skin excludes {', '.join(given)}: each patch sends untouched frames, or a "
            "robot recording's (--recording RUN), in the tactsense protocol at its own rate"
        )
    skin = _skin(options["skin"])
    drift, offset = options["drift_ppm"], options["clock_offset_s"]
    if drift is not None and not abs(drift) <= 1000:
        fail(f"--drift-ppm must lie in -1000 to 1000 [ppm]; got {drift:g}")
    if offset is not None and not 0 <= offset <= 1e7:
        fail(f"--clock-offset-s must lie in 0 to 1e7 [s]; got {offset:g}")
    port = options["port"]
    devices = list(skin.devices)
    if port and port + len(devices) - 1 > 65535:
        fail(f"--port {port}: the {len(devices)} devices need ports {port} to "
             f"{port + len(devices) - 1}, beyond 65535")  # fmt: skip
    recording = options["recording"]
    try:
        rates = ("garbage", "bitflip", "drop", "truncate", "stall", "stall_s")
        faults = FaultRates(*(options[k] for k in rates))
        if recording is not None:
            if not is_robot_recording(recording):
                fail(f"--recording {recording}: with --skin, a robot recording (a folder)")
            played = {n: s.frames for n, s in read_robot_recording(recording).streams.items()}
            if not set(played) & {p.name for p in skin.patches}:
                fail(f"--recording {recording} holds no stream of a patch of {skin.name!r}")
            # a patch that recorded nothing sends untouched frames
            streams = {**rest_streams(skin, rng=options["seed"]), **played}
        else:
            streams = rest_streams(skin, rng=options["seed"])
        emulators = device_emulators(
            skin, streams, drift_ppm=drift, offset_s=offset, seed=options["seed"],
            faults=faults, repeat=bool(options["loop"]) or recording is None,
        )  # fmt: skip
    except TactsenseInputError as error:
        fail(str(error))
    except KeyboardInterrupt:  # a normal stop, before any device served: nothing to close
        console.print(f"stopped (by {stopped_by()}) before serving; no device was started")
        return
    threads = []
    try:
        for i, (device, emulator) in enumerate(emulators.items()):
            if port is None:  # a pseudo-terminal each, as a board on USB
                thread, where = emulator.start_pty()
            else:
                thread, chosen = emulator.start_tcp(port + i if port else 0)
                where = f"socket://127.0.0.1:{chosen}"
            threads.append(thread)
            typer.echo(f"{device}={where}")
            console.print(
                f"emulating {device} ({', '.join(emulator.layout.patches)}) on {where}: "
                f"{emulator.layout.rate_hz:g} frames/s, clock {emulator.drift_ppm:+.1f} ppm"
            )
        sys.stdout.flush()
        console.print("Ctrl-C stops")
        while all(t.is_alive() for t in threads):
            time.sleep(0.2)
    except KeyboardInterrupt:
        pass
    except (OSError, TactsenseInputError) as error:
        fail(f"cannot serve: {getattr(error, 'strerror', None) or error}")
    finally:
        _stop_all(emulators)
    for device, emulator in emulators.items():
        log = emulator.log
        console.print(f"{device}: sent {log.frames} frames ({log.delivered_intact} intact)")


def _stop_all(emulators) -> None:
    """Stop every emulator; a second Ctrl-C meanwhile is a normal stop too (emulate writes
    no file, so there is nothing half-written to report)."""
    for emulator in emulators.values():
        while True:
            try:
                emulator.stop()
                break
            except KeyboardInterrupt:
                continue


# ---- record --skin ----------------------------------------------------------------------
def record_skin(options: dict[str, Any]) -> None:
    """Record every device of the skin into a robot recording (a folder)."""
    from tactsense.stream.robot import RobotSources
    from tactsense.stream.robot_recorder import record_robot

    _refuse(
        options,
        {"frames": None, "record_format": None, "frame_id": None, "sensor": None},
        "to --skin (give --duration; each device's description comes from the skin)",
    )
    _check_dropout(options["dropout_s"])
    duration, out, quiet = options["duration"], options["out"], options["quiet"]
    out = Path(out)
    if out == Path("recording.h5"):  # record's default --out, a file: a skin needs a folder
        fail(
            "--skin: give --out RUN, the new robot recording's folder (a stream per patch); "
            "the default --out recording.h5 is for one device"
        )
    if duration is not None and not 0 < duration <= 1e7:
        fail(f"--duration must be more than 0 and at most 1e7 [s]; got {duration:g}")
    skin = _skin(options["skin"])
    _check_robot_output(out, options["force"], inputs=[options["skin"]])
    try:
        sources = RobotSources(skin, options["source"], timeout_s=options["timeout"],
                               dropout_s=options["dropout_s"])  # fmt: skip
    except TactsenseInputError as error:
        fail(str(error))
    written = [0]
    with Progress(
        TextColumn("{task.description}"), console=console,
        disable=quiet or not console.is_terminal,
    ) as bar:  # fmt: skip
        task = bar.add_task(f"recording {_plural(len(sources.sources), 'device')}")

        def update(_sources, frames: int) -> None:
            written[0] = frames
            bar.update(task, description=f"{out}: {frames} frames\n" + sources.status_line())

        interrupted = False
        try:
            record_robot(sources, out, duration_s=duration, overwrite=options["force"],
                         progress=update)  # fmt: skip
        except KeyboardInterrupt:
            interrupted = True
        except (TactsenseInputError, FileExistsError) as error:
            sources.close()
            text = str(error)
            if not out.exists() and "nothing written" not in text:
                text += "; nothing written"
            fail(text)
    console.print(sources.status_line())
    stopped = f" (stopped by {stopped_by()})" if interrupted else ""
    if not out.exists():
        console.print(f"stopped{stopped} before any frame arrived; nothing written")
        raise typer.Exit(0)
    dropped = [d for d, s in sources.status.items() if s.state == "dropped"]
    console.print(
        f"wrote {out}{stopped}: {_plural(written[0], 'frame')} from "
        f"{_plural(len(sources.sources), 'device')}"
        + (f"; dropped out: {', '.join(dropped)}" if dropped else "")
    )


# ---- live --skin ------------------------------------------------------------------------
def live_skin(options: dict[str, Any]) -> None:
    """Status of every device (rate, losses, clock) as the frames arrive: one JSON line
    per device each second on standard output (or --out)."""
    from tactsense.cli._common import atomic_output, check_output
    from tactsense.stream.robot import RobotSources

    options = {**options, "output_format": str(getattr(options["output_format"], "value", ""))}
    _refuse(options, {"calibration": None, "frames": None, "lsl": False, "foxglove": None,
                      "ros2": False, "sensor": None, "output_format": "jsonl"},
            "to --skin (live --skin reports each device's status)")  # fmt: skip
    _check_dropout(options["dropout_s"])
    duration, out = options["duration"], options["out"]
    if duration is not None and not 0 < duration <= 1e7:
        fail(f"--duration must be more than 0 and at most 1e7 [s]; got {duration:g}")
    skin = _skin(options["skin"])
    if out is not None:
        check_output(out, options["force"], inputs=[options["skin"]])
    try:
        sources = RobotSources(skin, options["source"], timeout_s=options["timeout"],
                               dropout_s=options["dropout_s"])  # fmt: skip
        sources.open()
    except TactsenseInputError as error:
        fail(str(error))
    interrupted = False

    def run(stream) -> None:
        reported = time.perf_counter()
        for _frame in sources.frames(duration_s=duration):
            now = time.perf_counter()
            if now - reported >= 1.0:
                reported = now
                _report(sources, stream)
        _report(sources, stream)

    try:
        if out is None:
            run(sys.stdout)
        else:
            with atomic_output(Path(out)) as temporary, open(temporary, "w") as stream:
                try:
                    run(stream)
                except KeyboardInterrupt:
                    interrupted = True
    except KeyboardInterrupt:
        interrupted = True
    except BrokenPipeError:
        sys.stderr.close()
        return
    finally:
        sources.close()
    stopped = f" (stopped by {stopped_by()})" if interrupted else ""
    console.print(f"{_plural(len(sources.status), 'device')}{stopped}:\n" + sources.status_line())


def status_record(status, wall_offset_s: float) -> dict[str, Any]:
    """One device's status as a JSON object: state, rate [Hz], losses, clock."""
    clock = status.clock.as_dict() if status.clock.count else {}
    return {
        "time_s": time.time(),
        "device": status.device,
        "state": status.state,
        "rate_hz": round(status.rate_hz, 3),
        **status.losses.as_dict(),
        "drift_ppm": clock.get("drift_ppm"),
        "skew_ms": None if not clock else status.skew_s * 1e3,
        "delay_median_ms": None if not clock else clock["residual_s"] * 1e3,
        "delay_p99_ms": None if not clock else clock["residual_p99_s"] * 1e3,
        "dropped_at_s": status.dropped_at_s,
        "error": status.error,
    }


def _report(sources, stream) -> None:
    for status in sources.status.values():
        stream.write(json.dumps(status_record(status, sources.wall_offset_s)) + "\n")
    stream.flush()
