"""Foxglove live (issue 37, items 3 and 4): ``live``/``view --foxglove`` serve a Foxglove
WebSocket with the MCAP export's channels, checked by a client in node that a Foxglove
user's tools run: ``@foxglove/ws-protocol``'s ``FoxgloveClient``, the messages decoded
from the advertised ``ros2msg`` schema by ``@foxglove/rosmsg`` and
``@foxglove/rosmsg2-serialization`` (tests/interop/foxglove_node/, installed by the test
into its own folder with ``npm ci``). Every server here binds 127.0.0.1.

Without node and npm the node tests skip, and fail when ``CI`` is set (.ci/run installs
Debian's nodejs and npm).
"""

import base64
import json
import math
import os
import re
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

import tactsense as ts
from tactsense._validation import TactsenseInputError

pytest.importorskip("foxglove")
pytest.importorskip("mcap_ros2")

from mcap.reader import make_reader
from mcap_ros2.decoder import DecoderFactory

from tactsense.interop.foxglove_live import (
    CHANNELS,
    FoxgloveAddressError,
    FoxgloveLive,
    parse_address,
)
from tactsense.interop.mcap import export_mcap
from tactsense.stream.reader import StreamFrame

CLI = [sys.executable, "-m", "tactsense_launcher"]
NODE_PACKAGE = Path(__file__).with_name("foxglove_node")
SUBPROTOCOL = "foxglove.sdk.v1"  # what foxglove-sdk's server speaks (docs/foxglove.md)
TOPICS = [topic for topic, _, _ in CHANNELS]
OFFSET_S = 1.8e9  # Unix time of the first frame: the stamps of the in-process runs [s]


# ---- the node client --------------------------------------------------------------------


@pytest.fixture(scope="module")
def node_client(tmp_path_factory):
    """The client's folder, its packages installed there from the lock file (npm ci)."""
    node, npm = shutil.which("node"), shutil.which("npm")
    if node is None or npm is None:
        if os.environ.get("CI"):
            pytest.fail("no node/npm and CI is set: .ci/run must install Debian's nodejs, npm")
        pytest.skip("no node/npm (apt-get install nodejs npm) and CI is unset")
    folder = tmp_path_factory.mktemp("foxglove_node")
    for name in ("package.json", "package-lock.json", "client.js"):
        shutil.copy(NODE_PACKAGE / name, folder / name)
    result = subprocess.run(
        [npm, "ci", "--no-audit", "--no-fund", "--loglevel=error"],
        cwd=folder, capture_output=True, text=True, timeout=300,
    )  # fmt: skip
    assert result.returncode == 0, result.stderr
    return folder


def start_client(folder: Path, url: str, counts: dict, timeout_s: float = 60.0):
    """``node client.js`` subscribing to ``counts``' topics; returns the process."""
    return subprocess.Popen(
        ["node", str(folder / "client.js"), url, SUBPROTOCOL, json.dumps(counts),
         str(int(timeout_s * 1000))],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
    )  # fmt: skip


def client_output(process, timeout_s: float = 90.0) -> list[dict]:
    out, err = process.communicate(timeout=timeout_s)
    lines = [json.loads(line) for line in out.splitlines()]
    assert process.returncode == 0, (lines[-3:], err[-2000:])
    return lines


def wait_subscribed(server: FoxgloveLive, process, timeout_s: float = 30.0) -> None:
    """Until the client has subscribed to every channel (the server sees a sink on each)."""
    deadline = time.monotonic() + timeout_s
    while not all(channel.has_sinks() for channel in server.channels.values()):
        assert process.poll() is None, process.communicate()
        assert time.monotonic() < deadline, "the node client did not subscribe"
        time.sleep(0.05)


def messages_by_topic(lines: list[dict]) -> dict[str, list[dict]]:
    got = {topic: [] for topic in TOPICS}
    for line in lines:
        if line["op"] == "message":
            got[line["topic"]].append(line)
    return got


def mcap_messages(path: Path) -> dict[str, list]:
    """(schema, channel, message, decoded) per topic, as mcap's own reader gives them."""
    got = {topic: [] for topic in TOPICS}
    with open(path, "rb") as stream:
        reader = make_reader(stream, decoder_factories=[DecoderFactory()])
        for item in reader.iter_decoded_messages():
            got[item[1].topic].append(item)
    return got


