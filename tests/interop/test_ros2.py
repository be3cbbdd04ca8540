"""``tactsense live --ros2``: a ROS 2 node over DDS, checked by an independent subscriber
in another process (``ros2_subscriber.py``, written from the upstream ``.msg`` texts) and
by rosbags' CDR serialiser; DDS on 127.0.0.1 with multicast off throughout."""

import json
import os
import random
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

pytest.importorskip("cyclonedds")
pytest.importorskip("rosbags")

import tactsense as ts
from tactsense import flat_scenarios as fs
from tactsense.cli import app
from tactsense.interop.ros2 import (
    LOOPBACK_XML,
    Ros2Publisher,
    is_loopback_only,
    loopback_config,
)
from tactsense.interop.ros2 import publisher as publisher_module
from tactsense.stream.reader import StreamFrame

from ..stream.test_record import CLI, emulator  # noqa: F401  (the fixture)
from .ros2_subscriber import TOPIC_TYPES, typestore

SUBSCRIBER = Path(__file__).with_name("ros2_subscriber.py")
runner = CliRunner()


@pytest.fixture(autouse=True)
def loopback_dds(tmp_path, monkeypatch):
    """Every participant of a test (this process's and the subscriber's) reads the
    loopback-only configuration from CYCLONEDDS_URI, on a domain of its own. A
    participant this process starts without a loopback-only configuration (its domain's,
    else CYCLONEDDS_URI) fails the test as it starts; and after the test, every
    configuration the publisher started with is checked again."""
    from cyclonedds import domain as dds

    path = loopback_config(tmp_path)
    monkeypatch.setenv("CYCLONEDDS_URI", f"file://{path}")
    monkeypatch.setenv("ROS_DOMAIN_ID", str(random.randint(100, 230)))
    monkeypatch.delenv("ROS_DISTRO", raising=False)
    before = len(publisher_module.started_configs)
    domains: dict[int, str | None] = {}
    make_domain, make_participant = dds.Domain.__init__, dds.DomainParticipant.__init__

    def domain(self, domain_id, config=None):
        domains[domain_id] = config
        make_domain(self, domain_id, config)

    def participant(self, domain_id=dds.dds_domain_default, *args, **kwargs):
        config = domains.get(domain_id) or os.environ.get("CYCLONEDDS_URI")
        if not (config and is_loopback_only(config)):
            pytest.fail("a DDS participant started without the loopback-only configuration")
        make_participant(self, domain_id, *args, **kwargs)

    monkeypatch.setattr(dds.Domain, "__init__", domain)
    monkeypatch.setattr(dds.DomainParticipant, "__init__", participant)
    yield
    started = publisher_module.started_configs[before:]
    assert all(is_loopback_only(config) for config in started), "a participant left loopback"


@pytest.fixture(scope="module")
def store():
    return typestore()


def _subscribe(tmp_path, namespace, count, seconds=60.0):
    out = tmp_path / "received.pickle"
    process = subprocess.Popen(
        [sys.executable, str(SUBSCRIBER), str(out), "--domain", os.environ["ROS_DOMAIN_ID"],
         "--namespace", namespace, "--count", str(count), "--seconds", str(seconds)],
        stdout=subprocess.PIPE, text=True, env=dict(os.environ),
    )  # fmt: skip
    assert process.stdout.readline().strip() == "ready"
    return process, out


def _strip(raw: bytes, cdr: bytes) -> bytes:
    """The raw sample without the padding to 4 bytes a DDS writer adds after the CDR."""
    assert raw[: len(cdr)] == cdr and set(raw[len(cdr) :]) <= {0} and len(raw) - len(cdr) < 4
    return raw[: len(cdr)]


