"""Joint states for the hand's estimator: a fixed pose (``name=rad,...``), a CSV
(``time_s`` and one column per joint) or a ``sensor_msgs/JointState`` topic of a
rosbag2 bag (sqlite3 or MCAP storage, read with rosbags) or of a plain MCAP file, each
joint interpolated linearly to the hand frames' times (held at its first or last value outside its
samples, with a warning).

Times are on the recording's clock (its streams' ``time_s`` [s]); a bag's messages are
timed by their header stamp (their log time where the stamp is zero).
"""

from __future__ import annotations

import csv
import math
from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np

from tactsense._validation import TactsenseInputError


class JointStateError(TactsenseInputError):
    """A joint state that cannot be used: says what was wrong and what was expected."""


def parse_joints(text: str) -> dict[str, float]:
    """``"name=rad,name=rad"`` -> {name: position [rad or m]}."""
    out: dict[str, float] = {}
    for item in (part.strip() for part in text.split(",")):
        if not item:
            continue
        name, sep, value = item.partition("=")
        name = name.strip()
        try:
            position = float(value)
        except ValueError:
            position = math.nan
        if not sep or not name or not math.isfinite(position):
            raise JointStateError(
                f"--joints item {item!r}: expected NAME=POSITION with a finite position "
                "[rad or m], e.g. index_joint1=0.4"
            )
        if name in out:
            raise JointStateError(f"--joints names {name!r} twice")
        out[name] = position
    if not out:
        raise JointStateError("--joints is empty: expected NAME=POSITION,... [rad or m]")
    return out


class JointStates:
    """Joint positions over time, each joint its own samples.

    Parameters
    ----------
    series : mapping of joint name -> (time_s (m,), position (m,))
        Times [s], strictly increasing, and positions [rad or m], finite.
    source : str
        Where they came from (for messages).
    """

    def __init__(self, series: Mapping[str, tuple[np.ndarray, np.ndarray]], source: str = ""):
        self.source = source
        self.series: dict[str, tuple[np.ndarray, np.ndarray]] = {}
        for name, (time_s, position) in series.items():
            time_s = np.asarray(time_s, float)
            position = np.asarray(position, float)
            if time_s.ndim != 1 or time_s.shape != position.shape or len(time_s) == 0:
                raise JointStateError(f"{source}: joint {name!r} has no samples or mismatched ones")
            if not (np.isfinite(time_s).all() and np.isfinite(position).all()):
                raise JointStateError(f"{source}: joint {name!r} has a non-finite time or position")
            if np.any(np.diff(time_s) <= 0):
                raise JointStateError(
                    f"{source}: the times of joint {name!r} are not strictly increasing"
                )
            self.series[name] = (time_s, position)
        if not self.series:
            raise JointStateError(f"{source}: no joint positions in it")

    def check(self, skin) -> None:
        """Every joint named is a movable joint of ``skin`` and stays within its limits."""
        movable = {j.name: j for j in skin.joints if j.type != "fixed"}
        for name, (time_s, position) in self.series.items():
            joint = movable.get(name)
            if joint is None:
                raise JointStateError(
                    f"{self.source}: joint {name!r} is not a movable joint of {skin.name!r}; "
                    f"expected some of {', '.join(movable) or '(none)'}"
                )
            bad = (position < joint.lower - 1e-9) | (position > joint.upper + 1e-9)
            if bad.any():
                k = int(np.argmax(bad))
                raise JointStateError(
                    f"{self.source}: joint {name!r} at {position[k]} (time {time_s[k]} s) is "
                    f"outside its limits [{joint.lower}, {joint.upper}] [rad or m]"
                )

    def at(self, time_s, names: Sequence[str]) -> np.ndarray:
        """Positions (n, len(names)) at ``time_s`` [s], linearly interpolated; a joint not
        given here is at 0."""
        time_s = np.asarray(time_s, float)
        out = np.zeros((len(time_s), len(names)))
        for j, name in enumerate(names):
            if name in self.series:
                t, position = self.series[name]
                out[:, j] = np.interp(time_s, t, position)
        return out

    def coverage_warnings(self, time_s) -> list[str]:
        """One line per joint whose samples do not cover ``time_s`` [s]."""
        time_s = np.asarray(time_s, float)
        lines = []
        for name, (t, _) in self.series.items():
            outside = int(np.count_nonzero((time_s < t[0]) | (time_s > t[-1])))
            if outside:
                lines.append(
                    f"joint {name!r}: {outside} hand frames outside its samples' time span "
                    f"[{t[0]:.6g}, {t[-1]:.6g}] s: its first or last position is held there"
                    + _clock_hint(time_s)
                )
        return lines


UNIX_SECONDS = 1e8  # [s] times above this are Unix seconds (after 1973), not from 0


def _clock_hint(time_s) -> str:
    """Where the recording's clock starts, for a warning about joint times off its span."""
    if not len(time_s):
        return ""
    span = f"; the recording's hand frames span [{time_s.min():.6g}, {time_s.max():.6g}] s"
    if time_s.max() > UNIX_SECONDS:
        return span + " (a capture: Unix seconds on the host clock; time the joints on it)"
    return span + " (a simulation's or import's clock: from 0)"


