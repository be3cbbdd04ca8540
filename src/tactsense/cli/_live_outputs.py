"""What the live commands write: a recording's format by its name, and the estimates of
``live`` as JSON lines or CSV (one row per frame, or per contact where a kind has many)."""

from __future__ import annotations

import csv
import json
import sys
from enum import StrEnum
from pathlib import Path

import numpy as np

from tactsense.cli._common import fail


class RecordFormat(StrEnum):
    h5 = "h5"
    mcap = "mcap"


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


class LiveFormat(StrEnum):
    jsonl = "jsonl"
    csv = "csv"


LIVE_CONTACT_COLUMNS = (
    "sequence", "device_time_s", "host_time_s", "n_contacts", "id", "x_mm", "y_mm", "z_mm",
    "row", "col", "force_n", "peak", "major_mm", "minor_mm", "orientation_deg", "taxels",
    "area_mm2", "vx_mm_s", "vy_mm_s", "vz_mm_s", "slip", "flags", "flag_names", "rezeroing",
    "latency_ms",
)  # fmt: skip
"""Columns of ``live --format csv`` on a pad or a point set: one row per contact."""

SHEAR_COLUMNS = (
    "shear_x_n", "shear_y_n", "shear_n", "shear_angle_deg", "shear_ratio", "slip_state",
    "stick_ratio", "friction", "slip_onset_s", "slip_detected_s",
)  # fmt: skip
"""More columns of ``live --format csv`` on a three-axis pad (r8-triview): each contact's
tangential force along x and y, its size [N], direction [deg] from +x toward +y, ratio to
the normal force [-], slip (``stick``, ``partial``, ``gross``), stick ratio c/a [-],
friction coefficient [-], slip onset and its detection [s]
(:mod:`tactsense.estimate.triaxial.live`)."""


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


class _FrameSteps:
    """Ctrl-C (or SIGTERM) between frames, never inside one: while a frame is being
    estimated, published and written, a press is held (``tactsense._signals``' gate, as
    around compiled code) and delivered once the frame is complete, so that every count
    kept is of steps completed. Waiting for the next frame, it interrupts at once. Off
    the main thread it changes nothing."""

    __slots__ = ("outer",)

    def __enter__(self):
        from tactsense import _signals

        self.outer = None
        if _signals.gate_ready():
            self.outer = _signals._inside_compiled
            _signals._inside_compiled = True
        return self

    def __exit__(self, *exc) -> None:
        from tactsense import _signals

        if self.outer is not None:
            _signals._inside_compiled = self.outer
            if not self.outer:
                _signals.deliver()


def write_estimates(stream, reader, locator, *, output_format, multi, frames, duration,
                    rezero, outlets, latencies, used) -> None:  # fmt: skip
    """Estimate the frames of ``reader`` with ``locator`` and write them to ``stream``:
    one JSON object per frame, or CSV rows (one per contact where ``multi``); the
    latencies of the estimates written are appended to ``latencies`` and the frames
    done counted in ``used[0]``; ``rezero`` (an Event) re-zeroes the locator before the
    next frame.

    Every count is of steps completed: a frame is counted once its estimate is made,
    given to ``outlets`` and its line written (a frame in the baseline: once given to
    ``outlets``), an estimate once its line is written; Ctrl-C during a frame takes
    effect when the frame is complete (:class:`_FrameSteps`)."""
    from tactsense.stream.live import CONTACT_FIELDS, FIELDS

    writer = None
    contact_fields = CONTACT_FIELDS
    if int(getattr(reader.sensor, "components", 1)) > 1:  # r8-triview: shear and slip
        contact_fields = (*CONTACT_FIELDS, *SHEAR_COLUMNS)
    if output_format is LiveFormat.csv:
        fields = LIVE_CONTACT_COLUMNS if multi else FIELDS
        if contact_fields is not CONTACT_FIELDS:  # r8-triview
            fields = (*LIVE_CONTACT_COLUMNS, *SHEAR_COLUMNS)
        writer = csv.DictWriter(stream, fieldnames=fields, lineterminator="\n")
        writer.writeheader()
    steps = _FrameSteps()
    for frame in reader.frames(max_frames=frames, duration_s=duration):
        with steps:
            _one_frame(frame, stream, writer, locator, outlets, rezero, multi, latencies,
                       contact_fields)  # fmt: skip
            used[0] += 1


