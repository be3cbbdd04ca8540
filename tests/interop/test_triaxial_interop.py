"""Three-axis frames in other tools' files (issue 35 item 3), each read back with the other
tool's own reader: CSV (pyarrow's CSV reader), MCAP (mcap's reader and the mcap_ros2
decoder; rosbags' CDR from the upstream ``.msg`` texts), LeRobot v3 (pyarrow and JSON
against LeRobot's layout), LSL (pylsl's inlet), Rerun (rerun.chunk.RrdReader), ROS 2
live (rosbags' CDR of the publisher's bytes). The twin's mag4x4 press: frames
``(T, 4, 4, 3)`` in counts."""

from __future__ import annotations

import importlib.util
import json
import time
import uuid
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

import tactsense as ts
from tactsense.cli import app

runner = CliRunner()
ESTIMATOR = importlib.util.find_spec("tactsense.estimate.triaxial") is not None
"""Whether the three-axis contact estimator (issue 35 item 4) is installed: the exports
then carry contacts and their shear; else the frames alone."""


def _expected_names(rows: int, cols: int) -> list[str]:
    """Written here from the documented rule, not from tactsense's helper: row-major
    taxels, then x, y, z."""
    out = []
    for r in range(rows):
        for c in range(cols):
            out += [f"r{r}c{c}x", f"r{r}c{c}y", f"r{r}c{c}z"]
    return out


@pytest.fixture(scope="module")
def pressed(tmp_path_factory):
    """A simulated mag4x4 press: its path and recording."""
    where = tmp_path_factory.mktemp("triinterop")
    path = where / "press.h5"
    result = runner.invoke(
        app, ["simulate", "--sensor", "mag4x4", "--scenario", "press", "-o", str(path)]
    )
    assert result.exit_code == 0, result.output
    rec = ts.read_recording(path)
    assert rec.frames.shape[1:] == (4, 4, 3)
    # the press moves every component somewhere (else the checks below prove little)
    change = rec.frames.astype(float) - rec.frames[0].astype(float)
    assert all(np.abs(change[..., k]).max() > 5 for k in range(3))
    return path, rec


def _import(source, out, *extra):
    result = runner.invoke(app, ["import", str(source), "-o", str(out), *extra])
    assert result.exit_code == 0, result.output
    return ts.read_recording(out)


# ---- CSV --------------------------------------------------------------------------------


def test_csv_has_a_column_per_taxel_and_component(tmp_path, pressed):
    import pyarrow.csv as pacsv

    path, rec = pressed
    out = tmp_path / "press.csv"
    result = runner.invoke(app, ["export", str(path), "-o", str(out), "--quiet"])
    assert result.exit_code == 0, result.output
    table = pacsv.read_csv(out)
    assert table.column_names == ["time", *_expected_names(4, 4)]
    for name, (r, c, k) in (("r0c0x", (0, 0, 0)), ("r2c3y", (2, 3, 1)), ("r3c1z", (3, 1, 2))):
        np.testing.assert_array_equal(table.column(name).to_numpy(), rec.frames[:, r, c, k])
    result = runner.invoke(app, ["import", str(out), "--sensor", "mag4x4", "-o",
                                 str(tmp_path / "back.h5")])  # fmt: skip
    assert result.exit_code == 0, result.output
    assert f"{len(rec)} frames of mag4x4 (4 x 4 x 3 components)" in result.output
    back = ts.read_recording(tmp_path / "back.h5")
    np.testing.assert_array_equal(back.frames, rec.frames)
    assert back.frames.dtype == np.uint16


def test_csv_columns_of_another_order_are_refused(tmp_path, pressed):
    """Two components swapped in the header: the same number of columns, a wrong frame if
    taken in order; refused with the column named (exit 2, one line)."""
    path, _ = pressed
    out = tmp_path / "press.csv"
    assert runner.invoke(app, ["export", str(path), "-o", str(out), "--quiet"]).exit_code == 0
    lines = out.read_text().splitlines()
    lines[0] = lines[0].replace("r0c0x,r0c0y", "r0c0y,r0c0x")
    out.write_text("\n".join(lines) + "\n")
    result = runner.invoke(app, ["import", str(out), "--sensor", "mag4x4", "-o",
                                 str(tmp_path / "x.h5")])  # fmt: skip
    assert result.exit_code == 2
    assert "value column 1 is 'r0c0y'; sensor 'mag4x4' names it 'r0c0x'" in result.output
    assert not (tmp_path / "x.h5").exists()