def read_joint_csv(path: str | Path) -> JointStates:
    """A CSV of joint states: a ``time_s`` column [s] and one column per joint [rad or m]."""
    path = Path(path)
    try:
        with open(path, newline="", encoding="utf-8") as stream:
            rows = list(csv.reader(stream))
    except (OSError, UnicodeDecodeError) as error:
        raise JointStateError(f"{path}: cannot read it as a CSV ({error})") from None
    if not rows:
        raise JointStateError(f"{path}: empty; expected a header 'time_s,JOINT,...'")
    header = [cell.strip() for cell in rows[0]]
    if not header or header[0] != "time_s" or len(header) < 2:
        raise JointStateError(
            f"{path}: header {','.join(header)!r}; expected 'time_s' then one column per joint"
        )
    if len(set(header)) != len(header):
        raise JointStateError(f"{path}: a column is named twice in its header")
    values = []
    for number, row in enumerate(rows[1:], start=2):
        if not any(cell.strip() for cell in row):
            continue
        if len(row) != len(header):
            raise JointStateError(
                f"{path} line {number}: {len(row)} cells; expected {len(header)} (the header's)"
            )
        try:
            values.append([float(cell) for cell in row])
        except ValueError:
            raise JointStateError(f"{path} line {number}: a cell is not a number") from None
    if not values:
        raise JointStateError(f"{path}: no rows under its header")
    table = np.array(values)
    return JointStates(
        {name: (table[:, 0], table[:, j]) for j, name in enumerate(header) if j > 0},
        source=str(path),
    )


JOINT_STATE = "sensor_msgs/msg/JointState"


def _add_sample(samples, when: float, names, positions) -> None:
    for name, position in zip(names, positions, strict=False):
        times, values = samples.setdefault(str(name), ([], []))
        if times and when <= times[-1]:
            continue  # a repeated or late stamp: the first sample at a time wins
        times.append(when)
        values.append(float(position))


def _choose(path, found, topic):
    if topic is None and len(found) != 1:
        raise JointStateError(
            f"{path}: {len(found)} JointState topics ({', '.join(found) or 'none'}); "
            "name one with --joints-topic"
        )
    chosen = topic or found[0]
    if chosen not in found:
        raise JointStateError(
            f"{path}: no JointState topic {chosen!r}; its JointState topics: "
            f"{', '.join(found) or 'none'}"
        )
    return chosen


def _read_joint_mcap(path: Path, topic: str | None) -> JointStates:
    """A plain MCAP file's JointState topic (mcap's reader, the ros2 decoder)."""
    try:
        from mcap.exceptions import McapError
        from mcap.reader import make_reader
        from mcap_ros2.decoder import DecoderFactory
    except ImportError:
        raise JointStateError(
            'MCAP files need the mcap extra: pip install "tactsense[mcap]"'
        ) from None
    samples: dict[str, tuple[list, list]] = {}
    try:
        with open(path, "rb") as stream:
            reader = make_reader(stream, decoder_factories=[DecoderFactory()])
            summary = reader.get_summary()
            if summary is None:
                raise JointStateError(f"{path}: the MCAP file has no summary; 'mcap recover' it")
            found = sorted(
                ch.topic for ch in summary.channels.values()
                if ch.schema_id in summary.schemas
                and summary.schemas[ch.schema_id].name == JOINT_STATE
            )  # fmt: skip
            chosen = _choose(path, found, topic)
            for _, _, message, ros in reader.iter_decoded_messages(topics=[chosen]):
                stamp = ros.header.stamp.sec + ros.header.stamp.nanosec * 1e-9
                _add_sample(samples, stamp if stamp > 0 else message.log_time * 1e-9,
                            ros.name, ros.position)  # fmt: skip
    except JointStateError:
        raise  # a readable file without the topic asked for says so itself
    except (McapError, ValueError, KeyError, EOFError, OSError) as error:
        raise JointStateError(f"{path} is not a readable MCAP file ({error})") from None
    return JointStates(
        {name: (np.array(t), np.array(v)) for name, (t, v) in samples.items()},
        source=f"{path} ({chosen})",
    )


def read_joint_bag(path: str | Path, topic: str | None = None) -> JointStates:
    """The ``sensor_msgs/msg/JointState`` messages of a rosbag2 bag (a folder with its
    metadata.yaml, or one of its files; rosbags) or of a plain MCAP file (mcap's reader),
    on ``topic`` or the only such topic."""
    path = Path(path)
    bag = path.parent if path.is_file() else path
    if path.is_file() and not (bag / "metadata.yaml").is_file():
        with open(path, "rb") as stream:
            if stream.read(8) == b"\x89MCAP0\r\n":
                return _read_joint_mcap(path, topic)
    if not (bag / "metadata.yaml").is_file():
        raise JointStateError(
            f"{path}: not a rosbag2 bag (no metadata.yaml in {bag}) nor an MCAP file"
        )
    try:
        from rosbags.highlevel import AnyReader, AnyReaderError
        from rosbags.typesys import Stores, get_typestore
    except ImportError:
        raise JointStateError(
            'joint topics need rosbags: pip install "tactsense[import]"'
        ) from None
    samples: dict[str, tuple[list, list]] = {}
    try:
        with AnyReader([bag], default_typestore=get_typestore(Stores.ROS2_HUMBLE)) as reader:
            found = sorted(
                name for name, info in reader.topics.items() if info.msgtype == JOINT_STATE
            )
            chosen = _choose(path, found, topic)
            connections = [c for c in reader.connections if c.topic == chosen]
            for connection, log_ns, raw in reader.messages(connections=connections):
                message = reader.deserialize(raw, connection.msgtype)
                stamp = message.header.stamp.sec + message.header.stamp.nanosec * 1e-9
                _add_sample(samples, stamp if stamp > 0 else log_ns * 1e-9, message.name,
                            message.position)  # fmt: skip
    except JointStateError:
        raise
    except AnyReaderError as error:
        raise JointStateError(f"{path} is not a readable rosbag2 bag ({error})") from None
    return JointStates(
        {name: (np.array(t), np.array(v)) for name, (t, v) in samples.items()},
        source=f"{path} ({chosen})",
    )
