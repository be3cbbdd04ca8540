"""An independent ROS 2 subscriber, for the tests and the benchmark of ``live --ros2``.

Written from the upstream ``.msg`` texts (below, as the ROS tactile toolbox and ROS 2's
common_interfaces publish them), not from tactsense's code: the DDS types it subscribes
with are generated here from rosbags' parse of those texts, named as ROS 2 names them
on the wire (``pkg::msg::dds_::Type_``), and it keeps every sample's raw CDR bytes and
its arrival on ``time.perf_counter`` and ``time.time`` (the listener's callback, in
Cyclone DDS's receive thread), for the test to decode with rosbags. It also records
what DDS discovery says about the publisher: participants' user data, endpoints' topic
and type names and QoS, and the ``ros_discovery_info`` samples.

Run: ``python ros2_subscriber.py OUT.pickle --domain D --namespace /ns --seconds S
[--count N]``; prints ``ready`` once its readers exist; stops after S seconds, or once N
``tactile_states`` samples have arrived and then 0.5 s of quiet. Refuses to start (exit
3) unless ``CYCLONEDDS_URI`` keeps DDS on 127.0.0.1 with multicast off.
"""

import argparse
import os
import pickle
import sys
import threading
import time

TACTILE_MSGS = {  # ubi-agni/tactile_toolbox, tactile_msgs/msg/*.msg (comments kept)
    "tactile_msgs/msg/TactileState": """\
# Message to publish (raw) tactile data of one or more arrays of tactile sensors,
# i.e. a tactile skin
# For now this considers normal forces only. As is, this applies to
# UNIBI's myrmex, finger, and palm sensors as well as SynTouch.

# specify the timestamp (frame not used)
Header header

# a list of individual, named sensor arrays
sensor_msgs/ChannelFloat32[] sensors
""",
    "tactile_msgs/msg/TactileContact": """\
# Message describing the net effect of a single contact

# specify link frame and timestamp of contact
Header header

# unique name of the contact
string name
# contact point location
geometry_msgs/Point position
# surface normal at contact point
geometry_msgs/Vector3 normal
# wrench applied through this contact point
# this wrench should be represented in reference frame, not in contact point frame
geometry_msgs/Wrench wrench
""",
    "tactile_msgs/msg/TactileContacts": "TactileContact[] contacts\n",
}
RMW_DDS_COMMON = {  # ros2/rmw_dds_common (Iron and later), rmw_dds_common/msg/*.msg
    "rmw_dds_common/msg/Gid": "char[16] data\n",
    "rmw_dds_common/msg/NodeEntitiesInfo": (
        "string<=256 node_namespace\nstring<=256 node_name\nGid[] reader_gid_seq\n"
        "Gid[] writer_gid_seq\n"
    ),
    "rmw_dds_common/msg/ParticipantEntitiesInfo": (
        "Gid gid\nNodeEntitiesInfo[] node_entities_info_seq\n"
    ),
}
TOPIC_TYPES = {
    "tactile_states": "tactile_msgs/msg/TactileState",
    "contact_states": "tactile_msgs/msg/TactileContacts",
    "tactile_image": "sensor_msgs/msg/Image",
    "wrench": "geometry_msgs/msg/WrenchStamped",
}


def typestore():
    """rosbags' ROS 2 (Jazzy) store with the tactile and discovery messages added from
    their ``.msg`` texts."""
    from rosbags.typesys import Stores, get_types_from_msg, get_typestore

    store = get_typestore(Stores.ROS2_JAZZY)
    for texts in (TACTILE_MSGS, RMW_DDS_COMMON):
        for name, text in texts.items():
            store.register(get_types_from_msg(text, name))
    return store


def loopback_only(uri: str) -> bool:
    """A crude check, written here on purpose: the configuration names 127.0.0.1 as its
    interface and turns multicast off."""
    text = uri
    if not uri.lstrip().startswith("<"):
        path = uri.strip().removeprefix("file://")
        text = open(path).read()
    squeezed = "".join(text.split()).lower()
    return (
        "<allowmulticast>false</allowmulticast>" in squeezed and 'address="127.0.0.1"' in squeezed
    )


def dds_types(store):
    """Cyclone DDS types of every message the store knows that is needed, from rosbags'
    field definitions: ROS 2's ``pkg::msg::dds_::T_`` names."""
    from cyclonedds.idl import make_idl_struct
    from cyclonedds.idl import types as t

    base = {
        "bool": bool, "int8": t.int8, "uint8": t.uint8, "int16": t.int16, "uint16": t.uint16,
        "int32": t.int32, "uint32": t.uint32, "int64": t.int64, "uint64": t.uint64,
        "float32": t.float32, "float64": t.float64, "char": t.uint8, "byte": t.uint8,
    }  # fmt: skip
    made = {}

    def of(name):
        if name in made:
            return made[name]
        fields = {}
        for field, (node, detail) in store.fielddefs[name][1]:
            fields[field] = resolve(node, detail)
        package, kind, short = name.split("/")
        made[name] = make_idl_struct(short, f"{package}::{kind}::dds_::{short}_", fields)
        return made[name]

    def resolve(node, detail):
        kind = node.name
        if kind == "BASE":
            type_name, bound = detail
            if type_name == "string":
                return t.bounded_str[bound] if bound else str
            return base[type_name]
        if kind == "NAME":
            return of(detail)
        inner, count = detail
        element = resolve(*inner)
        return t.array[element, count] if kind == "ARRAY" else t.sequence[element]

    return of


