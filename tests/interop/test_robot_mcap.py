"""A robot recording to one MCAP file and back (tactsense.interop.robot_mcap, robot_bag).

The file is read with mcap's own reader and its messages decoded with rosbags against the
upstream tactile_msgs .msg texts (an independent CDR decoder); a bag written by rosbags
is imported into a robot recording by its topics' and channels' names."""

from __future__ import annotations

import shutil

import numpy as np
import pytest
from typer.testing import CliRunner

from tactsense.cli import app
from tactsense.interop.robot_bag import read_robot_bag
from tactsense.interop.robot_mcap import export_robot_mcap, topic_token
from tactsense.io.robot_recording import read_manifest, read_robot_recording, write_manifest
from tactsense.robot import rotation_matrix, skin_to_toml_string

from .robot_helpers import PATCHES, PRESS, robot_recording, small_hand, write

pytest.importorskip("mcap_ros2")
pytest.importorskip("rosbags")

runner = CliRunner()
START = 1_763_900_000.0  # --start-time of the simulated recording [Unix s]

STATE_MSG = "std_msgs/Header header\nsensor_msgs/ChannelFloat32[] sensors\n"
CONTACT_MSG = (
    "std_msgs/Header header\nstring name\ngeometry_msgs/Point position\n"
    "geometry_msgs/Vector3 normal\ngeometry_msgs/Wrench wrench\n"
)
CONTACTS_MSG = "tactile_msgs/TactileContact[] contacts\n"
"""The upstream .msg texts without their comments (ubi-agni/tactile_toolbox,
tactile_msgs/msg/TactileState.msg at db670ce7, TactileContact.msg at bb47fdbf,
TactileContacts.msg), typed here again rather than taken from tactsense.interop.ros."""


@pytest.fixture(scope="module")
def simulated(tmp_path_factory):
    folder = tmp_path_factory.mktemp("robot") / "run"
    recording = robot_recording()
    write(folder, recording)
    out = folder.parent / "run.mcap"
    counts = export_robot_mcap(folder, out, start_time_s=START)
    return folder, out, recording, counts


@pytest.fixture(scope="module")
def captured(tmp_path_factory):
    folder = tmp_path_factory.mktemp("robot") / "cap"
    recording = robot_recording(host0=START, rng=3)
    write(folder, recording)
    out = folder.parent / "cap.mcap"
    export_robot_mcap(folder, out, contacts=False)
    return folder, out, recording


def _typestore():
    from rosbags.typesys import Stores, get_types_from_msg, get_typestore

    store = get_typestore(Stores.ROS2_HUMBLE)
    types = {}
    for name, text in (
        ("tactile_msgs/msg/TactileState", STATE_MSG),
        ("tactile_msgs/msg/TactileContact", CONTACT_MSG),
        ("tactile_msgs/msg/TactileContacts", CONTACTS_MSG),
    ):
        types.update(get_types_from_msg(text, name))
    store.register(types)
    return store


def _messages(path):
    """(topic, schema name, log time, raw CDR) of every message, with mcap's reader."""
    from mcap.reader import make_reader

    with open(path, "rb") as stream:
        reader = make_reader(stream)
        return [
            (channel.topic, schema.name, message.log_time, message.data)
            for schema, channel, message in reader.iter_messages(log_time_order=False)
        ]


def test_a_topic_per_patch_read_by_mcap_and_rosbags(simulated):
    _folder, out, recording, counts = simulated
    store = _typestore()
    messages = _messages(out)
    log_times = [m[2] for m in messages]
    assert log_times == sorted(log_times)  # one time order over every patch
    states = {}
    for topic, schema, log_time, data in messages:
        if schema != "tactile_msgs/msg/TactileState":
            continue
        msg = store.deserialize_cdr(data, schema)
        stamp_ns = msg.header.stamp.sec * 1_000_000_000 + msg.header.stamp.nanosec
        assert stamp_ns == log_time
        (channel,) = msg.sensors
        assert topic == f"/tactile_states/{channel.name}"
        assert msg.header.frame_id == recording.skin.patch(channel.name).link
        states.setdefault(channel.name, []).append((stamp_ns, channel.values))
    assert sorted(states) == sorted(PATCHES)
    for name, stream in recording.streams.items():
        stamps = np.array([s for s, _ in states[name]])
        values = np.stack([v for _, v in states[name]])
        np.testing.assert_array_equal(values.reshape(stream.frames.shape), stream.frames)
        # nanoseconds: the stamps are the frame times plus --start-time, to the ns
        expected = np.round((START + stream.time_s) * 1e9).astype(np.int64)
        assert np.abs(stamps - expected).max() <= 1
    assert counts["frames"] == {name: len(s) for name, s in recording.streams.items()}