def plain(value):
    """A decoded ROS 2 message (mcap_ros2's objects) as JSON-like dicts and lists."""
    if hasattr(value, "__slots__"):
        return {name: plain(getattr(value, name)) for name in value.__slots__}
    if isinstance(value, list | tuple | np.ndarray):
        return [plain(v) for v in value]
    return value


def push_recording(server, spec, rec, locator) -> int:
    """Push a recording's frames as a stream would deliver them, stamped OFFSET_S on."""
    contacts = 0
    for k in range(len(rec.frames)):
        frame = StreamFrame(k, k, float(rec.time_s[k]), float(rec.time_s[k]) + OFFSET_S,
                            time.perf_counter(), rec.frames[k])  # fmt: skip
        before = server.contacts
        server.push(frame, locator(frame))
        contacts += server.contacts - before
        time.sleep(0.001)  # a client's backlog (1024 messages) never fills
    return contacts


# ---- the address and the bind -----------------------------------------------------------


@pytest.mark.parametrize(
    "text, expected",
    [
        ("8765", ("127.0.0.1", 8765)),
        ("0", ("127.0.0.1", 0)),
        ("localhost:9000", ("localhost", 9000)),
        ("0.0.0.0:8765", ("0.0.0.0", 8765)),
        ("[::1]:8765", ("::1", 8765)),
    ],
)
def test_address_parsing(text, expected):
    assert parse_address(text) == expected


@pytest.mark.parametrize("text", ["", "abc", "70000", "-1", ":8765", "::1:8765", "host:", "a b:1"])
def test_bad_addresses_are_one_line_errors(text):
    with pytest.raises(FoxgloveAddressError, match="--foxglove"):
        parse_address(text)


def _listening_addresses(port: int) -> set[str]:
    """Local addresses listening on ``port`` (Linux: /proc/net/tcp, /proc/net/tcp6)."""
    found = set()
    for table in ("/proc/net/tcp", "/proc/net/tcp6"):
        if not os.path.exists(table):
            continue
        for line in Path(table).read_text().splitlines()[1:]:
            local, state = line.split()[1], line.split()[3]
            address, hex_port = local.split(":")
            if state == "0A" and int(hex_port, 16) == port:  # 0A: LISTEN
                found.add(address)
    return found


@pytest.mark.skipif(not os.path.exists("/proc/net/tcp"), reason="reads Linux's socket table")
def test_the_server_binds_loopback_unless_told():
    with FoxgloveLive(ts.preset("pad16"), port=0) as server:
        assert server.url == f"ws://127.0.0.1:{server.port}"
        # 127.0.0.1 in /proc/net/tcp: 0100007F (little-endian hex); nothing else listens
        assert _listening_addresses(server.port) == {"0100007F"}


def test_a_port_in_use_is_a_one_line_error():
    with FoxgloveLive(ts.preset("pad16"), port=0) as first:
        in_use = f"cannot serve Foxglove on 127.0.0.1:{first.port}"
        with pytest.raises(TactsenseInputError, match=in_use):
            FoxgloveLive(ts.preset("pad16"), port=first.port)


def check_against_export(lines: list[dict], expected: dict) -> None:
    """Every channel advertised with the export's schema, and every message the client
    got the export's (same order): log time, bytes, and what Foxglove's decoder reads
    equal to what mcap's reader decodes from the file."""
    assert lines[0] == {"op": "open", "protocol": SUBPROTOCOL}
    advertised = {line["channel"]["topic"]: line["channel"] for line in lines
                  if line["op"] == "advertise"}  # fmt: skip
    got = messages_by_topic(lines)
    for topic in TOPICS:
        schema, channel = expected[topic][0][0], expected[topic][0][1]
        fox = advertised[topic]
        assert (fox["schemaName"], fox["schemaEncoding"], fox["encoding"]) == (
            schema.name, schema.encoding, channel.message_encoding)  # fmt: skip
        assert fox["schema"].encode() == schema.data
        assert len(got[topic]) == len(expected[topic])
        for line, (_, _, message, decoded) in zip(got[topic], expected[topic], strict=True):
            assert int(line["timestamp"]) == message.log_time
            assert base64.b64decode(line["data"]) == message.data
            assert line["decoded"] == plain(decoded)


