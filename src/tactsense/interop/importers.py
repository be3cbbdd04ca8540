"""Other tools' files into a tactsense recording (``tactsense import SOURCE --out rec.h5``).

Sources, told apart by their extension (a folder by what it holds):

* **MCAP** (``.mcap``): ``tactile_msgs/msg/TactileState`` messages (ROS 2 CDR) read with
  ``mcap``'s reader and the ``mcap_ros2`` decoder (the definition the file carries).
* **rosbag2** (a bag folder with ``metadata.yaml``, sqlite3 or mcap storage, or its
  ``.db3`` file): read with ``rosbags``, the ``TactileState`` type registered from the
  upstream ``.msg`` text (the body of :data:`tactsense.interop.ros.TACTILE_STATE_MSGDEF`).
* **XDF** (``.xdf``, ``.xdfz``): one stream read with ``pyxdf`` (clock offsets applied,
  time stamps not de-jittered: the times are those recorded). A tactsense LSL outlet's
  stream carries its sensor (``desc/tactsense/sensor_toml``); any other stream takes
  ``--sensor`` and must have rows x cols channels.
* **CSV** (``.csv``): a header line, then one frame per row: a time column
  (``--time-column``, default ``time``, in seconds) and the frame's rows x cols values
  in row-major order in the other columns; ``--sensor`` gives the shape.
* **LeRobot** (a folder with ``meta/info.json``): :func:`tactsense.interop.lerobot.
  import_lerobot`.
* **iCub grasp trial** (``--format icub-grasp``, or a ``.txt`` whose first line is
  ``-10000``): one fingertip (``--finger``) of a trial of the iCub grasp dataset (Soh et
  al., 2012), :mod:`tactsense.interop.icub_grasp`; the files carry no times
  (``--period``).

Times: a ``TactileState``'s header stamp, the XDF time stamp, the CSV time. Stamps on the
Unix clock (after 2001, as ``tactsense export`` writes when the recording has host
times) are kept as the recording's host times, and its frame times start at 0; other
stamps are the frame times as they are. Frames are counts as given: whole numbers within
0-65535 are stored as ``uint16``, anything else as ``float64``.
"""

from __future__ import annotations

import csv
import dataclasses
import errno
import math
import re
from pathlib import Path

import numpy as np

from tactsense.interop._build import (  # noqa: F401 (the threshold: re-exported)
    UNIX_EPOCH_THRESHOLD_S,
    ImportError_,
    _sensor,
    build_recording,
)
from tactsense.sensor import SensorSpecError, load_sensor
from tactsense.sensor.common import SpecBase

# ---- ROS 2: MCAP and rosbag2 -----------------------------------------------------------


def _pick_values(sensors: list, sensor: SpecBase, where: str) -> list:
    """The values of the ``ChannelFloat32`` for this sensor in one ``TactileState``."""
    if sensor.components > 1:  # ---- several components a taxel (r8-triinterop) ----
        from tactsense.interop.components import pick_component_values

        return pick_component_values(sensors, sensor, where, _get)
    if len(sensors) == 1:
        entry = sensors[0]
    else:
        named = [s for s in sensors if _get(s, "name") == sensor.name]
        if len(named) != 1:
            names = ", ".join(repr(_get(s, "name")) for s in sensors)
            raise ImportError_(
                f"{where}: a TactileState holds the sensors {names}; none is named "
                f"{sensor.name!r} (pass --sensor with that name)"
            )
        entry = named[0]
    values = list(_get(entry, "values"))
    if len(values) != sensor.n_taxels:
        rows, cols = sensor.shape
        raise ImportError_(
            f"{where}: sensor {_get(entry, 'name')!r} has {len(values)} values; "
            f"{sensor.name!r} has {rows} x {cols} = {rows * cols} taxels"
        )
    return values


def _get(obj, name):
    return obj[name] if isinstance(obj, dict) else getattr(obj, name)


