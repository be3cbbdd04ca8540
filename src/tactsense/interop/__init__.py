"""tactsense in the lab's other tools: URDF tactile descriptions (ROS tactile toolbox),
MCAP files (ROS 2, Foxglove), the Lab Streaming Layer and Rerun. Each optional
dependency is imported only when its function is called (``docs/interop.md``)."""
