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


def write_estimates(stream, reader, locator, *, output_format, multi, frames, duration,
                    rezero, outlets, latencies, used) -> None:  # fmt: skip
    """Estimate the frames of ``reader`` with ``locator`` and write them to ``stream``:
    one JSON object per frame, or CSV rows (one per contact where ``multi``); the
    latencies and the frames used are appended to ``latencies`` and counted in
    ``used[0]``; ``rezero`` (an Event) re-zeroes the locator before the next frame."""
    from tactsense.stream.live import CONTACT_FIELDS, FIELDS

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


class _Fanout:
    """Several outputs that each take every frame and its estimate (``push``)."""

    def __init__(self, *outputs):
        self._outputs = [o for o in outputs if o is not None]

    def push(self, frame, estimate) -> None:
        for output in self._outputs:
            if hasattr(output, "push"):
                output.push(frame, estimate)
            else:
                output.publish(frame, estimate)


# ---- /ROS 2 topics (r6-ros2) ----