def _ros_sensor(sensor, first_names: list[str], source: Path) -> SpecBase:
    """--sensor, else the preset named by the TactileState's sensor name."""
    if sensor is not None:
        return _sensor(sensor, source, "")
    from tactsense.sensor import PRESETS

    for name in first_names:
        name = name.split("/")[0]  # a channel per component: <sensor>/<component>
        if name.removeprefix("fearing1990_") in PRESETS:
            return load_sensor(name)
    raise ImportError_(
        f"{source}: the TactileState sensor name {', '.join(map(repr, first_names))} is not a "
        "tactsense preset; pass --sensor (a preset or a sensor TOML) for its shape"
    )


def _choose_topic(topics: dict[str, str], topic: str | None, source: Path) -> str:
    """The topic to read: ``topic``, else the one ``TactileState`` topic."""
    from tactsense.interop.ros import TACTILE_STATE

    states = sorted(
        t for t, kind in topics.items() if kind in (TACTILE_STATE, "tactile_msgs/TactileState")
    )
    if topic is not None:
        if topic not in states:
            raise ImportError_(
                f"{source}: no tactile_msgs/msg/TactileState topic {topic!r}; it has "
                f"{', '.join(states) or 'none'}"
            )
        return topic
    if not topics:
        raise ImportError_(
            f"{source}: the file holds no messages (no topic at all); expected "
            "tactile_msgs/msg/TactileState frames"
        )
    if not states:
        found = ", ".join(f"{t} ({k})" for t, k in sorted(topics.items()))
        raise ImportError_(f"{source}: no tactile_msgs/msg/TactileState topic; it has {found}")
    if len(states) > 1:
        raise ImportError_(
            f"{source}: several TactileState topics ({', '.join(states)}); pass --topic"
        )
    return states[0]


MCAP_MAGIC = b"\x89MCAP0\r\n"
"""The eight bytes an MCAP file starts (and ends) with (MCAP specification, "Magic")."""


def _check_mcap_start(stream, source: Path) -> None:
    """An empty file or one that is no MCAP file, said as such (the reader's own errors
    for them are an empty message or a bare seek error)."""
    start = stream.read(len(MCAP_MAGIC))
    stream.seek(0)
    if not start:
        raise ImportError_(
            f"{source} is empty (0 bytes); expected an MCAP file of "
            "tactile_msgs/msg/TactileState messages"
        )
    if start == MCAP_MAGIC[: len(start)] and len(start) < len(MCAP_MAGIC):
        raise ImportError_(
            f"{source} is truncated ({len(start)} bytes): the start of MCAP's magic bytes "
            "and nothing more"
        )
    if start != MCAP_MAGIC:
        raise ImportError_(
            f"{source} is not an MCAP file: it does not start with MCAP's magic bytes "
            f"(\\x89MCAP0\\r\\n); it starts with {start!r}"
        )


def read_mcap(source: Path, *, sensor=None, topic: str | None = None):
    """``TactileState`` messages of a plain MCAP file."""
    try:
        from mcap.exceptions import McapError
        from mcap.reader import make_reader
        from mcap_ros2.decoder import DecoderFactory
    except ImportError:
        raise ImportError_('MCAP needs the mcap extra: pip install "tactsense[mcap]"') from None
    frames, stamps = [], []
    spec = None
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
            topics = {
                ch.topic: summary.schemas[ch.schema_id].name
                for ch in summary.channels.values()
                if ch.schema_id in summary.schemas
            }
            chosen = _choose_topic(topics, topic, source)
            losses = _mcap_losses(reader, source)
            for _, _, _, ros in reader.iter_decoded_messages(topics=[chosen]):
                if spec is None:
                    spec = _ros_sensor(sensor, [s.name for s in ros.sensors], source)
                frames.append(_pick_values(ros.sensors, spec, str(source)))
                stamps.append(ros.header.stamp.sec + ros.header.stamp.nanosec * 1e-9)
    except ImportError_:
        raise
    except (McapError, ValueError, KeyError, EOFError) as error:
        why = str(error) or type(error).__name__
        raise ImportError_(f"{source} is not a readable MCAP file ({why})") from None
    except OSError as error:
        if error.errno == errno.EINVAL:  # a seek before the start: too short for its index
            raise ImportError_(
                f"{source} is truncated ({source.stat().st_size} bytes): an MCAP file's "
                "start without its records and summary (a recorder killed at once?)"
            ) from None
        raise ImportError_(f"{source}: cannot read it ({error.strerror or error})") from None
    if spec is None:
        raise ImportError_(f"{source}: topic {chosen} holds no messages")
    return build_recording(
        spec, frames, stamps, source=str(source), description=f"imported from {source} ({chosen})",
        losses=losses,
    )  # fmt: skip


