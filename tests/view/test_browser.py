"""The view in a real browser (headless Chromium driven by Playwright), asserting what a
person sees: the colours on the map, the marker, the counters, the playback position.

The map's colours are read back from the canvas pixels and turned into values through
the colour map's table; nothing is read from the page's data. These tests skip only
when no Chromium can be found and ``CI`` is unset; in CI they fail instead (.ci/run
installs Debian's chromium)."""

import os
import shutil
import subprocess
import sys

import numpy as np
import pytest

import tactsense as ts
from tactsense.estimate.finger.deflection import baseline_from, deflection_from_counts
from tactsense.io.recording import write_recording
from tactsense.stream import Emulator, FaultRates, LiveLocator, StreamReader
from tactsense.view import LiveFeed, RecordingFeed, ViewServer


def _chromium() -> str | None:
    for candidate in (
        os.environ.get("TACTSENSE_CHROMIUM"),
        shutil.which("chromium"),
        "/usr/bin/chromium",
        shutil.which("chromium-browser"),
    ):
        if candidate and os.path.exists(candidate):
            return candidate
    return None


@pytest.fixture(scope="module")
def browser():
    path = _chromium()
    if path is None:
        if os.environ.get("CI"):
            pytest.fail("no Chromium found and CI is set: .ci/run must install Debian's chromium")
        pytest.skip("no Chromium found (apt-get install chromium) and CI is unset")
    from playwright.sync_api import sync_playwright

    playwright = sync_playwright().start()
    chromium = playwright.chromium.launch(executable_path=path)
    yield chromium
    chromium.close()
    playwright.stop()


@pytest.fixture
def page(browser):
    context = browser.new_context(viewport={"width": 1200, "height": 900})
    page = context.new_page()
    page.errors = []
    page.on("pageerror", lambda error: page.errors.append(str(error)))
    yield page
    errors = page.errors
    context.close()
    assert errors == [], f"the page raised: {errors}"


def _serve_emulated(recording, **emulator_options):
    emulator = Emulator.from_recording(recording, **emulator_options)
    _, port = emulator.start_tcp()
    reader = StreamReader(f"socket://127.0.0.1:{port}", start=False)
    feed = LiveFeed(reader, LiveLocator(reader.sensor, keep_deflection=True))
    server = ViewServer(feed)
    server.start()
    return server, emulator


def _stop(server, emulator=None):
    server.stop()
    if emulator is not None:
        emulator.stop()


# the value index (0..255 in the colour map) drawn on each tactel's dot: the median of
# five pixels inside the dot, so a marker or trail over part of it does not matter
SEEN_JS = """() => {
  const s = window.tactsenseView, L = s.layout, lut = L.colormap.lut;
  const ctx = document.getElementById('map').getContext('2d');
  const index = (x, y) => {
    const d = ctx.getImageData(Math.round(x), Math.round(y), 1, 1).data;
    let best = 0, bestErr = Infinity;
    lut.forEach((c, i) => {
      const e = (c[0] - d[0]) ** 2 + (c[1] - d[1]) ** 2 + (c[2] - d[2]) ** 2;
      if (e < bestErr) { bestErr = e; best = i; }
    });
    return best;
  };
  const seen = [];
  for (let r = 0; r < L.rows; r++) {
    const row = [];
    for (let c = 0; c < L.cols; c++) {
      const [x, y] = s.cellCentre(r, c);
      const v = [index(x + 10, y), index(x - 10, y), index(x, y + 10), index(x, y - 10),
                 index(x, y)].sort((a, b) => a - b);
      row.push(v[2]);
    }
    seen.push(row);
  }
  return seen;
}"""

TOUCHING_JS = "() => window.tactsenseView.touching === true"
# the marker as drawn and the readout beside it, read in one go (one frame's)
SNAPSHOT_JS = (
    "() => [window.tactsenseView.marker, Number(document.getElementById('axial').textContent)]"
)


def _seen(page) -> np.ndarray:
    return np.asarray(page.evaluate(SEEN_JS))


def _hottest(page) -> tuple[int, int]:
    seen = _seen(page)
    return tuple(int(v) for v in np.unravel_index(np.argmax(seen), seen.shape))