# ---- in process: every message, byte for byte the MCAP export's ------------------------


@pytest.fixture(scope="module")
def finger_recording(tmp_path_factory):
    spec = ts.fearing1990_initial()
    rec = ts.simulate(spec, ts.probe_sweep(spec, lift_s=0.5), rng=2)
    path = tmp_path_factory.mktemp("fox") / "finger.h5"
    ts.write_recording(path, rec)
    return spec, rec, path


def test_finger_live_equals_the_mcap_export(tmp_path, node_client, finger_recording):
    """A finger's frames and contacts, live: the node client gets every message, and each
    is the MCAP export's of the same recording (stamps: recording time + OFFSET_S, as
    ``export --start-time``): the same schema (name, encoding, text), topic, encoding,
    log time and bytes; and Foxglove's own decoder reads from it what mcap's reader
    decodes from the file."""
    from tactsense.stream.live import LiveLocator

    spec, rec, path = finger_recording
    export = tmp_path / "finger.mcap"
    summary = export_mcap(path, export, start_time_s=OFFSET_S)
    expected = mcap_messages(export)
    counts = {topic: len(expected[topic]) for topic in TOPICS}
    assert counts["/tactile_states"] == len(rec.frames) and summary["contacts"] > 100
    with FoxgloveLive(spec, port=0) as server:
        client = start_client(node_client, server.url, counts)
        wait_subscribed(server, client)
        push_recording(server, spec, rec, LiveLocator(spec, baseline_frames=5))
        lines = client_output(client)
    check_against_export(lines, expected)


@pytest.fixture(scope="module", params=["pad16", "dome12"])
def pad_recording(tmp_path_factory, request):
    """Two probes on a pad and on a point set, the sensor saying its creep is known, as
    the emulator's identity says it (a simulated recording's sensor does not: the live
    locator then leaves the creep in, while the batch export takes the simulation's out,
    and their contacts differ; through the emulator ``live`` equals ``locate``)."""
    import dataclasses

    from tactsense.flat_scenarios import two_probes

    spec = ts.preset(request.param)
    spec = spec.replace(flaws=dataclasses.replace(spec.flaws, creep_known=True))
    rec = ts.simulate(spec, two_probes(spec), rng=2)
    path = tmp_path_factory.mktemp("fox") / f"{request.param}.h5"
    ts.write_recording(path, rec)
    return spec, rec, path


