"""The view on a three-axis pad (issue 35 item 5): the normal component as the map, an
arrow per taxel for the tangential components, the contacts' shear and slip.

The recordings are simulated on the twin (``mag4x4``) with a sphere pressed at the pad's
centre and pushed tangentially in a known direction; the view's arrows must point the way
the shear pushes. The pad is symmetric about its centre, so the radial displacement a
press alone gives (magnets pushed out from under the load) cancels in the sum of the
arrows, and what is left is the shear's. No flaws (the direction is the model's, not the
noise's), and one run with noise to show the arrows still point the right way.
"""

import json
import math
import time

import numpy as np
import pytest

from tactsense.io.recording import write_recording
from tactsense.physics.indenters import SphereProbe
from tactsense.sensor import preset
from tactsense.simulate import Scenario, Step, simulate
from tactsense.stream.reader import StreamFrame
from tactsense.view import RecordingFeed, ViewServer, view_locator
from tactsense.view.vectors import (
    VectorReading,
    baseline_of,
    decorate_frame,
    slip_state,
    taxel_vectors,
)

CENTRE_MM = (7.05, 7.05)  # mag4x4: rows and columns 0..3 at 4.7 mm, centre between them

DIRECTION_TOL_DEG = 3.0
"""Largest angle between the summed taxel arrows and the simulated shear [deg] without
noise: the pad is symmetric about the contact, so the sum is along the shear but for the
magnets' crosstalk (a neighbour's field), which is symmetric too; 3 deg leaves room for
the converter's rounding."""


def _sheared(spec, shear_xy_n, path=None, *, flaws=(), force_n=1.0, rng=0):
    """Untouched, then a sphere pressed at the pad's centre with ``shear_xy_n`` [N]."""
    probe = SphereProbe(
        x_mm=CENTRE_MM[0], y_mm=CENTRE_MM[1], force_n=force_n, radius_mm=5.0,
        shear_x_n=shear_xy_n[0], shear_y_n=shear_xy_n[1], friction=1.0,
    )  # fmt: skip
    scenario = Scenario((Step((), 0.1), Step((probe,), 0.2)), name="shear")
    rec = simulate(spec, scenario, rng=rng, flaws=flaws)
    if path is not None:
        write_recording(path, rec)
    return rec


def _angle_deg(u, v) -> float:
    return math.degrees(math.atan2(v, u))


def _off_deg(a, b) -> float:
    return abs((a - b + 180.0) % 360.0 - 180.0)


def _frames(spec, rec):
    for k, counts in enumerate(rec.frames):
        yield StreamFrame(k, k, float(rec.time_s[k]), 0.0, 0.0, counts)


@pytest.mark.parametrize("shear", [(0.3, 0.0), (0.0, 0.3), (-0.2, 0.2), (0.1, -0.25)])
def test_the_arrows_point_where_the_shear_pushes(shear):
    spec = preset("mag4x4")
    rec = _sheared(spec, shear)
    reading = view_locator(spec, baseline_frames=5)
    assert isinstance(reading, VectorReading)
    for frame in _frames(spec, rec):
        reading(frame)
    arrows = reading.last_tangential.reshape(-1, 2).sum(axis=0)
    assert _off_deg(_angle_deg(*arrows), _angle_deg(*shear)) < DIRECTION_TOL_DEG


@pytest.mark.parametrize("taxel", [(1, 1), (2, 3)])
def test_the_map_is_highest_at_the_pressed_magnet(taxel):
    # a press right over a magnet: its normal change is positive and the largest
    spec = preset("mag4x4")
    probe = SphereProbe(x_mm=4.7 * taxel[0], y_mm=4.7 * taxel[1], force_n=1.0, radius_mm=5.0)
    rec = simulate(spec, Scenario((Step((), 0.1), Step((probe,), 0.2))), rng=0, flaws=())
    reading = view_locator(spec, baseline_frames=5)
    for frame in _frames(spec, rec):
        reading(frame)
    normal = reading.last_deflection
    assert normal.shape == spec.shape
    assert np.unravel_index(np.argmax(normal), normal.shape) == taxel
    assert normal[taxel] > 0