def test_a_scalar_csv_of_the_same_grid_is_refused_with_the_counts(tmp_path):
    out = tmp_path / "scalar.csv"
    names = [f"r{r}c{c}" for r in range(4) for c in range(4)]
    rows = [",".join(["time", *names])] + [
        ",".join([str(k * 0.01)] + ["32768"] * 16) for k in range(3)
    ]
    out.write_text("\n".join(rows) + "\n")
    result = runner.invoke(app, ["import", str(out), "--sensor", "mag4x4", "-o",
                                 str(tmp_path / "x.h5")])  # fmt: skip
    assert result.exit_code == 2
    assert "16 value columns" in result.output and "= 48 values" in result.output


# ---- MCAP: TactileState, a channel per component ------------------------------------------


def _mcap_states(path):
    """(schema text, decoded messages, raw CDR) of the TactileState topic, with mcap's
    reader and the mcap_ros2 decoder (the definition the file carries)."""
    from mcap.reader import make_reader
    from mcap_ros2.decoder import DecoderFactory

    with open(path, "rb") as stream:
        reader = make_reader(stream, decoder_factories=[DecoderFactory()])
        decoded = [
            (schema, message, ros)
            for schema, _, message, ros in reader.iter_decoded_messages(topics=["/tactile_states"])
        ]
    return decoded[0][0].data.decode(), [d[2] for d in decoded], [d[1].data for d in decoded]