def test_live_ros2_every_sample_bit_for_bit(emulator, tmp_path, store):  # noqa: F811
    """pad16, two probes pressing: every frame reaches the other process on the four
    topics, and each sample is, bit for bit, the frame's counts and the contacts 'live'
    located (its JSON lines, written at the same time); rosbags re-serialises every
    decoded sample to the very bytes received; the node is on the graph."""
    import pickle

    pad = ts.preset("pad16")
    truth = ts.simulate(pad, fs.two_probes(pad), rng=0)
    n = truth.frames.shape[0]
    namespace = "/test_ros2/pad"
    process, out = _subscribe(tmp_path, namespace, n)
    url = emulator("--sensor", "pad16", "--scenario", "two-probes", "--speed", "5")
    lines = tmp_path / "live.jsonl"
    result = runner.invoke(
        app, ["live", url, "--ros2", "--namespace", namespace, "--out", str(lines),
              "--frames", str(n)],
    )  # fmt: skip
    assert result.exit_code == 0, result.output
    assert process.wait(90) == 0
    received = pickle.loads(out.read_bytes())
    assert f"{n} frames on {namespace}" in result.output
    assert f"{4 * n} samples sent, 0 not sent" in result.output
    assert received["lost"] == dict.fromkeys(TOPIC_TYPES, 0)
    for topic in TOPIC_TYPES:  # every sample, none lost
        assert len(received["received"][topic]) == n, topic

    decoded = {}
    for topic, ros_type in TOPIC_TYPES.items():
        decoded[topic] = []
        for *_, raw in received["received"][topic]:
            message = store.deserialize_cdr(raw, ros_type)
            _strip(raw, bytes(store.serialize_cdr(message, ros_type)))  # rosbags' bytes
            decoded[topic].append(message)
    # frames: the recording's counts, row-major, as float32, bit for bit
    states = decoded["tactile_states"]
    for k, message in enumerate(states):
        (channel,) = message.sensors
        assert channel.name == "pad16" and message.header.frame_id == "finger"
        np.testing.assert_array_equal(channel.values, truth.frames[k].ravel().astype(np.float32))
        image = decoded["tactile_image"][k]
        assert (image.height, image.width, image.encoding, image.step) == (16, 16, "32FC1", 64)
        assert image.is_bigendian == 0
        assert image.data.tobytes() == truth.frames[k].astype("<f4").tobytes()
    # every sample of a frame carries that frame's stamp; stamps are distinct, rising
    stamps = [m.header.stamp.sec * 10**9 + m.header.stamp.nanosec for m in states]
    assert np.all(np.diff(stamps) > 0)
    for topic in ("tactile_image", "wrench"):
        got = [m.header.stamp.sec * 10**9 + m.header.stamp.nanosec for m in decoded[topic]]
        assert got == stamps
    # contacts: what live located (its JSON lines), bit for bit (repr round-trips floats)
    rows = {r["sequence"]: r for r in map(json.loads, lines.read_text().splitlines())}
    normals = pad.taxel_normals()
    positions = pad.taxel_positions_mm()
    seen_two = 0
    for k, message in enumerate(decoded["contact_states"]):
        contacts = rows[k]["contacts"] if k in rows else []
        assert len(message.contacts) == len(contacts)
        seen_two += len(contacts) == 2
        wrench = np.zeros(6)
        for got, want in zip(message.contacts, contacts, strict=True):
            assert got.name == f"pad16/{want['id']}"
            assert got.header.stamp.sec * 10**9 + got.header.stamp.nanosec == stamps[k]
            xyz = np.array([want["x_mm"], want["y_mm"], want["z_mm"]])
            normal = normals[np.argmin(((positions - xyz) ** 2).sum(axis=1))]
            point = xyz * 1e-3
            force = -want["force_n"] * normal
            torque = np.array([point[1] * force[2] - point[2] * force[1],
                               point[2] * force[0] - point[0] * force[2],
                               point[0] * force[1] - point[1] * force[0]])  # fmt: skip
            p, v = got.position, got.normal
            f, t = got.wrench.force, got.wrench.torque
            assert [p.x, p.y, p.z] == point.tolist() and [v.x, v.y, v.z] == normal.tolist()
            assert [f.x, f.y, f.z] == force.tolist() and [t.x, t.y, t.z] == torque.tolist()
            wrench += np.concatenate([force, torque])
        w = decoded["wrench"][k].wrench
        got_total = [w.force.x, w.force.y, w.force.z, w.torque.x, w.torque.y, w.torque.z]
        assert got_total == wrench.tolist()
    assert seen_two > 10  # the two probes were published as two named contacts
    # and what 'tactsense locate' computes on the same frames (a recording of them, its
    # creep described as the emulator's identity says), bit for bit: parquet keeps float64
    import dataclasses

    import pyarrow.parquet as pq

    known = pad.replace(flaws=dataclasses.replace(pad.flaws, creep_known=True))
    same = ts.simulate(known, fs.two_probes(known), rng=0)
    np.testing.assert_array_equal(same.frames, truth.frames)
    ts.write_recording(tmp_path / "same.h5", same)
    located = tmp_path / "located.parquet"
    result = runner.invoke(app, ["locate", str(tmp_path / "same.h5"), "-o", str(located)])
    assert result.exit_code == 0, result.output
    table = pq.read_table(located).to_pylist()
    by_frame: dict[int, list[dict]] = {}
    for row in table:
        by_frame.setdefault(row["frame"], []).append(row)
    compared = 0
    for k, message in enumerate(decoded["contact_states"]):
        rows_k = sorted(by_frame.get(k, []), key=lambda r: r["contact"])
        assert [c.name for c in message.contacts] == [f"pad16/{r['id']}" for r in rows_k], k
        for got, want in zip(message.contacts, rows_k, strict=True):
            xyz = np.array([want["x_mm"], want["y_mm"], want["z_mm"]]) * 1e-3
            assert [got.position.x, got.position.y, got.position.z] == xyz.tolist()
            assert -got.wrench.force.z == want["force_n"]  # a pad's normal is +z
            compared += 1
    assert compared == len(table) > 2 * 10
    # a pair of contacts of one frame never share a name
    for message in decoded["contact_states"]:
        names = [c.name for c in message.contacts]
        assert len(set(names)) == len(names)

    # the node as ROS 2 sees it: names, types and QoS on the wire, enclave, discovery
    publications = [
        p for p in received["publications"].values() if p["topic"] != "ros_discovery_info"
    ]
    mine = {p["topic"]: p for p in publications if p["topic"].startswith("rt" + namespace)}
    assert set(mine) == {f"rt{namespace}/{t}" for t in TOPIC_TYPES}
    for topic, ros_type in TOPIC_TYPES.items():
        package, _, name = ros_type.split("/")
        p = mine[f"rt{namespace}/{topic}"]
        assert p["type"] == f"{package}::msg::dds_::{name}_"
        assert "BestEffort" in p["reliability"] and "KeepLast(depth=5)" in p["history"]
    owner = {p["participant"] for p in mine.values()}
    assert len(owner) == 1
    (participant,) = owner
    assert received["participants"][participant][0] == b"enclave=/;"
    infos = [
        d
        for d in received["discovery"]
        if d["nodes"] and d["nodes"][0][:2] == (namespace, "tactsense")
    ]
    assert infos, received["discovery"]
    import uuid

    assert uuid.UUID(bytes=infos[-1]["gid"]) == uuid.UUID(participant)
    writer_gids = {uuid.UUID(bytes=g) for g in infos[-1]["nodes"][0][2]}
    assert writer_gids == {uuid.UUID(k) for k, p in received["publications"].items()
                           if p["topic"].startswith("rt" + namespace)}  # fmt: skip


