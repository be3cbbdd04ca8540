"""Frames and contacts of a live sensor as ROS 2 topics, over DDS, without ROS 2.

A ROS 2 node is, on the wire, a DDS participant whose topics are named ``rt`` + the ROS
name (``rt/pad16/tactile_states``), whose types are named ``pkg::msg::dds_::Type_`` and
encoded as plain CDR, whose participant says ``enclave=/;`` in its user data, and which
publishes on ``ros_discovery_info`` which node owns which writers (so ``ros2 node list``
shows it). :class:`Ros2Publisher` is such a participant with one node, built on the
``cyclonedds`` wheel (Cyclone DDS, the C library every ROS 2 distribution ships as an
RMW), with the sensor-data QoS of ROS 2 (``rclcpp::SensorDataQoS``: best effort,
volatile, keep last 5) on every topic.

Per sensor, under the node's namespace (default ``/<sensor name>``):

=====================  ===============================  =====================================
topic                  type                             what
=====================  ===============================  =====================================
``tactile_states``     ``tactile_msgs/msg/TactileState``     the frame's counts, row-major (a
                                                        channel per component, ``<sensor>/x``,
                                                        ``/y``, ``/z``, for three-axis taxels)
``contact_states``     ``tactile_msgs/msg/TactileContacts``  every contact of the frame (may be
                                                        empty), each named ``<sensor>/<id>``
``tactile_image``      ``sensor_msgs/msg/Image``             the counts as a rows x cols
                                                        ``32FC1`` image (``32FC3``, the
                                                        channels x, y, z, for three-axis
                                                        taxels)
``wrench``             ``geometry_msgs/msg/WrenchStamped``   the total force of the contacts [N]
                                                        and its torque about the frame's
                                                        origin [N m]
=====================  ===============================  =====================================

Every message of one frame carries that frame's stamp (its arrival on the host's
clock, Unix time) and ``frame_id``; contacts are filled as the MCAP export fills them
(:mod:`tactsense.interop.ros`).
"""

from __future__ import annotations

import os
import re
import struct

import numpy as np

from tactsense._validation import TactsenseInputError
from tactsense.interop._state_bytes import ComponentStateBytes, state_message
from tactsense.interop.mcap import _ContactBytes
from tactsense.interop.ros import contact_geometry
from tactsense.interop.ros2.config import resolve_config
from tactsense.kinds import kind_of

TOPICS = ("tactile_states", "contact_states", "tactile_image", "wrench")
"""The topics of one sensor, relative to the node's namespace."""
QOS_DEPTH = 5
"""Keep-last depth of the sensor-data QoS (``rmw_qos_profile_sensor_data``)."""
DISCOVERY_TOPIC = "ros_discovery_info"
ENCLAVE = b"enclave=/;"
OLD_DISTROS = ("ardent", "bouncy", "crystal", "dashing", "eloquent", "foxy", "galactic", "humble")
"""ROS 2 distributions whose ``rmw_dds_common/Gid`` has 24 bytes (16 since Iron)."""

started_configs: list[str] = []
"""The configuration of every participant this process started (the tests check that each
kept to the loopback interface)."""

_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]*\Z")
_STAMP = struct.Struct("<iI")


class Ros2Error(TactsenseInputError):
    """A ROS 2 publisher that cannot start (a bad name, the extra missing, DDS refusing)."""


def _cyclonedds():
    try:
        import cyclonedds  # noqa: F401
    except ImportError:
        raise Ros2Error('ROS 2 topics need the ros2 extra: pip install "tactsense[ros2]"') from None


def ros_token(name: str) -> str:
    """A name as a ROS name token: characters other than letters, digits and ``_``
    become ``_``, and one starting with a digit gets a leading ``_``."""
    token = re.sub(r"[^A-Za-z0-9_]", "_", name)
    return token if _NAME.match(token) else "_" + token