def test_a_press_alone_draws_no_net_arrow():
    # the control of the test above: with no shear the arrows cancel (radial about the
    # contact); one pushed by 0.3 N sums to far more
    spec = preset("mag4x4")
    sums = {}
    for shear in [(0.0, 0.0), (0.3, 0.0)]:
        reading = view_locator(spec, baseline_frames=5)
        for frame in _frames(spec, _sheared(spec, shear)):
            reading(frame)
        sums[shear] = np.linalg.norm(reading.last_tangential.reshape(-1, 2).sum(axis=0))
        assert np.abs(reading.last_tangential).max() > 0  # a press moves magnets sideways
    assert sums[(0.0, 0.0)] < 0.02 * sums[(0.3, 0.0)]


def test_with_noise_the_arrows_still_point_the_way():
    # the preset's read noise (3 counts) and gains: averaged over the last 10 frames,
    # within 10 deg (noise of 3 counts on ~ 700 counts of summed tangential change)
    spec = preset("mag4x4")
    rec = _sheared(spec, (0.2, 0.2), flaws=None, rng=3)
    reading = view_locator(spec, baseline_frames=5)
    seen = []
    for frame in _frames(spec, rec):
        reading(frame)
        if reading.last_tangential is not None:
            seen.append(reading.last_tangential.reshape(-1, 2).sum(axis=0))
    u, v = np.mean(seen[-10:], axis=0)
    assert _off_deg(_angle_deg(u, v), 45.0) < 10.0


def test_the_normal_change_is_signed_by_the_rest_field():
    # a magnet whose moment points inward reads a negative rest field: the same press
    # must still read positive, and the same shear point the same way
    spec = preset("mag4x4")
    zero = spec.electronics.nominal_counts
    baseline = np.full(spec.frame_shape, zero)
    baseline[..., 2] += 1000.0
    pressed = baseline.copy()
    pressed[1, 1] += [50.0, -20.0, 400.0]
    flipped_base = 2 * zero - baseline
    flipped = 2 * zero - pressed
    a = taxel_vectors(pressed, baseline, spec)
    b = taxel_vectors(flipped, flipped_base, spec)
    np.testing.assert_allclose(a, b, rtol=0, atol=1e-9)
    # in uT: counts times the Hall sensor's field per count (lsb_t, in T)
    np.testing.assert_allclose(a[1, 1], [50.0, -20.0, 400.0] * spec.lsb_t * 1e6, rtol=1e-12)


def test_slip_states_from_what_an_estimator_gives():
    assert [slip_state(v) for v in (0, 1, 2)] == ["stick", "partial", "gross"]
    assert [slip_state(v) for v in ("stick", "partial", "gross slip")] == [
        "stick", "partial", "gross"
    ]  # fmt: skip
    assert slip_state(True) == "slip" and slip_state(False) == "stick"
    assert slip_state(None) is None and slip_state(float("nan")) is None
    assert slip_state("") is None and slip_state("unknown") is None


def test_a_contacts_shear_goes_onto_the_page_plane():
    spec = preset("mag4x4")
    message = {"estimate": {"contacts": [
        {"id": 1, "shear_x_n": 0.3, "shear_y_n": -0.1, "slip": 1},
        {"id": 2, "slip": None},
    ]}}  # fmt: skip
    decorate_frame(message, None, spec)
    first, second = message["estimate"]["contacts"]
    # a flat pad seen from +z: u along x, v along y
    assert (first["shear_u_n"], first["shear_v_n"]) == (0.3, -0.1)
    assert first["slip_state"] == "partial"
    assert "shear_u_n" not in second and second["slip_state"] is None
    assert message["tangential"] is None