def _frame(counts, host_time_s=1_700_000_000.123456789):
    return StreamFrame(0, 0, 0.0, host_time_s, time.perf_counter(), counts)


@pytest.mark.parametrize("name", ["pad16", "initial"])
def test_template_bytes_are_rosbags_bytes(store, name):
    """The publisher's template bytes (a pad's two contacts; the finger's one) equal
    Cyclone DDS's serialiser's and rosbags' serialiser's for the same messages; the
    stamp is the frame's host time to the nanosecond."""
    from tactsense.interop.ros2.messages import Header  # noqa: F401  (the module loads)

    sensor = ts.preset(name)
    publisher = Ros2Publisher(sensor, namespace="/unit", frame_id="link_a")
    try:
        counts = np.arange(np.prod(sensor.shape), dtype=np.uint16).reshape(sensor.shape) + 900
        if sensor.kind == "finger":
            estimate = {"flags": 0, "axial_mm": 3.25, "angle_deg": 12.5, "force_n": 0.4}
        else:
            estimate = {"contacts": [
                {"id": 4, "x_mm": 3.1, "y_mm": 7.7, "z_mm": 0.0, "force_n": 0.25},
                {"id": 11, "x_mm": 9.0, "y_mm": 2.5, "z_mm": 0.0, "force_n": 1.5},
            ]}  # fmt: skip
        frame = _frame(counts)
        fast = publisher.encode(frame, estimate)
        publisher._fast = False
        slow = publisher.encode(frame, estimate)
        for topic, ros_type in TOPIC_TYPES.items():
            reference = bytes(slow[topic].serialize())
            assert fast[topic] == reference + b"\0" * (-len(reference) % 4), topic
            message = store.deserialize_cdr(fast[topic], ros_type)
            assert _strip(fast[topic], bytes(store.serialize_cdr(message, ros_type)))
        state = store.deserialize_cdr(fast["tactile_states"], TOPIC_TYPES["tactile_states"])
        # the host time [s] to the nanosecond nearest its float64 (123456768 ns here)
        expected_ns = divmod(round(frame.host_time_s * 1e9), 10**9)
        assert (state.header.stamp.sec, state.header.stamp.nanosec) == expected_ns
        assert state.header.frame_id == "link_a"
        contacts = store.deserialize_cdr(fast["contact_states"], TOPIC_TYPES["contact_states"])
        expected = 1 if sensor.kind == "finger" else 2
        assert len(contacts.contacts) == expected
        assert len({c.name for c in contacts.contacts}) == expected
    finally:
        publisher.close()