TOPIC_MAX_LENGTH = 255 - 8
"""Longest fully qualified ROS 2 topic name (``RMW_TOPIC_MAX_NAME_LENGTH``)."""
NAMESPACE_MAX_LENGTH = TOPIC_MAX_LENGTH - 2
"""Longest ROS 2 namespace (``RMW_NAMESPACE_MAX_LENGTH``)."""
NODE_NAME_MAX_LENGTH = 255
"""Longest ROS 2 node name (``RMW_NODE_NAME_MAX_NAME_LENGTH``); ``ros_discovery_info``
holds it in a ``string<=256``."""
NAMESPACE_RULE = (
    "a ROS 2 namespace is '/' or /name/name... of letters, digits and _ (a name not "
    "starting with a digit; no trailing /)"
)


def check_namespace(namespace: str, option: str = "--namespace") -> str:
    """A node's ROS 2 namespace, checked by ROS 2's own rule, or a one-line
    :class:`Ros2Error`.

    As ``rcl_node_init`` does with a node's namespace, an empty one becomes ``/`` and a
    relative one (``foo``) gets a leading ``/``; then ``rmw_validate_namespace``'s rule:
    absolute, no trailing ``/`` (except ``/`` itself), no ``//``, tokens
    ``[A-Za-z_][A-Za-z0-9_]*``, at most :data:`NAMESPACE_MAX_LENGTH` characters; and
    short enough that every topic under it (``<namespace>/tactile_states``) keeps within
    :data:`TOPIC_MAX_LENGTH`.
    """
    given = namespace
    if not namespace.startswith("/"):
        namespace = "/" + namespace  # rcl: "" -> "/", "foo" -> "/foo"
    problem = None
    if namespace != "/" and namespace.endswith("/"):
        problem = "it ends with /"
    elif "//" in namespace:
        problem = "it has //"
    elif namespace != "/" and not all(_NAME.match(t) for t in namespace[1:].split("/")):
        problem = NAMESPACE_RULE
    if problem is not None:
        if problem != NAMESPACE_RULE:
            problem += "; " + NAMESPACE_RULE
        raise Ros2Error(f"{option} {_short(given)}: {problem}")
    longest = max(len(_topic(namespace, t)) for t in TOPICS)
    if len(namespace) > NAMESPACE_MAX_LENGTH or longest > TOPIC_MAX_LENGTH:
        limit = TOPIC_MAX_LENGTH - (longest - len(namespace))
        raise Ros2Error(
            f"{option} {_short(given)}: {len(namespace)} characters; a ROS 2 topic name has at "
            f"most {TOPIC_MAX_LENGTH}, so the namespace of these topics at most {limit}"
        )
    return namespace


def check_node_name(node_name: str) -> str:
    """A ROS 2 node name (``rmw_validate_node_name``), or a one-line :class:`Ros2Error`."""
    if not _NAME.match(node_name):
        raise Ros2Error(
            f"node name {_short(node_name)}: letters, digits and _ only, not starting with a digit"
        )
    if len(node_name) > NODE_NAME_MAX_LENGTH:
        raise Ros2Error(
            f"node name {_short(node_name)}: {len(node_name)} characters; a ROS 2 node name "
            f"has at most {NODE_NAME_MAX_LENGTH}"
        )
    return node_name


def _topic(namespace: str, topic: str) -> str:
    return ("" if namespace == "/" else namespace) + "/" + topic


def _short(text: str) -> str:
    """A name quoted for an error line, its middle cut when long."""
    return repr(text) if len(text) <= 40 else repr(text[:20] + "..." + text[-12:])


def domain_id_from_environment() -> int:
    """``ROS_DOMAIN_ID`` (0-232), as ROS 2 reads it; 0 when unset."""
    text = os.environ.get("ROS_DOMAIN_ID", "").strip()
    if not text:
        return 0
    if not text.isdigit() or int(text) > 232:
        raise Ros2Error(f"ROS_DOMAIN_ID={text!r}: expected an integer 0-232")
    return int(text)


