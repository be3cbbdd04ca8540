"""Issue 31 (round three), interop: nothing lost between tactsense and the lab's other
tools. Each case failed before its fix."""

from collections import defaultdict
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from typer.testing import CliRunner

import tactsense as ts
from tactsense.cli import app
from tactsense.flat_scenarios import two_probes

runner = CliRunner()


@pytest.fixture(scope="module")
def recordings(tmp_path_factory):
    """A pad and a point set, each pressed by two probes at once; and a finger."""
    folder = tmp_path_factory.mktemp("round3_interop")
    paths = {}
    for name in ("pad16", "dome12"):
        sensor = ts.preset(name)
        paths[name] = folder / f"{name}.h5"
        ts.write_recording(paths[name], ts.simulate(sensor, two_probes(sensor), rng=2))
    finger = ts.fearing1990_initial()
    paths["finger"] = folder / "finger.h5"
    ts.write_recording(paths["finger"], ts.simulate(finger, ts.probe_sweep(finger), rng=0))
    return paths


# --- item 4: every contact of a frame keeps its own name in MCAP -------------------------


@pytest.mark.parametrize("kind", ["pad16", "dome12"])
def test_mcap_contacts_of_one_frame_have_distinct_names(tmp_path, recordings, kind):
    """Upstream's TactileContact.name is the "unique name of the contact" and RViz's
    contact display keeps one contact per (frame_id, name): two contacts of one frame
    named alike show as one. Each is ``<sensor>/<tracked id>`` (locate's long table
    gives the ids), and each frame's contacts also come as one TactileContacts list
    (upstream's merger's message), an empty one for a frame without a contact; decoded
    with mcap-ros2-support's own decoder."""
    from mcap.reader import make_reader
    from mcap_ros2.decoder import DecoderFactory

    rec = recordings[kind]
    out = tmp_path / "x.mcap"
    assert runner.invoke(app, ["export", str(rec), "--out", str(out)]).exit_code == 0
    by_stamp, lists, frames = defaultdict(list), [], 0
    with open(out, "rb") as stream:
        reader = make_reader(stream, decoder_factories=[DecoderFactory()])
        for schema, channel, message, decoded in reader.iter_decoded_messages():
            if channel.topic == "/tactile_contacts":
                by_stamp[message.log_time].append(decoded.name)
            elif channel.topic == "/contact_states":
                assert schema.name == "tactile_msgs/msg/TactileContacts"
                lists.append((message.log_time, [c.name for c in decoded.contacts]))
            else:
                frames += 1
    several = [names for names in by_stamp.values() if len(names) > 1]
    assert len(several) > 10  # two probes at once in many frames
    assert all(len(set(names)) == len(names) for names in several)
    # the names are the tracked ids of locate's long table, frame by frame
    table_path = tmp_path / "c.csv"
    assert runner.invoke(app, ["locate", str(rec), "--out", str(table_path)]).exit_code == 0
    table = pd.read_csv(table_path)
    sensor = ts.read_recording(rec).sensor.name
    expected = defaultdict(list)
    for time_s, i in zip(table["time_s"], table["id"], strict=True):
        expected[round(time_s * 1e9)].append(f"{sensor}/{i}")
    assert dict(by_stamp) == dict(expected)
    # one list per frame, holding that frame's contacts
    assert len(lists) == frames
    assert {t: names for t, names in lists if names} == dict(by_stamp)


# --- item 3: every kind of sensor exports to every format -------------------------------


def _lerobot_stat_shape(feature: dict) -> tuple[int, ...]:
    """The shape of LeRobot's statistics (min, max, mean, std, quantiles) of a feature, as
    ``lerobot.datasets.compute_stats.compute_episode_stats`` (0.4.4) makes them: a scalar
    ``(1,)``, a vector its length, and a ``[rows, cols]`` array ``(cols,)`` (its
    ``RunningQuantileStats`` takes every axis but the last as samples)."""
    shape = tuple(feature["shape"])
    return shape[-1:]


