"""The live side's bad-input and fault matrix: refusals of values that would record
nothing or be ignored, and devices that misbehave (frames of the wrong shape, no frames
after START, a line that drops mid-recording). Each ends with exit status 2 and one
line naming what was wrong, no traceback, and no empty file at the output name; a
recording cut short keeps its frames and says how many."""

import socket
import threading

import numpy as np
import pytest
from typer.testing import CliRunner

import tactsense as ts
from tactsense.cli import app
from tactsense.io.recording import read_recording
from tactsense.stream.protocol import (
    Kind,
    PacketSplitter,
    decode_packet,
    encode_control,
    encode_frame,
)

runner = CliRunner()


@pytest.fixture(scope="module")
def workspace(tmp_path_factory):
    folder = tmp_path_factory.mktemp("stream_matrix")
    spec = ts.fearing1990_initial()
    ts.write_recording(folder / "rec.h5", ts.simulate(spec, ts.probe_sweep(spec), rng=0))
    return folder


def _check(result, names: str) -> None:
    message = " ".join(result.output.split())  # rich wraps long lines
    assert result.exit_code == 2, message
    assert "Traceback" not in message
    assert names in message, message


BAD_OPTIONS = [
    # (command line, what the message must name)
    ("record loop:// --duration 0 --out OUT", "--duration must be more than 0 s"),
    ("record loop:// --duration nan --out OUT", "--duration must be more than 0 s"),
    ("live loop:// --duration 0", "--duration must be more than 0 s"),
    ("emulate --speed 0", "--speed must be more than 0"),
    ("emulate --speed -2 --port 0", "--speed must be more than 0"),
    ("emulate --recording REC --scenario repeated", "--recording excludes --scenario"),
    ("emulate --recording REC --seed 3 --row 2", "--recording excludes --row, --seed"),
    ("record socket://127.0.0.1:99999 --out OUT", "port 99999 is out of range 1-65535"),
    ("live socket://127.0.0.1:0", "port 0 is out of range 1-65535"),
    ("record socket://127.0.0.1:http --out OUT", "port 'http' is not a number"),
    ("record socket://127.0.0.1 --out OUT", "expected socket://HOST:PORT"),
]


@pytest.mark.parametrize("line, names", BAD_OPTIONS, ids=[line for line, _ in BAD_OPTIONS])
def test_bad_option_values(workspace, line, names):
    out = workspace / "never_written.h5"
    args = line.replace("REC", str(workspace / "rec.h5")).replace("OUT", str(out)).split()
    result = runner.invoke(app, args)
    _check(result, names)
    assert not out.exists()


class FakeDevice:
    """A scripted device on a TCP port: answers IDENTIFY with the initial finger, and
    after START sends ``frames`` frames of shape ``shape``, then closes the line
    (``hang_up``) or goes silent."""

    def __init__(self, *, frames: int, shape=(8, 8), hang_up: bool = True):
        self.spec = ts.fearing1990_initial()
        self.frames, self.shape, self.hang_up = frames, shape, hang_up
        self.server = socket.create_server(("127.0.0.1", 0))
        self.url = f"socket://127.0.0.1:{self.server.getsockname()[1]}"
        self.done = threading.Event()
        self.thread = threading.Thread(target=self._serve, daemon=True)
        self.thread.start()

    def _serve(self) -> None:
        conn, _ = self.server.accept()
        splitter = PacketSplitter()
        counts = np.full(self.shape, 2000, dtype=np.uint16)
        period_us = round(self.spec.scan_period_s * 1e6)
        with conn:
            while not self.done.is_set():
                data = conn.recv(1 << 16)
                if not data:
                    return
                for raw in splitter.feed(data):
                    kind = decode_packet(raw).kind
                    if kind == Kind.IDENTIFY:
                        body = {
                            "rows": 8, "cols": 8, "frame_rate_hz": 7.0,
                            "sensor_toml": self.spec.to_toml_string(),
                        }  # fmt: skip
                        conn.sendall(encode_control(Kind.IDENT, body))
                    elif kind == Kind.START:
                        conn.sendall(
                            b"".join(
                                encode_frame(i, i * period_us, counts) for i in range(self.frames)
                            )
                        )
                        if self.hang_up:
                            return
                    elif kind == Kind.STOP:
                        return

    def close(self) -> None:
        self.done.set()
        self.server.close()


@pytest.fixture
def device():
    made = []

    def make(**options):
        made.append(FakeDevice(**options))
        return made[-1]

    yield make
    for fake in made:
        fake.close()


def test_frames_of_the_wrong_shape_are_an_error(tmp_path, device):
    fake = device(frames=20, shape=(4, 6), hang_up=False)
    out = tmp_path / "rec.h5"
    result = runner.invoke(app, ["record", fake.url, "--out", str(out), "--quiet"])
    _check(result, "the device sends frames of 4x6 tactels, but the sensor")
    assert "no frame was recorded, nothing written" in " ".join(result.output.split())
    assert not out.exists()


def test_a_device_that_never_streams_is_an_error_after_a_stated_timeout(tmp_path, device):
    fake = device(frames=0, hang_up=False)
    out = tmp_path / "rec.h5"
    result = runner.invoke(app, ["record", fake.url, "--out", str(out), "--quiet"])
    _check(result, "no frame arrived within 5 s of START")
    assert not out.exists()


def test_a_line_that_drops_keeps_the_frames_and_says_how_many(tmp_path, device):
    fake = device(frames=394, hang_up=True)
    out = tmp_path / "rec.h5"
    result = runner.invoke(app, ["record", fake.url, "--out", str(out), "--quiet"])
    _check(result, f"socket disconnected; kept 394 frames in {out}")
    rec = read_recording(out)
    assert len(rec) == 394 and rec.closed_cleanly
    np.testing.assert_array_equal(rec.sequence, np.arange(394))


def test_a_line_that_drops_before_any_frame_leaves_no_file(tmp_path, device):
    fake = device(frames=0, hang_up=True)
    out = tmp_path / "rec.h5"
    result = runner.invoke(app, ["record", fake.url, "--out", str(out), "--quiet"])
    _check(result, "no frame was recorded, nothing written")
    assert not out.exists()
