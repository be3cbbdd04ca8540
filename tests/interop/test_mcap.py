"""MCAP for ROS 2 and Foxglove: written by tactsense, read back by mcap's own ROS 2 reader
(``mcap_ros2``, CDR decoding from the schema in the file), compared field by field."""

import math

import numpy as np
import pytest
from mcap.reader import make_reader
from mcap_ros2.decoder import DecoderFactory
from typer.testing import CliRunner

import tactsense as ts
from tactsense.cli import app
from tactsense.estimate import Flag
from tactsense.io.recording import write_recording
from tactsense.stream import Emulator

runner = CliRunner()


@pytest.fixture(scope="module")
def sweep(tmp_path_factory, initial):
    rec = ts.simulate(initial, ts.probe_sweep(initial, along="around", dwell_s=0.3), rng=4)
    path = tmp_path_factory.mktemp("mcap") / "sweep.h5"
    write_recording(path, rec)
    return path, rec


class _Message:
    def __init__(self, schema, channel, message, decoded):
        self.schema, self.channel, self.message, self.ros_msg = schema, channel, message, decoded
        self.log_time_ns = message.log_time


def _messages(path):
    states, contacts = [], []
    with open(path, "rb") as stream:
        reader = make_reader(stream, decoder_factories=[DecoderFactory()])
        for m in map(lambda args: _Message(*args), reader.iter_decoded_messages()):
            if m.channel.topic == "/tactile_states":
                states.append(m)
            elif m.channel.topic == "/tactile_contacts":
                contacts.append(m)
    return states, contacts


def test_export_frames_and_contacts_field_by_field(tmp_path, sweep):
    path, rec = sweep
    out = tmp_path / "sweep.mcap"
    result = runner.invoke(app, ["export", str(path), "--out", str(out)])
    assert result.exit_code == 0, result.output
    states, contacts = _messages(out)
    assert len(states) == len(rec)
    assert states[0].schema.name == "tactile_msgs/msg/TactileState"
    for k, m in enumerate(states):
        msg = m.ros_msg
        (channel,) = msg.sensors
        assert channel.name == rec.sensor.name
        np.testing.assert_array_equal(np.asarray(channel.values).reshape(8, 8), rec.frames[k])
        stamp = msg.header.stamp.sec + msg.header.stamp.nanosec * 1e-9
        assert stamp == pytest.approx(rec.time_s[k], abs=1e-9)
        assert m.log_time_ns == round(rec.time_s[k] * 1e9)
        assert msg.header.frame_id == "finger"

    est = ts.locate(rec.frames, rec.sensor, baseline=ts.baseline_from(rec.frames, 5))
    touching = np.flatnonzero(((est.flags & int(Flag.NO_CONTACT)) == 0) & np.isfinite(est.force_n))
    assert len(contacts) == len(touching) > 100
    radius_m = rec.sensor.body.diameter_mm / 2 * 1e-3
    for m, i in zip(contacts, touching, strict=True):
        msg = m.ros_msg
        assert m.schema.name == "tactile_msgs/msg/TactileContact"
        assert m.log_time_ns == round(rec.time_s[i] * 1e9)
        # the cylinder by hand: x along the finger, the angle from +y toward +z
        angle = math.radians(est.angle_deg[i])
        assert est.axial_mm[i] >= 0  # a sweep around row 4: on the cylinder
        expected = (est.axial_mm[i] * 1e-3, radius_m * math.cos(angle), radius_m * math.sin(angle))
        got = (msg.position.x, msg.position.y, msg.position.z)
        np.testing.assert_allclose(got, expected, atol=1e-12)
        normal = (msg.normal.x, msg.normal.y, msg.normal.z)
        np.testing.assert_allclose(normal, (0.0, math.cos(angle), math.sin(angle)), atol=1e-12)
        force = (msg.wrench.force.x, msg.wrench.force.y, msg.wrench.force.z)
        np.testing.assert_allclose(force, -est.force_n[i] * np.asarray(normal), rtol=1e-12)
        # upstream: the wrench in the reference frame; the torque of the force about its
        # origin, position x force, worked by hand component by component
        (px, py, pz), (fx, fy, fz) = got, force
        by_hand = (py * fz - pz * fy, pz * fx - px * fz, px * fy - py * fx)
        torque = (msg.wrench.torque.x, msg.wrench.torque.y, msg.wrench.torque.z)
        np.testing.assert_allclose(torque, by_hand, rtol=1e-12, atol=1e-18)
        assert max(abs(t) for t in torque) > 0  # off the axis, a push has a moment


@pytest.mark.parametrize("name, options", [("live.mcap", []), ("live.bag", ["--format", "mcap"])])
def test_record_writes_mcap_as_frames_arrive(tmp_path, sweep, name, options):
    _, rec = sweep
    emulator = Emulator.from_recording(rec, speed=0)
    _, port = emulator.start_tcp()
    out = tmp_path / name  # by the extension, or any name with --format
    try:
        result = runner.invoke(
            app,
            ["record", f"socket://127.0.0.1:{port}", "--frames", "60", *options,
             "--out", str(out)],
        )  # fmt: skip
    finally:
        emulator.stop()
    assert result.exit_code == 0, result.output
    states, contacts = _messages(out)
    assert contacts == []  # record keeps frames; 'export' adds the contacts
    got = np.stack([np.asarray(m.ros_msg.sensors[0].values).reshape(8, 8) for m in states])
    np.testing.assert_array_equal(got, rec.frames[:60])
    assert [m.message.sequence for m in states] == list(range(60))