def _click_tactel(page, row: int, col: int) -> None:
    """Click the dot of tactel (row, col) on the map, as a person would."""
    box = page.locator("#map").bounding_box()
    x, y = page.evaluate(f"() => window.tactsenseView.cellCentre({row}, {col})")
    page.mouse.click(box["x"] + x, box["y"] + y)


def _frame_after(page, frames: int, timeout_s: float = 10.0) -> None:
    """Wait for ``frames`` more frames, and until the map shows the latest one received
    (drawing happens on animation frames, which a loaded machine delays)."""
    start = page.evaluate("() => window.tactsenseView.framesReceived")
    page.wait_for_function(
        f"() => window.tactsenseView.framesReceived >= {start + frames}",
        timeout=1000 * timeout_s,
    )
    page.wait_for_function(
        "() => window.tactsenseView.drawnIndex === window.tactsenseView.lastIndex",
        timeout=1000 * timeout_s,
    )


@pytest.mark.parametrize("row, col", [(3, 5), (6, 1)])
def test_hottest_cell_is_the_tactel_the_scenario_touches(page, initial, row, col):
    scene = ts.repeated_load(initial, row=row, col=col, repeats=1, on_s=60.0, settle_s=1.0)
    rec = ts.simulate(initial, scene, rng=1)
    server, emulator = _serve_emulated(rec, speed=5.0)
    try:
        page.goto(server.url)
        page.wait_for_function(TOUCHING_JS, timeout=15000)
        _frame_after(page, 3)
        assert _hottest(page) == (row, col)
        # the readout says where, in the finger's own units
        axial = float(page.text_content("#axial"))
        assert axial == pytest.approx(initial.row_axial_mm[row], abs=0.5)
        # uncalibrated, the force carries the tactel's gain (the finger's spread is up to
        # x2): the page says so rather than pass it off as the load
        assert page.text_content("#calibration").startswith("uncalibrated")
        assert 20.0 < float(page.text_content("#force-g")) < 120.0
        # click the touched tactel: the lower trace follows it (its title, and its values
        # read from the trace's own data, as uPlot draws it)
        _click_tactel(page, row, col)
        title = f"tactel ({row}, {col}) [deflection]"
        page.wait_for_function(
            f"() => document.querySelector('#tactel-trace .u-title').textContent === '{title}'",
            timeout=5000,
        )
        assert page.evaluate("() => window.tactsenseView.traces.tactel.at(-1)") > 0.02
        far = (col + 4) % 8  # half a turn away: followed, and not loaded
        _click_tactel(page, row, far)
        page.wait_for_function(f"() => window.tactsenseView.selected[1] === {far}")
        assert abs(page.evaluate("() => window.tactsenseView.traces.tactel.at(-1)")) < 0.005
        _click_tactel(page, row, col)
        # the counts toggle: the tactel trace says what it shows, in counts
        page.check('input[value="counts"]')
        title = f"tactel ({row}, {col}) [counts]"
        page.wait_for_function(
            f"() => document.querySelector('#tactel-trace .u-title').textContent === '{title}'",
            timeout=5000,
        )
        counts = page.evaluate("() => window.tactsenseView.traces.tactel")
        assert min(counts) > 1000  # raw readings (about 2000), not fractions
    finally:
        _stop(server, emulator)


def test_marker_moves_when_the_contact_moves(page, initial):
    scene = ts.probe_sweep(initial, along="axial", col=2, dwell_s=0.5)
    rec = ts.simulate(initial, scene, rng=2)
    server, emulator = _serve_emulated(rec, speed=4.0)
    try:
        page.goto(server.url)
        page.wait_for_function(TOUCHING_JS, timeout=15000)
        _frame_after(page, 2)
        first, axial_first = page.evaluate(SNAPSHOT_JS)
        page.wait_for_timeout(2500)  # about 10 mm further at 4x the paper's rate
        page.wait_for_function(TOUCHING_JS, timeout=5000)
        _frame_after(page, 1)
        second, axial_second = page.evaluate(SNAPSHOT_JS)
        assert axial_second > axial_first + 3.0
        assert second["x"] > first["x"] + 40  # along the finger is across the map
        assert abs(second["y"] - first["y"]) < 12  # at the angle of column 2 all along
        # and the marker is drawn there: its white ring, 7 px around the contact
        pixels = page.evaluate(
            "([x, y]) => [[7, 0], [-7, 0], [0, 7], [0, -7]].map(([dx, dy]) => Array.from("
            "document.getElementById('map').getContext('2d')"
            ".getImageData(Math.round(x + dx), Math.round(y + dy), 1, 1).data))",
            [second["x"], second["y"]],
        )
        assert sum(min(p[:3]) > 200 for p in pixels) >= 3, pixels
        # the map's hottest column is the sweep's column
        assert _hottest(page)[1] == 2
    finally:
        _stop(server, emulator)


