"""A whole hand in a real browser (headless Chromium driven by Playwright): the skin in 3-D.

The robot recordings are made here with the batch forward model
(:func:`tactsense.simulate.frames_from_contacts`): every patch untouched, one patch
pressed from a third of the way in. What is asserted is read from the page's state
(``window.tactsenseHand``: the layout it drew, the camera, where each taxel was drawn and
with which colour), not from pixels, and waits on that state, never on timers:

* every taxel of every patch is where the skin says at the joint state
  (:meth:`RobotSkin.taxels_in_base`), and drawn where an independent evaluation of the
  camera's perspective projection puts it (before and after orbiting and zooming);
* the pressed patch's taxels are the hottest;
* the contacts table lists the pressed patch's link, and the contact's base-frame
  position is the pressed place moved by the skin's kinematics.
"""

import dataclasses
import math

import numpy as np
import pytest

from tactsense.io._layout import Recording
from tactsense.io.robot_recording import RobotRecording, write_robot_recording
from tactsense.robot import Joint, Patch, Pose, RobotSkin, load_skin
from tactsense.sensor import Grid, preset
from tactsense.simulate import ContactBatch, frames_from_contacts
from tactsense.view.robot_feed import RobotRecordingFeed
from tactsense.view.robot_server import RobotViewServer

from .test_browser import browser, page  # noqa: F401  (the fixtures)

JOINTS = {"knuckle": 0.5}


def _pad(name, rows, cols, pitch_mm, rate_hz):
    spec = preset("pad16").replace(
        grid=Grid(rows=rows, cols=cols, row_pitch_mm=pitch_mm, col_pitch_mm=pitch_mm,
                  electrode_x_mm=0.8 * pitch_mm, electrode_y_mm=0.8 * pitch_mm),
        electronics__scan_rate_hz=rate_hz,
    )  # fmt: skip
    return dataclasses.replace(spec, name=name)


def small_hand() -> RobotSkin:
    """A palm and one finger on a revolute joint: a pad on each, a point-set tip; three
    rates (100, 250 and 50 Hz: the dome's)."""
    return RobotSkin(
        name="testhand",
        base_link="palm",
        links=("palm", "finger"),
        joints=(
            Joint(
                "knuckle",
                "revolute",
                "palm",
                "finger",
                Pose((0.06, 0.0, 0.0)),
                (0.0, 1.0, 0.0),
                -0.2,
                1.6,
            ),
        ),
        patches=(
            Patch(
                "palm_pad",
                _pad("palmpad", 6, 6, 4.0, 100.0),
                "palm",
                Pose((0.0, -0.01, -0.005), (math.pi, 0.0, 0.0)),
            ),
            Patch(
                "finger_pad",
                _pad("fingerpad", 4, 8, 3.0, 250.0),
                "finger",
                Pose((0.005, -0.0105, -0.006), (math.pi, 0.0, 0.0)),
            ),
            Patch(
                "tip",
                dataclasses.replace(preset("dome12"), name="tip"),
                "finger",
                Pose((0.035, 0.0, 0.0), (0.0, math.pi / 2, 0.0)),
            ),
        ),
    )


def pressed_centre_mm(skin, patch):
    """The middle of a patch's taxels (x, y) in its own frame [mm]: where it is pressed."""
    return skin.patch(patch).sensor.taxel_positions_mm()[:, :2].mean(axis=0)


