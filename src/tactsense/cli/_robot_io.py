"""``export`` and ``import`` of a robot recording (a folder: a stream per patch).

Called by short marked blocks in :mod:`tactsense.cli.interop` and
:mod:`tactsense.cli.imports`; the work is in ``tactsense.interop.robot_*``.
"""

from __future__ import annotations

from pathlib import Path

from tactsense._validation import TactsenseInputError
from tactsense.cli._common import (
    atomic_output,
    check_output,
    console,
    fail,
    inside,
    progress_bar,
    remove_stale_partials,
)


def export_robot(
    recording: Path,
    out: Path,
    export_format,
    *,
    frame_id_given: bool,
    calibration,
    start_time: float | None,
    baseline_frames: int,
    threshold: float | None,
    episode_split: int | None,
    fps: int | None,
    quiet: bool,
    force: bool,
) -> None:
    """``tactsense export RUN/``: MCAP (a topic per patch and per link) or LeRobot (a
    feature per patch)."""
    fmt = None if export_format is None else export_format.value
    if fmt is None:
        fmt = {".mcap": "mcap"}.get(out.suffix.lower())
        if fmt is None:
            fail(
                f"{recording} is a robot recording: say --format mcap or lerobot (or name "
                "the output .mcap)"
            )
    if fmt not in ("mcap", "lerobot"):
        fail(
            f"--format {fmt}: a robot recording exports to mcap or lerobot; export one patch's "
            f"stream ({recording}/streams/PATCH.h5) for --format {fmt}"
        )
    if frame_id_given:
        fail("--frame-id: a robot recording's frame ids are its patches' links (from its skin)")
    if calibration is not None:
        fail("--calibration applies to one array; a robot recording's patches take none here")
    if inside(out, recording):
        fail(f"--out {out} lies inside the input {recording}; write it elsewhere")
    if fmt == "lerobot":
        if start_time is not None:
            fail("--start-time applies to --format mcap only")
        if out.suffix:
            fail(f"--out {out}: a LeRobot dataset is a folder; name it without an extension")
        if out.exists():
            fail(
                f"{out} exists; a LeRobot dataset goes into a new folder (--force never "
                "replaces a folder): remove it or choose another name"
            )
        check_output(out, False, what="dataset folder", inputs=[recording])
        remove_stale_partials(out.parent)
        from tactsense.interop.robot_lerobot import export_robot_lerobot

        try:
            counts = export_robot_lerobot(recording, out, fps=fps, episode_split=episode_split)
        except TactsenseInputError as error:
            fail(str(error))
        held = sum(counts["held"].values())
        console.print(
            f"wrote {out}: {counts['rows']} rows at {counts['fps']} fps in "
            f"{counts['episodes']} episodes, a feature per patch ({len(counts['patches'])} "
            f"patches; {held} patch frames held from the row before) (lerobot)"
        )
        if counts["empty"]:
            console.print(f"streams without a frame, left out: {', '.join(counts['empty'])}")
        return
    if episode_split is not None or fps is not None:
        fail("--episode-split and --fps apply to --format lerobot only")
    if out.suffix.lower() != ".mcap":
        fail(f"--out {out}: name the MCAP file with .mcap")
    check_output(out, force, inputs=[recording])
    from tactsense.interop.mcap import _writer_class
    from tactsense.interop.robot_mcap import export_robot_mcap

    try:
        _writer_class()
        with progress_bar("exporting", unit="frames", quiet=quiet) as bar:
            task = bar.add_task("frames", total=None)
            with atomic_output(out) as temporary:
                counts = export_robot_mcap(
                    recording, temporary, start_time_s=start_time,
                    baseline_frames=baseline_frames, threshold=threshold,
                    progress=lambda done, total: bar.update(task, completed=done, total=total),
                )  # fmt: skip
    except (TactsenseInputError, FileExistsError) as error:
        fail(str(error))
    frames = sum(counts["frames"].values())
    contacts = sum(counts["contacts"].values())
    console.print(
        f"wrote {out}: {frames} frames of {len(counts['patches'])} patches (a "
        f"TactileState topic each), {contacts} contacts in {counts['messages']} "
        f"TactileContacts per link (mcap, {counts['clock']} clock)"
    )
    if counts["empty"]:
        console.print(f"streams without a frame, left out: {', '.join(counts['empty'])}")
    if counts["without_contacts"]:
        console.print(
            "streams too short for a baseline, their frames without contacts: "
            + ", ".join(counts["without_contacts"])
        )


