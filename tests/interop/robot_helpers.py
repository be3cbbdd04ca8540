"""Robot recordings for the tests of tactsense.interop.robot_* (frames from
tactsense.simulate.frames_from_contacts, written with write_robot_recording)."""

from __future__ import annotations

import numpy as np

from tactsense.io.recording import Recording
from tactsense.io.robot_recording import RobotRecording, write_robot_recording
from tactsense.physics.transduction import sample_offsets
from tactsense.robot import skin_preset
from tactsense.simulate import ContactBatch, frames_from_contacts

PATCHES = ("index_distal_pad", "index_tip", "palm_0")
"""Three patches of hand4 on two links, at three rates (250, 50, 100 Hz)."""
PRESS = {"index_distal_pad": ((4.5, 10.5), 1.0)}
"""The pressed patch: a contact at (x, y) [mm] in its frame, normal force [N], over the
second half of the recording."""


def robot_recording(
    *, duration_s: float = 0.4, host0: float | None = None, rng: int = 0, skin="hand4",
    patches=PATCHES, press=PRESS,
) -> RobotRecording:  # fmt: skip
    """A short robot recording of ``patches``; with ``host0`` [Unix s] each stream also has
    host times (host0 + time + a jittery delay), device clock stamps and sequence numbers."""
    generator = np.random.default_rng(rng)
    skin = skin_preset(skin) if isinstance(skin, str) else skin
    streams = {}
    for name in patches:
        sensor = skin.patch(name).sensor
        rate = sensor.electronics.scan_rate_hz
        n = round(duration_s * rate)
        time_s = np.arange(n) / rate
        position = np.zeros((n, 1, 2))
        force = np.zeros((n, 1))
        if name in press:
            xy, newtons = press[name]
            position[:, 0] = xy
            force[time_s >= duration_s / 2, 0] = newtons
        frames = frames_from_contacts(
            sensor, ContactBatch(position_mm=position, normal_force_n=force), rng=generator
        )
        frames = np.rint(frames).clip(0, 65535).astype(np.uint16).reshape(n, *sensor.shape)
        extra = {}
        if host0 is not None:
            extra = dict(
                host_time_s=host0 + time_s + generator.uniform(1e-4, 2e-3, n),
                device_time_us=np.round(time_s * 1e6).astype(np.int64) + 12_345,
                sequence=(np.arange(n) + 65_530).astype(np.uint16),
                losses={"lost": 3, "gaps": 1},
            )
        streams[name] = Recording(
            frames=frames, time_s=time_s, sample_offset_s=sample_offsets(sensor),
            sensor=sensor, **extra,
        )  # fmt: skip
    return RobotRecording(skin=skin, streams=streams, description="a test hand")


def write(path, recording: RobotRecording):
    return write_robot_recording(path, recording)