def main() -> int:
    parser = argparse.ArgumentParser()
    parser.add_argument("out")
    parser.add_argument("--domain", type=int, required=True)
    parser.add_argument("--namespace", required=True)
    parser.add_argument("--seconds", type=float, default=30.0)
    parser.add_argument("--count", type=int, default=0)
    parser.add_argument("--depth", type=int, default=5)
    args = parser.parse_args()
    uri = os.environ.get("CYCLONEDDS_URI", "")
    if not uri or not loopback_only(uri):
        print("CYCLONEDDS_URI does not keep DDS on 127.0.0.1 with multicast off", file=sys.stderr)
        return 3

    from cyclonedds._clayer import ddspy_take
    from cyclonedds.builtin import (
        BuiltinDataReader,
        BuiltinTopicDcpsParticipant,
        BuiltinTopicDcpsPublication,
    )
    from cyclonedds.core import InstanceState, Listener, SampleState, ViewState
    from cyclonedds.domain import DomainParticipant
    from cyclonedds.qos import Policy, Qos
    from cyclonedds.sub import DataReader
    from cyclonedds.topic import Topic

    store = typestore()
    of = dds_types(store)
    participant = DomainParticipant(args.domain)
    sensor_qos = Qos(Policy.Reliability.BestEffort, Policy.History.KeepLast(args.depth))
    received = {name: [] for name in TOPIC_TYPES}
    lost = {name: 0 for name in TOPIC_TYPES}
    mask = SampleState.Any | ViewState.Any | InstanceState.Any
    done = threading.Event()
    last = [time.perf_counter()]

    def listener_for(name):
        def on_data_available(reader):
            now, wall = time.perf_counter(), time.time()
            for data, info in ddspy_take(reader._ref, mask, 64):
                if info.valid_data:
                    received[name].append((now, wall, bytes(data)))
            last[0] = now
            if args.count and len(received["tactile_states"]) >= args.count:
                done.set()

        def on_sample_lost(reader, status):
            lost[name] = status.total_count

        return Listener(on_data_available=on_data_available, on_sample_lost=on_sample_lost)

    readers = []
    prefix = "" if args.namespace == "/" else args.namespace
    for name, ros_type in TOPIC_TYPES.items():
        topic = Topic(participant, f"rt{prefix}/{name}", of(ros_type))
        readers.append(DataReader(participant, topic, qos=sensor_qos, listener=listener_for(name)))
    info_type = of("rmw_dds_common/msg/ParticipantEntitiesInfo")
    info_reader = DataReader(
        participant,
        Topic(participant, "ros_discovery_info", info_type),
        qos=Qos(Policy.Reliability.Reliable(0), Policy.Durability.TransientLocal,
                Policy.History.KeepLast(10)),
    )  # fmt: skip
    participants = BuiltinDataReader(participant, BuiltinTopicDcpsParticipant)
    publications = BuiltinDataReader(participant, BuiltinTopicDcpsPublication)
    print("ready", flush=True)
    start = time.perf_counter()
    seen = {"participants": {}, "publications": {}, "discovery": []}
    while time.perf_counter() - start < args.seconds:
        if done.is_set() and time.perf_counter() - last[0] > 0.5:
            break
        for sample in participants.take(64):
            if getattr(sample, "qos", None) is None:  # a participant gone
                continue
            data = sample.qos[Policy.Userdata].data if Policy.Userdata in sample.qos else None
            if data is not None or str(sample.key) not in seen["participants"]:
                seen["participants"][str(sample.key)] = (data,)
        for sample in publications.take(64):
            if getattr(sample, "topic_name", None) is None:  # a writer gone: keep what it was
                continue
            qos = sample.qos
            reliability = type(qos[Policy.Reliability]).__name__ if qos else None
            history = qos[Policy.History] if qos else None
            seen["publications"][str(sample.key)] = {
                "topic": sample.topic_name, "type": sample.type_name,
                "participant": str(sample.participant_key),
                "reliability": reliability if reliability != "_PolicySingleton"
                else str(qos[Policy.Reliability]),
                "history": str(history),
            }  # fmt: skip
        for sample in info_reader.take(16):
            if hasattr(sample, "gid"):
                seen["discovery"].append(
                    {"gid": bytes(sample.gid.data),
                     "nodes": [(n.node_namespace, n.node_name,
                                [bytes(g.data) for g in n.writer_gid_seq])
                               for n in sample.node_entities_info_seq]}
                )  # fmt: skip
        time.sleep(0.02)
    result = {"received": received, "lost": lost, **seen}
    with open(args.out + ".tmp", "wb") as stream:
        pickle.dump(result, stream)
    os.replace(args.out + ".tmp", args.out)
    del readers
    return 0


if __name__ == "__main__":
    sys.exit(main())
