"""Several sensors' ``TactileState`` topics of one bag into one robot recording.

``tactsense import FILE --skin SKIN --out RUN`` (an MCAP file, a rosbag2 bag folder or
its ``.db3``/``.mcap``): every ``tactile_msgs/msg/TactileState`` message is read
(MCAP: ``mcap``'s reader with the ``mcap_ros2`` decoder; rosbag2: ``rosbags``, the type
registered from the upstream ``.msg`` text) and its frames go to the skin's patches:

0. ``--map NAME=PATCH`` first: a channel named NAME, or the one channel of a message on
   the topic NAME, goes to PATCH;
1. each ``ChannelFloat32`` of a message whose ``name`` is a patch of the skin goes to
   that patch (a device's one message may carry all its patches, as upstream's
   ``sensors[]`` allows);
2. a message with one ``ChannelFloat32`` whose name is no patch goes to the patch named
   by the topic's last part (``/tactile_states/index_tip`` -> ``index_tip``, compared
   with the patches' names as ROS 2 topic tokens: ``-`` and ``.`` as ``_``);
3. anything else is an error naming the topic and the names it carries.

The skin is ``--skin`` (a preset's name or a TOML file), else the one a tactsense export
stored in the file (metadata ``tactsense.robot``). Stamps are the headers'; stamps on the
Unix clock become every stream's host times and its frame times count from the EARLIEST
first stamp of all the streams (so the streams stay aligned with each other). A file
tactsense wrote gives back its exact times, device clocks, sequence numbers and loss
counters (:mod:`tactsense.interop.robot_mcap`'s records). Topics of other types are
skipped (counted in the result).
"""

from __future__ import annotations

import dataclasses
import io
import json
from pathlib import Path

import numpy as np

from tactsense.interop._build import UNIX_EPOCH_THRESHOLD_S, ImportError_, build_recording
from tactsense.interop.robot_mcap import (
    JOINTS_ATTACHMENT,
    LOSSES_PREFIX,
    ROBOT_METADATA,
    TIMES_ATTACHMENT,
    topic_token,
)
from tactsense.robot import RobotSkin, RobotSkinError, load_skin, skin_from_dict

STATE_TYPES = ("tactile_msgs/msg/TactileState", "tactile_msgs/TactileState")


class _Collector:
    """Frames and stamps per patch, routed by the rules of the module's description."""

    def __init__(self, skin: RobotSkin, source: Path, mapping: dict[str, str] | None = None):
        self.skin, self.source = skin, source
        self.by_name = {p.name: p for p in skin.patches}
        self.mapping = dict(mapping or {})
        for name, patch in self.mapping.items():
            if patch not in self.by_name:
                raise ImportError_(
                    f"--map {name}={patch}: {skin.name!r} has no patch {patch!r}; its "
                    f"patches: {', '.join(self.by_name)}"
                )
        self.by_token = {topic_token(p.name): p.name for p in skin.patches}
        self.frames: dict[str, list] = {}
        self.stamps: dict[str, list] = {}
        self.messages = 0

    def add(self, topic: str, sensors, stamp_ns: int) -> None:
        self.messages += 1
        entries = [(str(_get(s, "name")), _get(s, "values")) for s in sensors]
        entries = [(self.mapping.get(name, name), values) for name, values in entries]
        if len(entries) == 1 and topic in self.mapping:
            entries = [(self.mapping[topic], entries[0][1])]
        routed = [(name, values) for name, values in entries if name in self.by_name]
        if not routed and len(entries) == 1:
            token = topic.rstrip("/").rsplit("/", 1)[-1]
            if token in self.by_token:
                routed = [(self.by_token[token], entries[0][1])]
        if not routed:
            names = ", ".join(repr(n) for n, _ in entries) or "none"
            raise ImportError_(
                f"{self.source}: topic {topic} carries the sensors {names}; neither they nor "
                f"the topic's last part name a patch of {self.skin.name!r} "
                f"({', '.join(self.by_name)})"
            )
        for name, values in routed:
            n = self.by_name[name].n_taxels
            values = np.asarray(values, dtype=np.float64)
            if values.size != n:
                raise ImportError_(
                    f"{self.source}: topic {topic}: patch {name!r} has {n} taxels; a message "
                    f"carries {values.size} values"
                )
            self.frames.setdefault(name, []).append(values)
            self.stamps.setdefault(name, []).append(stamp_ns)


def _get(obj, name):
    return obj[name] if isinstance(obj, dict) else getattr(obj, name)


