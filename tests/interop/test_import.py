"""tactsense import: MCAP, rosbag2, XDF, CSV and LeRobot sources into recordings, each
compared frame by frame and time by time with the recording they were made from.

Tolerances: frames are counts (whole numbers) carried as float32, so they come back
exactly; times pass through integer nanoseconds (ROS ``builtin_interfaces/Time``), so
they come back within 1 ns; XDF and CSV carry the times as doubles / repr text, exactly.
"""

import json
import struct
import xml.etree.ElementTree as ET

import numpy as np
import pytest
from typer.testing import CliRunner

import tactsense as ts
from tactsense.cli import app
from tactsense.io.recording import read_recording, write_recording

runner = CliRunner()


@pytest.fixture(scope="module")
def sweep(initial):
    return ts.simulate(initial, ts.probe_sweep(initial, along="axial", dwell_s=0.3), rng=5)


@pytest.fixture()
def rec_path(tmp_path, sweep):
    path = tmp_path / "rec.h5"
    write_recording(path, sweep)
    return path


def _import(source, out, *extra):
    result = runner.invoke(app, ["import", str(source), "--out", str(out), *map(str, extra)])
    assert result.exit_code == 0, result.output
    return read_recording(out)


def test_mcap_export_then_import_gives_the_same_frames_and_times(tmp_path, rec_path, sweep):
    mcap = tmp_path / "rec.mcap"
    assert runner.invoke(app, ["export", str(rec_path), "--out", str(mcap)]).exit_code == 0
    back = _import(mcap, tmp_path / "back.h5")
    np.testing.assert_array_equal(back.frames, sweep.frames)
    assert back.frames.dtype == np.uint16
    np.testing.assert_allclose(back.time_s, sweep.time_s, rtol=0, atol=1e-9)
    assert back.sensor == sweep.sensor  # the TactileState's sensor name is a preset


def _tactile_state_type():
    from rosbags.typesys import Stores, get_types_from_msg, get_typestore

    from tactsense.interop.ros import SEPARATOR, TACTILE_STATE, TACTILE_STATE_MSGDEF

    store = get_typestore(Stores.ROS2_HUMBLE)
    store.register(get_types_from_msg(TACTILE_STATE_MSGDEF.split(SEPARATOR)[0], TACTILE_STATE))
    return store


