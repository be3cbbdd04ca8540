"""Robot recordings for the tests of tactsense.interop.robot_* (frames from
tactsense.simulate.frames_from_contacts, written with write_robot_recording)."""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from tactsense.io.recording import Recording
from tactsense.io.robot_recording import RobotRecording, write_robot_recording
from tactsense.physics.transduction import sample_offsets
from tactsense.robot import Joint, Patch, Pose, RobotSkin
from tactsense.sensor import Grid, preset
from tactsense.simulate import ContactBatch, frames_from_contacts

PATCHES = ("distal_pad", "tip", "palm_pad", "finger_skin")
"""The test skin's patches: a pad, a point set, a pad, a finger, on three links, at four
rates (250, 50, 100, 50 Hz)."""
PRESS = {"distal_pad": ((4.5, 10.5), 1.0)}
"""The pressed patch: a contact at (x, y) [mm] in its frame, normal force [N], over the
second half of the recording."""


def small_hand() -> RobotSkin:
    """A small hand of its own (not a preset, which may change): a palm, a finger of two
    links on revolute joints, a 4 x 8 pad and a 12-taxel dome on the distal link (turned
    and moved in it), a 4 x 4 pad on the palm and the paper's finger on the proximal link."""
    pad = dataclasses.replace(
        preset("pad16").replace(
            grid=Grid(rows=4, cols=8, row_pitch_mm=3.0, col_pitch_mm=3.0,
                      electrode_x_mm=2.4, electrode_y_mm=2.4),
            electronics__scan_rate_hz=250.0,
        ),
        name="phalanx_pad",
    )  # fmt: skip
    finger = preset("initial").replace(electronics__scan_rate_hz=50.0)
    return RobotSkin(
        name="testhand",
        base_link="palm",
        links=("palm", "finger_proximal", "finger_distal"),
        joints=(
            Joint(name="finger_joint1", type="revolute", parent="palm", child="finger_proximal",
                  origin=Pose((0.09, 0.0, 0.0)), axis=(0, 1, 0), lower=-0.2, upper=1.6),
            Joint(name="finger_joint2", type="revolute", parent="finger_proximal",
                  child="finger_distal", origin=Pose((0.05, 0.0, 0.0)), axis=(0, 1, 0),
                  lower=-0.2, upper=1.6),
        ),
        patches=(
            Patch(name="distal_pad", sensor=pad, link="finger_distal",
                  origin=Pose((0.004, -0.0105, -0.008), (math.pi, 0.0, 0.3)), device="board_a"),
            Patch(name="tip", sensor=preset("dome12"), link="finger_distal",
                  origin=Pose((0.03, 0.0, 0.0), (0.0, math.pi / 2, 0.0)), device="board_a"),
            Patch(name="palm_pad", sensor=preset("pad4"), link="palm",
                  origin=Pose((0.02, -0.01, -0.01), (math.pi, 0.0, 0.0)), device="board_palm"),
            Patch(name="finger_skin", sensor=finger, link="finger_proximal",
                  origin=Pose((0.01, 0.0, 0.0)), device="board_b"),
        ),
    )  # fmt: skip


def robot_recording(
    *, duration_s: float = 0.4, host0: float | None = None, rng: int = 0, skin=None,
    patches=PATCHES, press=PRESS,
) -> RobotRecording:  # fmt: skip
    """A short robot recording of ``patches``; with ``host0`` [Unix s] each stream also has
    host times (host0 + time + a jittery delay), device clock stamps and sequence numbers."""
    generator = np.random.default_rng(rng)
    skin = small_hand() if skin is None else skin
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