def test_pad_live_equals_the_export_and_contacts_the_estimates(
    tmp_path, node_client, pad_recording
):
    """A pad and a point set, several contacts a frame: every message the MCAP export's
    (as the finger's); and, independently of the export, each contact what ``live``'s
    locator estimated, decoded by Foxglove's decoder (name ``<sensor>/<id>``, position
    [m], the outward normal of the taxel nearest the contact (a pad's: +z), force
    -force_n * normal [N], torque position x force [N m]), its bytes those of
    mcap-ros2-support's encoder for that message."""
    from mcap_ros2._dynamic import serialize_dynamic

    from tactsense.interop.ros import TACTILE_CONTACT, TACTILE_CONTACT_MSGDEF
    from tactsense.stream.live import LiveContacts

    spec, rec, path = pad_recording
    export = tmp_path / "pad.mcap"
    export_mcap(path, export, start_time_s=OFFSET_S)
    expected = mcap_messages(export)
    counts = {topic: len(expected[topic]) for topic in TOPICS}
    assert counts["/tactile_contacts"] > len(rec.frames) / 2
    estimates = {}
    locator = LiveContacts(spec, baseline_frames=5, drift_s=2.0)

    def keep(frame):
        estimate = locator(frame)
        estimates[frame.sequence] = estimate
        return estimate

    with FoxgloveLive(spec, port=0) as server:
        client = start_client(node_client, server.url, counts)
        wait_subscribed(server, client)
        push_recording(server, spec, rec, keep)
        lines = client_output(client)
    check_against_export(lines, expected)
    got = messages_by_topic(lines)
    encode = serialize_dynamic(TACTILE_CONTACT, TACTILE_CONTACT_MSGDEF)[TACTILE_CONTACT]
    positions, normals = spec.taxel_positions_mm(), spec.taxel_normals()
    if spec.name == "pad16":
        assert (normals == [0.0, 0.0, 1.0]).all()  # a pad's outward normal is +z
    contacts = iter(got["/tactile_contacts"])
    lists = iter(got["/contact_states"])
    for k in range(len(rec.frames)):
        ns = round((float(rec.time_s[k]) + OFFSET_S) * 1e9)
        stamp = {"sec": ns // 10**9, "nanosec": ns % 10**9}
        listed = next(lists)
        assert int(listed["timestamp"]) == ns
        estimate = estimates[k]
        mine = [] if estimate is None else estimate["contacts"]
        assert len(listed["decoded"]["contacts"]) == len(mine)
        for c, in_list in zip(mine, listed["decoded"]["contacts"], strict=True):
            line = next(contacts)
            point = [c["x_mm"] * 1e-3, c["y_mm"] * 1e-3, c["z_mm"] * 1e-3]
            nearest = np.argmin(np.linalg.norm(positions - np.array(point) * 1e3, axis=1))
            normal = normals[nearest]
            force = (-c["force_n"] * normal).tolist()  # upstream: what the object applies
            torque = np.cross(point, force).tolist()
            message = {
                "header": {"stamp": stamp, "frame_id": "finger"},
                "name": f"{spec.name}/{c['id']}",
                "position": dict(zip("xyz", point, strict=True)),
                "normal": dict(zip("xyz", normal.tolist(), strict=True)),
                "wrench": {"force": dict(zip("xyz", force, strict=True)),
                           "torque": dict(zip("xyz", torque, strict=True))},
            }  # fmt: skip
            assert int(line["timestamp"]) == ns
            assert line["decoded"] == in_list == message
            assert base64.b64decode(line["data"]) == bytes(encode(message))
    assert next(contacts, None) is None


# ---- the commands --------------------------------------------------------------------------


def _foxglove_url(process, timeout_s: float = 120.0) -> str:
    """The ``foxglove: ws://...`` line a command prints on standard error."""
    deadline = time.monotonic() + timeout_s
    seen = []
    while time.monotonic() < deadline:
        line = process.stderr.readline()
        if not line:
            raise AssertionError(f"no Foxglove address printed: {seen}")
        seen.append(line)
        if line.startswith("foxglove: ws://"):
            return line.split()[1]
    raise AssertionError(f"no Foxglove address printed: {seen}")


def _stop(process) -> None:
    if process.poll() is None:
        process.send_signal(signal.SIGINT)
        try:
            process.wait(20)
        except subprocess.TimeoutExpired:
            process.kill()
            process.wait()


def _frame_index(rec, values) -> int:
    """The recording frame whose counts are ``values`` (float32 as sent), exactly."""
    flat = rec.frames.reshape(len(rec.frames), -1).astype(np.float32)
    hits = np.flatnonzero((flat == np.asarray(values, dtype=np.float32)).all(axis=1))
    assert len(hits) >= 1, "a frame that is not the recording's"
    return int(hits[0])


def test_live_command_serves_foxglove(tmp_path, node_client, finger_recording):
    """``tactsense live SOURCE --foxglove 127.0.0.1:0`` with the emulator playing a
    recording: each frame Foxglove gets is one of the recording's, stamped with the
    arrival ``live`` reports for it, and each contact is ``live``'s estimate of that
    frame (force, and the contact's name)."""
    spec, rec, path = finger_recording
    emulator = subprocess.Popen(
        [*CLI, "emulate", "--recording", str(path), "--port", "0", "--speed", "0.5", "--loop"],
        stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True,
    )  # fmt: skip
    live = client = None
    estimates = tmp_path / "live.jsonl"
    try:
        url = emulator.stdout.readline().strip()
        assert url.startswith("socket://127.0.0.1:"), url
        live = subprocess.Popen(
            [*CLI, "live", url, "--foxglove", "127.0.0.1:0", "--out", str(estimates)],
            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
        )  # fmt: skip
        fox = _foxglove_url(live)
        assert fox.startswith("ws://127.0.0.1:")
        counts = {"/tactile_states": 40, "/tactile_contacts": 20, "/contact_states": 40}
        client = start_client(node_client, fox, counts, timeout_s=90)
        lines = client_output(client, timeout_s=120)
    finally:
        for process in (client, live, emulator):
            if process is not None:
                _stop(process)
    rest = live.stderr.read()
    assert live.returncode == 0, rest
    sent = re.search(r"foxglove: sent (\d+) frames and (\d+) contacts", rest)
    assert sent is not None, rest
    by_ns = {}
    for line in estimates.read_text().splitlines():
        estimate = json.loads(line)
        by_ns[round(estimate["host_time_s"] * 1e9)] = estimate
    got = messages_by_topic(lines)
    assert int(sent[1]) >= len(got["/tactile_states"]) == 40
    assert int(sent[2]) >= len(got["/tactile_contacts"]) == 20
    for line in got["/tactile_states"]:
        sensors = line["decoded"]["sensors"]
        assert [s["name"] for s in sensors] == [spec.name]
        _frame_index(rec, sensors[0]["values"])
        stamp = line["decoded"]["header"]["stamp"]
        assert int(line["timestamp"]) == stamp["sec"] * 10**9 + stamp["nanosec"]
    for line in got["/tactile_contacts"]:
        estimate = by_ns[int(line["timestamp"])]  # a frame live estimated, by its arrival
        force = line["decoded"]["wrench"]["force"]
        magnitude = math.sqrt(sum(v * v for v in force.values()))
        assert magnitude == pytest.approx(estimate["force_n"], rel=1e-12)
        assert line["decoded"]["name"] == spec.name


def test_view_command_serves_foxglove(tmp_path, node_client, finger_recording):
    """``tactsense view REC --foxglove 127.0.0.1:0``: Foxglove gets the frames the page
    plays, each one of the recording's, in order."""
    _, rec, path = finger_recording
    view = subprocess.Popen(
        [*CLI, "view", str(path), "--foxglove", "127.0.0.1:0", "--speed", "0.5"],
        stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
    )  # fmt: skip
    client = None
    try:
        fox = _foxglove_url(view)
        counts = {"/tactile_states": 30, "/contact_states": 30}
        client = start_client(node_client, fox, counts, timeout_s=90)
        lines = client_output(client, timeout_s=120)
    finally:
        for process in (client, view):
            if process is not None:
                _stop(process)
    got = messages_by_topic(lines)
    indices = [_frame_index(rec, line["decoded"]["sensors"][0]["values"])
               for line in got["/tactile_states"]]  # fmt: skip
    assert len(indices) == 30 and np.all(np.diff(indices) == 1), indices


def test_view_foxglove_port_in_use(finger_recording):
    from typer.testing import CliRunner

    from tactsense.cli import app

    with FoxgloveLive(ts.preset("pad16"), port=0) as taken:
        result = CliRunner().invoke(
            app, ["view", str(finger_recording[2]), "--foxglove", f"127.0.0.1:{taken.port}"]
        )
    message = " ".join(result.output.split())
    assert result.exit_code == 2 and "Traceback" not in message
    assert f"cannot serve Foxglove on 127.0.0.1:{taken.port}" in message


# ---- Ctrl-C counts (r6-fix37) ----
class _Frames:
    """A reader of ``n`` frames of ``sensor`` (zeros)."""

    def __init__(self, sensor, n):
        self.sensor, self.n = sensor, n

    def frames(self, max_frames=None, duration_s=None):
        for i in range(self.n):
            yield StreamFrame(i, i, 0.001 * i, 1.7e9 + 0.001 * i, time.perf_counter(),
                              np.zeros(self.sensor.shape))  # fmt: skip


class _Locator:
    """No estimate for the first ``baseline`` frames, then a finger's contact."""

    def __init__(self, baseline):
        self.baseline, self.seen = baseline, 0

    def __call__(self, frame):
        self.seen += 1
        if self.seen <= self.baseline:
            return None
        return {"sequence": int(frame.sequence), "latency_ms": 0.5 + self.seen,
                "force_n": 1.0, "flags": 0, "axial_mm": 5.0, "angle_deg": 0.0}  # fmt: skip


class _Interrupt:
    """An outlet (or a stream) that sends this process SIGINT on its ``at``-th call: the
    signal arrives in the middle of a frame's steps."""

    def __init__(self, at, inner=None):
        self.at, self.calls, self.inner = at, 0, inner

    def push(self, frame, estimate):
        self._tick()

    def write(self, text):
        self._tick()
        self.inner.write(text)

    def flush(self):
        self.inner.flush()

    def _tick(self):
        self.calls += 1
        if self.calls == self.at:
            os.kill(os.getpid(), signal.SIGINT)
            time.sleep(0.01)  # the handler runs here, in the main thread


@pytest.mark.parametrize("where", ["before foxglove", "after foxglove", "writing the line"])
def test_ctrl_c_counts_only_completed_steps(where):
    """A SIGINT between a frame's steps (estimate, publish, write) leaves every count
    equal to what was done: frames given to the locator and published, estimates and
    lines written, the baseline's frames (once counted 6 for a baseline of 5, 307
    estimates for 306 lines, Foxglove 135 frames for 136)."""
    import io
    import threading

    from tactsense import _signals
    from tactsense.cli._live_outputs import LiveFormat, Outlets, write_estimates

    sensor = ts.preset("initial")
    server = FoxgloveLive(sensor, port=0)
    interrupt = _Interrupt(9)
    stream = io.StringIO()
    if where == "before foxglove":
        outlets, out = Outlets(interrupt, server), stream
    elif where == "after foxglove":
        outlets, out = Outlets(server, interrupt), stream
    else:
        outlets, out = Outlets(server), _Interrupt(4, stream)
    latencies, used = [], [0]
    # Python's own SIGINT handler, whatever an earlier test in this process left there
    # (in the full suite one left SIGINT without KeyboardInterrupt)
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        with pytest.raises(KeyboardInterrupt):
            write_estimates(out, _Frames(sensor, 50), _Locator(5), output_format=LiveFormat.jsonl,
                            multi=False, frames=None, duration=None, rezero=threading.Event(),
                            outlets=outlets, latencies=latencies, used=used)  # fmt: skip
    finally:
        server.close()
        _signals.remove_gate()
        signal.signal(signal.SIGINT, previous)
    lines = stream.getvalue().splitlines()
    assert used[0] == 9  # the interrupted frame completed, and no frame after it began
    assert server.frames == used[0]
    assert len(lines) == len(latencies) == used[0] - 5
    assert [json.loads(line)["latency_ms"] for line in lines] == latencies


# ---- /Ctrl-C counts (r6-fix37) ----


# ---- Foxglove bound before the source (r6-fix37) ----
@pytest.mark.parametrize("command", ["live", "view"])
def test_a_foxglove_port_in_use_is_refused_before_the_source_opens(command):
    """The server binds before the source is opened: with a port in use the error is
    Foxglove's, not the source's (nothing listens on port 9, the discard port), so no
    device is touched; a source that fails after the bind leaves the port free again."""
    import socket

    from typer.testing import CliRunner

    from tactsense.cli import app

    source = "socket://127.0.0.1:9"
    with FoxgloveLive(ts.preset("pad16"), port=0) as taken:
        result = CliRunner().invoke(app, [command, source, "--foxglove", str(taken.port)])
    message = " ".join(result.output.split())
    assert result.exit_code == 2 and "Traceback" not in message, message
    assert f"cannot serve Foxglove on 127.0.0.1:{taken.port}" in message
    with socket.socket() as probe:  # a free port, to be taken and given back by the command
        probe.bind(("127.0.0.1", 0))
        port = probe.getsockname()[1]
    result = CliRunner().invoke(app, [command, source, "--foxglove", str(port), "--timeout", "1"])
    message = " ".join(result.output.split())
    assert result.exit_code == 2 and "cannot serve Foxglove" not in message, message
    deadline = time.monotonic() + 5.0  # the SDK's stop releases the port a moment later
    while True:
        try:
            with FoxgloveLive(ts.preset("pad16"), port=port) as again:  # given back
                assert again.port == port
            break
        except TactsenseInputError:
            if time.monotonic() > deadline:
                raise
            time.sleep(0.05)


# ---- /Foxglove bound before the source (r6-fix37) ----
