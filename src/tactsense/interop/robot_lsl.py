"""A robot's skin on the Lab Streaming Layer: one frames outlet per patch.

:func:`robot_lsl_outlets` opens, for every patch of a skin, the frames outlet of
:mod:`tactsense.interop.lsl` (type ``Tactile``, one float32 channel per taxel, row-major,
each channel's XDF metadata with its ``location`` [mm] in the sensor's frame, the
sensor's TOML in ``desc/tactsense/sensor_toml``) under the patch's own name: stream name
``<patch>-frames``, the sensor described under the patch's name (so tactsense's
inlet, ``tactsense record lsl:NAME``, reads a patch like a device), ``source_id``
``tactsense:<skin>:<patch>:frames`` (stable across restarts, and apart from another
robot's patch of the same name), nominal rate the patch's
scan rate. ``desc/tactsense/robot`` says where the patch is: ``skin``, ``patch``,
``link``, ``device``, and its ``origin`` in the link (``xyz_m``, ``rpy_rad``, URDF's
roll-pitch-yaw), so a consumer places every channel on the robot.

Contacts are not streamed here (a patch's contacts outlet is :class:`~tactsense.interop.
lsl.LslOutlets`' for one array).
"""

from __future__ import annotations

import dataclasses
import time

import numpy as np

from tactsense._validation import TactsenseInputError
from tactsense.interop.lsl import _pylsl, frames_info
from tactsense.robot import RobotSkin, load_skin


def patch_stream_name(patch: str) -> str:
    return f"{patch}-frames"


def patch_source_id(skin: RobotSkin, patch: str) -> str:
    return f"tactsense:{skin.name}:{patch}:frames"


class RobotLslOutlets:
    """Frames of every patch of a skin, each on its own LSL outlet.

    Parameters
    ----------
    skin : RobotSkin, preset name or TOML path
    patches : sequence of str, optional
        The patches to open outlets for (default: all).
    """

    def __init__(self, skin, patches=None):
        pylsl = _pylsl()
        self.skin = load_skin(skin)
        names = [p.name for p in self.skin.patches] if patches is None else list(patches)
        for name in names:
            self.skin.patch(name)  # a clear error for a name that is not a patch
        self.outlets = {}
        for name in names:
            patch = self.skin.patch(name)
            sensor = dataclasses.replace(patch.sensor, name=name)
            rate = float(sensor.electronics.scan_rate_hz)
            info = frames_info(sensor, {"serial": f"{self.skin.name}:{name}"}, rate)
            robot = info.desc().child("tactsense").append_child("robot")
            for key, value in (
                ("skin", self.skin.name),
                ("patch", name),
                ("link", patch.link),
                ("device", patch.device),
            ):
                robot.append_child_value(key, value)
            origin = robot.append_child("origin")
            origin.append_child_value("xyz_m", " ".join(f"{v:.9g}" for v in patch.origin.xyz_m))
            origin.append_child_value("rpy_rad", " ".join(f"{v:.9g}" for v in patch.origin.rpy_rad))
            self.outlets[name] = pylsl.StreamOutlet(info)
        self._clock = pylsl.local_clock
        self._offset = pylsl.local_clock() - time.perf_counter()

    def push(self, patch: str, counts, stamp_s: float | None = None) -> None:
        """One frame of a patch; ``stamp_s`` on LSL's clock [s] (default: now)."""
        outlet = self.outlets.get(patch)
        if outlet is None:
            raise TactsenseInputError(
                f"no outlet for patch {patch!r}; outlets: {', '.join(self.outlets)}"
            )
        values = np.asarray(counts, dtype=np.float32).ravel()
        outlet.push_sample(values, self._clock() if stamp_s is None else float(stamp_s))

    def push_robot_frame(self, frame) -> None:
        """A frame of several patches (``patches``: name -> counts, ``arrival``: its
        arrival on :func:`time.perf_counter`'s clock [s] when it has one)."""
        arrival = getattr(frame, "arrival", None)
        stamp = None if arrival is None else arrival + self._offset
        for name, counts in frame.patches.items():
            self.push(name, counts, stamp)

    def close(self) -> None:
        self.outlets.clear()

    def __enter__(self) -> RobotLslOutlets:
        return self

    def __exit__(self, *exc) -> None:
        self.close()


def robot_lsl_outlets(skin, patches=None) -> RobotLslOutlets:
    """One LSL frames outlet per patch of ``skin`` (see the module's description)."""
    return RobotLslOutlets(skin, patches)