def _skin_of(skin, stored: dict | None, source: Path) -> RobotSkin:
    if skin is not None:
        try:
            return load_skin(skin)
        except RobotSkinError as error:
            raise ImportError_(f"--skin: {error}") from None
    if stored and stored.get("skin_toml"):
        import tomllib

        try:
            return skin_from_dict(tomllib.loads(stored["skin_toml"]))
        except (tomllib.TOMLDecodeError, RobotSkinError) as error:
            raise ImportError_(f"{source}: its stored skin: {error}") from None
    raise ImportError_(
        f"{source}: the file does not describe its robot skin (not written by tactsense); "
        "pass --skin (a preset or a skin TOML)"
    )


def _read_mcap_file(source: Path, skin, mapping) -> tuple:
    from mcap.exceptions import McapError
    from mcap.reader import make_reader
    from mcap_ros2.decoder import DecoderFactory

    from tactsense.interop.importers import _check_mcap_start

    stored, losses, extras = None, {}, {}
    try:
        with open(source, "rb") as stream:
            _check_mcap_start(stream, source)
            reader = make_reader(stream, decoder_factories=[DecoderFactory()])
            summary = reader.get_summary()
            if summary is None:
                raise ImportError_(
                    f"{source}: the MCAP file has no summary (a recorder killed mid-way?); "
                    "rebuild it with 'mcap recover'"
                )
            for record in reader.iter_metadata():
                if record.name == ROBOT_METADATA:
                    stored = dict(record.metadata)
                elif record.name.startswith(LOSSES_PREFIX):
                    losses[record.name[len(LOSSES_PREFIX) :]] = dict(record.metadata)
            for attachment in reader.iter_attachments():
                if attachment.name == JOINTS_ATTACHMENT:  # r7-fixc
                    extras[JOINTS_ATTACHMENT] = bytes(attachment.data)
                prefix, suffix = TIMES_ATTACHMENT.split("{patch}")
                if attachment.name.startswith(prefix) and attachment.name.endswith(suffix):
                    name = attachment.name[len(prefix) : -len(suffix)]
                    with np.load(io.BytesIO(attachment.data)) as arrays:
                        extras[name] = {k: arrays[k] for k in arrays.files}
            spec_skin = _skin_of(skin, stored, source)
            collector = _Collector(spec_skin, source, mapping)
            states = [
                ch.topic
                for ch in summary.channels.values()
                if ch.schema_id in summary.schemas
                and summary.schemas[ch.schema_id].name in STATE_TYPES
            ]
            skipped = len(summary.channels) - len(states)
            if not states:
                raise ImportError_(f"{source}: no tactile_msgs/msg/TactileState topic in it")
            for _, channel, _, ros in reader.iter_decoded_messages(
                topics=states, log_time_order=True
            ):
                stamp = ros.header.stamp.sec * 1_000_000_000 + ros.header.stamp.nanosec
                collector.add(channel.topic, ros.sensors, stamp)
    except ImportError_:
        raise
    except (McapError, ValueError, KeyError, EOFError, OSError) as error:
        why = str(error) or type(error).__name__
        raise ImportError_(f"{source} is not a readable MCAP file ({why})") from None
    return collector, stored, losses, extras, skipped


def _read_bag(source: Path, skin, mapping) -> tuple:
    from rosbags.highlevel import AnyReader, AnyReaderError
    from rosbags.typesys import Stores, get_types_from_msg, get_typestore

    from tactsense.interop.ros import SEPARATOR, TACTILE_STATE, TACTILE_STATE_MSGDEF

    bag = source.parent if source.is_file() else source
    typestore = get_typestore(Stores.ROS2_HUMBLE)
    typestore.register(get_types_from_msg(TACTILE_STATE_MSGDEF.split(SEPARATOR)[0], TACTILE_STATE))
    collector = _Collector(_skin_of(skin, None, source), source, mapping)
    try:
        with AnyReader([bag], default_typestore=typestore) as reader:
            connections = [c for c in reader.connections if c.msgtype in STATE_TYPES]
            skipped = len({c.topic for c in reader.connections}) - len(
                {c.topic for c in connections}
            )
            if not connections:
                raise ImportError_(f"{source}: no tactile_msgs/msg/TactileState topic in it")
            for connection, _, raw in reader.messages(connections=connections):
                message = reader.deserialize(raw, connection.msgtype)
                stamp = message.header.stamp.sec * 1_000_000_000 + message.header.stamp.nanosec
                collector.add(connection.topic, message.sensors, stamp)
    except AnyReaderError as error:
        raise ImportError_(f"{source} is not a readable rosbag2 bag ({error})") from None
    return collector, None, {}, {}, skipped