def test_export_stamps_on_the_host_clock_and_says_which(tmp_path):
    """Issue 25: a recorded stream is exported on its host times (so the file aligns with
    the lab's other bags), a simulation on its own times plus --start-time; the metadata
    record 'tactsense' names the clock; --frame-id is every header's frame_id."""
    from mcap.reader import make_reader
    from typer.testing import CliRunner

    from tactsense.cli import app
    from tactsense.io.recording import Recording, write_recording

    spec = ts.fearing1990_initial()
    simulated = ts.simulate(spec, ts.probe_sweep(spec), rng=1)
    sim_path = tmp_path / "sim.h5"
    write_recording(sim_path, simulated)
    host = 1_795_000_000.0 + np.arange(len(simulated.frames)) / 7.0 + 0.0123
    streamed = Recording(
        frames=simulated.frames, time_s=simulated.time_s, sample_offset_s=simulated.sample_offset_s,
        sensor=spec, host_time_s=host, sequence=np.arange(len(host), dtype=np.uint16),
    )  # fmt: skip
    rec_path = tmp_path / "rec.h5"
    write_recording(rec_path, streamed)
    runner = CliRunner()
    for path, options, clock, first in (
        (rec_path, [], "host", host[0]),
        (sim_path, ["--start-time", "1700000000"], "recording", 1_700_000_000.0),
    ):
        out = tmp_path / f"{path.stem}.mcap"
        result = runner.invoke(app, ["export", str(path), "--out", str(out), "--frame-id",
                                     "index_tip", *options])  # fmt: skip
        assert result.exit_code == 0, result.output
        assert f"{clock} clock" in result.output
        with open(out, "rb") as stream:
            reader = make_reader(stream)
            (meta,) = [m for m in reader.iter_metadata() if m.name == "tactsense"]
            assert meta.metadata["clock"] == clock
            assert meta.metadata["frame_id"] == "index_tip"
            stamps = [m.log_time for _, c, m in reader.iter_messages(topics=["/tactile_states"])]
        assert stamps[0] == round(first * 1e9)
    refused = runner.invoke(app, ["export", str(rec_path), "--out", str(tmp_path / "x.mcap"),
                                  "--start-time", "5"])  # fmt: skip
    assert refused.exit_code == 2 and "holds host times" in refused.output


# upstream's message texts (ubi-agni/tactile_toolbox, tactile_msgs/msg/*.msg), verbatim
UPSTREAM_TACTILE_CONTACT = """# Message describing the net effect of a single contact

# specify link frame and timestamp of contact
Header header

# unique name of the contact
string name
# contact point location
geometry_msgs/Point position
# surface normal at contact point
geometry_msgs/Vector3 normal
# wrench applied through this contact point
# this wrench should be represented in reference frame, not in contact point frame
geometry_msgs/Wrench wrench
"""
UPSTREAM_TACTILE_CONTACTS = (
    "# Message to publish tactile contact information extracted from raw tactile data.\n"
    """# This msg provides a list of contact points and corresponding
# contact wrenches, both represented w.r.t the link reference frame.

tactile_msgs/TactileContact[] contacts
"""
)
UPSTREAM_TACTILE_STATE = """# specify the timestamp (frame not used)
Header header

# a list of individual, named sensor arrays
sensor_msgs/ChannelFloat32[] sensors
"""


def test_rosbags_decodes_the_export_from_the_upstream_message_text(tmp_path, sweep):
    """Issue 25: rosbags, given only upstream's .msg text (and ROS 2's standard types),
    decodes every message of an exported file; each contact's torque is position x force."""
    from mcap.reader import make_reader
    from rosbags.typesys import Stores, get_types_from_msg, get_typestore
    from typer.testing import CliRunner

    from tactsense.cli import app

    path, _ = sweep
    out = tmp_path / "x.mcap"
    assert CliRunner().invoke(app, ["export", str(path), "--out", str(out)]).exit_code == 0
    store = get_typestore(Stores.ROS2_HUMBLE)
    store.register(get_types_from_msg(UPSTREAM_TACTILE_CONTACT, "tactile_msgs/msg/TactileContact"))
    store.register(get_types_from_msg(UPSTREAM_TACTILE_STATE, "tactile_msgs/msg/TactileState"))
    lists = "tactile_msgs/msg/TactileContacts"
    store.register(get_types_from_msg(UPSTREAM_TACTILE_CONTACTS, lists))
    counts = {"/tactile_states": 0, "/tactile_contacts": 0, "/contact_states": 0}
    with open(out, "rb") as stream:
        for schema, channel, message in make_reader(stream).iter_messages():
            decoded = store.deserialize_cdr(message.data, schema.name)
            counts[channel.topic] += 1
            if channel.topic == "/tactile_contacts":
                p, f = decoded.position, decoded.wrench.force
                expected = np.cross([p.x, p.y, p.z], [f.x, f.y, f.z])
                t = decoded.wrench.torque
                np.testing.assert_allclose([t.x, t.y, t.z], expected, rtol=1e-12, atol=1e-18)
    assert counts["/tactile_states"] > 100 and counts["/tactile_contacts"] > 100
    assert counts["/contact_states"] == counts["/tactile_states"]