def _mcap_losses(reader, source: Path) -> dict[str, int]:
    """The loss counters tactsense's MCAP writers keep (metadata ``tactsense.losses``), or
    none; a counter that is not a whole number is refused rather than dropped."""
    from tactsense.interop.mcap import LOSSES_METADATA

    losses = {}
    for record in reader.iter_metadata():
        if record.name != LOSSES_METADATA:
            continue
        for kind, value in record.metadata.items():
            try:
                losses[kind] = int(value)
            except ValueError:
                raise ImportError_(
                    f"{source}: the loss counter {kind!r} in its {LOSSES_METADATA} record is "
                    f"{value!r}; expected a whole number"
                ) from None
    return losses


def read_rosbag2(source: Path, *, sensor=None, topic: str | None = None):
    """``TactileState`` messages of a rosbag2 bag (sqlite3 or mcap storage) with rosbags."""
    try:
        from rosbags.highlevel import AnyReader, AnyReaderError
        from rosbags.typesys import Stores, get_types_from_msg, get_typestore
    except ImportError:
        raise ImportError_(
            'rosbag2 bags need the import extra: pip install "tactsense[import]"'
        ) from None
    from tactsense.interop.ros import SEPARATOR, TACTILE_STATE, TACTILE_STATE_MSGDEF

    msg_text = TACTILE_STATE_MSGDEF.split(SEPARATOR)[0]  # the upstream .msg, no dependencies

    bag = source.parent if source.is_file() else source
    if not (bag / "metadata.yaml").is_file():
        raise ImportError_(f"{source}: not a rosbag2 bag (no metadata.yaml in {bag})")
    typestore = get_typestore(Stores.ROS2_HUMBLE)
    typestore.register(get_types_from_msg(msg_text, TACTILE_STATE))
    frames, stamps = [], []
    spec = None
    try:
        with AnyReader([bag], default_typestore=typestore) as reader:
            topics = {name: info.msgtype for name, info in reader.topics.items()}
            chosen = _choose_topic(topics, topic, source)
            connections = [c for c in reader.connections if c.topic == chosen]
            for connection, _, raw in reader.messages(connections=connections):
                message = reader.deserialize(raw, connection.msgtype)
                if spec is None:
                    spec = _ros_sensor(sensor, [s.name for s in message.sensors], source)
                frames.append(_pick_values(message.sensors, spec, str(source)))
                stamps.append(message.header.stamp.sec + message.header.stamp.nanosec * 1e-9)
    except AnyReaderError as error:
        raise ImportError_(f"{source} is not a readable rosbag2 bag ({error})") from None
    if spec is None:
        raise ImportError_(f"{source}: topic {chosen} holds no messages")
    return build_recording(
        spec, frames, stamps, source=str(source), description=f"imported from {source} ({chosen})"
    )


# ---- XDF ------------------------------------------------------------------------------


def _xdf_text(info: dict, *path: str) -> str | None:
    node = info
    for key in path:
        if not isinstance(node, dict) or not node.get(key):
            return None
        node = node[key][0]
    return node if isinstance(node, str) else None