class _StampedBytes:
    """The CDR bytes of a message whose only varying parts are its header's stamp (right
    after the encapsulation) and its trailing bytes: the rest is taken from one message
    Cyclone DDS's serialiser encoded, and checked against it on two probes."""

    def __init__(self, serialize, make, first: bytes, second: bytes):
        self.tail = len(first)
        data = serialize(make(1, 2, first))
        self.head, self.middle = data[:4], data[12 : len(data) - self.tail]
        for sec, nanosec, values in ((1, 2, first), (-7, 999_999_999, second)):
            if self.encode(sec, nanosec, values) != _padded(serialize(make(sec, nanosec, values))):
                raise AssertionError("the CDR layout is not the one assumed")  # pragma: no cover

    def encode(self, sec: int, nanosec: int, tail: bytes) -> bytes:
        return _padded(b"".join((self.head, _STAMP.pack(sec, nanosec), self.middle, tail)))


class _ComponentStates:
    """``encode(sec, nanosec, tail)`` of a ``TactileState`` of several channels, from a
    :class:`~tactsense.interop._state_bytes.ComponentStateBytes` (checked against the
    serialiser's bytes when made)."""

    def __init__(self, template):
        self.template = template

    def encode(self, sec: int, nanosec: int, tail: bytes) -> bytes:
        values = np.frombuffer(tail, dtype="<f4")
        return _padded(self.template.encode(sec, nanosec, values))


def _state_of(m, message: dict):
    """A ``TactileState`` (Cyclone DDS's class) of the encoder's dictionary."""
    stamp = message["header"]["stamp"]
    return m.TactileState(
        m.Header(m.Time(stamp["sec"], stamp["nanosec"]), message["header"]["frame_id"]),
        [m.ChannelFloat32(ch["name"], list(ch["values"])) for ch in message["sensors"]],
    )


def _padded(data: bytes) -> bytes:
    """What Cyclone DDS's writer sends: the CDR padded to a multiple of 4 bytes."""
    return data + b"\0" * (-len(data) % 4)


