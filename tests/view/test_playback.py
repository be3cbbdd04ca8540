"""Playback of a recording as the page shows it: the speed selector says the speed the
server plays at (``--speed 0.25`` showed 1x), and a recording played to its last frame
says "ended", not "paused" (issue 31). The feed without a browser, then the page in
headless Chromium (skipped as in test_browser.py when there is none and CI is unset)."""

import json
import time

import pytest

import tactsense as ts
from tactsense.estimate.finger.deflection import baseline_from
from tactsense.io.recording import write_recording
from tactsense.stream import LiveLocator
from tactsense.view import RecordingFeed, ViewServer

from .test_browser import browser, page  # noqa: F401  (fixtures)


@pytest.fixture(scope="module")
def short_file(tmp_path_factory, initial):
    rec = ts.simulate(initial, ts.probe_sweep(initial, along="axial", dwell_s=0.3), rng=2)
    path = tmp_path_factory.mktemp("playback") / "short.h5"
    write_recording(path, rec)
    return path, len(rec)


SHOWN_SPEED = """() => {
  const s = document.getElementById('speed');
  return s.options[s.selectedIndex].textContent;
}"""
"""The label of the speed the selector shows."""


def _locator(spec, file):
    return LiveLocator(spec, baseline=baseline_from(file.frames(0, 5)), keep_deflection=True)


def _until(condition, timeout_s: float = 20.0) -> None:
    deadline = time.monotonic() + timeout_s
    while not condition():
        assert time.monotonic() < deadline, "timed out"
        time.sleep(0.01)


def test_feed_says_ended_at_the_last_frame_and_paused_when_paused(short_file):
    path, n = short_file
    feed = RecordingFeed(path, _locator, speed=1000.0)
    statuses = []

    def publish(text):
        message = json.loads(text)
        if message["type"] == "status":
            statuses.append(message["status"])

    feed.start(publish)
    try:
        _until(lambda: feed.status == "ended")
        assert feed.position == n - 1 and not feed.playing
        assert "paused" not in statuses  # it never claimed to be paused on the way
        feed.command({"command": "seek", "value": 3})  # a jump: now merely paused there
        _until(lambda: feed.status == "paused")
        feed.command({"command": "play"})
        _until(lambda: feed.status == "ended")
        said = len(statuses)
        feed.command({"command": "play"})  # play at the end starts over
        # at 1000x the short file may end again before a poll sees "playing": the status
        # it published says it played
        _until(lambda: "playing" in statuses[said:])
        feed.command({"command": "pause"})
        _until(lambda: feed.status in ("paused", "ended"))
        if feed.position < n - 1:
            assert feed.status == "paused"
    finally:
        feed.stop()


@pytest.mark.parametrize(("speed", "label"), [(0.25, "0.25×"), (3.0, "3×"), (50.0, "50×")])
def test_speed_selector_shows_the_speed_played(page, short_file, speed, label):  # noqa: F811
    path, _ = short_file
    server = ViewServer(RecordingFeed(path, _locator, speed=speed))
    server.start()
    try:
        page.goto(server.url)
        page.wait_for_function(f"() => ({SHOWN_SPEED})() === {json.dumps(label)}", timeout=5000)
        values = page.evaluate(
            "() => [...document.getElementById('speed').options].map((o) => Number(o.value))"
        )
        assert values == sorted(values) and values.count(speed) == 1
        # choosing another speed on the page reaches the server and stays shown
        page.select_option("#speed", "2")
        _until(lambda: server.feed.speed == 2.0, 5.0)
        page.wait_for_timeout(300)
        assert page.evaluate(SHOWN_SPEED) == "2×"
    finally:
        server.stop()


@pytest.mark.parametrize("opened", ["after-the-end", "while-playing"])
def test_page_says_ended_when_the_recording_is_over(page, short_file, opened):  # noqa: F811
    """Opened after the end (the layout says where playback is) or while playing (the
    feed tells every page when it stops at the last frame): "ended", and the button
    offers "play"."""
    path, n = short_file
    feed = RecordingFeed(path, _locator, speed=1000.0)
    if opened == "while-playing":
        feed.speed = n * feed.period_s / 4.0  # about 4 s from the first frame to the last
    server = ViewServer(feed)
    server.start()
    try:
        if opened == "after-the-end":
            _until(lambda: feed.status == "ended")
        page.goto(server.url)
        if opened == "while-playing":
            page.wait_for_function(
                "() => document.getElementById('status').textContent === 'playing'",
                timeout=5000,
            )
            assert page.text_content("#play") == "pause"
        page.wait_for_function(
            "() => document.getElementById('status').textContent === 'ended'", timeout=20000
        )
        assert page.text_content("#play") == "play"
        assert page.text_content("#position").startswith(f"frame {n - 1} ")
        feed.speed = n * feed.period_s / 4.0  # slow enough that the page sees the restart
        page.click("#play")  # starts over
        page.wait_for_function(f"() => window.tactsenseView.lastIndex < {n - 1}", timeout=5000)
    finally:
        server.stop()