def import_robot(
    source: Path,
    out: Path,
    *,
    skin: str | None,
    format: str,
    period: float | None,
    others: dict,
    force: bool,
    mapping: list[str] | None = None,
) -> None:
    """``tactsense import FILE --skin SKIN --out RUN``: a bag of several sensors' topics,
    or an iCub grasp trial's five fingertips, into one robot recording (a folder)."""
    given = [name for name, value in others.items() if value]
    if given:
        fail(
            f"{', '.join(given)} do not apply to a robot import (--skin, or a tactsense "
            "robot MCAP): the skin names the patches"
        )
    if not source.exists():
        fail(f"{source} does not exist")
    if out.suffix:
        fail(f"--out {out}: a robot recording is a folder; name it without an extension")
    if inside(source, out) or inside(out, source):
        fail(f"--out {out} and the input {source} overlap; an output never replaces an input")
    parent = out.parent if str(out.parent) else Path(".")
    if not parent.is_dir():
        fail(f"folder {parent} of --out {out} does not exist; create it first")
    if out.exists() and not force:
        fail(f"{out} exists; pass --force to replace it, or choose another name")
    from tactsense.interop.importers import _is_icub_grasp

    icub = format == "icub-grasp" or (
        format == "auto" and source.is_file() and source.suffix.lower() == ".txt"
        and _is_icub_grasp(source)
    )  # fmt: skip
    pairs = {}
    for item in mapping or []:
        name, sep, patch = item.partition("=")
        if not sep or not name.strip() or not patch.strip():
            fail(f"--map {item!r}: expected NAME=PATCH (a channel name or a topic, and a patch)")
        if name.strip() in pairs:
            fail(f"--map: {name.strip()!r} is mapped twice")
        pairs[name.strip()] = patch.strip()
    if icub:
        if pairs:
            fail("--map applies to bags; an iCub grasp trial's fingertips are its patches")
        from tactsense.interop.icub_grasp import read_trial
        from tactsense.interop.robot_icub import (
            icub_hand_recording,
            outside_limits,
            write_icub_hand,
        )

        if source.is_dir():
            fail(f"{source} is a folder; --format icub-grasp reads one trial file (book_8.txt)")
        trial = read_trial(source)
        recording, joints = icub_hand_recording(trial, skin or "icub_hand", period_s=period)
        write_icub_hand(out, recording, joints, overwrite=force)
        lines = len(trial) * len(recording.streams)
        kept = sum(len(s) for s in recording.streams.values())
        mapped = ", ".join(
            f"{e} -> " + "/".join(f"{j} x{share:.3g}" for j, share in driven)
            for e, driven in joints["mapping"].items()
        )
        console.print(
            f"wrote {out}: {len(trial)} slices of {len(recording.streams)} fingertips "
            f"({lines} taxel lines read, {kept} frames kept), the 9 joint encoders in "
            f"icub_encoders.csv \\[deg]"
        )
        if mapped:
            console.print(f"joint_states.csv \\[rad]: {mapped}")
            bad = outside_limits(recording.skin, joints["positions_rad"])
            if bad:
                said = ", ".join(f"{j} {n}" for j, n in bad.items())
                console.print(
                    f"warning: encoder angles outside the skin's joint limits (slices): {said}"
                )
        else:
            console.print(f"no encoder maps to a joint of {recording.skin.name!r}")
        if period is None:
            console.print(
                "note: the iCub grasp trial carries no times; frame times are slice numbers "
                "(1 s apart): give --period S if the slices' period is known"
            )
        return
    if period is not None:
        fail("--period applies to iCub grasp trials (--format icub-grasp) only")
    if format != "auto":
        fail(f"--format {format!r}: a bag's robot import takes --format auto")
    from tactsense.interop.robot_bag import read_robot_bag
    from tactsense.io.robot_recording import write_robot_recording

    recording, summary = read_robot_bag(source, skin=skin, mapping=pairs)
    write_robot_recording(out, recording, overwrite=force)
    if summary.get("joint_states_csv"):  # r7-fixc: the exported joint states, given back
        from tactsense.io.robot_recording import JOINT_STATES_FILE

        partial = Path(out) / f".{JOINT_STATES_FILE}.partial"
        partial.write_bytes(summary["joint_states_csv"])
        partial.replace(Path(out) / JOINT_STATES_FILE)
        console.print(f"{JOINT_STATES_FILE}: the joint states, as exported")
    frames = sum(summary["frames"].values())
    console.print(
        f"wrote {out}: {summary['messages']} TactileState messages read, {frames} frames "
        f"kept in {len(recording.streams)} streams of {recording.skin.name!r}"
    )
    for name, count in summary["frames"].items():
        console.print(f"  {name}: {count} frames")
    if summary["missing"]:
        console.print(f"patches without a message: {', '.join(summary['missing'])}")
    if summary["skipped"]:
        console.print(f"topics of other types skipped: {summary['skipped']}")