def read_xdf(source: Path, *, sensor=None, stream: str | None = None):
    """One stream of an XDF file: a tactsense frames stream or any stream with ``--sensor``."""
    try:
        import pyxdf
    except ImportError:
        raise ImportError_(
            'XDF files need the import extra: pip install "tactsense[import]"'
        ) from None
    try:
        streams, _ = pyxdf.load_xdf(str(source), dejitter_timestamps=False, verbose=False)
    except Exception as error:  # pyxdf raises what its parser meets
        raise ImportError_(
            f"{source} is not a readable XDF file ({type(error).__name__}: {error})"
        ) from None
    if not streams:
        raise ImportError_(f"{source} is not a readable XDF file (no streams in it)")
    described = []
    for s in streams:
        info = s["info"]
        described.append(
            (
                _xdf_text(info, "name") or "",
                _xdf_text(info, "type") or "",
                _xdf_text(info, "source_id") or "",
                s,
            )
        )
    if stream is not None:
        chosen = [d for d in described if stream in (d[0], d[2])]
        if not chosen:
            names = ", ".join(repr(d[0]) for d in described) or "none"
            raise ImportError_(f"{source}: no stream named {stream!r}; streams: {names}")
    else:
        chosen = [
            d for d in described if _xdf_text(d[3]["info"], "desc", "tactsense", "sensor_toml")
        ]
        if not chosen:
            chosen = [d for d in described if d[1] == "Tactile"] or (
                described if len(described) == 1 else []
            )
        if len(chosen) != 1:
            names = ", ".join(f"{d[0]!r} ({d[1]})" for d in described) or "none"
            raise ImportError_(f"{source}: say which stream with --stream; streams: {names}")
    name, _, _, picked = chosen[0]
    info = picked["info"]
    toml = _xdf_text(info, "desc", "tactsense", "sensor_toml")
    if sensor is not None or toml is None:
        spec = _sensor(sensor, source, f"stream {name!r}")
    else:
        import tomllib

        from tactsense.sensor import sensor_from_dict

        try:
            spec = sensor_from_dict(tomllib.loads(toml), source=f"{source} stream {name!r}")
        except (tomllib.TOMLDecodeError, SensorSpecError) as error:
            raise ImportError_(f"{source}: stream {name!r}'s sensor description: {error}") from None
    series = picked["time_series"]
    if isinstance(series, list):
        raise ImportError_(f"{source}: stream {name!r} holds strings; expected numbers")
    series = np.asarray(series, dtype=np.float64)
    channels = int(_xdf_text(info, "channel_count") or (series.shape[1] if series.ndim == 2 else 0))
    from tactsense.interop.components import describe_values, value_count

    if channels != value_count(spec):  # one channel per taxel and component
        raise ImportError_(
            f"{source}: stream {name!r} has {channels} channels; sensor {spec.name!r} has "
            f"{describe_values(spec)}"
        )
    return build_recording(
        spec, series.reshape(-1, channels), picked["time_stamps"], source=str(source),
        description=f"imported from {source} (stream {name!r})",
    )  # fmt: skip


# ---- CSV ------------------------------------------------------------------------------