def test_the_loopback_configuration_is_recognised(tmp_path):
    """The loopback check says no to Cyclone DDS's defaults (no interface named, multicast
    allowed), to another interface and to a remote peer."""
    assert is_loopback_only(LOOPBACK_XML) and is_loopback_only(
        f"file://{loopback_config(tmp_path)}"
    )
    assert not is_loopback_only('<CycloneDDS xmlns="https://cdds.io/config"/>')
    for old, new in [
        ("<AllowMulticast>false", "<AllowMulticast>true"),
        ('address="127.0.0.1" multicast', 'address="192.168.1.5" multicast'),
        ('<Peer address="127.0.0.1"/>', '<Peer address="10.0.0.2"/>'),
    ]:
        assert not is_loopback_only(LOOPBACK_XML.replace(old, new)), new


def test_the_subscriber_refuses_to_start_off_loopback(tmp_path, monkeypatch):
    """The independent subscriber starts no participant without a loopback-only
    CYCLONEDDS_URI (exit 3)."""
    monkeypatch.delenv("CYCLONEDDS_URI")
    done = subprocess.run(
        [sys.executable, str(SUBSCRIBER), str(tmp_path / "x"), "--domain", "1",
         "--namespace", "/", "--seconds", "1"], capture_output=True, text=True, timeout=60,
    )  # fmt: skip
    assert done.returncode == 3 and "127.0.0.1" in done.stderr


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--namespace", "/a"], "--namespace applies to --ros2"),
        (["--ros2-config", "x.xml"], "--ros2-config applies to --ros2"),
        (["--ros2", "--namespace", "/1a"], "a ROS 2 namespace is"),
        (["--ros2", "--namespace", "/a b"], "a ROS 2 namespace is"),
        (["--ros2", "--namespace", "/" + "a" * 300], "301 characters; a ROS 2 topic name"),
        (["--ros2", "--namespace", "/" + "a" * 233], "the namespace of these topics at most 232"),
        (["--ros2", "--namespace", "/a/"], "--namespace '/a/': it ends with /"),
        (["--ros2", "--namespace", "a/"], "--namespace 'a/': it ends with /"),
        (["--ros2", "--namespace", "/a//b"], "it has //"),
        (["--ros2", "--ros2-config", "/nonexistent/c.xml"], "cannot read it"),
        (["--ros2", "--ros2-config", "<a/>"], "root element <CycloneDDS>"),
        (["--ros2", "--ros2-config", "<CycloneDDS"], "not XML"),
    ],
)
def test_live_refuses_bad_ros2_options_before_opening_the_line(args, message):
    """Checked before the device is opened (the port named does not exist)."""
    result = runner.invoke(app, ["live", "socket://127.0.0.1:9", *args])
    assert result.exit_code != 0
    assert message in " ".join(result.output.split()), result.output


