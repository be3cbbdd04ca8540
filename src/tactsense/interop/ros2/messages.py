"""The ROS 2 messages tactsense publishes, as DDS types with ROS 2's names on the wire.

ROS 2 maps a message ``pkg/msg/Type`` to the DDS type ``pkg::msg::dds_::Type_`` (the
``rosidl_generator_dds_idl`` naming every RMW uses) and encodes it as plain CDR (XCDR1,
little-endian) with the fields in the order of its ``.msg`` file: these classes are those
``.msg`` files written as Cyclone DDS IDL types. ``tactile_msgs`` is the ROS tactile
toolbox's package (:mod:`tactsense.interop.ros` holds its definitions);
``rmw_dds_common`` is ROS 2's own discovery package (the ``ros_discovery_info`` topic
that says which nodes own which readers and writers).
"""

# no "from __future__ import annotations": Cyclone DDS resolves the field types at run time
from dataclasses import dataclass, field

from cyclonedds.idl import IdlStruct
from cyclonedds.idl.types import (
    array,
    bounded_str,
    float32,
    float64,
    int32,
    sequence,
    uint8,
    uint32,
)


def _dds(ros_type: str) -> str:
    """The DDS type name of a ROS 2 message type: ``pkg/msg/T`` -> ``pkg::msg::dds_::T_``."""
    package, kind, name = ros_type.split("/")
    return f"{package}::{kind}::dds_::{name}_"


@dataclass
class Time(IdlStruct, typename=_dds("builtin_interfaces/msg/Time")):
    sec: int32
    nanosec: uint32


@dataclass
class Header(IdlStruct, typename=_dds("std_msgs/msg/Header")):
    stamp: Time
    frame_id: str


@dataclass
class ChannelFloat32(IdlStruct, typename=_dds("sensor_msgs/msg/ChannelFloat32")):
    name: str
    values: sequence[float32]


@dataclass
class TactileState(IdlStruct, typename=_dds("tactile_msgs/msg/TactileState")):
    header: Header
    sensors: sequence[ChannelFloat32]


@dataclass
class Point(IdlStruct, typename=_dds("geometry_msgs/msg/Point")):
    x: float64
    y: float64
    z: float64


@dataclass
class Vector3(IdlStruct, typename=_dds("geometry_msgs/msg/Vector3")):
    x: float64
    y: float64
    z: float64


@dataclass
class Wrench(IdlStruct, typename=_dds("geometry_msgs/msg/Wrench")):
    force: Vector3
    torque: Vector3


@dataclass
class TactileContact(IdlStruct, typename=_dds("tactile_msgs/msg/TactileContact")):
    header: Header
    name: str
    position: Point
    normal: Vector3
    wrench: Wrench


@dataclass
class TactileContacts(IdlStruct, typename=_dds("tactile_msgs/msg/TactileContacts")):
    contacts: sequence[TactileContact]


@dataclass
class WrenchStamped(IdlStruct, typename=_dds("geometry_msgs/msg/WrenchStamped")):
    header: Header
    wrench: Wrench


@dataclass
class Image(IdlStruct, typename=_dds("sensor_msgs/msg/Image")):
    header: Header
    height: uint32
    width: uint32
    encoding: str
    is_bigendian: uint8
    step: uint32
    data: sequence[uint8]


GID_BYTES = 16
"""Size of an ``rmw_dds_common/Gid`` since ROS 2 Iron (``char[16] data``); Humble and
older have 24 (:data:`GID_BYTES_HUMBLE`)."""
GID_BYTES_HUMBLE = 24


@dataclass
class Gid(IdlStruct, typename=_dds("rmw_dds_common/msg/Gid")):
    data: array[uint8, GID_BYTES]


@dataclass
class GidHumble(IdlStruct, typename=_dds("rmw_dds_common/msg/Gid")):
    data: array[uint8, GID_BYTES_HUMBLE]


@dataclass
class NodeEntitiesInfo(IdlStruct, typename=_dds("rmw_dds_common/msg/NodeEntitiesInfo")):
    node_namespace: bounded_str[256]
    node_name: bounded_str[256]
    reader_gid_seq: sequence[Gid] = field(default_factory=list)
    writer_gid_seq: sequence[Gid] = field(default_factory=list)


@dataclass
class ParticipantEntitiesInfo(
    IdlStruct, typename=_dds("rmw_dds_common/msg/ParticipantEntitiesInfo")
):
    gid: Gid
    node_entities_info_seq: sequence[NodeEntitiesInfo]


@dataclass
class NodeEntitiesInfoHumble(IdlStruct, typename=_dds("rmw_dds_common/msg/NodeEntitiesInfo")):
    node_namespace: bounded_str[256]
    node_name: bounded_str[256]
    reader_gid_seq: sequence[GidHumble] = field(default_factory=list)
    writer_gid_seq: sequence[GidHumble] = field(default_factory=list)


@dataclass
class ParticipantEntitiesInfoHumble(
    IdlStruct, typename=_dds("rmw_dds_common/msg/ParticipantEntitiesInfo")
):
    gid: GidHumble
    node_entities_info_seq: sequence[NodeEntitiesInfoHumble]