@pytest.mark.parametrize("storage", ["sqlite3", "mcap"])
def test_rosbag2_bag_imports_with_rosbags(tmp_path, sweep, storage):
    """A bag written by rosbags (as ros2 bag record writes it), read back by the import."""
    from rosbags.rosbag2 import StoragePlugin, Writer

    store = _tactile_state_type()
    State = store.types["tactile_msgs/msg/TactileState"]
    Header = store.types["std_msgs/msg/Header"]
    Time = store.types["builtin_interfaces/msg/Time"]
    Channel = store.types["sensor_msgs/msg/ChannelFloat32"]
    bag = tmp_path / "bag"
    plugin = StoragePlugin.SQLITE3 if storage == "sqlite3" else StoragePlugin.MCAP
    host0 = 1_763_900_000.0  # a host clock: kept as host times, frame times from 0
    with Writer(bag, version=8, storage_plugin=plugin) as writer:
        conn = writer.add_connection(
            "/right_hand/tactile_states", "tactile_msgs/msg/TactileState", typestore=store
        )
        for k, counts in enumerate(sweep.frames):
            ns = round((host0 + sweep.time_s[k]) * 1e9)
            msg = State(
                Header(Time(ns // 10**9, ns % 10**9), "finger"),
                [
                    Channel("other_sensor", np.zeros(3, np.float32)),
                    Channel(sweep.sensor.name, counts.astype(np.float32).ravel()),
                ],
            )
            writer.write(conn, ns, store.serialize_cdr(msg, "tactile_msgs/msg/TactileState"))
    back = _import(bag, tmp_path / "back.h5")
    np.testing.assert_array_equal(back.frames, sweep.frames)
    # 1.76e9 s in a double: 2.4e-7 s steps; the nanoseconds are exact in the message
    np.testing.assert_allclose(back.host_time_s, host0 + sweep.time_s, rtol=0, atol=5e-7)
    np.testing.assert_allclose(back.time_s, sweep.time_s - sweep.time_s[0], rtol=0, atol=5e-7)


# ---- XDF: a minimal writer of the format (github.com/sccn/xdf/wiki/Specifications) ------


def _varlen(n: int) -> bytes:
    """XDF's variable-length integer: 1 byte saying 1, 4 or 8, then the number."""
    if n < 256:
        return struct.pack("<BB", 1, n)
    if n < 2**32:
        return struct.pack("<BI", 4, n)
    return struct.pack("<BQ", 8, n)


def _chunk(tag: int, content: bytes) -> bytes:
    return _varlen(len(content) + 2) + struct.pack("<H", tag) + content


def write_xdf(path, streams):
    """``streams``: (stream id, header XML, float32 samples (T, N), time stamps (T,))."""
    out = [b"XDF:", _chunk(1, b'<?xml version="1.0"?><info><version>1.0</version></info>')]
    for sid, header, _, _ in streams:
        out.append(_chunk(2, struct.pack("<I", sid) + header.encode()))
    for sid, _, samples, stamps in streams:
        for start in range(0, len(samples), 50):  # several Samples chunks, as recorders do
            body = [struct.pack("<I", sid), _varlen(len(samples[start : start + 50]))]
            for row, t in zip(samples[start : start + 50], stamps[start : start + 50], strict=True):
                body.append(struct.pack("<Bd", 8, t) + np.asarray(row, "<f4").tobytes())
            out.append(_chunk(3, b"".join(body)))
    for sid, _, samples, stamps in streams:
        footer = (
            f'<?xml version="1.0"?><info><first_timestamp>{stamps[0]!r}</first_timestamp>'
            f"<last_timestamp>{stamps[-1]!r}</last_timestamp><sample_count>{len(samples)}"
            "</sample_count><clock_offsets></clock_offsets></info>"
        )
        out.append(_chunk(6, struct.pack("<I", sid) + footer.encode()))
    path.write_bytes(b"".join(out))


def _plain_header(name, kind, channels, rate=7.0):
    return (
        f'<?xml version="1.0"?><info><name>{name}</name><type>{kind}</type>'
        f"<channel_count>{channels}</channel_count><nominal_srate>{rate}</nominal_srate>"
        "<channel_format>float32</channel_format><source_id>x</source_id><desc/></info>"
    )


def test_xdf_of_a_tactsense_outlet_imports_with_its_sensor(tmp_path, sweep):
    """The stream header is the XML of tactsense's LSL frames outlet (what LabRecorder
    writes), beside an unrelated stream; no --sensor needed."""
    from tactsense.interop.lsl import frames_info

    header = frames_info(sweep.sensor, {"serial": "x1"}, 7.0).as_xml()
    stamps = 5000.0 + sweep.time_s  # LSL's clock
    frames = sweep.frames.reshape(len(sweep), -1).astype(np.float32)
    other = np.random.default_rng(0).normal(size=(40, 3)).astype(np.float32)
    path = tmp_path / "lab.xdf"
    write_xdf(path, [(1, _plain_header("eeg", "EEG", 3, 100), other, 5000 + np.arange(40) / 100),
                     (2, header, frames, stamps)])  # fmt: skip
    back = _import(path, tmp_path / "back.h5")
    np.testing.assert_array_equal(back.frames, sweep.frames)
    np.testing.assert_array_equal(back.time_s, stamps)
    assert back.sensor == sweep.sensor
    assert ET.fromstring(header).findtext("desc/tactsense/sensor_toml")


def test_xdf_of_another_stream_takes_sensor_and_checks_channels(tmp_path, sweep):
    frames = sweep.frames.reshape(len(sweep), -1).astype(np.float32)
    stamps = 10.0 + sweep.time_s
    path = tmp_path / "glove.xdf"
    write_xdf(path, [(7, _plain_header("glove", "Tactile", 64), frames, stamps)])
    result = runner.invoke(app, ["import", str(path), "--out", str(tmp_path / "a.h5")])
    assert result.exit_code == 2 and "--sensor" in result.output
    back = _import(path, tmp_path / "b.h5", "--sensor", "initial")
    np.testing.assert_array_equal(back.frames, sweep.frames)
    np.testing.assert_array_equal(back.time_s, stamps)
    result = runner.invoke(
        app, ["import", str(path), "--out", str(tmp_path / "c.h5"), "--sensor", "pad4"]
    )
    assert result.exit_code == 2
    assert "64 channels" in result.output and "taxels" in result.output
    assert not (tmp_path / "c.h5").exists()


def test_csv_round_trip(tmp_path, sweep):
    rows, cols = sweep.sensor.shape
    path = tmp_path / "frames.csv"
    header = ["t_s"] + [f"r{r}c{c}" for r in range(rows) for c in range(cols)]
    lines = [",".join(header)]
    for t, frame in zip(sweep.time_s, sweep.frames, strict=True):
        lines.append(",".join([repr(float(t))] + [str(int(v)) for v in frame.ravel()]))
    path.write_text("\n".join(lines) + "\n")
    back = _import(path, tmp_path / "back.h5", "--sensor", "initial", "--time-column", "t_s")
    np.testing.assert_array_equal(back.frames, sweep.frames)
    np.testing.assert_array_equal(back.time_s, sweep.time_s)  # repr round-trips a double


# ---- LeRobot ---------------------------------------------------------------------------


def _check_layout(folder):
    """An independent reader of LeRobot v3's layout (pyarrow and JSON only)."""
    import pyarrow.parquet as pq

    info = json.loads((folder / "meta/info.json").read_text())
    assert info["codebase_version"] == "v3.0"
    assert info["data_path"] == "data/chunk-{chunk_index:03d}/file-{file_index:03d}.parquet"
    episodes = pq.read_table(folder / "meta/episodes/chunk-000/file-000.parquet").to_pylist()
    assert len(episodes) == info["total_episodes"]
    assert info["splits"] == {"train": f"0:{info['total_episodes']}"}
    total = 0
    files = {(e["data/chunk_index"], e["data/file_index"]) for e in episodes}
    tables = []
    for chunk, file in sorted(files):
        path = folder / info["data_path"].format(chunk_index=chunk, file_index=file)
        assert path.is_file(), path  # every file the metadata promises exists
        tables.append(pq.read_table(path))
        total += tables[-1].num_rows
    assert total == info["total_frames"]
    for table in tables:
        assert set(table.column_names) == set(info["features"])
        for key, feature in info["features"].items():
            value = np.asarray(table.column(key).to_pylist()[0])
            shape = [] if feature["shape"] == [1] else feature["shape"]
            assert list(value.shape) == shape, key
            if feature["names"] is not None and len(feature["shape"]) == 1:
                assert len(feature["names"]) == feature["shape"][0]
    for e in episodes:
        assert e["length"] == e["dataset_to_index"] - e["dataset_from_index"]
        assert e["tasks"] == ["tactile recording"]
    tasks = pq.read_table(folder / "meta/tasks.parquet").to_pydict()
    assert tasks["task"] == ["tactile recording"] and tasks["task_index"] == [0]
    stats = json.loads((folder / "meta/stats.json").read_text())
    assert set(stats) == set(info["features"])
    return info, episodes, tables


def test_lerobot_export_has_the_v3_layout_and_imports_back(tmp_path, rec_path, sweep):
    out = tmp_path / "dataset"
    result = runner.invoke(
        app, ["export", str(rec_path), "--format", "lerobot", "--out", str(out),
              "--episode-split", "40"],
    )  # fmt: skip
    assert result.exit_code == 0, result.output
    info, episodes, tables = _check_layout(out)
    n = len(sweep)
    assert info["total_frames"] == n and info["fps"] == 7
    assert info["total_episodes"] == -(-n // 40)
    assert [e["length"] for e in episodes] == [min(40, n - s) for s in range(0, n, 40)]
    table = tables[0].to_pydict()
    tactile = np.asarray(table["observation.tactile"])
    np.testing.assert_array_equal(tactile, sweep.frames.astype(np.float32))
    np.testing.assert_array_equal(table["frame_time"], sweep.time_s)
    np.testing.assert_array_equal(table["frame_index"], np.arange(n) % 40)
    np.testing.assert_array_equal(table["episode_index"], np.arange(n) // 40)
    np.testing.assert_allclose(table["timestamp"], (np.arange(n) % 40) / 7, rtol=1e-6)
    # the contact estimates, named, as locate gives them
    names = info["features"]["observation.state"]["names"]
    state = np.asarray(table["observation.state"])
    est = ts.locate(sweep.frames, sweep.sensor, baseline=ts.baseline_from(sweep.frames, 5))
    touching = np.isfinite(est.force_n) & np.isfinite(est.axial_mm)
    present = state[:, names.index("contact.present")] == 1
    np.testing.assert_array_equal(present, touching)
    np.testing.assert_allclose(
        state[present, names.index("contact.force_n")], est.force_n[touching], rtol=1e-6
    )
    # the dataset's statistics are the frames' (independent: numpy over the raw frames),
    # of LeRobot's shape for a [rows, cols] feature: per column, over frames and rows
    stats = json.loads((out / "meta/stats.json").read_text())
    cols = sweep.sensor.shape[1]
    np.testing.assert_allclose(
        stats["observation.tactile"]["mean"], sweep.frames.reshape(-1, cols).mean(0)
    )
    assert stats["frame_index"]["count"] == [n]

    back = _import(out, tmp_path / "back.h5")
    np.testing.assert_array_equal(back.frames, sweep.frames)
    np.testing.assert_array_equal(back.time_s, sweep.time_s)
    assert back.sensor == sweep.sensor


def test_lerobot_export_interrupted_leaves_nothing(tmp_path, rec_path, monkeypatch):
    """Ctrl-C while the dataset is being written: no dataset, no temporary folder."""
    from tactsense.interop import lerobot

    original = lerobot.write_dataset

    def interrupted(folder, **kwargs):
        original(folder, **kwargs)  # every file written, then the interrupt
        raise KeyboardInterrupt

    monkeypatch.setattr(lerobot, "write_dataset", interrupted)
    out = tmp_path / "dataset"
    with pytest.raises(KeyboardInterrupt):
        lerobot.export_lerobot(rec_path, out)
    assert not out.exists()
    assert [p.name for p in tmp_path.iterdir()] == ["rec.h5"]


def test_lerobot_dataset_of_another_writer_needs_a_sensor_of_its_shape(tmp_path, sweep):
    """A v3 dataset without tactsense's metadata: --sensor gives the sensor, and a sensor of
    another shape is refused (exit 2, both shapes named)."""
    from tactsense.interop.lerobot import write_dataset

    out = tmp_path / "other"
    out.mkdir()
    write_dataset(out, sensor=sweep.sensor, frames=sweep.frames, frame_time=sweep.time_s,
                  state=np.zeros((len(sweep), 6)))  # fmt: skip
    (out / "meta" / "tactsense.json").unlink()
    result = runner.invoke(app, ["import", str(out), "--out", str(tmp_path / "a.h5")])
    assert result.exit_code == 2 and "--sensor" in result.output
    back = _import(out, tmp_path / "b.h5", "--sensor", "initial")
    np.testing.assert_array_equal(back.frames, sweep.frames)
    result = runner.invoke(
        app, ["import", str(out), "--out", str(tmp_path / "c.h5"), "--sensor", "pad4"]
    )
    assert result.exit_code == 2 and "[8, 8]" in result.output and "[4, 4]" in result.output
