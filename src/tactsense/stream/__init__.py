"""The live system: the wire protocol, a reader, the twin as an emulated device, and a
crash-safe recorder (``docs/protocol.md``).

This package imports the forward model and the estimation; neither imports it.

>>> from tactsense.stream import Emulator, StreamReader          # doctest: +SKIP
>>> rec = tactsense.simulate(finger, tactsense.probe_sweep(finger), rng=1)
>>> emulator = Emulator.from_recording(rec, speed=10)
>>> thread, port = emulator.start_tcp()
>>> with StreamReader(f"socket://127.0.0.1:{port}") as stream:
...     for frame in stream.frames(max_frames=50):
...         ...

Devices that speak other wire formats (text lines, marker-framed bytes, JustFloat;
``docs/devices.md``): ``open_source("text:/dev/ttyACM0", sensor=...)``.
"""

from tactsense.stream.emulator import Emulator, FaultLog, FaultRates
from tactsense.stream.framed import FormatReader
from tactsense.stream.live import LiveLocator
from tactsense.stream.protocol import ProtocolError, decode_packet, encode_frame
from tactsense.stream.reader import (
    LOSS_KINDS,
    LossCounters,
    StreamError,
    StreamFrame,
    StreamReader,
    open_port,
)
from tactsense.stream.recorder import record
from tactsense.stream.sources import FORMATS, open_source

__all__ = [
    "FORMATS",
    "LOSS_KINDS",
    "Emulator",
    "FaultLog",
    "FaultRates",
    "FormatReader",
    "LiveLocator",
    "LossCounters",
    "ProtocolError",
    "StreamError",
    "StreamFrame",
    "StreamReader",
    "decode_packet",
    "encode_frame",
    "open_port",
    "open_source",
    "record",
]

# ---- several devices of a robot skin (r7-capture) ----
from tactsense.stream.robot import RobotFrame, RobotSources

__all__ += ["RobotFrame", "RobotSources"]
# ---- /r7-capture ----