def test_loss_counter_rises_when_the_line_drops_frames(page, initial):
    rec = ts.simulate(initial, ts.probe_sweep(initial, along="around", dwell_s=0.3), rng=3)
    faults = FaultRates(drop=0.2, garbage=0.1)
    server, emulator = _serve_emulated(rec, speed=5.0, faults=faults, rng=4, repeat=True)
    try:
        page.goto(server.url)
        _frame_after(page, 10)
        lost_first = int(page.text_content("#lost"))
        garbage_first = int(page.text_content("#garbage"))
        page.wait_for_timeout(3000)
        lost_second = int(page.text_content("#lost"))
        assert 0 < lost_first < lost_second
        assert int(page.text_content("#garbage")) > garbage_first >= 0
        # what the page shows is what the reader counted, not more
        assert lost_second <= server.feed.reader.stats.lost
        assert "bad" in (page.get_attribute("#lost", "class") or "")
    finally:
        _stop(server, emulator)


def test_contact_on_the_seam_is_one_blob(page, initial):
    """Between column 7 (315 deg) and column 0 (360 deg): the two hottest dots are drawn
    next to each other, not at the two ends of the map."""
    scene = ts.probe_sweep(
        initial, along="around", row=4, start=334.0, stop=341.0, increment=1.0, dwell_s=20
    )
    rec = ts.simulate(initial, scene, rng=5)
    server, emulator = _serve_emulated(rec, speed=5.0)
    try:
        page.goto(server.url)
        page.wait_for_function(TOUCHING_JS, timeout=15000)
        _frame_after(page, 3)
        seen = _seen(page)
        order = np.argsort(seen[4])[::-1]
        assert set(order[:2].tolist()) == {7, 0}
        y7 = page.evaluate("() => window.tactsenseView.cellCentre(4, 7)[1]")
        y0 = page.evaluate("() => window.tactsenseView.cellCentre(4, 0)[1]")
        assert abs(y7 - y0) == pytest.approx(48, abs=1)  # one cell apart: one blob
    finally:
        _stop(server, emulator)


@pytest.fixture(scope="module")
def sweep_file(tmp_path_factory, initial):
    rec = ts.simulate(initial, ts.probe_sweep(initial, along="axial", dwell_s=1.0), rng=6)
    path = tmp_path_factory.mktemp("browser") / "sweep.h5"
    write_recording(path, rec)
    return path, rec


