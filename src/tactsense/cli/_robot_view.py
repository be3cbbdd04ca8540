"""``tactsense view`` on a whole hand: a robot recording played back, or a skin's devices
live (``--skin SKIN SOURCES...``), drawn in 3-D (:mod:`tactsense.view.robot_feed`)."""

from __future__ import annotations

import sys
from pathlib import Path

import typer

from tactsense._validation import TactsenseInputError
from tactsense.cli._common import console, fail

ROBOT_SKIN_HELP = (
    "A robot skin (preset name such as hand4, or a skin TOML file): the SOURCES are its "
    "devices, as DEVICE=SOURCE items or plain sources in the skin's device order; the "
    "page draws the hand in 3-D. A robot recording (a folder) names its own skin."
)
ROBOT_JOINTS_CSV_HELP = (
    "A recording's joint states over time: a CSV with a time_s column [s, on the "
    "recording's clock] and one column per joint [rad; m for a prismatic joint], "
    "interpolated to each shown frame. Default: the recording's own joint_states.csv "
    "where it holds one."
)
ROBOT_JOINTS_HELP = (
    "The hand's joint state, NAME=POSITION items separated by commas [rad; m for a "
    "prismatic joint], each within its joint's limits; joints left out are at 0. "
    "Default: the recording's joint states (--joints-csv), else its manifest's or its "
    "simulation's joint state where it holds one, else every joint at 0."
)


JOINT_STATES_FILE = "joint_states.csv"
"""A robot recording's joint states over time, where it holds them (the iCub import
writes one: ``time_s`` then one column per joint [rad])."""


def is_robot_view(sources: list[str], skin: str | None) -> bool:
    """Whether ``tactsense view`` shows a hand: a skin is given, or the one source is a
    robot recording's folder."""
    from tactsense.io.robot_recording import is_robot_recording

    return skin is not None or (len(sources) == 1 and is_robot_recording(sources[0]))


def view_robot(
    sources: list[str],
    *,
    skin: str | None,
    joints: str | None,
    joints_csv: Path | None,
    port: int,
    host: str | None,
    open_browser: bool,
    speed: float,
    baseline_frames: int,
    threshold: float | None,
    timeout: float | None,
    refused: dict[str, bool],
) -> None:
    """Serve the hand's page until Ctrl-C; every option is checked before anything opens.

    ``refused`` names the single-array options that were given (a hand refuses them)."""
    import webbrowser

    from tactsense.io.robot_recording import read_robot_skin
    from tactsense.robot import load_skin
    from tactsense.view.robot_scene import parse_joint_state
    from tactsense.view.server import is_loopback

    for option, given in refused.items():
        if given:
            fail(f"{option} applies to one array, not to a robot skin's view")
    listen = "127.0.0.1" if host is None else host.strip()
    if not listen:
        fail("--host is empty; give an address such as 127.0.0.1 or 0.0.0.0")
    recording = skin is None
    if recording and timeout is not None:
        fail("--timeout applies to devices, not to a recording")
    if not recording and speed != 1.0:
        fail("--speed applies to recordings; devices send at their own rate")
    if recording and len(sources) != 1:
        fail("give one robot recording (a folder), or --skin SKIN and its devices' sources")
    if not recording and joints_csv is not None:
        fail("--joints-csv applies to a recording; live, give the joint state with --joints")
    if joints is not None and joints_csv is not None:
        fail("give the joint state once: --joints (fixed) or --joints-csv (over time)")
    if joints_csv is not None and not joints_csv.is_file():
        fail(f"--joints-csv: no file at {joints_csv}")
    try:
        if recording:
            from tactsense.view.robot_feed import RobotRecordingFeed

            hand = read_robot_skin(sources[0])
            state = None if joints is None else parse_joint_state(joints, hand)
            own = Path(sources[0]) / JOINT_STATES_FILE
            if joints is None and joints_csv is None and own.is_file():
                joints_csv = own
            table = None
            if joints_csv is not None:
                from tactsense.estimate._robot_joints import read_joint_csv

                table = read_joint_csv(joints_csv)
                table.check(hand)
                console.print(f"joint states from {joints_csv}", soft_wrap=True)
            feed = RobotRecordingFeed(
                Path(sources[0]),
                joint_positions=state,
                joint_states=table,
                speed=speed,
                baseline_frames=baseline_frames,
                threshold=threshold,
            )
            what = f"robot recording {sources[0]} ({len(feed.streams)} streams)"
        else:
            from tactsense.stream.robot import RobotSources
            from tactsense.view.robot_live import RobotLiveFeed

            hand = load_skin(skin)
            state = parse_joint_state(joints, hand)
            live = RobotSources(hand, list(sources), timeout_s=timeout)
            live.open()  # a source that cannot be opened is an error here, not on the page
            feed = RobotLiveFeed(
                live, joint_positions=state, baseline_frames=baseline_frames, threshold=threshold
            )
            what = f"{hand.name} from {len(live.sources)} devices"
    except (TactsenseInputError, FileNotFoundError) as error:
        fail(str(error))
    from tactsense.view.robot_server import RobotViewServer

    try:
        server = RobotViewServer(feed, host=listen, port=port)
    except OSError as error:
        feed.stop()
        fail(f"cannot listen on {listen}:{port}: {error.strerror or error}")
    if not is_loopback(listen):
        console.print(
            f"[bold red]warning:[/] listening on {listen}, not only on this machine: anyone "
            "who can reach it sees the hand and can control playback (there is no login)."
        )
    typer.echo(server.url)
    sys.stdout.flush()
    console.print(f"showing {what} at {server.url}; Ctrl-C stops", soft_wrap=True)
    if open_browser:
        webbrowser.open(server.url)
    try:
        server.run()
    except KeyboardInterrupt:
        pass
    console.print(f"stopped: {feed.frames_in} hand frames shown")