def test_layout_says_what_the_map_and_the_arrows_show():
    from tactsense.view.layout import layout_message

    spec = preset("mag4x4")
    layout = layout_message(spec, {"kind": "recording", "name": "x"})
    vector = layout["vector"]
    assert vector["components"] == ["x", "y", "z"]
    assert vector["normal_index"] == 2 and vector["tangential_index"] == [0, 1]
    assert vector["unit"] == "uT" and "[uT]" in vector["map_label"]
    # counts mode: counts of the normal component per uT
    assert layout["transduction"]["counts_per_strain"] == pytest.approx(1.0 / 1.210)
    json.dumps(layout, allow_nan=False)


def test_a_baseline_of_the_wrong_shape_is_refused():
    from tactsense._validation import TactsenseInputError

    spec = preset("mag4x4")
    with pytest.raises(TactsenseInputError, match=r"expected \(4, 4, 3\)"):
        view_locator(spec, baseline=np.zeros(spec.shape))
    with pytest.raises(TactsenseInputError, match="untouched frames"):
        baseline_of(np.zeros((2, 4, 4, 3)), 5)


def test_the_feed_sends_the_arrows_of_a_recording(tmp_path):
    spec = preset("mag4x4")
    path = tmp_path / "shear.h5"
    _sheared(spec, (0.0, 0.3), path)

    def locator_for(spec, file):
        return view_locator(spec, baseline=baseline_of(file.frames(0, 5), 5))

    feed = RecordingFeed(path, locator_for, speed=1e6)
    frames = []
    feed.start(lambda text: frames.append(json.loads(text)))
    deadline = time.monotonic() + 60
    while feed.status != "ended" and time.monotonic() < deadline:
        time.sleep(0.02)
    feed.stop()
    frames = [m for m in frames if m["type"] == "frame"]
    assert len(frames) == feed.n_frames
    last = frames[-1]
    assert np.asarray(last["counts"]).shape == (4, 4, 3)
    assert np.asarray(last["deflection"]).shape == (4, 4)
    arrows = np.asarray(last["tangential"])
    assert arrows.shape == (4, 4, 2)
    assert _off_deg(_angle_deg(*arrows.reshape(-1, 2).sum(axis=0)), 90.0) < DIRECTION_TOL_DEG


# ---- in a real browser ------------------------------------------------------------------

from .test_browser import browser, page  # noqa: E402, F401  (the fixtures)

ARROWS_JS = """() => {
  const s = window.tactsenseView;
  if (!s.latest || s.drawnIndex !== s.lastIndex || !s.latest.tangential) return null;
  const ctx = document.getElementById('map').getContext('2d');
  // the whitest pixel (of its darkest channel) within a pixel of the point 3/4 along each
  // arrow's shaft, as drawn (a thin slanted line is antialiased over its neighbours)
  const marks = s.arrowMarks.map((m) => {
    const x = m.x0 + 0.75 * (m.x1 - m.x0), y = m.y0 + 0.75 * (m.y1 - m.y0);
    const d = ctx.getImageData(Math.round(x) - 1, Math.round(y) - 1, 3, 3).data;
    let white = 0;
    for (let i = 0; i < 36; i += 4) white = Math.max(white, Math.min(d[i], d[i + 1], d[i + 2]));
    return { ...m, white };
  });
  return { marks, units: document.getElementById('units-deflection').textContent,
           arrowsShown: !document.getElementById('show-arrows').parentElement.hidden };
}"""


def _serve(path, locator_for=None):
    def default(spec, file):
        return view_locator(spec, baseline_frames=5)

    server = ViewServer(RecordingFeed(path, locator_for or default, speed=2.0))
    server.start()
    return server