# ---- a robot LeRobot dataset given to import (r7-fixc) ----
def refuse_robot_lerobot(source: Path) -> None:
    """A clear error for a LeRobot dataset with a feature per patch (what ``export RUN/
    --format lerobot`` writes): import does not read it back (yet)."""
    import json

    info = Path(source) / "meta" / "info.json"
    if not info.is_file():
        return
    try:
        features = json.loads(info.read_text()).get("features", {})
    except (OSError, ValueError, AttributeError):
        return
    if not isinstance(features, dict) or not any(
        str(k).startswith("observation.tactile.") for k in features
    ):
        return
    fail(
        f"{source} is a robot LeRobot dataset (a feature per patch); import cannot read it "
        "back: for a robot recording it reads an MCAP file or rosbag2 bag (write one with "
        "'tactsense export RUN/ --format mcap') or an iCub grasp trial (--skin icub_hand); "
        "from LeRobot only a single sensor's dataset (one observation.tactile feature)"
    )


# ---- /a robot LeRobot dataset (r7-fixc) ----


# ---- info on a robot recording (r7-fixc) ----
def robot_info(recording: Path) -> None:
    """``tactsense info RUN/``: the skin, each stream (frames, rate, duration), each device
    (status, losses, clock) and whether the writer closed it."""
    from rich.table import Table

    from tactsense.io.recording import RecordingReader
    from tactsense.io.robot_recording import read_manifest, stream_path

    try:
        manifest = read_manifest(recording)
    except TactsenseInputError as error:
        fail(str(error))
    table = Table(title=f"{recording} (a robot recording)", show_header=False)
    table.add_row("skin", str(manifest.get("skin", "")))
    table.add_row("description", str(manifest.get("description", "")))
    spans = []
    rows = []
    for patch in manifest.get("streams", []):
        try:
            with RecordingReader(stream_path(recording, patch)) as reader:
                n, spec = reader.n_frames, reader.sensor
                times = reader.time_s(0, 1) if n else None
                last = reader.time_s(n - 1, n) if n else None
        except TactsenseInputError as error:
            rows.append((patch, f"unreadable: {error}"))
            continue
        # a stream's times are its device clock's, which need not start at 0
        span = float(last[-1] - times[0]) + spec.scan_period_s if n else 0.0
        spans.append(span)
        rows.append(
            (patch, f"{n} x {spec.shape[0]} x {spec.shape[1]} counts, {span:.3f} s at "
                    f"{spec.electronics.scan_rate_hz:g} Hz")
        )  # fmt: skip
    table.add_row("streams", f"{len(rows)}")
    table.add_row("duration", f"{max(spans, default=0.0):.3f} s (longest stream)")
    for patch, text in rows:
        table.add_row(f"  {patch}", text)
    devices = manifest.get("devices", {}) or {}
    table.add_row("devices", f"{len(devices)}")
    for device, entry in devices.items():
        losses = entry.get("losses", {}) or {}
        lost = ", ".join(f"{k} {v}" for k, v in losses.items() if v and k != "frames") or "none"
        status = str(entry.get("status", ""))
        if entry.get("dropped_at_s") is not None:
            at = entry["dropped_at_s"]
            status += f" (dropped at {at:.3f} s, host clock, Unix: {entry.get('error', '')})"
        clock = entry.get("clock") or {}
        drift = f", clock {clock['drift_ppm']:+.1f} ppm" if "drift_ppm" in clock else ""
        table.add_row(f"  {device}", f"{status}; {losses.get('frames', 0)} frames; losses: "
                                     f"{lost}{drift}")  # fmt: skip
    if not manifest.get("closed_cleanly", False):
        table.add_row("state", "not closed by its writer (killed?): frames up to its last flush")
    console.print(table)


# ---- /info on a robot recording (r7-fixc) ----