def read_csv(source: Path, *, sensor=None, time_column: str = "time"):
    """One frame per row: a time column [s] and rows x cols values in row-major order.

    An optional ``host_time`` column (Unix time [s], as ``tactsense export X.csv`` writes
    for a recorded stream) becomes the recording's host times. A value ``nan`` is a lost
    reading (a float recording keeps it as NaN); a time must be a finite number, and the
    times must increase from row to row: a time that goes backwards or repeats is
    refused with its line (frames out of order or a clock that stepped back would give
    the estimators wrong rates and the tracker wrong velocities; sort the file or fix
    its times). A byte-order mark (Excel's "CSV UTF-8") is skipped.
    """
    from tactsense.interop.components import describe_values, value_count
    from tactsense.interop.csvfile import HOST_TIME_COLUMN

    spec = _sensor(sensor, source, "a CSV file")
    frames, stamps, hosts = [], [], []
    try:
        # utf-8-sig: the byte-order mark Excel writes before the header is not a name
        with open(source, newline="", encoding="utf-8-sig") as stream:
            reader = csv.reader(stream)
            header = next(reader, None)
            if header is None:
                raise ImportError_(f"{source} is empty; expected a header line and frames")
            header = [h.strip() for h in header]
            if time_column not in header:
                raise ImportError_(
                    f"{source}: no time column {time_column!r} in the header "
                    f"({', '.join(header[:6])}{', ...' if len(header) > 6 else ''}); "
                    "pass --time-column"
                )
            t = header.index(time_column)
            h = header.index(HOST_TIME_COLUMN) if HOST_TIME_COLUMN in header else None
            times = 1 if h is None else 2
            if len(header) - times != value_count(spec):
                raise ImportError_(
                    f"{source}: {len(header) - times} value columns; sensor {spec.name!r} has "
                    f"{describe_values(spec)}"
                )
            _check_value_names([n for k, n in enumerate(header) if k not in (t, h)], spec,
                               source)  # fmt: skip
            names = [n for k, n in enumerate(header) if k not in (t, h)]  # r8-fixb8
            full = 2**spec.electronics.adc_bits - 1
            previous = None
            for line, row in enumerate(reader, start=2):
                if not row:
                    continue
                if len(row) != len(header):
                    raise ImportError_(
                        f"{source} line {line}: {len(row)} fields; the header has {len(header)}"
                    )
                try:
                    numbers = [float(x) for x in row]
                except ValueError as error:
                    raise ImportError_(f"{source} line {line}{_bad_cell(row, header)}: "
                                       f"{error}") from None  # fmt: skip
                if not all(math.isfinite(x) or math.isnan(x) for x in numbers):
                    raise ImportError_(f"{source} line {line}: a value is infinite")
                stamp = numbers[t]
                host = None if h is None else numbers[h]
                for name, value in ((time_column, stamp), (HOST_TIME_COLUMN, host)):
                    if value is not None and not math.isfinite(value):
                        raise ImportError_(
                            f"{source} line {line}: the {name} {value} is not a finite number"
                        )
                if previous is not None and stamp <= previous[1]:
                    how = "repeats" if stamp == previous[1] else "goes backwards from"
                    raise ImportError_(
                        f"{source} line {line}: the time {stamp!r} s {how} "
                        f"{previous[1]!r} s on line {previous[0]}; the times must increase "
                        "(sort the rows by time, or fix the clock)"
                    )
                previous = (line, stamp)
                stamps.append(stamp)
                if h is not None:
                    hosts.append(host)
                values = [x for k, x in enumerate(numbers) if k != t and k != h]
                _check_counts(values, line, names, full, source)  # r8-fixb8
                frames.append(values)
    except UnicodeDecodeError:
        raise ImportError_(f"{source} is not a text (UTF-8) CSV file") from None
    except csv.Error as error:
        raise ImportError_(f"{source}: not a CSV file ({error})") from None
    recording = build_recording(
        spec, frames, stamps, source=str(source), description=f"imported from {source}"
    )
    if hosts:  # the host's arrival times, as the recording that was exported had them
        recording = dataclasses.replace(recording, host_time_s=np.asarray(hosts, float))
    return recording


# ---- counts the converter cannot give are refused (r8-fixb8) ----
def _check_counts(values: list[float], line: int, names: list[str], full: int,
                  source: Path) -> None:  # fmt: skip
    """A row's values must be counts the sensor's converter can give: 0..2**adc_bits - 1
    (``nan``: a lost reading; fractions are kept: an unquantized simulation exports them,
    and ``export`` then ``import`` gives them back). A negative value or one beyond the
    range (a typo or another unit) is refused with its line and column, as the text and
    JustFloat readers count such values as garbage; imported, it would read as a phantom
    contact."""
    for name, x in zip(names, values, strict=True):
        if math.isnan(x) or 0.0 <= x <= full:
            continue
        why = "negative" if x < 0 else f"beyond {full}"
        raise ImportError_(
            f"{source} line {line}, column {name}: {x!r} is {why}; the sensor's converter "
            f"gives counts 0..{full} (nan for a lost reading)"
        )


def _bad_cell(row: list[str], header: list[str]) -> str:
    """``, column NAME`` of a row's first cell that is not a number (or "")."""
    for name, cell in zip(header, row, strict=True):
        try:
            float(cell)
        except ValueError:
            return f", column {name}"
    return ""


# ---- /r8-fixb8 ----


_TACTSENSE_NAME = re.compile(r"r\d+c\d+[a-z]?")