def test_mcap_tactile_state_has_a_channel_per_component(tmp_path, pressed):
    from .ros2_subscriber import TACTILE_MSGS, typestore

    path, rec = pressed
    out = tmp_path / "press.mcap"
    result = runner.invoke(app, ["export", str(path), "-o", str(out), "--quiet"])
    assert result.exit_code == 0, result.output
    assert ("contacts (one TactileContact" if ESTIMATOR else "no contacts") in result.output
    schema, states, raws = _mcap_states(out)
    assert schema.startswith("std_msgs/Header header\nsensor_msgs/ChannelFloat32[] sensors")
    assert len(states) == len(rec)
    store = typestore()  # rosbags, from the upstream .msg text
    assert "sensor_msgs/ChannelFloat32[] sensors" in TACTILE_MSGS["tactile_msgs/msg/TactileState"]
    for k in (0, len(rec) // 2, len(rec) - 1):
        names = [ch.name for ch in states[k].sensors]
        assert names == ["mag4x4/x", "mag4x4/y", "mag4x4/z"]
        for c, channel in enumerate(states[k].sensors):
            want = rec.frames[k, :, :, c].ravel().astype(np.float32)  # row-major taxels
            np.testing.assert_array_equal(np.asarray(channel.values, np.float32), want)
        again = store.deserialize_cdr(raws[k], "tactile_msgs/msg/TactileState")
        assert [ch.name for ch in again.sensors] == names
        assert bytes(store.serialize_cdr(again, "tactile_msgs/msg/TactileState")) == raws[k]
    back = _import(out, tmp_path / "back.h5", "--sensor", "mag4x4")
    np.testing.assert_array_equal(back.frames, rec.frames)
    # and without --sensor: the channels' sensor name is the preset's
    again = _import(out, tmp_path / "again.h5")
    assert again.sensor == rec.sensor


def test_mcap_fast_writer_makes_the_encoder_bytes(tmp_path, pressed):
    """The template's bytes (fast) against mcap_ros2's encoder of every message (slow)."""
    from tactsense.interop.mcap import export_mcap

    path, _ = pressed
    export_mcap(path, tmp_path / "fast.mcap", fast=True)
    export_mcap(path, tmp_path / "slow.mcap", fast=False)
    assert _mcap_states(tmp_path / "fast.mcap")[2] == _mcap_states(tmp_path / "slow.mcap")[2]


def _write_single_channel(path, frames, values_per_frame=None):
    """A driver's TactileState: one channel 'mag4x4' of the taxels' vectors interleaved."""
    from mcap_ros2.writer import Writer

    from tactsense.interop.ros import TACTILE_STATE, TACTILE_STATE_MSGDEF

    with open(path, "wb") as stream:
        writer = Writer(stream)
        schema = writer.register_msgdef(TACTILE_STATE, TACTILE_STATE_MSGDEF)
        for k, frame in enumerate(frames):
            values = frame.astype(np.float32).ravel().tolist()[:values_per_frame]
            ns = 1_000_000_000 + k * 10_000_000
            message = {
                "header": {"stamp": {"sec": ns // 10**9, "nanosec": ns % 10**9},
                           "frame_id": "pad"},
                "sensors": [{"name": "mag4x4", "values": values}],
            }  # fmt: skip
            writer.write_message("/skin", schema, message, log_time=ns, publish_time=ns)
        writer.finish()


def test_mcap_of_one_interleaved_channel_is_read(tmp_path, pressed):
    _, rec = pressed
    path = tmp_path / "driver.mcap"
    _write_single_channel(path, rec.frames[:20])
    back = _import(path, tmp_path / "back.h5", "--sensor", "mag4x4")
    np.testing.assert_array_equal(back.frames, rec.frames[:20])


def test_mcap_channel_of_a_wrong_length_is_a_one_line_error(tmp_path, pressed):
    _, rec = pressed
    path = tmp_path / "short.mcap"
    _write_single_channel(path, rec.frames[:3], values_per_frame=16)
    result = runner.invoke(app, ["import", str(path), "--sensor", "mag4x4", "-o",
                                 str(tmp_path / "x.h5")])  # fmt: skip
    assert result.exit_code == 2
    assert "channel 'mag4x4' has 16 values" in result.output
    assert "x 3 components (x, y, z) = 48 values" in result.output


def test_rosbag2_bag_of_a_channel_per_component_imports(tmp_path, pressed):
    """A bag written by rosbags (sqlite3, as ``ros2 bag record`` writes it), the type from
    the upstream .msg text, an unrelated sensor beside: the three channels are found by
    their names, whatever their order in the message."""
    from rosbags.rosbag2 import StoragePlugin, Writer

    from .ros2_subscriber import typestore

    _, rec = pressed
    store = typestore()
    kind = "tactile_msgs/msg/TactileState"
    State, Channel = store.types[kind], store.types["sensor_msgs/msg/ChannelFloat32"]
    Header, Time = store.types["std_msgs/msg/Header"], store.types["builtin_interfaces/msg/Time"]
    bag = tmp_path / "bag"
    with Writer(bag, version=8, storage_plugin=StoragePlugin.SQLITE3) as writer:
        conn = writer.add_connection("/skin/tactile_states", kind, typestore=store)
        for k, counts in enumerate(rec.frames):
            ns = 5 * 10**9 + round(rec.time_s[k] * 1e9)
            channels = [Channel(f"mag4x4/{p}", counts[..., c].astype(np.float32).ravel())
                        for c, p in enumerate("xyz")]  # fmt: skip
            channels = [Channel("glove", np.zeros(5, np.float32)), *channels[::-1]]
            message = State(Header(Time(ns // 10**9, ns % 10**9), "pad"), channels)
            writer.write(conn, ns, store.serialize_cdr(message, kind))
    back = _import(bag, tmp_path / "back.h5")  # the sensor from the channels' name
    np.testing.assert_array_equal(back.frames, rec.frames)
    assert back.sensor == rec.sensor


# ---- LeRobot ----------------------------------------------------------------------------


def test_lerobot_feature_is_rows_cols_3(tmp_path, pressed):
    import pyarrow.parquet as pq

    path, rec = pressed
    out = tmp_path / "dataset"
    result = runner.invoke(app, ["export", str(path), "--format", "lerobot", "-o", str(out)])
    assert result.exit_code == 0, result.output
    info = json.loads((out / "meta/info.json").read_text())
    feature = info["features"]["observation.tactile"]
    assert feature == {"dtype": "float32", "shape": [4, 4, 3],
                       "names": ["row", "col", "component"]}  # fmt: skip
    # without the three-axis estimator no made-up state; with it, the slots and their shear
    assert ("contact0.shear_x_n" in info["features"]["observation.state"]["names"]
            if ESTIMATOR else "observation.state" not in info["features"])  # fmt: skip
    table = pq.read_table(out / "data/chunk-000/file-000.parquet")
    hf = json.loads(table.schema.metadata[b"huggingface"])["info"]["features"]
    assert hf["observation.tactile"] == {"shape": [4, 4, 3], "dtype": "float32",
                                         "_type": "Array3D"}  # fmt: skip
    assert set(table.column_names) == set(info["features"])
    tactile = np.asarray(table.column("observation.tactile").to_pylist())
    np.testing.assert_array_equal(tactile, rec.frames.astype(np.float32))
    # LeRobot's statistics take every axis but the last as samples: per component
    stats = json.loads((out / "meta/stats.json").read_text())["observation.tactile"]
    flat = rec.frames.reshape(-1, 3).astype(np.float64)
    np.testing.assert_allclose(stats["mean"], flat.mean(0), rtol=1e-12)
    np.testing.assert_allclose(stats["max"], flat.max(0))
    own = json.loads((out / "meta/tactsense.json").read_text())
    assert own["components"] == ["x", "y", "z"]
    back = _import(out, tmp_path / "back.h5")
    np.testing.assert_array_equal(back.frames, rec.frames)
    assert back.sensor == rec.sensor


def test_lerobot_dataset_of_the_wrong_shape_is_refused(tmp_path, pressed):
    """A three-axis dataset imported as the 16 x 16 pad: both shapes named."""
    path, _ = pressed
    out = tmp_path / "dataset"
    assert runner.invoke(app, ["export", str(path), "--format", "lerobot", "-o",
                               str(out)]).exit_code == 0  # fmt: skip
    result = runner.invoke(app, ["import", str(out), "--sensor", "pad16", "-o",
                                 str(tmp_path / "x.h5")])  # fmt: skip
    assert result.exit_code == 2
    assert "[4, 4, 3]" in result.output and "[16, 16]" in result.output


# ---- LSL --------------------------------------------------------------------------------


def _stream_frames(rec):
    from tactsense.stream.reader import StreamFrame

    for k, counts in enumerate(rec.frames):
        yield StreamFrame(k, k, float(rec.time_s[k]), time.time(), time.perf_counter(), counts)


def test_lsl_has_a_channel_per_taxel_and_component(pressed):
    import dataclasses

    from tactsense.interop.lsl import LslOutlets, _pylsl

    pylsl = _pylsl()
    _, rec = pressed
    sensor = dataclasses.replace(rec.sensor, name=f"lsltri{uuid.uuid4().hex[:8]}")
    serial = f"tri-{uuid.uuid4().hex[:6]}"
    outlets = LslOutlets(sensor, {"serial": serial}, 100.0)
    try:
        (found,) = pylsl.resolve_byprop("source_id", f"tactsense:{serial}:frames", 1, 5)
        inlet = pylsl.StreamInlet(found)
        info = inlet.info(timeout=5)
        assert info.channel_count() == 48
        channel = info.desc().child("channels").child("channel")
        labels, components = [], []
        while not channel.empty():
            labels.append(channel.child_value("label"))
            components.append(channel.child_value("component"))
            channel = channel.next_sibling()
        assert labels == _expected_names(4, 4)
        assert components == ["x", "y", "z"] * 16
        inlet.open_stream(timeout=5)
        time.sleep(0.3)
        for frame in _stream_frames(rec):
            outlets.push(frame, None)
        got, deadline = [], time.time() + 10
        while len(got) < len(rec) and time.time() < deadline:
            samples, _ = inlet.pull_chunk(timeout=0.2)
            got.extend(samples)
        assert len(got) == len(rec)
        np.testing.assert_array_equal(np.asarray(got).reshape(-1, 4, 4, 3), rec.frames)
    finally:
        outlets.close()


def test_xdf_of_the_three_axis_outlet_imports(tmp_path, pressed):
    """An XDF file (the format's own chunks, written by test_import's minimal writer) whose
    stream header is the outlet's XML, read with pyxdf: the frames and the sensor back."""
    from tactsense.interop.lsl import frames_info

    from .test_import import write_xdf

    _, rec = pressed
    header = frames_info(rec.sensor, {"serial": "tri"}, 100.0).as_xml()
    stamps = 7000.0 + rec.time_s
    samples = rec.frames.reshape(len(rec), -1).astype(np.float32)
    path = tmp_path / "lab.xdf"
    write_xdf(path, [(3, header, samples, stamps)])
    back = _import(path, tmp_path / "back.h5")
    np.testing.assert_array_equal(back.frames, rec.frames)
    assert back.sensor == rec.sensor
    result = runner.invoke(app, ["import", str(path), "--sensor", "pad4", "-o",
                                 str(tmp_path / "x.h5")])  # fmt: skip
    assert result.exit_code == 2 and "48 channels" in result.output


# ---- Rerun ------------------------------------------------------------------------------


def _rerun_columns(path):
    from rerun.chunk import RrdReader

    found = {}
    for chunk in RrdReader(str(path)).stream().to_chunks():
        batch = chunk.to_record_batch()
        if "time" not in batch.schema.names:
            continue
        times = [t.total_seconds() for t in batch.column("time").to_pylist()]
        for name in batch.schema.names:
            if ":" in name:
                rows = zip(times, batch.column(name).to_pylist(), strict=True)
                found.setdefault((str(chunk.entity_path), name), []).extend(rows)
    return {key: sorted(rows, key=lambda row: row[0]) for key, rows in found.items()}


def test_rerun_tensor_map_and_arrows(tmp_path, pressed):
    path, rec = pressed
    out = tmp_path / "press.rrd"
    result = runner.invoke(app, ["export", str(path), "-o", str(out), "--quiet"])
    assert result.exit_code == 0, result.output
    columns = _rerun_columns(out)
    baseline = np.median(rec.frames[:5].astype(float), axis=0)
    change = rec.frames.astype(float) - baseline
    tensors = columns[("/triaxial/values", "Tensor:data")]
    assert len(tensors) == len(rec)
    k = int(np.argmax(np.abs(change[..., :2]).sum(axis=(1, 2, 3))))  # the most sheared
    tensor = tensors[k][1][0]
    assert tensor["shape"] == [4, 4, 3]
    np.testing.assert_array_equal(
        np.asarray(tensor["buffer"], np.float32).reshape(4, 4, 3), change[k].astype(np.float32)
    )
    images = columns[("/triaxial/normal", "Image:buffer")]
    assert len(images) == len(rec)
    # the arrows on the map: from each pixel's centre, x (along rows) drawn down the
    # image, y (along columns) across; the largest of the file one pixel long
    largest = np.linalg.norm(change[..., :2], axis=-1).max()
    origins = np.asarray(columns[("/triaxial/normal/shear", "Arrows2D:origins")][k][1])
    vectors = np.asarray(columns[("/triaxial/normal/shear", "Arrows2D:vectors")][k][1])
    np.testing.assert_allclose(origins[5], [1 + 0.5, 1 + 0.5])  # taxel (1, 1)
    want = np.stack([change[k, ..., 1], change[k, ..., 0]], axis=-1).reshape(-1, 2) / largest
    np.testing.assert_allclose(vectors, want, rtol=1e-6, atol=1e-6)
    assert np.linalg.norm(vectors, axis=1).max() <= 1 + 1e-6
    arrows = np.asarray(columns[("/triaxial/shear", "Arrows3D:vectors")][k][1])
    assert np.allclose(arrows[:, 2], 0) and np.allclose(
        arrows[:, :2] / np.linalg.norm(arrows[:, :2], axis=1, keepdims=True).clip(1e-12),
        want[:, ::-1] / np.linalg.norm(want, axis=1, keepdims=True).clip(1e-12),
        atol=1e-6,
    )  # the same directions on the pad: (x, y)


# ---- ROS 2 live -------------------------------------------------------------------------


@pytest.fixture
def loopback_dds(tmp_path, monkeypatch):
    pytest.importorskip("cyclonedds")
    import random

    from tactsense.interop.ros2 import loopback_config

    path = loopback_config(tmp_path)
    monkeypatch.setenv("CYCLONEDDS_URI", f"file://{path}")
    monkeypatch.setenv("ROS_DOMAIN_ID", str(random.randint(100, 230)))
    monkeypatch.delenv("ROS_DISTRO", raising=False)


def test_ros2_state_and_image_of_three_components(loopback_dds, pressed):
    """The publisher's bytes (fast templates) are the serialiser's (slow), and rosbags,
    from the upstream .msg text, reads a channel per component and a 32FC3 image."""
    from tactsense.interop.ros2 import Ros2Publisher

    from .ros2_subscriber import typestore

    _, rec = pressed
    store = typestore()
    publisher = Ros2Publisher(rec.sensor, node_name="tri", frame_id="pad")
    try:
        for frame in list(_stream_frames(rec))[::17]:
            made = publisher.encode(frame, None)
            publisher._fast = False  # the serialiser's messages (the straightforward path)
            reference = publisher.encode(frame, None)
            publisher._fast = True
            for topic in ("tactile_states", "tactile_image"):
                cdr = bytes(reference[topic].serialize())
                assert made[topic][: len(cdr)] == cdr, topic
            state = store.deserialize_cdr(made["tactile_states"], "tactile_msgs/msg/TactileState")
            assert [ch.name for ch in state.sensors] == ["mag4x4/x", "mag4x4/y", "mag4x4/z"]
            for c, channel in enumerate(state.sensors):
                want = frame.counts[..., c].ravel().astype(np.float32)
                np.testing.assert_array_equal(channel.values, want)
            image = store.deserialize_cdr(made["tactile_image"], "sensor_msgs/msg/Image")
            assert (image.height, image.width, image.encoding, image.step) == (4, 4, "32FC3", 48)
            pixels = np.frombuffer(image.data.tobytes(), "<f4").reshape(4, 4, 3)
            np.testing.assert_array_equal(pixels, frame.counts.astype(np.float32))
    finally:
        publisher.close()


def test_ros2_three_axis_frames_reach_another_process(loopback_dds, tmp_path, pressed):
    """Published over DDS (loopback only) and received by the independent subscriber
    (tests/interop/ros2_subscriber.py, types from the upstream .msg texts): every frame,
    a channel per component, decoded with rosbags."""
    import os
    import pickle
    import subprocess
    import sys

    from tactsense.interop.ros2 import Ros2Publisher

    from .ros2_subscriber import typestore

    _, rec = pressed
    n = 30
    namespace = "/test_triaxial/pad"
    out = tmp_path / "received.pickle"
    process = subprocess.Popen(
        [sys.executable, str(Path(__file__).with_name("ros2_subscriber.py")), str(out),
         "--domain", os.environ["ROS_DOMAIN_ID"], "--namespace", namespace, "--count", str(n),
         "--seconds", "60"],
        stdout=subprocess.PIPE, text=True, env=dict(os.environ),
    )  # fmt: skip
    assert process.stdout.readline().strip() == "ready"
    publisher = Ros2Publisher(rec.sensor, namespace=namespace, frame_id="pad")
    try:
        assert publisher.wait_for_subscribers(30.0) >= 1
        for frame in list(_stream_frames(rec))[:n]:
            publisher.publish(frame, None)
            time.sleep(0.005)
    finally:
        publisher.close()
    assert process.wait(90) == 0
    received = pickle.loads(out.read_bytes())["received"]["tactile_states"]
    assert len(received) == n
    store = typestore()
    for k, (*_, raw) in enumerate(received):
        state = store.deserialize_cdr(raw, "tactile_msgs/msg/TactileState")
        assert [ch.name for ch in state.sensors] == ["mag4x4/x", "mag4x4/y", "mag4x4/z"]
        got = np.stack([np.asarray(ch.values) for ch in state.sensors], axis=-1)
        np.testing.assert_array_equal(got.reshape(4, 4, 3), rec.frames[k].astype(np.float32))


def test_lerobot_shear_slots_follow_the_contacts_rank():
    """Each contact's tangential force goes to its rank's slot, 0 in an empty slot; a
    table without the shear columns is refused (no made-up zeros); a kind without shear
    gets no columns."""
    from types import SimpleNamespace

    from tactsense._validation import TactsenseInputError
    from tactsense.interop.components import shear_state, shear_state_names

    table = SimpleNamespace(
        frame=np.array([10, 10, 12]), contact=np.array([0, 1, 0]),
        shear_x_n=np.array([0.5, -0.25, np.nan]), shear_y_n=np.array([0.125, 1.0, 2.0]),
    )  # fmt: skip
    state = shear_state(table, 10, 3, 2)
    names = shear_state_names(2)
    assert names == ("contact0.shear_x_n", "contact0.shear_y_n",
                     "contact1.shear_x_n", "contact1.shear_y_n")  # fmt: skip
    want = np.array([[0.5, 0.125, -0.25, 1.0], [0, 0, 0, 0], [0.0, 2.0, 0, 0]], np.float32)
    np.testing.assert_array_equal(state, want)
    with pytest.raises(TactsenseInputError, match="no shear_x_n column"):
        shear_state(SimpleNamespace(frame=table.frame, contact=table.contact), 10, 3, 2)
    assert shear_state(SimpleNamespace(), 0, 3, 0).shape == (3, 0)


# ---- with the three-axis estimator: contacts with their tangential force --------------


@pytest.fixture(scope="module")
def sheared(tmp_path_factory):
    """A press at taxel (1, 2), then a tangential force along +x at 0.3 times the normal
    force, held (below mu = 1: no slip)."""
    pytest.importorskip("tactsense.estimate.triaxial")
    from tactsense.physics.indenters import SphereProbe
    from tactsense.simulate.scenario import Scenario, Step

    spec = ts.preset("mag4x4")
    x, y, p = spec.x_mm[1], spec.y_mm[2], 0.49
    period = spec.scan_period_s

    def probe(q):
        return SphereProbe(x, y, p, radius_mm=1.6, friction=1.0, shear_x_n=q)

    steps = (
        Step((), 10 * period, "untouched"),
        Step((probe(0.0),), 10 * period, "pressed"),
        Step((probe(0.3 * p),), 20 * period, "sheared"),
        Step((), 5 * period, "lifted"),
    )
    rec = ts.simulate(spec, Scenario(steps, "shear-x", "press, shear along +x", {}), rng=3)
    path = tmp_path_factory.mktemp("sheared") / "sheared.h5"
    ts.write_recording(path, rec)
    return path, rec


def test_mcap_contacts_carry_the_estimated_shear(tmp_path, sheared):
    """Each TactileContact's wrench is the estimate's, as 'locate' writes it: force =
    (shear_x_n, shear_y_n, -force_n) on the pad (normal +z); the sheared frames push +x."""
    import pyarrow.parquet as pq
    from mcap.reader import make_reader
    from mcap_ros2.decoder import DecoderFactory

    path, _ = sheared
    out, located = tmp_path / "sheared.mcap", tmp_path / "located.parquet"
    result = runner.invoke(app, ["export", str(path), "-o", str(out), "--quiet"])
    assert result.exit_code == 0, result.output
    result = runner.invoke(app, ["locate", str(path), "-o", str(located)])
    assert result.exit_code == 0, result.output
    table = pq.read_table(located).to_pylist()
    with open(out, "rb") as stream:
        reader = make_reader(stream, decoder_factories=[DecoderFactory()])
        contacts = [ros for *_, ros in reader.iter_decoded_messages(topics=["/tactile_contacts"])]
    rows = [r for r in table if np.isfinite(r["force_n"])]
    assert len(contacts) == len(rows) > 10
    for got, want in zip(contacts, rows, strict=True):
        f = got.wrench.force
        assert got.name == f"mag4x4/{want['id']}"
        assert [f.x, f.y, f.z] == [want["shear_x_n"], want["shear_y_n"], -want["force_n"]]
    held = [r["shear_x_n"] for r in rows if r["frame"] >= 25]
    assert held and np.median(held) > 0.05  # +x shear, seen as +x


def test_lerobot_state_carries_the_estimated_shear(tmp_path, sheared):
    import pyarrow.parquet as pq

    path, _ = sheared
    out = tmp_path / "dataset"
    result = runner.invoke(app, ["export", str(path), "--format", "lerobot", "-o", str(out)])
    assert result.exit_code == 0, result.output
    names = json.loads((out / "meta/info.json").read_text())["features"]["observation.state"][
        "names"
    ]
    state = np.asarray(
        pq.read_table(out / "data/chunk-000/file-000.parquet").column("observation.state")
        .to_pylist()
    )  # fmt: skip
    present = state[:, names.index("contact0.present")] == 1
    shear_x = state[:, names.index("contact0.shear_x_n")]
    assert present.sum() > 10 and np.median(shear_x[present][-10:]) > 0.05
    assert np.all(shear_x[~present] == 0)


def test_lsl_contact_slots_carry_the_shear(pressed):
    """A shear-sensing sensor's contacts outlet: each slot's tangential force after its
    force (c<k>_shear_x_n, c<k>_shear_y_n [N]), read by pylsl's inlet; NaN in empty slots."""
    import dataclasses

    from tactsense.interop.lsl import SLOTS, LslOutlets, _pylsl

    pylsl = _pylsl()
    _, rec = pressed
    sensor = dataclasses.replace(rec.sensor, name=f"lslshear{uuid.uuid4().hex[:8]}")
    serial = f"shear-{uuid.uuid4().hex[:6]}"
    outlets = LslOutlets(sensor, {"serial": serial}, 100.0)
    try:
        (found,) = pylsl.resolve_byprop("source_id", f"tactsense:{serial}:contacts", 1, 5)
        inlet = pylsl.StreamInlet(found)
        channel = inlet.info(timeout=5).desc().child("channels").child("channel")
        labels, units = [], []
        while not channel.empty():
            labels.append(channel.child_value("label"))
            units.append(channel.child_value("unit"))
            channel = channel.next_sibling()
        assert len(labels) == 4 + 7 * SLOTS
        assert labels[4:11] == ["c0_id", "c0_x_mm", "c0_y_mm", "c0_z_mm", "c0_force_n",
                                "c0_shear_x_n", "c0_shear_y_n"]  # fmt: skip
        assert units[9:11] == ["N", "N"]
        inlet.open_stream(timeout=5)
        time.sleep(0.3)
        contact = {"id": 7, "x_mm": 4.7, "y_mm": 9.4, "z_mm": 0.0, "force_n": 0.5,
                   "shear_x_n": 0.125, "shear_y_n": -0.0625}  # fmt: skip
        estimate = {"n_contacts": 1, "force_n": 0.5, "flags": 0, "latency_ms": 1.0,
                    "contacts": [contact]}  # fmt: skip
        frame = next(_stream_frames(rec))
        got, deadline = [], time.time() + 10
        outlets.push(frame, estimate)
        while not got and time.time() < deadline:
            got, _ = inlet.pull_chunk(timeout=0.2)
        assert got[0][4:11] == [7, 4.7, 9.4, 0.0, 0.5, 0.125, -0.0625]
        assert np.isnan(got[0][11:]).all()
    finally:
        outlets.close()


def test_record_from_a_three_axis_lsl_outlet(tmp_path, pressed):
    """``record lsl:NAME``: the sensor from the outlet's own description, the frames
    (T, 4, 4, 3) as pushed."""
    import dataclasses
    import threading

    from tactsense.interop.lsl import LslOutlets

    _, rec = pressed
    sensor = dataclasses.replace(rec.sensor, name=f"lslrec{uuid.uuid4().hex[:8]}")
    outlets = LslOutlets(sensor, {"serial": uuid.uuid4().hex[:6]}, 100.0)
    stop = threading.Event()

    def push():
        time.sleep(1.0)  # the recorder resolves and opens the inlet first
        for frame in _stream_frames(rec):
            if stop.is_set():
                return
            outlets.push(frame, None)
            time.sleep(1 / 200)

    pusher = threading.Thread(target=push, daemon=True)
    pusher.start()
    out = tmp_path / "from_lsl.h5"
    try:
        result = runner.invoke(
            app, ["record", f"lsl:{sensor.name}-frames", "--frames", str(len(rec)), "--out",
                  str(out), "--duration", "30"],
        )  # fmt: skip
    finally:
        stop.set()
        pusher.join(5)
        outlets.close()
    assert result.exit_code == 0, result.output
    got = ts.read_recording(out)
    assert got.sensor == sensor
    np.testing.assert_array_equal(got.frames, rec.frames)


@pytest.mark.parametrize("form", ["mcap", "lerobot", "rrd"])
def test_frames_alone_refuse_the_options_of_contacts(tmp_path, pressed, monkeypatch, form):
    """Without a contact estimator (none installed: monkeypatched away where it is) the
    export writes the frames alone and refuses --threshold rather than ignore it."""
    from tactsense._validation import TactsenseInputError
    from tactsense.interop import components
    from tactsense.interop.lerobot import export_lerobot
    from tactsense.interop.mcap import export_mcap
    from tactsense.interop.rerun import export_rerun

    monkeypatch.setattr(components, "component_contacts", lambda *a, **k: None)
    path, _ = pressed
    run = {"mcap": export_mcap, "lerobot": export_lerobot, "rrd": export_rerun}[form]
    with pytest.raises(TactsenseInputError, match="apply to contacts; no contact estimator"):
        run(path, tmp_path / f"out.{form}", threshold=0.01)
    assert not (tmp_path / f"out.{form}").is_dir()
    summary = run(path, tmp_path / f"frames.{form}")
    assert summary["contacts"] is None


def test_ros2_live_contacts_carry_the_live_shear(loopback_dds, sheared):
    """The live three-axis estimate's contacts, published: each TactileContact's wrench
    force is (shear_x_n, shear_y_n, -force_n) of the estimate (rosbags decodes it)."""
    from tactsense.interop.ros2 import Ros2Publisher

    from .ros2_subscriber import typestore

    _, rec = sheared
    store = typestore()
    estimator = pytest.importorskip("tactsense.estimate.triaxial")
    live = estimator.LiveShearContacts(rec.sensor, baseline_frames=5)
    publisher = Ros2Publisher(rec.sensor, node_name="trishear", frame_id="pad")
    compared = 0
    try:
        for frame in _stream_frames(rec):
            estimate = live(frame)
            if estimate is None:
                continue
            raw = publisher.encode(frame, estimate)["contact_states"]
            message = store.deserialize_cdr(raw, "tactile_msgs/msg/TactileContacts")
            kept = [
                c
                for c in estimate["contacts"]
                if all(np.isfinite(c[k]) for k in ("x_mm", "y_mm", "z_mm", "force_n"))
            ]
            assert len(message.contacts) == len(kept)
            for got, want in zip(message.contacts, kept, strict=True):
                f = got.wrench.force
                assert [f.x, f.y, f.z] == [want["shear_x_n"], want["shear_y_n"],
                                           -want["force_n"]]  # fmt: skip
                compared += 1
    finally:
        publisher.close()
    assert compared > 10


def test_rerun_contacts_and_their_shear(tmp_path, sheared):
    """With the three-axis estimator: each frame's contacts in the Rerun file are
    'locate''s (positions [mm], ids), each with an arrow of its tangential force at
    SHEAR_MM_PER_N (rerun.chunk.RrdReader)."""
    import pyarrow.parquet as pq

    from tactsense.interop.rerun_components import SHEAR_MM_PER_N

    path, rec = sheared
    out, located = tmp_path / "sheared.rrd", tmp_path / "located.parquet"
    result = runner.invoke(app, ["export", str(path), "-o", str(out), "--quiet"])
    assert result.exit_code == 0, result.output
    assert runner.invoke(app, ["locate", str(path), "-o", str(located)]).exit_code == 0
    rows = [r for r in pq.read_table(located).to_pylist() if np.isfinite(r["x_mm"])]
    columns = _rerun_columns(out)
    points = columns[("/triaxial/contacts", "Points3D:positions")]
    arrows = columns[("/triaxial/contact_shear", "Arrows3D:vectors")]
    time_of = {round(t, 9): k for k, t in enumerate(rec.time_s)}
    by_frame = {}
    for r in rows:
        by_frame.setdefault(r["frame"], []).append(r)
    got = [(time_of[round(t, 9)], v) for t, v in points if v]
    assert len(got) == len(by_frame) > 10
    for (k, positions), (_, vectors) in zip(got, [a for a in arrows if a[1]], strict=True):
        want = sorted(by_frame[k], key=lambda r: r["contact"])
        np.testing.assert_allclose(
            positions, [[r["x_mm"], r["y_mm"], r["z_mm"]] for r in want], rtol=1e-6, atol=1e-5
        )
        np.testing.assert_allclose(
            vectors, [[r["shear_x_n"] * SHEAR_MM_PER_N, r["shear_y_n"] * SHEAR_MM_PER_N, 0]
                      for r in want], rtol=1e-5, atol=1e-5,
        )  # fmt: skip