class Ros2Publisher:
    """One ROS 2 node publishing a sensor's frames and contacts (see the module's table).

    Parameters
    ----------
    sensor : SensorSpec, PadSpec or PointsSpec
    namespace : str, optional
        The node's namespace; default ``/<sensor name>`` (as a ROS token).
    node_name : str
        The node's name (``ros2 node list`` shows ``<namespace>/<node_name>``).
    frame_id : str
        The ``frame_id`` of every header: the link the sensor is mounted on.
    config : str or path, optional
        A Cyclone DDS configuration (:func:`~tactsense.interop.ros2.config.resolve_config`:
        default ``CYCLONEDDS_URI``, else loopback only).
    domain_id : int, optional
        The DDS domain; default ``ROS_DOMAIN_ID`` or 0.
    distro : str, optional
        The ROS 2 distribution of the nodes that should list this one (``ROS_DISTRO`` by
        default): Humble and older use 24-byte gids in ``ros_discovery_info``.
    fast : bool
        Encode from templates of the serialiser's bytes (the same bytes, checked at
        construction); False serialises each message with Cyclone DDS's serialiser
        (the straightforward path, for the benchmark).
    """

    def __init__(
        self,
        sensor,
        *,
        namespace: str | None = None,
        node_name: str = "tactsense",
        frame_id: str = "finger",
        config=None,
        domain_id: int | None = None,
        distro: str | None = None,
        fast: bool = True,
    ):
        _cyclonedds()
        from cyclonedds.domain import Domain, DomainParticipant
        from cyclonedds.pub import DataWriter, Publisher
        from cyclonedds.qos import Policy, Qos
        from cyclonedds.topic import Topic

        from tactsense.interop.ros2 import messages as m

        self.sensor = sensor
        self.frame_id = frame_id
        self.namespace = (
            check_namespace(namespace)
            if namespace is not None
            else check_namespace("/" + ros_token(sensor.name), "the namespace of the sensor's name")
        )
        self.node_name = check_node_name(node_name)
        self.domain_id = domain_id_from_environment() if domain_id is None else int(domain_id)
        if not 0 <= self.domain_id <= 232:
            raise Ros2Error(f"DDS domain {self.domain_id}: expected 0-232")
        config_text, self.config_source = resolve_config(config)
        distro = (distro if distro is not None else os.environ.get("ROS_DISTRO", "")).lower()
        self.gid_bytes = m.GID_BYTES_HUMBLE if distro in OLD_DISTROS else m.GID_BYTES
        self._multi = kind_of(sensor).multi_contact
        self._positions = sensor.taxel_positions_mm() if self._multi else None
        self._taxel_normals = sensor.taxel_normals() if self._multi else None
        try:
            self._domain = Domain(self.domain_id, config_text)
            started_configs.append(config_text)
            self.participant = DomainParticipant(
                self.domain_id, qos=Qos(Policy.Userdata(data=ENCLAVE))
            )
        except Exception as error:  # Cyclone DDS says why in its own words
            raise Ros2Error(f"DDS would not start ({self.config_source} config): {error}") from None
        sensor_qos = Qos(
            Policy.Reliability.BestEffort,
            Policy.Durability.Volatile,
            Policy.History.KeepLast(QOS_DEPTH),
        )
        publisher = Publisher(self.participant)
        types = dict(zip(TOPICS, (m.TactileState, m.TactileContacts, m.Image, m.WrenchStamped),
                         strict=True))  # fmt: skip
        self.ros_topics = {name: self._ros_name(name) for name in TOPICS}
        self._writers = {}
        for name, kind in types.items():
            topic = Topic(self.participant, "rt" + self.ros_topics[name], kind)
            self._writers[name] = DataWriter(publisher, topic, qos=sensor_qos)
        self.published = dict.fromkeys(TOPICS, 0)
        """Samples written per topic."""
        self.failed = 0
        """Writes Cyclone DDS refused (a sample not sent)."""
        self.frames = 0
        self._fast = fast
        self._types = m
        self._announce(m, Topic, DataWriter, Publisher, Policy, Qos)
        self._build_templates(m)
        from cyclonedds._clayer import ddspy_write

        self._write_bytes = ddspy_write

    def _ros_name(self, topic: str) -> str:
        return _topic(self.namespace, topic)

    def _gid(self, entity) -> list[int]:
        guid = entity.get_guid().bytes
        return list(guid) + [0] * (self.gid_bytes - len(guid))

    def _announce(self, m, Topic, DataWriter, Publisher, Policy, Qos) -> None:
        """Publish the node and its writers on ``ros_discovery_info`` (reliable, transient
        local, keep last 1, as every RMW does), so ROS 2's graph shows them as a node."""
        humble = self.gid_bytes == m.GID_BYTES_HUMBLE
        gid = m.GidHumble if humble else m.Gid
        node = (m.NodeEntitiesInfoHumble if humble else m.NodeEntitiesInfo)(
            node_namespace=self.namespace, node_name=self.node_name, reader_gid_seq=[],
            writer_gid_seq=[gid(self._gid(w)) for w in self._writers.values()],
        )  # fmt: skip
        kind = m.ParticipantEntitiesInfoHumble if humble else m.ParticipantEntitiesInfo
        self.discovery_info = kind(gid=gid(self._gid(self.participant)),
                                   node_entities_info_seq=[node])  # fmt: skip
        qos = Qos(
            Policy.Reliability.Reliable(max_blocking_time=100_000_000),
            Policy.Durability.TransientLocal,
            Policy.History.KeepLast(1),
        )
        topic = Topic(self.participant, DISCOVERY_TOPIC, kind)
        self._discovery = DataWriter(Publisher(self.participant), topic, qos=qos)
        self._discovery.write(self.discovery_info)

    def _build_templates(self, m) -> None:
        rows, cols = self.sensor.shape
        header = {"frame_id": self.frame_id}
        # ---- taxels of several components (r8-triinterop): a TactileState channel per
        # component (<sensor>/x, /y, /z), the image 32FC3 (a pixel's channels x, y, z) ----
        parts = self.sensor.components

        def state(sec, nanosec, tail):
            values = np.frombuffer(tail, dtype="<f4")
            if parts > 1:
                return _state_of(m, state_message(self.sensor, sec, nanosec, values,
                                                  self.frame_id))  # fmt: skip
            channel = m.ChannelFloat32(self.sensor.name, values.tolist())
            return m.TactileState(m.Header(m.Time(sec, nanosec), **header), [channel])

        def image(sec, nanosec, tail):
            return m.Image(m.Header(m.Time(sec, nanosec), **header), rows, cols,
                           f"32FC{parts}", 0, 4 * cols * parts, list(tail))  # fmt: skip

        def wrench(sec, nanosec, tail):
            f, t = np.frombuffer(tail, dtype="<f8").reshape(2, 3).tolist()
            return m.WrenchStamped(m.Header(m.Time(sec, nanosec), **header),
                                   m.Wrench(m.Vector3(*f), m.Vector3(*t)))  # fmt: skip

        def contact(name, sec, nanosec, numbers):
            v = [float(x) for x in numbers]
            return m.TactileContact(
                m.Header(m.Time(sec, nanosec), **header), name, m.Point(*v[0:3]),
                m.Vector3(*v[3:6]), m.Wrench(m.Vector3(*v[6:9]), m.Vector3(*v[9:12])),
            )  # fmt: skip

        self._make = {"tactile_states": state, "tactile_image": image, "wrench": wrench}
        self._make_contact = contact
        cells = rows * cols * parts

        def serialize(message):
            return bytes(message.serialize())

        def probes(n: int, dtype: str) -> tuple[bytes, bytes]:
            first = np.arange(1, n + 1, dtype=dtype)
            return first.tobytes(), (-first[::-1] - 0.5).astype(dtype).tobytes()

        self._templates = {
            "tactile_states": (
                _StampedBytes(serialize, state, *probes(cells, "<f4")) if parts == 1 else None
            ),
            "tactile_image": _StampedBytes(serialize, image, *probes(cells, "<f4")),
            "wrench": _StampedBytes(serialize, wrench, *probes(6, "<f8")),
        }
        self._contacts = _ContactBytes(
            serialize, lambda d: serialize(m.TactileContacts(d["contacts"])), contact
        )
        if parts > 1:  # the channels' values are not trailing: a template of each part
            self._templates["tactile_states"] = _ComponentStates(
                ComponentStateBytes(
                    lambda d: _padded(serialize(_state_of(m, d))), self.sensor, self.frame_id
                )
            )

    def contact_numbers(self, estimate: dict | None) -> tuple[list[str], np.ndarray]:
        """The contacts of one estimate as names and rows of twelve numbers: position [m],
        outward normal, force the object applies [N] and its torque about the frame's
        origin [N m], as :meth:`McapTactileWriter.contacts_at` fills them."""
        if estimate is None:
            return [], np.zeros((0, 12))
        if self._multi:
            fields = ("x_mm", "y_mm", "z_mm", "force_n")
            contacts = [
                c for c in estimate["contacts"] if np.isfinite([c[k] for k in fields]).all()
            ]
            if not contacts:
                return [], np.zeros((0, 12))
            xyz = np.array([[c["x_mm"], c["y_mm"], c["z_mm"]] for c in contacts])
            nearest = np.argmin(
                ((xyz[:, None, :] - self._positions[None, :, :]) ** 2).sum(axis=-1), axis=1
            )
            points, normals = xyz * 1e-3, self._taxel_normals[nearest]
            force_n = np.array([c["force_n"] for c in contacts], dtype=float)
            names = [f"{self.sensor.name}/{c['id']}" for c in contacts]
        else:
            from tactsense.estimate import Flag

            touching = not (estimate["flags"] & int(Flag.NO_CONTACT)) and np.isfinite(
                estimate["force_n"]
            )
            if not touching:
                return [], np.zeros((0, 12))
            points, normals = contact_geometry(
                self.sensor, np.array([estimate["axial_mm"]]), np.array([estimate["angle_deg"]])
            )
            force_n = np.array([estimate["force_n"]], dtype=float)
            names = [self.sensor.name]
        force = -force_n[:, None] * normals
        if self._multi:  # ---- the tangential force of a shear-sensing kind (r8-triinterop)
            from tactsense.interop.components import contact_shear

            shear = contact_shear(contacts)
            force = force if shear is None else force + shear
        numbers = np.zeros((len(names), 12), dtype="<f8")
        numbers[:, 0:3], numbers[:, 3:6], numbers[:, 6:9] = points, normals, force
        numbers[:, 9:12] = np.cross(points, force)
        return names, numbers

    def encode(self, frame, estimate: dict | None) -> dict[str, bytes]:
        """The CDR bytes of one frame's four messages, by topic."""
        ns = round(float(frame.host_time_s) * 1e9)
        sec, nanosec = ns // 1_000_000_000, ns % 1_000_000_000
        values = np.ascontiguousarray(frame.counts, dtype="<f4").tobytes()
        names, numbers = self.contact_numbers(estimate)
        wrench = numbers[:, 6:12].sum(axis=0) if len(names) else np.zeros(6)
        total = np.ascontiguousarray(wrench, dtype="<f8").tobytes()
        if not self._fast:
            items = [
                self._make_contact(n, sec, nanosec, r) for n, r in zip(names, numbers, strict=True)
            ]
            messages = {
                "tactile_states": self._make["tactile_states"](sec, nanosec, values),
                "contact_states": self._types.TactileContacts(items),
                "tactile_image": self._make["tactile_image"](sec, nanosec, values),
                "wrench": self._make["wrench"](sec, nanosec, total),
            }
            return messages
        templates = self._templates
        return {
            "tactile_states": templates["tactile_states"].encode(sec, nanosec, values),
            "contact_states": _padded(self._contacts.contacts(
                [(n, sec, nanosec, r) for n, r in zip(names, numbers, strict=True)])),
            "tactile_image": templates["tactile_image"].encode(sec, nanosec, values),
            "wrench": templates["wrench"].encode(sec, nanosec, total),
        }  # fmt: skip

    def publish(self, frame, estimate: dict | None) -> None:
        """Publish one frame (and its estimate's contacts; none while there is no
        estimate, e.g. while the baseline is collected) on the four topics."""
        for name, data in self.encode(frame, estimate).items():
            writer = self._writers[name]
            try:
                if self._fast:
                    if self._write_bytes(writer._ref, data) < 0:
                        self.failed += 1
                        continue
                else:
                    writer.write(data)
            except Exception:  # a write DDS refuses is counted, never fatal mid-stream
                self.failed += 1
                continue
            self.published[name] += 1
        self.frames += 1

    def wait_for_subscribers(self, timeout_s: float = 1.0) -> int:
        """Wait until the subscribers already on the network have matched all four topics
        (at most ``timeout_s`` [s]; discovery on the loopback takes tens of milliseconds,
        more on a loaded machine), so that they get the first frame too; returns the
        subscribers matched on ``tactile_states``. Nobody there: returns 0 after the wait."""
        import time

        deadline = time.monotonic() + timeout_s
        while time.monotonic() < deadline:
            counts = [len(w.get_matched_subscriptions()) for w in self._writers.values()]
            if min(counts) > 0:
                return counts[0]
            time.sleep(0.01)
        return self.subscribers()

    def subscribers(self) -> int:
        """Readers matched now on the frames' topic (``tactile_states``)."""
        return len(self._writers["tactile_states"].get_matched_subscriptions())

    def summary(self) -> str:
        """One line for ``live``: what was published, where, and what was not sent."""
        return (
            f"ROS 2: {self.frames} frames on {self.namespace} ({', '.join(TOPICS)}; "
            f"node {self._ros_name(self.node_name)}, domain {self.domain_id}, "
            f"{self.config_source} DDS config): {sum(self.published.values())} samples "
            f"sent, {self.failed} not sent; {self.subscribers()} subscriber(s) at the end; "
            "losses on the way are the subscribers' to count (best effort)"
        )

    def close(self) -> None:
        """Leave the DDS domain (readers see the node go)."""
        for name in ("participant", "_domain"):  # the participant first: its writers go with it
            entity = self.__dict__.pop(name, None)
            if entity is not None:
                entity.__del__()
        self._writers = {}