def _wait_ended(view):
    view.wait_for_function(
        "() => { const s = window.tactsenseView, seek = document.getElementById('seek');"
        " return s.latest && s.latest.tangential && seek && seek.max !== ''"
        " && s.lastIndex === Number(seek.max) && s.drawnIndex === s.lastIndex; }",
        timeout=20000,
    )


@pytest.mark.parametrize("shear", [(0.3, 0.0), (-0.2, 0.2)])
def test_browser_arrows_point_where_the_shear_pushes(page, tmp_path, shear):  # noqa: F811
    spec = preset("mag4x4")
    _sheared(spec, shear, tmp_path / "shear.h5")
    server = _serve(tmp_path / "shear.h5")
    try:
        page.goto(server.url)
        _wait_ended(page)
        said = page.evaluate(ARROWS_JS)
    finally:
        server.stop()
    assert said["arrowsShown"] and "z field change [uT]" in said["units"]
    marks = said["marks"]
    assert len(marks) == 16
    # drawn on the canvas: canvas y grows downward, the pad's y (v) upward
    dx = sum(m["x1"] - m["x0"] for m in marks)
    dy = sum(m["y1"] - m["y0"] for m in marks)
    assert _off_deg(_angle_deg(dx, -dy), _angle_deg(*shear)) < DIRECTION_TOL_DEG
    # the longest arrows are really there: white (the arrow's colour) on their shafts
    longest = sorted(marks, key=lambda m: -math.hypot(m["x1"] - m["x0"], m["y1"] - m["y0"]))
    for m in longest[:4]:
        assert m["white"] > 200, m


class _Contacts:
    """A stand-in for the three-axis contact estimator: one contact at the pad's centre
    with the shear and slip it is given, so that every slip state's drawing is tested
    whatever the estimator finds on a given recording."""

    calibration = None

    def __init__(self, shear_xy_n, slip):
        self.shear, self.slip = shear_xy_n, slip

    def reset(self):
        pass

    def __call__(self, frame):
        q = math.hypot(*self.shear)
        contact = {
            "id": 1, "x_mm": CENTRE_MM[0], "y_mm": CENTRE_MM[1], "z_mm": 0.0, "force_n": 1.0,
            "shear_x_n": self.shear[0], "shear_y_n": self.shear[1], "shear_n": q,
            "shear_angle_deg": _angle_deg(*self.shear), "slip": self.slip, "major_mm": 2.0,
        }  # fmt: skip
        return {
            "sequence": frame.sequence, "n_contacts": 1, "contacts": [contact],
            "force_n": 1.0, "flags": 0, "flag_names": "", "rezeroing": False,
            "latency_ms": 0.1,
        }  # fmt: skip


@pytest.mark.parametrize("slip", ["stick", "partial", "gross"])
def test_browser_draws_a_contacts_shear_and_marks_its_slip(page, tmp_path, slip):  # noqa: F811
    spec = preset("mag4x4")
    shear = (-0.25, 0.1)
    _sheared(spec, shear, tmp_path / "shear.h5")

    def locator_for(spec, file):
        return VectorReading(spec, _Contacts(shear, slip), baseline_frames=5)

    server = _serve(tmp_path / "shear.h5", locator_for)
    try:
        page.goto(server.url)
        _wait_ended(page)
        marks = page.evaluate("() => window.tactsenseView.shearMarks")
        row = [td.text_content() for td in page.locator("#contact-rows tr td").all()]
        headers = [th.text_content() for th in page.locator("#contact-list th").all()
                   if th.is_visible()]  # fmt: skip
    finally:
        server.stop()
    assert len(marks) == 1 and marks[0]["slip"] == slip
    m = marks[0]
    assert _off_deg(_angle_deg(m["x1"] - m["x0"], m["y0"] - m["y1"]), _angle_deg(*shear)) < 0.5
    assert "shear [N]" in headers and "dir [deg]" in headers
    assert row[4] == f"{math.hypot(*shear):.4f}"
    assert row[5] == f"{_angle_deg(*shear):.1f}"
    assert row[6] == {"stick": "stick", "partial": "partial slip", "gross": "gross slip"}[slip]