def test_contacts_per_link_in_the_link_frame(simulated):
    """The pressed pad's contact comes back in its link's frame where the patch's origin
    puts the pressed point (tolerance 1.5 mm: half a taxel pitch of 3 mm, the single-array
    estimator's interpolation on a 4 x 8 pad); force along the inward normal; torque
    r x F about the link's origin, by components."""
    _folder, out, recording, counts = simulated
    store = _typestore()
    skin = recording.skin
    patch = skin.patch("distal_pad")
    (xy, newtons) = PRESS["distal_pad"]
    rotation = rotation_matrix(patch.origin.rpy_rad)
    expected = rotation @ np.array([xy[0], xy[1], 0.0]) * 1e-3 + np.array(patch.origin.xyz_m)
    normal = rotation @ np.array([0.0, 0.0, 1.0])
    by_link = {}
    for topic, schema, _, data in _messages(out):
        if schema == "tactile_msgs/msg/TactileContacts":
            by_link.setdefault(topic, []).append(store.deserialize_cdr(data, schema).contacts)
    assert sorted(by_link) == [
        "/tactile_contacts/finger_distal", "/tactile_contacts/finger_proximal",
        "/tactile_contacts/palm",
    ]  # fmt: skip
    assert not any(by_link["/tactile_contacts/palm"])  # palm_pad is not touched
    assert not any(by_link["/tactile_contacts/finger_proximal"])  # nor the finger
    pressed = [c for cs in by_link["/tactile_contacts/finger_distal"] for c in cs]
    assert pressed and sum(counts["contacts"].values()) > 0
    for contact in pressed:
        assert contact.header.frame_id == "finger_distal"
        assert contact.name.startswith("distal_pad/")
        p = np.array([contact.position.x, contact.position.y, contact.position.z])
        n = np.array([contact.normal.x, contact.normal.y, contact.normal.z])
        f = np.array([contact.wrench.force.x, contact.wrench.force.y, contact.wrench.force.z])
        t = np.array([contact.wrench.torque.x, contact.wrench.torque.y, contact.wrench.torque.z])
        assert np.linalg.norm(p - expected) < 1.5e-3
        np.testing.assert_allclose(n, normal, atol=1e-12)
        force = -float(f @ n)
        assert 0.0 < force < 3 * newtons  # pressing inward; the estimate of 1 N
        np.testing.assert_allclose(f, -force * n, atol=1e-12)
        by_hand = [p[1] * f[2] - p[2] * f[1], p[2] * f[0] - p[0] * f[2], p[0] * f[1] - p[1] * f[0]]
        np.testing.assert_allclose(t, by_hand, atol=1e-15)


def test_round_trip_is_bit_for_bit(simulated, captured, tmp_path):
    """Exported and imported back: every stream's frames (dtype too), times, host times,
    device clock, sequence numbers and losses equal the original's."""
    for folder, out, *_ in (simulated, captured):
        back, summary = read_robot_bag(out)
        original = read_robot_recording(folder)
        assert sorted(back.streams) == sorted(original.streams)
        assert back.skin == original.skin
        for name, stream in original.streams.items():
            got = back.streams[name]
            assert got.frames.dtype == stream.frames.dtype
            np.testing.assert_array_equal(got.frames, stream.frames)
            np.testing.assert_array_equal(got.time_s, stream.time_s)
            for key in ("host_time_s", "device_time_us", "sequence"):
                a, b = getattr(got, key), getattr(stream, key)
                assert (a is None) == (b is None), key
                if a is not None:
                    np.testing.assert_array_equal(a, b)
            assert got.losses == stream.losses
        assert summary["frames"] == {n: len(s) for n, s in original.streams.items()}


