"""A robot's skin on the Lab Streaming Layer: one outlet per patch
(tactsense.interop.robot_lsl), read by pylsl's own inlets in one process."""

from __future__ import annotations

import dataclasses
import time
import uuid

import numpy as np
import pytest

from tactsense.robot import RobotSkin, skin_preset
from tactsense.sensor import SensorSpec

pylsl = pytest.importorskip("pylsl")

from tactsense.interop.robot_lsl import patch_source_id, robot_lsl_outlets  # noqa: E402


def _unique(skin: RobotSkin) -> RobotSkin:
    """The skin under a name of its own: outlets of other tests never answer."""
    return dataclasses.replace(skin, name=f"lsl{uuid.uuid4().hex[:8]}")


def test_every_patch_on_its_own_outlet_read_by_pylsl():
    skin = _unique(skin_preset("icub_hand"))
    outlets = robot_lsl_outlets(skin)
    try:
        inlets = {}
        for patch in skin.patches:
            found = pylsl.resolve_byprop("source_id", patch_source_id(skin, patch.name), 1, 5)
            assert len(found) == 1, patch.name
            inlet = pylsl.StreamInlet(found[0])
            info = inlet.info(timeout=5)
            assert info.name() == f"{patch.name}-frames" and info.type() == "Tactile"
            assert info.channel_count() == patch.n_taxels
            assert info.nominal_srate() == patch.sensor.electronics.scan_rate_hz
            meta = info.desc().child("tactsense")
            robot = meta.child("robot")
            assert robot.child_value("skin") == skin.name
            assert robot.child_value("patch") == patch.name
            assert robot.child_value("link") == patch.link
            xyz = [float(v) for v in robot.child("origin").child_value("xyz_m").split()]
            np.testing.assert_allclose(xyz, patch.origin.xyz_m)
            sensor = SensorSpec.from_toml_string(meta.child_value("sensor_toml"))
            assert sensor.name == patch.name and sensor.shape == patch.sensor.shape
            inlet.open_stream(timeout=5)
            inlets[patch.name] = inlet
        time.sleep(0.3)
        rng = np.random.default_rng(1)
        sent = {p.name: rng.integers(0, 255, (5, p.n_taxels)) for p in skin.patches}
        now = pylsl.local_clock()
        for k in range(5):
            for name, frames in sent.items():
                outlets.push(name, frames[k], now + k * 0.02)
        for name, inlet in inlets.items():
            got, stamps = [], []
            deadline = time.monotonic() + 5
            while len(got) < 5 and time.monotonic() < deadline:
                samples, times = inlet.pull_chunk(timeout=0.5)
                got += samples
                stamps += times
            np.testing.assert_array_equal(np.array(got), sent[name])
            np.testing.assert_allclose(stamps, now + 0.02 * np.arange(5), atol=1e-6)
    finally:
        outlets.close()


def test_an_unknown_patch_is_refused():
    from tactsense.robot import RobotSkinError

    with pytest.raises(RobotSkinError, match="no patch"):
        robot_lsl_outlets(_unique(skin_preset("icub_hand")), patches=["palm"])
