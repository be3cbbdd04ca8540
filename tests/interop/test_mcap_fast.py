"""MCAP export from CDR templates (issue 21, item 7): the same bytes as encoding every
message with mcap-ros2-support's encoder, many times faster (benchmarks/bench_mcap.py)."""

import numpy as np
import pytest

import tactsense as ts

pytest.importorskip("mcap_ros2")

from tactsense.interop.mcap import McapTactileWriter, export_mcap


@pytest.mark.parametrize("frame_id", ["finger", "a_longer_link_name"])
def test_export_is_bit_identical_to_the_encoder(tmp_path, frame_id):
    """Frames and contacts, two frame_id lengths (the padding before the numbers
    changes with them): byte for byte the file the per-message encoder writes."""
    spec = ts.fearing1990_initial()
    rec = tmp_path / "rec.h5"
    ts.write_recording(rec, ts.simulate(spec, ts.probe_sweep(spec, lift_s=0.5), rng=2))
    counts = {}
    for fast in (True, False):
        out = tmp_path / f"{fast}.mcap"
        counts[fast] = export_mcap(rec, out, frame_id=frame_id, fast=fast)
    assert counts[True] == counts[False] and counts[True]["contacts"] > 50
    assert (tmp_path / "True.mcap").read_bytes() == (tmp_path / "False.mcap").read_bytes()


def test_float_counts_and_odd_sensor_names(tmp_path):
    """Fractional counts (a float recording) and a sensor name of each length mod 4."""
    rng = np.random.default_rng(0)
    for name in ("a", "ab", "abc", "abcd"):
        spec = ts.fearing1990_initial().replace(name=name)
        frames = rng.uniform(0, 4095, (20, *spec.shape))
        times = np.arange(20) * 0.1428571 + 1234.5
        where = rng.uniform(0, 20, 20), rng.uniform(-180, 180, 20), rng.uniform(0, 2, 20)
        files = []
        for fast in (True, False):
            path = tmp_path / f"{name}{fast}.mcap"
            with open(path, "wb") as stream:
                writer = McapTactileWriter(stream, spec, fast=fast)
                writer.frames_of(frames, times, np.arange(20) + 7)
                writer.contacts_of(times, *where, np.arange(20) % 3 > 0)
                writer.finish()
            files.append(path.read_bytes())
        assert files[0] == files[1], name


@pytest.mark.parametrize("sensor", ["pad16", "dome12"])
def test_pad_and_point_set_export_is_bit_identical_to_the_encoder(tmp_path, sensor):
    """Several contacts a frame, named ``<sensor>/<id>`` (names of several lengths), and a
    ``TactileContacts`` list per frame: byte for byte the file the encoder writes."""
    from tactsense.flat_scenarios import two_probes

    spec = ts.preset(sensor)
    rec = tmp_path / "rec.h5"
    ts.write_recording(rec, ts.simulate(spec, two_probes(spec), rng=2))
    counts = {}
    for fast in (True, False):
        counts[fast] = export_mcap(rec, tmp_path / f"{fast}.mcap", fast=fast)
    assert counts[True] == counts[False] and counts[True]["contacts"] > counts[True]["frames"] / 2
    assert (tmp_path / "True.mcap").read_bytes() == (tmp_path / "False.mcap").read_bytes()