def test_ci_keeps_dds_on_the_loopback():
    """.ci/run exports a CYCLONEDDS_URI that the loopback check accepts."""
    import re

    run = (Path(__file__).parents[2] / ".ci" / "run").read_text()
    (uri,) = re.findall(r"^export CYCLONEDDS_URI='(.*)'$", run, flags=re.M)
    assert is_loopback_only(uri)


@pytest.mark.parametrize(("distro", "size"), [("humble", 24), ("jazzy", 16), ("", 16)])
def test_discovery_gids_follow_the_distribution(store, distro, size):
    """ros_discovery_info's gids: 24 bytes for Humble (char[24] data), 16 since Iron
    (char[16] data, rmw_dds_common's Gid.msg); the participant's and writers' GUIDs first."""
    publisher = Ros2Publisher(ts.preset("pad16"), namespace="/gid", distro=distro)
    try:
        info = publisher.discovery_info
        assert len(info.gid.data) == size
        guid = publisher.participant.get_guid().bytes
        assert bytes(info.gid.data[:16]) == guid and not any(info.gid.data[16:])
        (node,) = info.node_entities_info_seq
        assert (node.node_namespace, node.node_name) == ("/gid", "tactsense")
        assert len(node.writer_gid_seq) == 4 and node.reader_gid_seq == []
        if size == 16:  # the upstream text decodes what was sent
            raw = bytes(info.serialize())
            back = store.deserialize_cdr(raw, "rmw_dds_common/msg/ParticipantEntitiesInfo")
            assert bytes(back.gid.data) == guid
    finally:
        publisher.close()


def test_live_ros2_finger(emulator, tmp_path, store):  # noqa: F811
    """The paper's finger (one contact a frame): every frame's counts bit for bit, and
    each contact where live's estimate puts it (tactsense.geometry's surface point and
    normal of its axial and angle), named as the sensor."""
    import pickle

    from tactsense.interop.ros import contact_geometry

    n = 60
    namespace = "/test_ros2/finger"
    process, out = _subscribe(tmp_path, namespace, n)
    url = emulator("--speed", "10", "--seed", "4")
    lines = tmp_path / "live.jsonl"
    result = runner.invoke(
        app, ["live", url, "--ros2", "--namespace", namespace, "--out", str(lines),
              "--frames", str(n)],
    )  # fmt: skip
    assert result.exit_code == 0, result.output
    assert process.wait(90) == 0
    received = pickle.loads(out.read_bytes())
    assert {t: len(s) for t, s in received["received"].items()} == dict.fromkeys(TOPIC_TYPES, n)
    sensor = ts.preset("initial")
    rows = {r["sequence"]: r for r in map(json.loads, lines.read_text().splitlines())}
    touched = 0
    for k, (*_, raw) in enumerate(received["received"]["contact_states"]):
        message = store.deserialize_cdr(raw, TOPIC_TYPES["contact_states"])
        row = rows.get(k)
        if row is None or "NO_CONTACT" in row["flag_names"] or row["force_n"] is None:
            assert message.contacts == []
            continue
        touched += 1
        (contact,) = message.contacts
        point, normal = contact_geometry(
            sensor, np.array([row["axial_mm"]]), np.array([row["angle_deg"]])
        )
        p, v = contact.position, contact.normal
        assert contact.name == sensor.name
        assert [p.x, p.y, p.z] == point[0].tolist() and [v.x, v.y, v.z] == normal[0].tolist()
        f = contact.wrench.force
        assert [f.x, f.y, f.z] == (-row["force_n"] * normal[0]).tolist()
    assert touched > 0
    states = [store.deserialize_cdr(raw, TOPIC_TYPES["tactile_states"])
              for *_, raw in received["received"]["tactile_states"]]  # fmt: skip
    # the emulator plays what 'simulate --seed 4' writes (tests/stream/test_record.py)
    simulated = tmp_path / "sim.h5"
    assert runner.invoke(app, ["simulate", "--out", str(simulated), "--seed", "4"]).exit_code == 0
    frames = ts.read_recording(simulated).frames[:n]
    for state, counts in zip(states, frames, strict=True):
        np.testing.assert_array_equal(state.sensors[0].values, counts.ravel().astype(np.float32))