def hand_recording(
    path, skin=None, pressed="finger_pad", *, seconds=1.0, force_n=1.0, scenario=None
):
    """A robot recording of ``skin`` (default :func:`small_hand`): every patch at rest with
    its read noise, ``pressed`` (None: none) under a 3 mm sphere at its middle with
    ``force_n`` from a third of the way in."""
    skin = small_hand() if skin is None else skin
    streams = {}
    for k, patch in enumerate(skin.patches):
        spec = patch.sensor
        n = max(round(seconds * spec.electronics.scan_rate_hz), 6)  # a baseline's frames
        force = np.zeros((n, 1))
        if patch.name == pressed:
            force[n // 3 :] = force_n
        centre = np.broadcast_to(pressed_centre_mm(skin, patch.name), (n, 1, 2)).copy()
        frames = frames_from_contacts(
            spec, ContactBatch(position_mm=centre, normal_force_n=force, radius_mm=3.0), rng=k
        )
        streams[patch.name] = Recording(
            frames=np.asarray(frames).reshape(n, *spec.shape),
            time_s=np.arange(n) / spec.electronics.scan_rate_hz,
            sample_offset_s=np.zeros(spec.shape),
            sensor=spec,
            scenario=scenario or {},
        )
    return write_robot_recording(path, RobotRecording(skin, streams, description="test"))


def _serve(path, joints=JOINTS, speed=4.0):
    server = RobotViewServer(RobotRecordingFeed(path, joint_positions=joints, speed=speed))
    server.start()
    return server


def _wait_ended(view):
    """Wait until the recording has played to its end and that last frame is drawn."""
    view.wait_for_function(
        "() => { const s = window.tactsenseHand; return s.layout && s.status === 'ended'"
        " && s.latest && s.drawnSerial === s.latest.serial && !s.dirty; }",
        timeout=20000,
    )


def _projected(camera, points_mm):
    """The perspective projection, evaluated independently of the page: a camera at
    ``distance`` from ``target`` along azimuth ``yaw`` and elevation ``pitch`` (z up),
    written as the rotation from base to camera axes (x right, y down, z forward) built
    from Rz(yaw) and Ry(pitch), then pixels = focal * (x, y) / z + centre."""
    yaw, pitch = camera["yaw"], camera["pitch"]
    cz, sz, cp, sp = math.cos(yaw), math.sin(yaw), math.cos(pitch), math.sin(pitch)
    rz = np.array([[cz, -sz, 0.0], [sz, cz, 0.0], [0.0, 0.0, 1.0]])
    ry = np.array([[cp, 0.0, -sp], [0.0, 1.0, 0.0], [sp, 0.0, cp]])
    # in the rotated frame the camera sits on +x looking down -x, with y to its right and
    # z up
    to_camera = np.array([[0.0, 1.0, 0.0], [0.0, 0.0, -1.0], [-1.0, 0.0, 0.0]])
    eye_local = np.array([camera["distance"], 0.0, 0.0])
    local = (np.asarray(points_mm) - camera["target"]) @ (rz @ ry)
    xyz = (local - eye_local) @ to_camera.T
    return np.column_stack(
        [camera["cx"] + camera["focal"] * xyz[:, 0] / xyz[:, 2],
         camera["cy"] + camera["focal"] * xyz[:, 1] / xyz[:, 2], xyz[:, 2]]
    )  # fmt: skip


def _check_taxels_drawn_in_place(view, skin, joints):
    state = view.evaluate(
        "() => { const s = window.tactsenseHand; return {layout: s.layout, camera: s.camera,"
        " screen: s.screen, positions: s.positions, normals: s.normals,"
        " width: document.getElementById('scene').width,"
        " height: document.getElementById('scene').height}; }"
    )
    expected = skin.taxels_in_base(joints)
    drawn = {p["name"]: p for p in state["layout"]["patches"]}
    assert list(drawn) == [p.name for p in skin.patches]
    for patch in skin.patches:
        in_link, _ = patch.taxels_in_link()
        np.testing.assert_allclose(drawn[patch.name]["positions_link_mm"], in_link * 1e3,
                                   atol=2e-4)  # fmt: skip
    for name, (positions_m, normals) in expected.items():
        # where the page put them (its link poses applied to the link-frame positions, both
        # rounded on the wire: 1e-4 mm and 1e-9)
        np.testing.assert_allclose(state["positions"][name], positions_m * 1e3, atol=1e-3)
        np.testing.assert_allclose(state["normals"][name], normals, atol=1e-6)
        screen = np.asarray(state["screen"][name])
        assert screen.shape == (len(positions_m), 3)
        # the same formula evaluated twice in float64: agreement to well under a pixel
        np.testing.assert_allclose(
            screen, _projected(state["camera"], np.asarray(state["positions"][name])),
            atol=1e-6,
        )  # fmt: skip
        assert (screen[:, 2] > 0).all(), f"{name}: taxels behind the camera"
        assert (screen[:, 0] >= 0).all() and (screen[:, 0] <= state["width"]).all(), name
        assert (screen[:, 1] >= 0).all() and (screen[:, 1] <= state["height"]).all(), name
    return state


def test_every_taxel_is_drawn_at_its_place_on_its_link(page, tmp_path):  # noqa: F811
    skin = small_hand()
    path = hand_recording(tmp_path / "run", skin)
    server = _serve(path)
    try:
        page.goto(server.url)
        _wait_ended(page)
        before = _check_taxels_drawn_in_place(page, skin, JOINTS)
        # orbit (drag) and zoom (wheel): the camera moves and the taxels with it
        box = page.locator("#scene").bounding_box()
        x, y = box["x"] + box["width"] / 2, box["y"] + box["height"] / 2
        page.mouse.move(x, y)
        page.mouse.down()
        page.mouse.move(x + 80, y + 30, steps=4)
        page.mouse.up()
        page.mouse.wheel(0, 300)
        page.wait_for_function(
            f"() => {{ const s = window.tactsenseHand; return !s.dirty"
            f" && s.camera.distance > {before['camera']['distance']}; }}"
        )
        after = _check_taxels_drawn_in_place(page, skin, JOINTS)
        assert after["camera"]["yaw"] == pytest.approx(before["camera"]["yaw"] - 0.8)
        assert after["camera"]["pitch"] == pytest.approx(before["camera"]["pitch"] + 0.3)
        moved = np.asarray(after["screen"]["palm_pad"]) - np.asarray(before["screen"]["palm_pad"])
        assert np.abs(moved[:, :2]).max() > 5.0  # pixels: the view really turned
        page.click("#reset-view")
        page.wait_for_function(
            f"() => window.tactsenseHand.camera.yaw === {before['camera']['yaw']}"
            " && !window.tactsenseHand.dirty"
        )
    finally:
        server.stop()


def test_the_preset_hand_at_a_joint_state(page, tmp_path):  # noqa: F811
    skin = load_skin("hand4")
    limits = {j.name: (j.lower, j.upper) for j in skin.joints if j.type != "fixed"}
    joints = {name: min(max(0.3, low), high) for name, (low, high) in limits.items()}
    path = hand_recording(tmp_path / "run", skin, pressed=None, seconds=0.1)
    server = _serve(path, joints=joints)
    try:
        page.goto(server.url)
        _wait_ended(page)
        state = _check_taxels_drawn_in_place(page, skin, joints)
        assert sum(len(v) for v in state["screen"].values()) == skin.n_taxels
        assert page.locator("#patch-rows tr").count() == len(skin.patches)
        assert page.locator("#link-rows tr").count() == 0  # nothing pressed: no contacts
        assert page.locator("#no-contacts").is_visible()
    finally:
        server.stop()


def test_pressed_patch_is_hottest_and_its_link_is_in_the_table(page, tmp_path):  # noqa: F811
    skin = small_hand()
    path = hand_recording(tmp_path / "run", skin, pressed="finger_pad")
    server = _serve(path)
    try:
        page.goto(server.url)
        _wait_ended(page)
        state = page.evaluate(
            "() => { const s = window.tactsenseHand; return {colours: s.colourIndex,"
            " latest: s.latest, arrows: s.arrows, scale: s.scale}; }"
        )
        colours = {name: np.asarray(v) for name, v in state["colours"].items()}
        hottest = max(colours, key=lambda name: colours[name].max())
        assert hottest == "finger_pad"
        assert colours["finger_pad"].max() == 255  # the scale tops at the hottest taxel
        for name in ("palm_pad", "tip"):  # untouched: read noise only, far below
            assert colours[name].max() < 64, name
        # the hottest taxel is the one under the press
        centre = pressed_centre_mm(skin, "finger_pad")
        taxels = skin.patch("finger_pad").sensor.taxel_positions_mm()[:, :2]
        nearest = np.argsort(((taxels - centre) ** 2).sum(axis=1))[:4]  # centre of a 4x8 grid
        assert int(np.argmax(colours["finger_pad"])) in nearest
        # the tables: one link, one contact, on the pressed patch
        links = page.locator("#link-rows tr")
        assert links.count() == 1
        assert links.nth(0).locator("td").nth(0).text_content() == "finger"
        assert links.nth(0).locator("td").nth(4).text_content() == "finger_pad"
        rows = page.locator("#contact-rows tr")
        assert rows.count() == 1
        cells = [rows.nth(0).locator("td").nth(k).text_content() for k in range(7)]
        assert cells[:2] == ["finger", "finger_pad"]
        assert page.locator("#no-contacts").is_hidden()
        assert [(a["patch"], a["link"]) for a in state["arrows"]] == [("finger_pad", "finger")]
        # where: the pressed place moved by the kinematics, computed here from the link
        # pose and the patch origin; 2 mm: the pad estimator's bias on a 3 mm pitch grid
        # (0.8 mm measured) plus the displayed rounding
        contact = state["latest"]["contacts"][0]
        pose = skin.patch_pose("finger_pad", JOINTS)
        pressed = pose[:3, :3] @ np.array([*centre, 0.0]) * 1e-3 + pose[:3, 3]
        np.testing.assert_allclose(contact["position_mm"], pressed * 1e3, atol=2.0)
        np.testing.assert_allclose([float(c) for c in cells[3:6]], pressed * 1e3, atol=2.0)
        # the force pushes into the skin: against the pad's outward normal (its +z)
        outward = pose[:3, 2]
        assert np.dot(contact["force_vector_n"], outward) < 0
        assert float(cells[6]) > 0
    finally:
        server.stop()


def test_the_page_and_health_of_the_hands_server(tmp_path):
    import json
    import urllib.request

    server = _serve(hand_recording(tmp_path / "run", pressed=None, seconds=0.2))
    try:
        page = urllib.request.urlopen(server.url, timeout=5).read().decode()
        assert "hand.js" in page and "tactsense hand" in page
        health = json.loads(urllib.request.urlopen(server.url + "api/health", timeout=5).read())
        assert set(health["feed"]["patch_frames"]) == {"palm_pad", "finger_pad", "tip"}
    finally:
        server.stop()


def _recorded_streams(path):
    from tactsense.io.robot_recording import read_robot_recording

    return {name: rec.frames for name, rec in read_robot_recording(path).streams.items()}


def test_live_from_several_devices(page, tmp_path):  # noqa: F811
    from tactsense.stream.robot import RobotSources
    from tactsense.stream.robot_emulator import device_emulators, start_device_emulators
    from tactsense.view.robot_live import RobotLiveFeed

    skin = small_hand()  # a device per patch: three boards at 100, 250 and 50 Hz
    streams = _recorded_streams(hand_recording(tmp_path / "run", skin, seconds=1.5))
    running = start_device_emulators(device_emulators(skin, streams, repeat=False, seed=3))
    server = None
    try:
        sources = RobotSources(skin, {device: d.url for device, d in running.items()})
        server = RobotViewServer(RobotLiveFeed(sources, joint_positions=JOINTS))
        server.start()
        page.goto(server.url)
        # every device streams its frames, then sends END: the page's last state holds
        page.wait_for_function(
            "() => { const s = window.tactsenseHand; return s.status === 'ended' && s.latest"
            " && s.drawnSerial === s.latest.serial && !s.dirty; }",
            timeout=20000,
        )
        _check_taxels_drawn_in_place(page, skin, JOINTS)
        state = page.evaluate(
            "() => ({colours: window.tactsenseHand.colourIndex,"
            " devices: window.tactsenseHand.latest.devices})"
        )
        assert {d["device"]: d["state"] for d in state["devices"]} == {
            "palm_pad": "ended", "finger_pad": "ended", "tip": "ended"
        }  # fmt: skip
        colours = {name: np.asarray(v) for name, v in state["colours"].items()}
        assert max(colours, key=lambda name: colours[name].max()) == "finger_pad"
        links = page.locator("#link-rows tr")
        assert links.count() == 1
        assert links.nth(0).locator("td").nth(0).text_content() == "finger"
        assert page.locator("#devices").text_content().count("ended") == 3
        # each patch's own estimator took the baselines, then the robot estimator took over
        assert "robot estimator" in page.text_content("#estimator")
    finally:
        if server is not None:
            server.stop()
        for device in running.values():
            device.stop()


def test_the_view_command_on_a_robot_recording(page, tmp_path):  # noqa: F811
    import subprocess
    import sys

    path = hand_recording(tmp_path / "run", pressed="finger_pad")
    view = subprocess.Popen(
        [sys.executable, "-m", "tactsense", "view", str(path), "--joints", "knuckle=0.5",
         "--speed", "4"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )  # fmt: skip
    try:
        address = view.stdout.readline().strip()
        assert address.startswith("http://127.0.0.1:"), view.stderr.read()
        page.goto(address)
        _wait_ended(page)
        _check_taxels_drawn_in_place(page, small_hand(), JOINTS)
        assert page.text_content("#skin") == "testhand"
        assert page.text_content("#joints") == "knuckle=0.5"
        assert page.locator("#link-rows tr").nth(0).locator("td").nth(0).text_content() == "finger"
    finally:
        view.send_signal(2)
        try:
            view.wait(10)
        except subprocess.TimeoutExpired:
            view.kill()
    err = view.stderr.read()
    assert view.returncode == 0, err
    assert "hand frames shown" in err  # Ctrl-C: a summary line, no traceback
    assert "Traceback" not in err


def test_seek_pause_and_play_act_on_the_whole_hand(page, tmp_path):  # noqa: F811
    skin = small_hand()
    path = hand_recording(tmp_path / "run", skin, pressed="finger_pad")  # pressed from 1/3 s
    server = _serve(path)
    try:
        page.goto(server.url)
        _wait_ended(page)
        assert page.locator("#link-rows tr").count() == 1
        # back to 0.1 s, before the press: no contacts, every patch at rest
        page.evaluate(
            "() => { const s = document.getElementById('seek'); s.value = 0.1;"
            " s.dispatchEvent(new Event('input')); }"
        )
        page.wait_for_function(
            "() => { const s = window.tactsenseHand; return s.latest && s.latest.playback"
            " && Math.abs(s.latest.playback.time_s - 0.1) < 1e-9"
            " && s.drawnSerial === s.latest.serial && !s.dirty; }"
        )
        assert page.locator("#link-rows tr").count() == 0
        assert page.text_content("#play") == "play"  # it ended: seeking does not play
        times = page.evaluate("() => window.tactsenseHand.latest.frame_times_s")
        # each patch shows its newest frame due by 0.1 s, at its own rate (the device times
        # of a simulation start at 0): within one scan period
        for name, rate in (("palm_pad", 100.0), ("finger_pad", 250.0)):
            assert 0.1 - 1.0 / rate - 1e-9 <= times[name] <= 0.1 + 1e-9, name
        page.click("#play")
        # played on to the end (the time at 0.1 s till then: no stale 'ended' passes)
        page.wait_for_function(
            "() => { const s = window.tactsenseHand, p = s.latest && s.latest.playback;"
            " return p && p.time_s === p.duration_s && s.status === 'ended'"
            " && s.drawnSerial === s.latest.serial && !s.dirty; }",
            timeout=20000,
        )
        assert page.locator("#link-rows tr").count() == 1
    finally:
        server.stop()


def test_a_device_that_drops_out_is_shown_and_the_others_go_on(page, tmp_path):  # noqa: F811
    from tactsense.stream.robot import RobotSources
    from tactsense.stream.robot_emulator import device_emulators, start_device_emulators
    from tactsense.view.robot_live import RobotLiveFeed

    skin = small_hand()
    streams = _recorded_streams(hand_recording(tmp_path / "run", skin, pressed=None))
    running = start_device_emulators(device_emulators(skin, streams, repeat=True, seed=4))
    server = None
    try:
        sources = RobotSources(skin, {device: d.url for device, d in running.items()})
        feed = RobotLiveFeed(sources, joint_positions=JOINTS)
        server = RobotViewServer(feed)
        server.start()
        page.goto(server.url)
        states_js = (
            "() => { const s = window.tactsenseHand; if (!s.latest || !s.latest.devices)"
            " return null; return Object.fromEntries(s.latest.devices.map("
            "d => [d.device, d.state])); }"
        )
        page.wait_for_function(
            f"() => {{ const d = ({states_js})(); return d && Object.values(d).every("
            "v => v === 'streaming'); }",
            timeout=20000,
        )
        running["tip"].stop()  # the tip's board goes away: its line closes
        page.wait_for_function(
            f"() => {{ const d = ({states_js})(); return d && d.tip === 'dropped'; }}",
            timeout=20000,
        )
        shown = feed.state.frames_seen["palm_pad"]
        page.wait_for_function(  # the others go on: more frames shown after the drop
            f"() => window.tactsenseHand.latest.frame_counts.palm_pad > {shown + 5}",
            timeout=20000,
        )
        states = page.evaluate(states_js)
        assert states == {"palm_pad": "streaming", "finger_pad": "streaming", "tip": "dropped"}
        assert page.locator("#devices li.dropped").count() == 1
        assert page.text_content("#status") == "streaming"
    finally:
        if server is not None:
            server.stop()
        for device in running.values():
            device.stop()


def test_the_view_command_live_from_several_devices(page, tmp_path):  # noqa: F811
    import subprocess
    import sys

    from tactsense.robot import skin_to_toml_string
    from tactsense.stream.robot_emulator import device_emulators, start_device_emulators

    skin = small_hand()
    skin_file = tmp_path / "hand.toml"
    skin_file.write_text(skin_to_toml_string(skin))
    streams = _recorded_streams(hand_recording(tmp_path / "run", skin))
    running = start_device_emulators(device_emulators(skin, streams, repeat=False, seed=5))
    # plain sources in the skin's device order (palm_pad, finger_pad, tip)
    urls = [running[device].url for device in skin.devices]
    view = subprocess.Popen(
        [sys.executable, "-m", "tactsense", "view", "--skin", str(skin_file), *urls,
         "--joints", "knuckle=0.5"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )  # fmt: skip
    try:
        address = view.stdout.readline().strip()
        assert address.startswith("http://127.0.0.1:"), view.stderr.read()
        page.goto(address)
        page.wait_for_function(
            "() => { const s = window.tactsenseHand; return s.status === 'ended' && s.latest"
            " && s.drawnSerial === s.latest.serial && !s.dirty; }",
            timeout=30000,
        )
        _check_taxels_drawn_in_place(page, skin, JOINTS)
        assert page.locator("#link-rows tr").nth(0).locator("td").nth(0).text_content() == "finger"
        assert page.locator("#rezero").is_visible()  # live: the baseline can be taken anew
    finally:
        view.send_signal(2)
        try:
            view.wait(10)
        except subprocess.TimeoutExpired:
            view.kill()
        for device in running.values():
            device.stop()
    err = view.stderr.read()
    assert view.returncode == 0, err
    assert "hand frames shown" in err and "Traceback" not in err


def _last_message(path, state_kind=None, joints=JOINTS):
    """The feed's message at the recording's end, shown in one tick (no thread, no page)."""
    feed = RobotRecordingFeed(path, joint_positions=joints)
    try:
        if state_kind is not None:  # the per-patch state, for comparison
            from tactsense.view.robot_state import HandState

            baselines = {
                name: np.median(s.file.frames(0, 5).astype(float), axis=0)
                for name, s in feed.streams.items()
            }
            feed.state = HandState(feed.skin, joints, baselines=baselines,
                                   frame_period_s=feed.period_s)  # fmt: skip
        feed._publish = lambda text: None
        feed.time_s = feed.end_s
        feed._tick()
        return feed, feed._latest
    finally:
        feed.close_streams()


def test_the_robot_estimator_and_each_patchs_own_agree(tmp_path):
    from tactsense.view.robot_estimator import HandEstimatorState
    from tactsense.view.robot_state import HandState

    path = hand_recording(tmp_path / "run", pressed="finger_pad")
    feed, hand = _last_message(path)
    assert type(feed.state) is HandEstimatorState  # pads and a point set: it takes them
    _, each = _last_message(path, state_kind=HandState)
    assert [(c["patch"], c["link"]) for c in hand["contacts"]] == [("finger_pad", "finger")]
    assert [(c["patch"], c["link"]) for c in each["contacts"]] == [("finger_pad", "finger")]
    a, b = hand["contacts"][0], each["contacts"][0]
    # the same interpolation on the same frame and baseline (the per-patch one's drift
    # baseline has not moved: the press is the only signal); 1e-3 mm and 1e-4 N: the
    # messages' rounding and the two code paths' arithmetic
    np.testing.assert_allclose(a["position_mm"], b["position_mm"], atol=1e-3)
    np.testing.assert_allclose(a["normal"], b["normal"], atol=1e-6)
    assert a["force_n"] == pytest.approx(b["force_n"], abs=1e-4)
    # the link's wrench: r x F about the link's origin, in the link's frame, by hand
    row = hand["links"][0]
    r = np.asarray(a["position_link_mm"])
    force_link = np.array([0.0, 0.0, a["force_n"]])  # the pad's -z normal, pressing +z
    np.testing.assert_allclose(row["force_link_n"], force_link, atol=1e-5)
    np.testing.assert_allclose(row["torque_link_n_mm"], np.cross(r, force_link), atol=1e-3)


def test_a_kind_the_robot_estimator_does_not_place_falls_back_to_each_patch(tmp_path):
    from tactsense.sensor import preset as sensor_preset
    from tactsense.view.robot_state import HandState

    skin = small_hand()
    finger = dataclasses.replace(skin.patches[0], sensor=sensor_preset("initial"))
    skin = dataclasses.replace(skin, patches=(finger, *skin.patches[1:]))
    path = hand_recording(tmp_path / "run", skin, pressed=None, seconds=0.3)
    feed, message = _last_message(path)
    assert type(feed.state) is HandState
    assert "each patch" in feed.layout()["estimator"]
    assert message["contacts"] == []


def test_the_hand_moves_as_the_recordings_joint_states_say(page, tmp_path):  # noqa: F811
    from tactsense.estimate._robot_joints import read_joint_csv

    skin = small_hand()
    path = hand_recording(tmp_path / "run", skin, pressed="finger_pad")
    table = tmp_path / "joints.csv"
    table.write_text("time_s,knuckle\n0,0\n1,1.2\n")  # 0 -> 1.2 rad over the second
    server = RobotViewServer(
        RobotRecordingFeed(path, joint_states=read_joint_csv(table), speed=4.0)
    )
    server.start()
    try:
        page.goto(server.url)
        _wait_ended(page)
        for t in (0.25, 0.75):
            page.evaluate(
                "(t) => { const s = document.getElementById('seek'); s.value = t;"
                " s.dispatchEvent(new Event('input')); }",
                t,
            )
            page.wait_for_function(
                "(t) => { const s = window.tactsenseHand; return s.latest"
                " && Math.abs(s.latest.playback.time_s - t) < 1e-9"
                " && s.drawnSerial === s.latest.serial && !s.dirty; }",
                arg=t,
            )
            # the joint state interpolated at t (the streams' clock starts at 0)
            joints = {"knuckle": 1.2 * t}
            _check_taxels_drawn_in_place(page, skin, joints)
            assert page.text_content("#joints") == f"knuckle={1.2 * t:g}"
        # the contact moves with its link: at 0.75 s, where the kinematics put the press
        contact = page.evaluate("() => window.tactsenseHand.latest.contacts[0]")
        pose = skin.patch_pose("finger_pad", {"knuckle": 0.9})
        centre = pressed_centre_mm(skin, "finger_pad")
        pressed = pose[:3, :3] @ np.array([*centre, 0.0]) * 1e-3 + pose[:3, 3]
        np.testing.assert_allclose(contact["position_mm"], pressed * 1e3, atol=2.0)
    finally:
        server.stop()


def test_the_view_command_takes_the_recordings_own_joint_states(tmp_path):
    import json
    import subprocess
    import sys
    import time
    import urllib.request

    path = hand_recording(tmp_path / "run", pressed=None, seconds=0.5)
    (path / "joint_states.csv").write_text("time_s,knuckle\n0,0.2\n1,1.2\n")
    view = subprocess.Popen(
        [sys.executable, "-m", "tactsense", "view", str(path), "--speed", "4"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        address = view.stdout.readline().strip()
        assert address.startswith("http://127.0.0.1:"), view.stderr.read()
        deadline = time.monotonic() + 30
        while time.monotonic() < deadline:
            feed = json.loads(urllib.request.urlopen(address + "api/health", timeout=5).read())
            if feed["feed"]["status"] == "ended":
                break
            time.sleep(0.1)
        feed = feed["feed"]
        assert feed["status"] == "ended"
        # at the end of the streams: the last frame of the slowest stream (the dome at
        # 50 Hz: 0.48 s) or later; the joint interpolated there
        end = feed["playback"]["time_s"]
        assert feed["joints"]["knuckle"] == pytest.approx(0.2 + end, abs=1e-9)
    finally:
        view.send_signal(2)
        try:
            view.wait(10)
        except subprocess.TimeoutExpired:
            view.kill()
    err = view.stderr.read()
    assert "joint states from" in err and "joint_states.csv" in err, err
    assert view.returncode == 0 and "Traceback" not in err, err


def test_a_simulations_joint_state_is_the_default(tmp_path):
    path = hand_recording(tmp_path / "run", pressed=None, seconds=0.2,
                          scenario={"kind": "grasp", "joints": {"knuckle": 0.7}})  # fmt: skip
    feed = RobotRecordingFeed(path)
    try:
        assert feed.state.joints == {"knuckle": 0.7}
        layout = feed.layout()
        expected = small_hand().taxels_in_base({"knuckle": 0.7})
        for patch in layout["patches"]:
            np.testing.assert_allclose(patch["positions_mm"], expected[patch["name"]][0] * 1e3,
                                       atol=2e-4)  # fmt: skip
    finally:
        feed.close_streams()
    feed = RobotRecordingFeed(path, joint_positions={"knuckle": 0.1})  # --joints wins
    try:
        assert feed.state.joints == {"knuckle": 0.1}
    finally:
        feed.close_streams()
