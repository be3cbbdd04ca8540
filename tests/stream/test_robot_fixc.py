"""Plain sources given out of the skin's device order are mapped by each device's IDENT
(trial 36 item 7)."""

import numpy as np

from tactsense.stream.robot import RobotSources
from tactsense.stream.robot_emulator import device_emulators, start_device_emulators

from .test_robot_capture import _streams, small_skin


def test_plain_sources_out_of_order_are_mapped_by_ident():
    skin = small_skin()
    running = start_device_emulators(device_emulators(skin, _streams(skin), seed=7))
    try:
        urls = [running[d].url for d in ("board_c", "board_a", "board_b")]  # not skin order
        with RobotSources(skin, urls) as sources:
            frames = list(sources.frames(duration_s=0.5))
    finally:
        for device in running.values():
            device.stop()
    assert {d: s for d, s in sources.sources.items()} == {d: running[d].url for d in running}
    names = [p.name for p in skin.patches]
    seen = set()
    for frame in frames:
        for name, counts in frame.patches.items():
            # patch p's frames hold 1000 (p + 1) + t: its own, none of another patch
            p = names.index(name)
            assert skin.patch(name).device == frame.device
            assert np.all((counts >= 1000 * (p + 1)) & (counts < 1000 * (p + 2))), name
            seen.add(name)
    assert seen == set(names)
    assert all(s.frames > 0 for s in sources.status.values())
