"""ROS 2 topics over DDS, without a ROS 2 installation (``tactsense live --ros2``).

:class:`~tactsense.interop.ros2.publisher.Ros2Publisher` is one ROS 2 node on the wire
(names, types, QoS and discovery as ROS 2's RMWs speak them; ``docs/ros2.md``);
:mod:`~tactsense.interop.ros2.config` keeps its traffic on the loopback interface unless
told otherwise. Needs the ``ros2`` extra (the ``cyclonedds`` wheel).
"""

from tactsense.interop.ros2.config import LOOPBACK_XML, is_loopback_only, loopback_config
from tactsense.interop.ros2.publisher import TOPICS, Ros2Error, Ros2Publisher

__all__ = [
    "LOOPBACK_XML",
    "TOPICS",
    "Ros2Error",
    "Ros2Publisher",
    "is_loopback_only",
    "loopback_config",
]
