"""The view's server side without a browser: the layout's surface weights, the bounded
hand-over to pages, playback commands, and the real server over a real websocket."""

import json
import time

import numpy as np
import pytest
from websockets.sync.client import connect

import tactsense as ts
from tactsense.estimate.finger.deflection import baseline_from
from tactsense.estimate.finger.interpolate import reconstruct_row
from tactsense.io.recording import write_recording
from tactsense.stream import Emulator, LiveLocator, StreamReader
from tactsense.view import LiveFeed, RecordingFeed, ViewServer, layout_message
from tactsense.view.feed import SURFACE_STEPS
from tactsense.view.server import QUEUE, Hub, _Page, is_loopback


def _surface(layout, z):
    s = layout["surface"]
    first = layout["first_row"]
    return np.asarray(s["w_rows"]) @ np.asarray(z)[first:] @ np.asarray(s["w_cols"]).T


@pytest.mark.parametrize("name", ["initial", "improved"])
def test_surface_weights_pass_through_the_tactels(name):
    """The windowed sinc interpolates: at a tactel's own position the surface is its value."""
    spec = ts.preset(name)
    layout = layout_message(spec, {"kind": "test", "name": "x"})
    rng = np.random.default_rng(1)
    z = rng.random(spec.shape)
    f = _surface(layout, z)
    rows = np.asarray(layout["surface"]["row"])
    cols = np.asarray(layout["surface"]["col"])
    first = layout["first_row"]
    checked = 0
    for k in range(spec.shape[0] - first):
        (i,) = np.flatnonzero(np.abs(rows - k) < 1e-9)[:1]  # one band centred on each tactel
        for c in range(spec.shape[1]):
            (j,) = np.flatnonzero(np.abs(cols - c) < 1e-9)
            assert f[i, j] == pytest.approx(z[first + k, c], abs=2e-6)
            checked += 1
    assert checked == (spec.shape[0] - first) * spec.shape[1]
    assert f.shape == ((spec.shape[0] - first) * SURFACE_STEPS, spec.shape[1] * SURFACE_STEPS)


def test_surface_weights_along_match_the_one_dimensional_reconstruction():
    """Along one column the 2-D weights reduce to eq. 46's row reconstruction (a separate
    implementation in tactsense.estimate.finger.interpolate)."""
    spec = ts.fearing1990_initial()
    layout = layout_message(spec, {"kind": "test", "name": "x"})
    first = layout["first_row"]
    z = np.zeros(spec.shape)
    profile = np.array([0.0, 0.1, 0.7, 1.0, 0.4, 0.05, 0.0])
    z[first:, 3] = profile
    f = _surface(layout, z)
    (j,) = np.flatnonzero(np.abs(np.asarray(layout["surface"]["col"]) - 3.0) < 1e-9)
    rows = np.asarray(layout["surface"]["row"])
    expected = reconstruct_row(profile, rows)
    np.testing.assert_allclose(f[:, j], expected, atol=2e-6)


def test_closed_finger_surface_is_periodic_across_the_seam():
    """A bump on column 0 shows on both sides of the seam (columns 7.5..8 and -0.5..0)."""
    spec = ts.fearing1990_initial()
    assert spec.closes_circumference
    layout = layout_message(spec, {"kind": "test", "name": "x"})
    z = np.zeros(spec.shape)
    z[4, 0] = 1.0
    f = _surface(layout, z)
    cols = np.asarray(layout["surface"]["col"])
    i = int(np.argmax(f.max(axis=1)))
    near_seam = f[i, 0]  # the band just across the seam from column 0 (column -0.44)
    assert near_seam > 0.5 and near_seam == pytest.approx(f[i, np.argmin(np.abs(cols - 0.444))])
    # symmetric about column 0 the long way round: f(y) == f(8 - y)
    for j, y in enumerate(cols):
        if 0 < y < 4:
            target = np.mod(-y + 0.5, 8) - 0.5  # -y, wrapped into the turn the bands cover
            (mirror,) = np.flatnonzero(np.abs(cols - target) < 1e-9)
            assert f[i, j] == pytest.approx(f[i, mirror], abs=1e-6)


def test_hub_memory_is_bounded_for_a_page_that_never_reads():
    import asyncio

    async def run():
        hub = Hub()
        hub.bind(asyncio.get_running_loop())
        page = _Page()
        hub.pages.add(page)
        for k in range(10_000):
            hub.publish(str(k))
            if k % 100 == 0:
                await asyncio.sleep(0)
        await asyncio.sleep(0.05)
        return hub, page

    hub, page = asyncio.run(run())
    assert hub.published + hub.dropped_pending == 10_000
    assert page.queue.qsize() == QUEUE
    assert page.dropped == hub.published - QUEUE
    # the newest messages are the ones kept
    kept = [page.queue.get_nowait() for _ in range(QUEUE)]
    assert kept[-1] == "9999"