def test_cli_export_and_import_back(captured, tmp_path):
    folder, _, recording = captured
    out = tmp_path / "hand.mcap"
    result = runner.invoke(app, ["export", str(folder), "--out", str(out), "-q"])
    assert result.exit_code == 0, result.output
    total = sum(len(s) for s in recording.streams.values())
    assert f"{total} frames of 4 patches" in result.output
    assert "host clock" in result.output
    back = tmp_path / "back"
    result = runner.invoke(app, ["import", str(out), "--out", str(back)])
    assert result.exit_code == 0, result.output
    assert f"{total} TactileState messages read, {total} frames kept" in result.output
    again = read_robot_recording(back)
    for name, stream in recording.streams.items():
        np.testing.assert_array_equal(again.streams[name].frames, stream.frames)
    # a second import over it needs --force; never over the input
    result = runner.invoke(app, ["import", str(out), "--out", str(back)])
    assert result.exit_code == 2 and "exists" in result.output


def _bag(path, store, topics):
    """A rosbag2 bag (rosbags' writer, mcap storage) of TactileState messages:
    ``topics`` maps a topic to a list of (stamp_ns, [(channel name, values)])."""
    from rosbags.rosbag2 import StoragePlugin, Writer

    State = store.types["tactile_msgs/msg/TactileState"]
    Header = store.types["std_msgs/msg/Header"]
    Time = store.types["builtin_interfaces/msg/Time"]
    Channel = store.types["sensor_msgs/msg/ChannelFloat32"]
    with Writer(path, version=8, storage_plugin=StoragePlugin.MCAP) as writer:
        for topic, messages in topics.items():
            connection = writer.add_connection(
                topic, "tactile_msgs/msg/TactileState", typestore=store
            )
            for ns, channels in messages:
                msg = State(
                    Header(Time(ns // 10**9, ns % 10**9), "hand"),
                    [Channel(name, np.asarray(v, np.float32)) for name, v in channels],
                )
                data = store.serialize_cdr(msg, "tactile_msgs/msg/TactileState")
                writer.write(connection, ns, data)


def test_a_bag_of_several_sensors_goes_to_the_patches_it_names(tmp_path):
    """Routing: a channel named as a patch (a board's message carrying two patches); a
    lone channel of another name, by the topic's last part; streams keep one origin."""
    store = _typestore()
    skin = small_hand()
    sizes = {p.name: p.n_taxels for p in skin.patches}
    rng = np.random.default_rng(5)
    t0 = 1_763_900_000 * 10**9
    pad = [(t0 + k * 4_000_000, rng.integers(0, 4000, sizes["distal_pad"])) for k in range(6)]
    tip = [(ns, rng.integers(0, 4000, sizes["tip"])) for ns, _ in pad]
    palm = [(t0 + 2_000_000 + k * 20_000_000, rng.integers(0, 4000, sizes["palm_pad"]))
            for k in range(3)]  # fmt: skip
    topics = {
        "/board_a/tactile_states": [
            (ns, [("distal_pad", v), ("tip", w)]) for (ns, v), (_, w) in zip(pad, tip, strict=True)
        ],
        "/hand/palm_pad": [(ns, [("some_sensor", v)]) for ns, v in palm],
    }
    _bag(tmp_path / "bag", store, topics)
    back, summary = read_robot_bag(tmp_path / "bag", skin=skin)
    assert summary["frames"] == {"distal_pad": 6, "tip": 6, "palm_pad": 3}
    assert summary["messages"] == 9
    assert summary["missing"] == ["finger_skin"]
    for name, sent in (("distal_pad", pad), ("tip", tip), ("palm_pad", palm)):
        frames = back.streams[name].frames.reshape(len(sent), -1)
        np.testing.assert_array_equal(frames, [v for _, v in sent])
    # one origin: the earliest first stamp of all streams (the board's), to the ns
    np.testing.assert_allclose(back.streams["palm_pad"].time_s, [0.002, 0.022, 0.042], atol=1e-9)
    np.testing.assert_allclose(back.streams["tip"].time_s[1], 0.004, atol=1e-9)
    assert back.streams["palm_pad"].host_time_s[0] == pytest.approx(1_763_900_000.002, abs=1e-6)


@pytest.mark.parametrize(
    "topics, message",
    [
        ({"/hand/unknown": [(10**18, [("something", np.zeros(32))])]}, "name a patch"),
        ({"/hand/tip": [(10**18, [("x", np.zeros(5))])]}, "has 12 taxels"),
    ],
)
def test_a_bag_that_names_no_patch_is_refused(tmp_path, topics, message):
    from tactsense.interop._build import ImportError_

    _bag(tmp_path / "bag", _typestore(), topics)
    with pytest.raises(ImportError_, match=message):
        read_robot_bag(tmp_path / "bag", skin=small_hand())


def test_topic_tokens_are_ros2_names():
    assert topic_token("palm-0.left") == "palm_0_left"
    assert topic_token("3rd_pad") == "_3rd_pad"


@pytest.mark.parametrize("fmt", ["mcap", "lerobot"])
def test_an_interrupted_export_leaves_nothing(simulated, tmp_path, monkeypatch, fmt):
    """Ctrl-C in the middle of the work: exit status 1, no output, no temporary file."""
    import tactsense.interop.robot_lerobot as robot_lerobot
    import tactsense.interop.robot_mcap as robot_mcap

    folder = simulated[0]

    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    if fmt == "mcap":
        monkeypatch.setattr(robot_mcap, "iter_patch_contacts", interrupted)
        out = tmp_path / "hand.mcap"
    else:
        monkeypatch.setattr(robot_lerobot, "_write_json", interrupted)
        out = tmp_path / "ds"
    result = runner.invoke(app, ["export", str(folder), "--format", fmt, "--out", str(out)])
    assert result.exit_code == 1, result.output
    assert "interrupted" in result.output
    assert list(tmp_path.iterdir()) == []


def test_a_capture_is_stamped_with_its_aligned_clock(captured, tmp_path, monkeypatch):
    """With the capture's clock fit (``aligned_times``; here a stand-in: the device clock
    plus an offset), every header stamp is the frame's scan on the host clock and every
    log time its arrival, to the nanosecond."""
    import tactsense.io.robot_recording as robot_recording_module

    folder, _, recording = captured
    offset = 1_763_900_000.25

    def aligned_times(path, patch):
        return offset + recording.streams[patch].device_time_us * 1e-6

    monkeypatch.setattr(robot_recording_module, "aligned_times", aligned_times, raising=False)
    # without a clock fit in the manifest, the arrival times stay the stamps
    assert export_robot_mcap(folder, tmp_path / "plain.mcap", contacts=False)["clock"] == "host"
    fitted = tmp_path / "fitted"
    shutil.copytree(folder, fitted)
    manifest = read_manifest(fitted)
    for entry in manifest["devices"].values():
        entry["clock"] = {"offset_s": offset, "drift_ppm": 0.0, "residual_s": 0.0}
    write_manifest(fitted, manifest)
    out = tmp_path / "aligned.mcap"
    counts = export_robot_mcap(fitted, out, contacts=False)
    assert counts["clock"] == "aligned"
    store = _typestore()
    seen = {}
    for _, schema, log_time, data in _messages(out):
        msg = store.deserialize_cdr(data, schema)
        stamp = msg.header.stamp.sec * 1_000_000_000 + msg.header.stamp.nanosec
        seen.setdefault(msg.sensors[0].name, []).append((stamp, log_time))
    for name, stream in recording.streams.items():
        stamps, logs = np.array(seen[name]).T
        expected = np.round(aligned_times(folder, name) * 1e9).astype(np.int64)
        np.testing.assert_array_equal(stamps, expected)
        np.testing.assert_array_equal(logs, np.round(stream.host_time_s * 1e9).astype(np.int64))


def test_map_sends_foreign_names_to_patches(tmp_path):
    """A lab's own names: --map CHANNEL=PATCH and --map TOPIC=PATCH, on the command line."""
    store = _typestore()
    skin = small_hand()
    sizes = {p.name: p.n_taxels for p in skin.patches}
    rng = np.random.default_rng(8)
    t0 = 1_763_900_000 * 10**9
    pad = [(t0 + k * 4_000_000, rng.integers(0, 4000, sizes["distal_pad"])) for k in range(4)]
    palm = [(t0 + k * 10_000_000, rng.integers(0, 4000, sizes["palm_pad"])) for k in range(2)]
    topics = {
        "/rh/ff/tactile": [(ns, [("ff_distal", v)]) for ns, v in pad],
        "/rh/palm/tactile": [(ns, [("sensor0", v)]) for ns, v in palm],
    }
    _bag(tmp_path / "bag", store, topics)
    skin_file = tmp_path / "hand.toml"
    skin_file.write_text(skin_to_toml_string(skin))
    out = tmp_path / "run"
    result = runner.invoke(
        app,
        ["import", str(tmp_path / "bag"), "--skin", str(skin_file), "--map",
         "ff_distal=distal_pad", "--map", "/rh/palm/tactile=palm_pad", "--out", str(out)],
    )  # fmt: skip
    assert result.exit_code == 0, result.output
    back = read_robot_recording(out)
    np.testing.assert_array_equal(back.streams["distal_pad"].frames.reshape(4, -1),
                                  [v for _, v in pad])  # fmt: skip
    np.testing.assert_array_equal(back.streams["palm_pad"].frames.reshape(2, -1),
                                  [v for _, v in palm])  # fmt: skip
    assert "6 TactileState messages read, 6 frames kept" in result.output
    # without the map, the names are no patches: refused, nothing written
    result = runner.invoke(
        app, ["import", str(tmp_path / "bag"), "--skin", str(skin_file), "--out",
              str(tmp_path / "other")],
    )  # fmt: skip
    assert result.exit_code == 2 and "ff_distal" in result.output
    assert not (tmp_path / "other").exists()


def test_a_device_that_dropped_out_at_once(tmp_path):
    """A stream of two frames (too few for a baseline) and an empty one: the MCAP export
    writes the short stream's frames without contacts, the LeRobot export leaves the
    empty one out, and both say so."""
    import dataclasses

    recording = robot_recording(rng=4)
    short = recording.streams["palm_pad"]
    recording.streams["palm_pad"] = dataclasses.replace(
        short, frames=short.frames[:2], time_s=short.time_s[:2]
    )
    tip = recording.streams["tip"]
    recording.streams["tip"] = dataclasses.replace(
        tip, frames=tip.frames[:0], time_s=tip.time_s[:0]
    )
    folder = write(tmp_path / "run", recording)
    result = runner.invoke(app, ["export", str(folder), "--out", str(tmp_path / "x.mcap")])
    assert result.exit_code == 0, result.output
    assert "their frames without contacts: palm_pad\n" in result.output
    assert "streams without a frame, left out: tip" in result.output
    assert "frames of 3 patches" in result.output
    back, summary = read_robot_bag(tmp_path / "x.mcap")
    np.testing.assert_array_equal(back.streams["palm_pad"].frames, short.frames[:2])
    assert "tip" not in summary["frames"]
    result = runner.invoke(
        app, ["export", str(folder), "--format", "lerobot", "--out", str(tmp_path / "ds")]
    )
    assert result.exit_code == 0, result.output
    assert "streams without a frame, left out: tip" in result.output


def test_a_real_capture_of_emulated_devices(tmp_path):
    """Emulated boards captured by the capture part (skipped where it is not present):
    the MCAP's header stamps are the capture's aligned times, its log times the arrivals,
    and the recording comes back bit for bit."""
    emulator = pytest.importorskip("tactsense.stream.robot_emulator")
    recorder = pytest.importorskip("tactsense.stream.robot_recorder")
    from tactsense.io.robot_recording import aligned_times
    from tactsense.robot import load_skin
    from tactsense.stream.robot import RobotSources

    skin = load_skin("icub_hand")
    emulators = emulator.device_emulators(skin, drift_ppm=50.0, seed=2)
    running = emulator.start_device_emulators(emulators)
    try:
        sources = RobotSources(skin, {d: r.url for d, r in running.items()})
        run = recorder.record_robot(sources, tmp_path / "run", duration_s=1.5)
    finally:
        for device in running.values():
            device.stop()
    counts = export_robot_mcap(run, tmp_path / "run.mcap", contacts=False)
    assert counts["clock"] == "aligned"
    store = _typestore()
    seen = {}
    for _, schema, log_time, data in _messages(tmp_path / "run.mcap"):
        msg = store.deserialize_cdr(data, schema)
        stamp = msg.header.stamp.sec * 1_000_000_000 + msg.header.stamp.nanosec
        seen.setdefault(msg.sensors[0].name, []).append((stamp, log_time))
    original = read_robot_recording(run)
    back, _ = read_robot_bag(tmp_path / "run.mcap")
    for name, stream in original.streams.items():
        stamps, logs = np.array(seen[name]).T
        np.testing.assert_array_equal(stamps, np.round(aligned_times(run, name) * 1e9))
        np.testing.assert_array_equal(logs, np.round(stream.host_time_s * 1e9))
        np.testing.assert_array_equal(back.streams[name].frames, stream.frames)
        np.testing.assert_array_equal(back.streams[name].device_time_us, stream.device_time_us)
        np.testing.assert_array_equal(back.streams[name].host_time_s, stream.host_time_s)