def _contacts_table(tmp_path, rec):
    out = tmp_path / f"{Path(rec).stem}.contacts.csv"
    assert runner.invoke(app, ["locate", str(rec), "--out", str(out)]).exit_code == 0
    return pd.read_csv(out)


@pytest.mark.parametrize("kind", ["pad16", "dome12"])
def test_lerobot_export_of_a_pad_and_a_point_set(tmp_path, recordings, kind):
    """The v3 layout (pyarrow and JSON, against the definitions in lerobot's utils.py and
    compute_stats.py), every contact of locate's long table in ``observation.state``
    slot by slot, and the frames and times back through ``tactsense import``."""
    import json

    import pyarrow.parquet as pq

    rec = recordings[kind]
    recording = ts.read_recording(rec)
    n, (rows, cols) = len(recording.frames), recording.sensor.shape
    out = tmp_path / "ds"
    result = runner.invoke(app, ["export", str(rec), "--format", "lerobot", "--out", str(out),
                                 "--episode-split", "20"])  # fmt: skip
    assert result.exit_code == 0, result.output
    info = json.loads((out / "meta/info.json").read_text())
    assert info["codebase_version"] == "v3.0" and info["total_frames"] == n
    assert info["features"]["observation.tactile"]["shape"] == [rows, cols]
    table = pq.read_table(out / "data/chunk-000/file-000.parquet").to_pydict()
    assert set(table) == set(info["features"])
    tactile = np.asarray(table["observation.tactile"])
    np.testing.assert_array_equal(tactile, recording.frames.astype(np.float32))
    # statistics: LeRobot's shapes, in the dataset and in every episode
    stats = json.loads((out / "meta/stats.json").read_text())
    episodes = pq.read_table(out / "meta/episodes/chunk-000/file-000.parquet").to_pylist()
    assert len(episodes) == -(-n // 20)
    for key, feature in info["features"].items():
        for name in ("min", "max", "mean", "std", "q01", "q50", "q99"):
            assert np.shape(stats[key][name]) == _lerobot_stat_shape(feature), (key, name)
            for e in episodes:
                assert np.shape(e[f"stats/{key}/{name}"]) == _lerobot_stat_shape(feature)
        assert stats[key]["count"] == [n]
    np.testing.assert_allclose(
        stats["observation.tactile"]["mean"], recording.frames.reshape(-1, cols).mean(0)
    )
    # the contacts: locate's long table, slot by slot (slot = rank in the frame)
    names = info["features"]["observation.state"]["names"]
    state = np.asarray(table["observation.state"])
    contacts = _contacts_table(tmp_path, rec)
    assert len(contacts) > n / 2
    np.testing.assert_array_equal(
        state[:, names.index("contacts.count")], np.bincount(contacts["frame"], minlength=n)
    )
    for field in ("id", "x_mm", "y_mm", "z_mm", "force_n"):
        got = state[contacts["frame"], [names.index(f"contact{k}.{field}") for k in
                                        contacts["contact"]]]  # fmt: skip
        np.testing.assert_allclose(got, contacts[field], rtol=1e-6, atol=1e-6)
    # and back
    back = tmp_path / "back.h5"
    assert runner.invoke(app, ["import", str(out), "--out", str(back)]).exit_code == 0
    again = ts.read_recording(back)
    np.testing.assert_array_equal(again.frames, recording.frames)
    np.testing.assert_array_equal(again.time_s, recording.time_s)


@pytest.mark.parametrize("kind", ["pad16", "dome12"])
def test_rerun_export_of_a_pad_and_a_point_set(tmp_path, recordings, kind):
    """Read with Rerun's own reader: every frame's signal, every contact of locate's long
    table at its position [mm], labelled with its tracked id."""
    from rerun.chunk import RrdReader

    rec = recordings[kind]
    recording = ts.read_recording(rec)
    root = recording.sensor.kind
    out = tmp_path / "x.rrd"
    result = runner.invoke(app, ["export", str(rec), "--out", str(out)])
    assert result.exit_code == 0, result.output
    tensors, points = 0, {}
    for chunk in RrdReader(str(out)).stream().to_chunks():
        batch = chunk.to_record_batch()
        if "time" not in batch.schema.names:
            continue
        times = [round(t.total_seconds() * 1e9) for t in batch.column("time").to_pylist()]
        path = str(chunk.entity_path)
        if path == f"/{root}/signal_values":
            tensors += len(times)
        elif path == f"/{root}/contacts" and "Points3D:positions" in batch.schema.names:
            positions = batch.column("Points3D:positions").to_pylist()
            labels = batch.column("Points3D:labels").to_pylist()
            for t, xyz, label in zip(times, positions, labels, strict=True):
                if xyz:
                    points[t] = sorted(zip(label, map(tuple, xyz), strict=True))
    assert tensors == len(recording.frames)
    contacts = _contacts_table(tmp_path, rec)
    expected = defaultdict(list)
    for row in contacts.itertuples():
        expected[round(row.time_s * 1e9)].append((str(row.id), (row.x_mm, row.y_mm, row.z_mm)))
    assert set(points) == set(expected)
    for t, got in points.items():
        want = sorted(expected[t])
        assert [label for label, _ in got] == [label for label, _ in want]
        np.testing.assert_allclose([p for _, p in got], [p for _, p in want], atol=1e-4)


def test_batch_on_pads_and_point_sets(tmp_path, recordings):
    """`batch` of a folder of pad and point-set recordings (all failed: 'this works on
    fingers'): each output is the long table `locate` writes, events beside a CSV, and
    the summary counts its contacts."""
    import shutil

    folder = tmp_path / "lab"
    folder.mkdir()
    for name in ("pad16", "dome12"):
        shutil.copy(recordings[name], folder / f"{name}.h5")
    out = tmp_path / "out"
    result = runner.invoke(app, ["batch", str(folder / "*.h5"), "--out", str(out),
                                 "--format", "csv", "--workers", "1", "--quiet"])  # fmt: skip
    assert result.exit_code == 0, result.output
    summary = pd.read_csv(out / "summary.csv")
    assert list(summary["status"]) == ["done", "done"], summary["reason"].tolist()
    for name, row in zip(("dome12", "pad16"), summary.itertuples(), strict=True):
        alone = _contacts_table(tmp_path, folder / f"{name}.h5")
        batch = pd.read_csv(out / f"{name}.csv")
        pd.testing.assert_frame_equal(batch, alone)
        assert (out / f"{name}.events.csv").is_file()
        assert row.contacts == len(alone) > 0
        assert row.force_mean_n == pytest.approx(alone["force_n"].mean(), rel=1e-9)
    assert sorted(p.name for p in out.iterdir() if p.name.startswith(".")) == []


def test_csv_export_imports_back_whole(tmp_path, recordings):
    """`export X.csv` (refused before: 'say --format mcap or rerun') writes what `import`
    reads: counts, times, host times and a lost reading (NaN) come back equal."""
    import dataclasses

    recording = ts.read_recording(recordings["pad16"])
    frames = recording.frames.astype(np.float64)
    frames[3, 2, 5] = np.nan  # a lost reading
    host = 1.7e9 + recording.time_s + 0.25
    streamed = dataclasses.replace(recording, frames=frames, host_time_s=host)
    cases = {"counts": recording, "stream": streamed}
    for name, rec in cases.items():
        path, out, back = (tmp_path / f"{name}.{ext}" for ext in ("h5", "csv", "back.h5"))
        ts.write_recording(path, rec)
        result = runner.invoke(app, ["export", str(path), "--out", str(out)])
        assert result.exit_code == 0, result.output
        result = runner.invoke(app, ["import", str(out), "--sensor", "pad16", "--out", str(back)])
        assert result.exit_code == 0, result.output
        again = ts.read_recording(back)
        np.testing.assert_array_equal(again.frames, rec.frames)
        np.testing.assert_array_equal(again.time_s, rec.time_s)
        if rec.host_time_s is None:
            assert again.host_time_s is None
        else:
            np.testing.assert_array_equal(again.host_time_s, rec.host_time_s)


# --- item 10: CSV import: times that go backwards or repeat; Excel's byte-order mark ----


def _csv(path, times, bom=False):
    header = "time," + ",".join(f"v{k}" for k in range(64))
    rows = [f"{t}," + ",".join(["2000"] * 64) for t in times]
    path.write_bytes(
        (b"\xef\xbb\xbf" if bom else b"") + ("\n".join([header, *rows]) + "\n").encode()
    )
    return path


@pytest.mark.parametrize(
    ("times", "message"),
    [
        ((0.0, 0.1, 0.05, 0.2), "line 4: the time 0.05 s goes backwards from 0.1 s on line 3"),
        ((0.0, 0.1, 0.1, 0.2), "line 4: the time 0.1 s repeats 0.1 s on line 3"),
    ],
)
def test_csv_import_refuses_times_out_of_order(tmp_path, times, message):
    """Refused, with the line (a flag would leave a recording whose rate and velocities
    are wrong; the file is the user's to sort or fix): exit 2, nothing written."""
    path = _csv(tmp_path / "x.csv", times)
    out = tmp_path / "x.h5"
    result = runner.invoke(app, ["import", str(path), "--sensor", "initial", "--out", str(out)])
    assert result.exit_code == 2
    said = " ".join(result.output.split())
    assert message in said and "must increase" in said and "Traceback" not in said
    assert not out.exists()


def test_csv_import_accepts_excels_byte_order_mark(tmp_path):
    """Excel's "CSV UTF-8" starts with a byte-order mark; it was read as part of the
    first column's name ("no time column 'time' in the header (\\ufefftime, ...)")."""
    path = _csv(tmp_path / "excel.csv", (0.0, 0.1, 0.2), bom=True)
    out = tmp_path / "x.h5"
    result = runner.invoke(app, ["import", str(path), "--sensor", "initial", "--out", str(out)])
    assert result.exit_code == 0, result.output
    back = ts.read_recording(out)
    np.testing.assert_array_equal(back.time_s, [0.0, 0.1, 0.2])
    assert (back.frames == 2000).all()


# --- item 13: an MCAP file that is empty, has no messages, or is cut short -------------


def _mcap_without_messages(path):
    from mcap_ros2.writer import Writer

    from tactsense.interop.ros import TACTILE_STATE, TACTILE_STATE_MSGDEF

    with open(path, "wb") as stream:
        writer = Writer(stream)
        writer.register_msgdef(TACTILE_STATE, TACTILE_STATE_MSGDEF)  # a schema, no channel
        writer.finish()


@pytest.mark.parametrize(
    ("content", "message"),
    [
        (b"", "empty.mcap is empty (0 bytes); expected an MCAP file"),
        (None, "the file holds no messages (no topic at all)"),
        (b"\x89MCAP0\r\n", "empty.mcap is truncated (8 bytes)"),
        (b"\x89MC", "empty.mcap is truncated (3 bytes)"),  # a traceback before
        (b"hello, world", "is not an MCAP file: it does not start with MCAP's magic bytes"),
    ],
)
def test_import_says_what_is_wrong_with_an_mcap_file(tmp_path, content, message):
    """It said 'not a readable MCAP file ()' for an empty file, wrapped 'no topics' in
    'not a readable MCAP file (...)', and 'cannot read it (Invalid argument)' for a
    file cut after MCAP's magic: exit 2, one line naming what is wrong."""
    path = tmp_path / "empty.mcap"
    if content is None:
        _mcap_without_messages(path)
    else:
        path.write_bytes(content)
    out = tmp_path / "x.h5"
    result = runner.invoke(app, ["import", str(path), "--out", str(out)])
    said = " ".join(result.output.split())
    assert result.exit_code == 2, said
    assert message in said and "not a readable MCAP file" not in said
    assert "()" not in said and "Traceback" not in said
    assert not out.exists()