def test_seek_and_step_on_a_recording(page, sweep_file):
    path, rec = sweep_file

    def locator_for(spec, file):
        return LiveLocator(spec, baseline=baseline_from(file.frames(0, 5)), keep_deflection=True)

    server = ViewServer(RecordingFeed(path, locator_for))
    server.start()
    try:
        page.goto(server.url)
        _frame_after(page, 2)
        page.click("#play")  # pause
        page.wait_for_function("() => document.getElementById('play').textContent === 'play'")
        target = 200
        page.evaluate(
            "(v) => { const s = document.getElementById('seek'); s.value = v;"
            " s.dispatchEvent(new Event('change')); }",
            target,
        )
        page.wait_for_function(f"() => window.tactsenseView.drawnIndex === {target}", timeout=5000)
        baseline = baseline_from(rec.frames)
        deflection, _ = deflection_from_counts(rec.frames[target], baseline, rec.sensor)
        expected = np.unravel_index(np.argmax(deflection), deflection.shape)
        assert _hottest(page) == tuple(int(v) for v in expected)

        def numbers():
            """The frame as the transport and as the stream panel say it."""
            position = page.text_content("#position")
            assert position.endswith("s") and f" of 0–{len(rec) - 1} · " in position, position
            return int(position.split()[1]), int(page.text_content("#frame-index"))

        # the seek bar's value is the frame shown, counted from 0 in both places
        page.wait_for_function(
            f"() => document.getElementById('position').textContent.startsWith('frame {target} ')",
            timeout=5000,
        )
        assert numbers() == (target, target)
        page.click("#step-fwd")
        page.wait_for_function(f"() => window.tactsenseView.lastIndex === {target + 1}")
        assert numbers() == (target + 1, target + 1)
        page.click("#step-back")
        page.click("#step-back")
        page.wait_for_function(f"() => window.tactsenseView.lastIndex === {target - 1}")
        assert numbers() == (target - 1, target - 1)
        # paused means paused: the position holds
        page.wait_for_timeout(600)
        assert numbers() == (target - 1, target - 1)
    finally:
        _stop(server)


def test_command_line_emulate_and_view(page, tmp_path):
    """The README's two terminals: 'tactsense emulate --port 0' and 'tactsense view'."""
    exe = [sys.executable, "-m", "tactsense.cli"]
    emulate = subprocess.Popen(
        [*exe, "emulate", "--port", "0", "--loop", "--speed", "3"],
        stdout=subprocess.PIPE,
        stderr=subprocess.DEVNULL,
        text=True,
    )
    view = None
    try:
        device = emulate.stdout.readline().strip()
        assert device.startswith("socket://127.0.0.1:")
        view = subprocess.Popen(
            [*exe, "view", device],
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
        )
        address = view.stdout.readline().strip()
        assert address.startswith("http://127.0.0.1:"), view.stderr.read()
        page.goto(address)
        page.wait_for_function(TOUCHING_JS, timeout=30000)
        assert page.text_content("#status") == "streaming"
        assert page.text_content("#sensor") == "fearing1990_initial"
    finally:
        for process in (view, emulate):
            if process is not None:
                process.send_signal(2)
                try:
                    process.wait(10)
                except subprocess.TimeoutExpired:
                    process.kill()
    err = view.stderr.read()
    assert view.returncode == 0, err
    assert "frames shown" in err  # Ctrl-C: a summary line, no traceback
    assert "Traceback" not in err


# colour-table index (0..255) of the canvas pixel at each of a list of points
INDEX_AT_JS = """(points) => {
  const lut = window.tactsenseView.layout.colormap.lut;
  const ctx = document.getElementById('map').getContext('2d');
  return points.map(([x, y]) => {
    const d = ctx.getImageData(Math.round(x), Math.round(y), 1, 1).data;
    let best = 0, bestErr = Infinity;
    lut.forEach((c, i) => {
      const e = (c[0] - d[0]) ** 2 + (c[1] - d[1]) ** 2 + (c[2] - d[2]) ** 2;
      if (e < bestErr) { bestErr = e; best = i; }
    });
    return best;
  });
}"""


def _centre(page, row, col) -> tuple[float, float]:
    return tuple(page.evaluate(f"() => window.tactsenseView.cellCentre({row}, {col})"))