def _check_value_names(names: list[str], spec: SpecBase, source: Path) -> None:
    """Columns named as tactsense names them (``r<row>c<col>``, ``r<row>c<col><component>``)
    must be this sensor's, in its order: a file of another shape or of other components
    with the same number of values would otherwise import as a wrong frame. Columns
    named otherwise are taken in their order (a lab's own file)."""
    from tactsense.interop.components import value_names

    if not names or not all(_TACTSENSE_NAME.fullmatch(n) for n in names):
        return
    expected = value_names(spec)
    if names != expected:
        first = next(k for k, (a, b) in enumerate(zip(names, expected, strict=True)) if a != b)
        raise ImportError_(
            f"{source}: value column {first + 1} is {names[first]!r}; sensor {spec.name!r} "
            f"names it {expected[first]!r} (the file is of another sensor, or its columns "
            "are reordered)"
        )


# ---- dispatch -------------------------------------------------------------------------


FORMATS = ("auto", "icub-grasp")
"""``--format``: ``auto`` tells sources apart by extension (and a ``.txt`` by its first
line); ``icub-grasp`` reads an iCub grasp trial whatever its name."""


def _is_icub_grasp(source: Path) -> bool:
    """A ``.txt`` file whose first line is the iCub grasp trials' ``-10000``."""
    from tactsense.interop.icub_grasp import HEADER

    try:
        with open(source, "rb") as stream:
            first = stream.readline(64)
    except OSError:
        return False
    return first.strip() == HEADER.encode()


def read_source(
    source: str | Path,
    *,
    sensor=None,
    time_column: str = "time",
    topic: str | None = None,
    stream: str | None = None,
    format: str = "auto",
    finger: str | None = None,
    period_s: float | None = None,
):
    """Any supported source as a :class:`~tactsense.io.recording.Recording`."""
    source = Path(source)
    if format not in FORMATS:
        raise ImportError_(f"--format {format!r}: expected one of {', '.join(FORMATS)}")
    if not source.exists():
        raise ImportError_(f"{source} does not exist")
    icub = format == "icub-grasp" or (
        format == "auto" and source.is_file() and source.suffix.lower() == ".txt"
        and _is_icub_grasp(source)
    )  # fmt: skip
    if icub:
        from tactsense.interop.icub_grasp import read_icub_grasp

        if source.is_dir():
            raise ImportError_(
                f"{source} is a folder; --format icub-grasp reads one trial file (book_8.txt)"
            )
        return read_icub_grasp(source, finger=finger, sensor=sensor, period_s=period_s)
    for name, value in (("--finger", finger), ("--period", period_s)):
        if value is not None and source.suffix.lower() != ".txt":  # a .txt: said below
            raise ImportError_(f"{name} applies to iCub grasp trials (--format icub-grasp) only")
    if source.is_dir():
        if (source / "meta" / "info.json").is_file():
            from tactsense.interop.lerobot import import_lerobot

            return import_lerobot(source, sensor=sensor)
        if (source / "metadata.yaml").is_file():
            return read_rosbag2(source, sensor=sensor, topic=topic)
        raise ImportError_(
            f"{source} is a folder but neither a LeRobot dataset (meta/info.json) nor a "
            "rosbag2 bag (metadata.yaml)"
        )
    suffix = source.suffix.lower()
    if suffix == ".mcap":
        if (source.parent / "metadata.yaml").is_file():
            return read_rosbag2(source, sensor=sensor, topic=topic)
        return read_mcap(source, sensor=sensor, topic=topic)
    if suffix == ".db3":
        return read_rosbag2(source, sensor=sensor, topic=topic)
    if suffix in (".xdf", ".xdfz"):
        return read_xdf(source, sensor=sensor, stream=stream)
    if suffix == ".csv":
        return read_csv(source, sensor=sensor, time_column=time_column)
    if suffix == ".txt":
        raise ImportError_(
            f"{source}: unknown kind of file .txt (its first line is not -10000, so it is no "
            "iCub grasp trial); expected .mcap, .db3 or a rosbag2 folder, .xdf, .csv, a "
            "LeRobot dataset folder, or an iCub grasp trial (--format icub-grasp)"
        )
    raise ImportError_(
        f"{source}: unknown kind of file {suffix or '(no extension)'}; expected .mcap, .db3 "
        "or a rosbag2 folder, .xdf, .csv, a LeRobot dataset folder, or an iCub grasp trial "
        "(.txt)"
    )