def _finite(value):
    """JSON has no NaN: None for a value that does not exist, in the contacts' dicts too
    (a three-axis contact's stick ratio before it is known, r8-triview)."""
    if isinstance(value, float) and not np.isfinite(value):
        return None
    if isinstance(value, dict):
        return {k: _finite(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [_finite(v) for v in value]
    return value


def _one_frame(frame, stream, writer, locator, outlets, rezero, multi, latencies, fields):
    """Estimate one frame, give it to ``outlets``, write its line; its latency goes to
    ``latencies`` once the line is written."""
    if rezero.is_set():
        rezero.clear()
        locator.rezero()
        print("re-zeroing: the baseline from the next frames", file=sys.stderr)
    estimate = locator(frame)
    if outlets is not None:
        outlets.push(frame, estimate)
    if estimate is None:
        return
    if writer is None:
        stream.write(json.dumps(_finite(estimate), allow_nan=False) + "\n")
    elif multi:
        for row in _contact_rows(estimate, fields):
            writer.writerow(row)
    else:
        writer.writerow({k: repr(v) if isinstance(v, float) else v for k, v in estimate.items()})
    stream.flush()
    latencies.append(estimate["latency_ms"])


# ---- foxglove live (r6-fox) ----
FOXGLOVE_HELP = (
    "Also serve the frames and contacts to Foxglove on a WebSocket at [HOST:]PORT: HOST "
    "127.0.0.1 (this machine only) unless given, PORT 0-65535 (0: a free port; 8765 is "
    "Foxglove's usual). The channels and schemas of the MCAP export (docs/foxglove.md)."
)
"""Help of ``--foxglove`` (live and view)."""


def check_foxglove(address: str | None) -> tuple[str, int] | None:
    """``--foxglove [HOST:]PORT`` parsed, and the extra there, before any work starts."""
    if address is None:
        return None
    from tactsense._validation import TactsenseInputError
    from tactsense.interop.foxglove_live import check_available, parse_address

    try:
        host_port = parse_address(address)
        check_available()
    except TactsenseInputError as error:
        fail(str(error))
    return host_port


def bind_foxglove(address: tuple[str, int] | None):
    """The Foxglove server of ``--foxglove`` bound (None without it), before the source
    is opened: a port in use is one line before any device is touched. Its sensor comes
    with :func:`serve_foxglove`."""
    if address is None:
        return None
    from tactsense._validation import TactsenseInputError
    from tactsense.interop.foxglove_live import FoxgloveLive

    host, port = address
    try:
        return FoxgloveLive(None, host=host, port=port)
    except TactsenseInputError as error:
        fail(str(error))


def serve_foxglove(server, sensor):
    """Give the bound server of ``--foxglove`` (None without it) its sensor and print its
    address on standard error; a warning when it listens beyond this machine."""
    if server is None:
        return None
    from tactsense.cli._common import console
    from tactsense.view.server import is_loopback

    server.attach(sensor)
    if not is_loopback(server.host):
        console.print(
            f"[bold red]warning:[/] Foxglove on {server.host}, not only on this machine: "
            "anyone who can reach it sees the sensor (there is no login)."
        )
    console.print(
        f"foxglove: {server.url} (Foxglove: Open connection, Foxglove WebSocket)",
        soft_wrap=True,
        highlight=False,
    )
    return server


def close_foxglove(server) -> None:
    """Stop the server of ``--foxglove`` (clients see the connection close) and say what
    it sent."""
    if server is None:
        return
    from tactsense.cli._common import console

    server.close()
    try:
        console.print(
            f"foxglove: sent {server.frames} frames and {server.contacts} contacts",
            highlight=False,
        )
    except (OSError, ValueError):  # standard error closed (a broken pipe)
        pass


class Outlets:
    """Several outlets (LSL, Foxglove, ROS 2) as one: each takes every frame and its
    estimate (``push``, or a ROS 2 publisher's ``publish``)."""

    def __init__(self, *outlets):
        self.outlets = [o for o in outlets if o is not None]

    def push(self, frame, estimate) -> None:
        for outlet in self.outlets:
            if hasattr(outlet, "push"):
                outlet.push(frame, estimate)
            else:
                outlet.publish(frame, estimate)


# ---- /foxglove live (r6-fox) ----
# ---- ROS 2 topics (r6-ros2) ----
def _check_ros2_options(ros2: bool, namespace: str | None, config: str | None) -> None:
    """Refuse --namespace or --ros2-config without --ros2, a bad namespace, an unreadable
    or non-Cyclone DDS configuration, or a missing extra: before any line is opened."""
    from tactsense._validation import TactsenseInputError

    if not ros2:
        given = [n for n, v in (("--namespace", namespace), ("--ros2-config", config)) if v]
        if given:
            fail(f"{' and '.join(given)} appl{'y' if len(given) > 1 else 'ies'} to --ros2")
        return
    try:
        from tactsense.interop.ros2.config import resolve_config
        from tactsense.interop.ros2.publisher import (
            _cyclonedds,
            check_namespace,
            domain_id_from_environment,
        )

        _cyclonedds()
        if namespace is not None:
            check_namespace(namespace)
        resolve_config(config)
        domain_id_from_environment()
    except TactsenseInputError as error:
        fail(str(error))


# ---- /ROS 2 topics (r6-ros2) ----