def test_counts_surface_does_not_ring_at_the_ends_of_the_finger(page, initial):
    """Counts mode, a touch in the middle of the finger: between the untouched tactels of
    the first two and the last two rows the surface has the colour of the dots beside
    it. (Interpolating raw counts, whose rows' weights sum to up to 1.10 there, painted
    those bands about 200 counts above every tactel: the top of the colour scale.)"""
    scene = ts.repeated_load(initial, row=4, col=2, repeats=1, on_s=60.0, settle_s=1.0)
    rec = ts.simulate(initial, scene, rng=7)
    server, emulator = _serve_emulated(rec, speed=5.0)
    try:
        page.goto(server.url)
        page.wait_for_function(TOUCHING_JS, timeout=15000)
        page.check('input[value="counts"]')
        page.wait_for_function("() => window.tactsenseView.units === 'counts'")
        _frame_after(page, 2)
        seen = _seen(page)  # the dots' colours
        rows = initial.shape[0]
        points, beside = [], []
        for r0, r1 in [(1, 2), (rows - 2, rows - 1)]:
            for c in (5, 6, 7, 0):  # away from the touched column 2
                (x0, y), (x1, _) = _centre(page, r0, c), _centre(page, r1, c)
                points.append([(x0 + x1) / 2, y])  # half-way between two dots
                beside.append((seen[r0, c], seen[r1, c]))
        between = page.evaluate(INDEX_AT_JS, points)
        # the touched tactel spreads the scale: the ends are in its lower part
        assert seen.max() > 200 and max(max(b) for b in beside) < 60, seen
        for value, (a, b) in zip(between, beside, strict=True):
            # 12 of 256 steps: a few counts of noise on a scale about 80 counts wide
            assert min(a, b) - 12 <= value <= max(a, b) + 12, (between, beside)
    finally:
        _stop(server, emulator)


def test_recentred_map_keeps_dots_in_their_cells_and_clear_of_the_labels(page, initial):
    """A touch 3 deg past the seam re-centres the map on it (column 0.07): every row of
    dots stays in the middle of its own band of the map, the surface's peak is at the
    touched dot, and no dot reaches the labels under the map. (Centring on the contact
    itself put the 180-deg dots on the top edge and the 135-deg dots over the labels.)"""
    scene = ts.probe_sweep(
        initial, along="around", row=4, start=3.0, stop=6.0, increment=1.0, dwell_s=20
    )
    rec = ts.simulate(initial, scene, rng=8)
    server, emulator = _serve_emulated(rec, speed=5.0)
    try:
        page.goto(server.url)
        page.wait_for_function(TOUCHING_JS, timeout=15000)
        _frame_after(page, 3)
        state = page.evaluate(
            "() => { const s = window.tactsenseView; return {centre: s.centre, map: s.map,"
            " labels: s.labels, dots: [...Array(s.layout.rows).keys()].map((r) =>"
            " [...Array(s.layout.cols).keys()].map((c) => s.cellCentre(r, c)))}; }"
        )
        cols = initial.shape[1]
        spacing = 360.0 / cols
        first = initial.col_angle_deg[0] + (cols - 1) / 2 * spacing  # the map's first centre
        assert abs((state["centre"] - first + 180) % 360 - 180) > 90  # it did re-centre
        top, height, cell, dot = (state["map"][k] for k in ("top", "height", "cell", "dot"))
        dots = np.asarray(state["dots"])  # (rows, cols, xy)
        for row in dots:
            ys = np.sort(row[:, 1])
            np.testing.assert_allclose(ys, top + (np.arange(cols) + 0.5) * cell, atol=0.5)
        # and drawn so: above the map, over each column of dots, the canvas is blank
        alpha = page.evaluate(
            "(xs) => xs.map((x) => document.getElementById('map').getContext('2d')"
            f".getImageData(Math.round(x), {top - 3}, 1, 1).data[3])",
            dots[:, 0, 0].tolist(),
        )
        assert alpha == [0] * len(alpha)
        # the contact (column 0) is in the middle band, and the surface beside the loaded
        # dot peaks at that dot's height
        y0 = dots[4, 0, 1]
        assert abs(y0 - (top + height / 2)) <= cell / 2 + 0.5
        x = dots[4, 0, 0] + cell / 2  # half-way to the next row: surface, no dot
        ys = np.arange(top + 1, top + height - 1)
        profile = page.evaluate(INDEX_AT_JS, [[x, float(y)] for y in ys])
        assert abs(ys[int(np.argmax(profile))] - y0) <= cell / 4
        # the labels: all drawn, none under a dot
        assert len(state["labels"]) >= initial.shape[0] + cols
        centres = dots.reshape(-1, 2)
        for box in state["labels"]:
            nearest_x = np.clip(centres[:, 0], box["left"], box["right"])
            nearest_y = np.clip(centres[:, 1], box["top"], box["bottom"])
            gap = np.hypot(centres[:, 0] - nearest_x, centres[:, 1] - nearest_y)
            assert gap.min() > dot, box
    finally:
        _stop(server, emulator)