def test_browser_draws_the_estimated_shear_of_the_kinds_estimator(page, tmp_path):  # noqa: F811
    # the three-axis kind's own estimator (estimate.triaxial): the contact's arrow points
    # where the simulated shear pushes, within the 5 deg, and carries its slip
    spec = preset("mag4x4")
    shear = (0.1, -0.1)  # Q/P = 0.28 at 0.5 N
    _sheared(spec, shear, tmp_path / "shear.h5", force_n=0.5)
    server = _serve(tmp_path / "shear.h5")
    try:
        page.goto(server.url)
        _wait_ended(page)
        said = page.evaluate(
            "() => { const s = window.tactsenseView;"
            " return {marks: s.shearMarks, contacts: s.latest.estimate.contacts,"
            " multi: s.layout.multi_contact, note: s.layout.estimation}; }"
        )
    finally:
        server.stop()
    assert said["multi"] and said["note"] is None
    assert len(said["marks"]) == len(said["contacts"]) >= 1
    k = max(range(len(said["contacts"])), key=lambda i: said["contacts"][i]["force_n"])
    m, contact = said["marks"][k], said["contacts"][k]
    drawn = _angle_deg(m["x1"] - m["x0"], m["y0"] - m["y1"])
    assert _off_deg(drawn, _angle_deg(*shear)) < 5.0
    assert m["slip"] == contact["slip_state"] and m["slip"] in ("stick", "partial", "gross")


def test_view_takes_locates_threshold_on_a_three_axis_pad():
    # r8-fixb8: one rule for --threshold on a three-axis pad (locate, export, live, view):
    # a fraction of the converter's full scale
    spec = preset("mag4x4")
    reading = view_locator(spec, threshold=0.01)
    assert reading.inner._options["threshold_counts"] == pytest.approx(0.01 * 65535)


def test_browser_a_three_axis_device_live(page, tmp_path):  # noqa: F811
    # `view DEVICE`: the twin emulated as a three-axis device (version-2 FRAMEs of the
    # wire protocol, docs/protocol.md), read by the stream reader, shown with its arrows
    from tactsense.stream import Emulator, StreamReader, protocol
    from tactsense.view import LiveFeed

    if not hasattr(protocol, "FRAME_V2"):
        pytest.skip("the wire's three-component FRAMEs (docs/protocol.md version 2) not here")
    spec = preset("mag4x4")
    rec = _sheared(spec, (0.3, 0.0), force_n=0.5)
    emulator = Emulator.from_recording(rec, repeat=True)
    _, port = emulator.start_tcp()
    reader = StreamReader(f"socket://127.0.0.1:{port}", start=False)
    server = ViewServer(LiveFeed(reader, view_locator(reader.sensor, baseline_frames=5)))
    server.start()
    try:
        page.goto(server.url)
        # read the marks in the same call that finds them drawn: the emulator repeats its
        # recording, so a later frame (untouched, at the start of a repeat) has none
        said = page.wait_for_function(
            "() => { const s = window.tactsenseView; if (!(s.latest && s.latest.tangential"
            " && s.latest.estimate && s.latest.estimate.n_contacts > 0"
            " && s.drawnIndex === s.lastIndex && s.shearMarks.length > 0)) return null;"
            " return {arrows: s.arrowMarks.length, shear: s.shearMarks,"
            " shape: [s.latest.counts.length, s.latest.counts[0].length,"
            " s.latest.counts[0][0].length]}; }",
            timeout=30000,
        ).json_value()
    finally:
        server.stop()
        emulator.stop()
    assert said["shape"] == [4, 4, 3] and said["arrows"] == 16
    m = said["shear"][0]
    assert _off_deg(_angle_deg(m["x1"] - m["x0"], m["y0"] - m["y1"]), 0.0) < 5.0