def read_robot_bag(source: str | Path, *, skin=None, mapping: dict[str, str] | None = None):
    """A bag of several sensors' ``TactileState`` topics as a robot recording.

    Parameters
    ----------
    source : path
        An MCAP file, a rosbag2 bag folder (``metadata.yaml``) or a file in one.
    skin : preset name, TOML path or RobotSkin, optional
        The robot skin whose patches the topics fill (default: the one the file stores).
    mapping : dict of str -> str, optional
        Channel names or topics -> patches, applied before the rules (``--map``).

    Returns
    -------
    (RobotRecording, dict)
        The recording, and a summary: ``messages`` read, ``frames`` per patch, ``missing``
        patches (no message), ``skipped`` topics (not TactileState).
    """
    from tactsense.io.robot_recording import RobotRecording

    source = Path(source)
    if not source.exists():
        raise ImportError_(f"{source} does not exist")
    in_bag = (source if source.is_dir() else source.parent) / "metadata.yaml"
    if in_bag.is_file():
        collector, stored, losses, extras, skipped = _read_bag(source, skin, mapping)
    elif source.is_file() and source.suffix.lower() == ".mcap":
        collector, stored, losses, extras, skipped = _read_mcap_file(source, skin, mapping)
    else:
        raise ImportError_(
            f"{source}: expected an MCAP file (.mcap) or a rosbag2 bag (a folder with "
            "metadata.yaml), or with --skin icub_hand an iCub grasp trial"
        )
    if not collector.frames:
        raise ImportError_(f"{source}: no TactileState message in it")
    origin_ns = min(stamps[0] for stamps in collector.stamps.values())
    unix = origin_ns * 1e-9 >= UNIX_EPOCH_THRESHOLD_S
    streams = {}
    for patch in collector.skin.patches:
        name = patch.name
        if name not in collector.frames:
            continue
        stamps_ns = np.asarray(collector.stamps[name], np.int64)
        stamps = stamps_ns * 1e-9
        frames = np.stack(collector.frames[name]).reshape(-1, *patch.sensor.shape)
        recording = build_recording(
            patch.sensor, list(frames), stamps, source=str(source),
            description=f"imported from {source} (patch {name})",
            losses={k: int(v) for k, v in losses.get(name, {}).items()},
        )  # fmt: skip
        if unix:  # one origin for every stream
            recording = dataclasses.replace(
                recording, host_time_s=stamps, time_s=(stamps_ns - origin_ns) * 1e-9
            )
        exact = extras.get(name)
        if exact is not None and len(exact.get("time_s", ())) == len(frames):
            recording = dataclasses.replace(
                recording,
                time_s=exact["time_s"],
                host_time_s=exact.get("host_time_s"),
                device_time_us=exact.get("device_time_us"),
                sequence=exact.get("sequence"),
            )
            recording = _with_scenario(recording, exact)  # r7-fixc
        streams[name] = recording
    devices = {}
    if stored and stored.get("devices"):
        try:
            devices = json.loads(stored["devices"])
        except json.JSONDecodeError:
            raise ImportError_(f"{source}: its stored devices are not JSON") from None
    description = (stored or {}).get("description") or f"imported from {source}"
    closed = json.loads((stored or {}).get("closed_cleanly", "true"))
    recording = RobotRecording(
        skin=collector.skin, streams=streams, devices=devices, description=description,
        closed_cleanly=bool(closed),
    )  # fmt: skip
    summary = {
        "messages": collector.messages,
        "frames": {name: len(s) for name, s in streams.items()},
        "missing": [p.name for p in collector.skin.patches if p.name not in streams],
        "skipped": skipped,
        "joint_states_csv": extras.get(JOINTS_ATTACHMENT),  # r7-fixc
    }
    return recording, summary


def _with_scenario(recording, exact: dict):
    """The stream's scenario, flaws and truth as the export stored them (r7-fixc)."""
    from tactsense.interop.robot_mcap import TRUTH_KEY

    changes = {}
    if "scenario_json" in exact:
        try:
            scenario = json.loads(str(exact["scenario_json"]))
        except json.JSONDecodeError:
            scenario = None
        if isinstance(scenario, dict) and scenario:
            changes["scenario"] = scenario
    if "flaws" in exact:
        changes["flaws"] = tuple(f for f in str(exact["flaws"]).split(",") if f)
    truth = {
        key[len(TRUTH_KEY) :]: (str(value) if value.dtype.kind == "U" else value)
        for key, value in exact.items()
        if key.startswith(TRUTH_KEY)
    }
    if truth:
        changes["truth"] = truth
    return dataclasses.replace(recording, **changes) if changes else recording


def is_robot_mcap(source: str | Path) -> bool:
    """Whether ``source`` is an MCAP file a robot export wrote (its ``tactsense.robot``
    metadata record); False for anything unreadable (the importers say why)."""
    source = Path(source)
    if not (source.is_file() and source.suffix.lower() == ".mcap"):
        return False
    try:
        from mcap.reader import make_reader

        with open(source, "rb") as stream:
            summary = make_reader(stream).get_summary()
    except Exception:  # not an MCAP file or a damaged one: the plain importer says what
        return False
    return summary is not None and any(
        index.name == ROBOT_METADATA for index in summary.metadata_indexes
    )