def test_a_participant_off_the_loopback_fails_the_test(monkeypatch):
    """The guard above fires: a configuration with multicast on (given to the publisher,
    as --ros2-config would) stops the participant before it starts."""
    with pytest.raises(pytest.fail.Exception, match="loopback-only"):
        Ros2Publisher(
            ts.preset("pad16"),
            config=LOOPBACK_XML.replace("<AllowMulticast>false", "<AllowMulticast>true"),
        )
    publisher_module.started_configs.pop()  # the refused one, for the fixture's check


# ---- names within ROS 2's bounds (r6-fix37) ----
def test_namespaces_follow_rcl():
    """rcl_node_init: '' is '/', a relative namespace gets a leading '/'; then
    rmw_validate_namespace (no trailing '/', no '//', tokens not starting with a digit)."""
    from tactsense.interop.ros2.publisher import Ros2Error, check_namespace

    assert check_namespace("") == "/"
    assert check_namespace("foo") == "/foo"
    assert check_namespace("foo/bar_1") == "/foo/bar_1"
    assert check_namespace("/") == "/"
    for bad in ("/a/", "//", "/a//b", "/9a", "/a b", "/a-b", "a/"):
        with pytest.raises(Ros2Error):
            check_namespace(bad)


def test_the_longest_namespace_and_node_name_publish(store):
    """A 232-character namespace (the longest whose topics keep within ROS 2's 247) and a
    255-character node name start and announce themselves; one more character is a
    one-line Ros2Error before any DDS entity exists (300 crashed in the announcement)."""
    from tactsense.interop.ros2.publisher import Ros2Error

    sensor = ts.preset("pad16")
    longest = "/" + "n" * 231
    publisher = Ros2Publisher(
        sensor, namespace=longest, node_name="x" * 255, frame_id="f" * 1000
    )  # fmt: skip  (frame_id: unbounded string)
    try:
        assert max(len(t) for t in publisher.ros_topics.values()) == 247
        node = publisher.discovery_info.node_entities_info_seq[0]
        assert (node.node_namespace, node.node_name) == (longest, "x" * 255)
        publisher.publish(_frame(np.zeros(sensor.shape)), None)
        assert publisher.failed == 0
    finally:
        publisher.close()
    before = len(publisher_module.started_configs)
    for kwargs in ({"namespace": longest + "n"}, {"namespace": "/" + "a" * 300},
                   {"namespace": "/a", "node_name": "x" * 256}):  # fmt: skip
        with pytest.raises(Ros2Error, match="characters"):
            Ros2Publisher(sensor, **kwargs)
    assert len(publisher_module.started_configs) == before  # refused before DDS started


@pytest.mark.parametrize(
    ("uri", "message"),
    [
        ("file:///nonexistent.xml", "CYCLONEDDS_URI file:///nonexistent.xml: cannot read it"),
        ("/nonexistent.xml", "CYCLONEDDS_URI /nonexistent.xml: cannot read it"),
        ("TEXT", "CYCLONEDDS_URI TEXT: not XML"),
        ("file://NOT_CYCLONE", "root element <CycloneDDS>"),
    ],
)
def test_a_bad_cyclonedds_uri_file_is_one_line_before_the_line_opens(
    tmp_path, monkeypatch, uri, message
):
    """A CYCLONEDDS_URI naming a file is checked as --ros2-config is (readable, XML,
    <CycloneDDS>), named as CYCLONEDDS_URI, before the device is opened (the port named
    does not exist), not DDS's raw log and 'Non specific error'."""
    text, other = tmp_path / "plain.txt", tmp_path / "other.xml"
    text.write_text("vm\n")
    other.write_text("<Other/>")
    uri = uri.replace("TEXT", str(text)).replace("NOT_CYCLONE", str(other))
    message = message.replace("TEXT", str(text))
    monkeypatch.setenv("CYCLONEDDS_URI", uri)
    result = runner.invoke(app, ["live", "socket://127.0.0.1:9", "--ros2"])
    assert result.exit_code == 2
    output = " ".join(result.output.split())
    assert message in output and "Traceback" not in output, result.output
    assert len(result.output.strip().splitlines()) == 1, result.output  # no DDS log line