@pytest.fixture(scope="module")
def axial_recording(tmp_path_factory, initial):
    rec = ts.simulate(initial, ts.probe_sweep(initial, along="axial", dwell_s=1.0), rng=5)
    assert len(rec) > 250
    path = tmp_path_factory.mktemp("view") / "sweep.h5"
    write_recording(path, rec)
    return path, rec


def _recording_locator(spec, file):
    return LiveLocator(spec, baseline=baseline_from(file.frames(0, 5)), keep_deflection=True)


def _until(condition, timeout_s: float = 10.0) -> None:
    """Wait until ``condition()`` holds (the feed runs in its own thread)."""
    deadline = time.monotonic() + timeout_s
    while not condition():
        assert time.monotonic() < deadline, "timed out"
        time.sleep(0.01)


def test_recording_feed_plays_seeks_and_steps(axial_recording):
    path, rec = axial_recording
    feed = RecordingFeed(path, _recording_locator, speed=50.0)
    messages = []
    feed.start(lambda text: messages.append(json.loads(text)))

    def frames():
        return [m for m in messages if m["type"] == "frame"]

    try:
        _until(lambda: len(frames()) > 10)
        assert [m["index"] for m in frames()] == list(range(len(frames())))  # none skipped
        feed.command({"command": "pause"})
        _until(lambda: feed.status == "paused")
        feed.command({"command": "seek", "value": 150})
        _until(lambda: frames()[-1]["index"] == 150)
        last = frames()[-1]
        assert last["playback"]["playing"] is False
        np.testing.assert_array_equal(last["counts"], rec.frames[150])
        assert last["time_s"] == pytest.approx(rec.time_s[150])
        time.sleep(0.3)
        assert frames()[-1]["index"] == 150  # paused: it stays
        feed.command({"command": "step", "value": -1})
        _until(lambda: frames()[-1]["index"] == 149)
        feed.command({"command": "seek", "value": 10**9})  # clamped to the last frame
        _until(lambda: frames()[-1]["index"] == len(rec) - 1)
        before = len(messages)
        feed.command({"command": "no such thing"})
        feed.command({"command": "seek", "value": "x"})
        time.sleep(0.3)
        assert len(messages) == before  # ignored, nothing shown, nothing broken
        assert feed.status == "paused"
    finally:
        feed.stop()


def test_recording_feed_estimates_match_the_batch_estimator(axial_recording):
    """The page's contact is locate()'s contact for the same frame and baseline."""
    path, rec = axial_recording
    feed = RecordingFeed(path, _recording_locator)
    messages = []
    feed._publish = lambda text: messages.append(json.loads(text))
    for index in (100, 200, 300):
        feed._show(index, 0.0)
    feed.file.close()
    est = ts.locate(rec.frames, rec.sensor, baseline=baseline_from(rec.frames[:5]))
    for message in messages:
        i = message["index"]
        assert message["estimate"]["axial_mm"] == pytest.approx(est.axial_mm[i], abs=1e-6)
        assert message["estimate"]["force_n"] == pytest.approx(est.force_n[i], rel=1e-6)


def test_server_pushes_layout_then_frames_and_reports_health(initial):
    rec = ts.simulate(initial, ts.repeated_load(initial, row=4, col=2, repeats=2), rng=2)
    emulator = Emulator.from_recording(rec, speed=10.0, repeat=True)
    _, port = emulator.start_tcp()
    reader = StreamReader(f"socket://127.0.0.1:{port}", start=False)
    feed = LiveFeed(reader, LiveLocator(reader.sensor, keep_deflection=True))
    server = ViewServer(feed)
    server.start()
    try:
        assert server.url.startswith("http://127.0.0.1:")
        ws_url = server.url.replace("http", "ws") + "ws"
        with connect(ws_url) as ws:
            layout = json.loads(ws.recv(timeout=5))
            assert layout["type"] == "layout" and layout["rows"] == 8 and layout["closes"]
            frames = []
            deadline = time.time() + 10
            while len(frames) < 20 and time.time() < deadline:
                message = json.loads(ws.recv(timeout=5))
                if message["type"] == "frame":
                    frames.append(message)
            assert len(frames) == 20
            serials = [m["serial"] for m in frames]
            assert serials == list(range(serials[0], serials[0] + 20))
            ws.send("not json")  # ignored, the connection stays
            ws.send(json.dumps({"command": "seek", "value": 3}))  # live: ignored
            assert json.loads(ws.recv(timeout=5))["type"] in ("frame", "status")
        import urllib.request

        with urllib.request.urlopen(server.url + "api/health", timeout=5) as response:
            health = json.loads(response.read())
        assert health["feed"]["status"] == "streaming"
        assert health["feed"]["frames_in"] >= 20
        with urllib.request.urlopen(server.url + "static/uPlot.iife.min.js", timeout=5) as r:
            assert b"uPlot" in r.read(200)  # served from the package, no internet needed
    finally:
        server.stop()
        emulator.stop()


def test_loopback_detection():
    assert is_loopback("127.0.0.1") and is_loopback("::1") and is_loopback("localhost")
    assert not is_loopback("0.0.0.0") and not is_loopback("192.168.1.5")