def test_ros2_config_reads_a_file_once(tmp_path):
    """--ros2-config of a text file that is not XML says so (its text was once taken for
    a second path)."""
    from tactsense.interop.ros2.config import Ros2ConfigError, resolve_config

    path = tmp_path / "plain.txt"
    path.write_text("vm\n")
    with pytest.raises(Ros2ConfigError, match="not XML"):
        resolve_config(str(path))
    assert resolve_config(loopback_config(tmp_path))[0] == LOOPBACK_XML


# ---- /names within ROS 2's bounds (r6-fix37) ----


# ---- one-line summaries (r6-fix37) ----
def test_live_summaries_are_single_lines_in_a_log(emulator, tmp_path):  # noqa: F811
    """Redirected (CliRunner: not a terminal, 80 columns), every summary line of live
    --ros2 --foxglove is one line: rich once broke 'p99 ... ms' and 'not sent' over
    lines at 80 columns."""
    url = emulator("--speed", "10", "--seed", "4")
    result = runner.invoke(
        app, ["live", url, "--ros2", "--namespace", "/test_ros2/summary", "--foxglove", "0",
              "--out", str(tmp_path / "live.jsonl"), "--frames", "30"],
    )  # fmt: skip
    assert result.exit_code == 0, result.output
    lines = result.output.splitlines()
    (estimates,) = [line for line in lines if " estimates from " in line]
    assert "latency median" in estimates and estimates.endswith(" ms")
    (ros2,) = [line for line in lines if line.startswith("ROS 2: ")]
    assert "not sent" in ros2 and ros2.endswith("(best effort)")
    (sent,) = [line for line in lines if line.startswith("foxglove: sent")]
    assert sent.endswith(" contacts") and max(map(len, (estimates, ros2))) > 80


def test_the_console_keeps_messages_whole_and_tables_laid_out():
    """The shared console (every command's messages) does not wrap a long message when
    redirected; a table is still laid out at the console's width."""
    import io

    from rich.table import Table

    from tactsense.cli._common import _MessageConsole

    out = io.StringIO()
    console = _MessageConsole(file=out, width=80)
    message = "wrote out.h5: " + ", ".join(f"{k} frames lost" for k in range(40))
    console.print(message)
    assert out.getvalue() == message + "\n"
    table = Table("a", "b")
    table.add_row("x " * 60, "y")
    out.seek(0), out.truncate()
    console.print(table)
    assert max(map(len, out.getvalue().splitlines())) <= 80


# ---- /one-line summaries (r6-fix37) ----


# ---- the .msg texts in docs/ros2.md (r6-fix37) ----
def test_the_doc_gives_every_published_msg_text(store):
    """docs/ros2.md holds the upstream .msg text of every tactile type published (the
    texts the independent subscriber is built from, character for character), and of
    sensor_msgs/ChannelFloat32 with the fields of ROS 2's own definition (rosbags')."""
    import re

    from rosbags.typesys import get_types_from_msg

    from .ros2_subscriber import TACTILE_MSGS

    doc = (Path(__file__).parents[2] / "docs" / "ros2.md").read_text()
    blocks = dict(re.findall(r"`([\w/]+)\.msg`[^`]*?:\n\n```\n(.*?)```", doc, flags=re.S))
    for name, text in TACTILE_MSGS.items():
        assert blocks.get(name) == text, name
    name = "sensor_msgs/msg/ChannelFloat32"
    parsed = get_types_from_msg(blocks[name], name)[name]
    assert parsed == store.fielddefs[name]
