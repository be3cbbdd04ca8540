"""The view's server side for pads and point sets: the deflection sent with each frame
(from counts, by the sensor's transduction), the tracked contacts, re-zeroing, and the
layout's geometry (millimetres, the projection of a point set, the pad's surface
weights)."""

import json

import numpy as np
import pytest

import tactsense as ts
from tactsense._validation import TactsenseInputError
from tactsense.estimate.finger.interpolate import reconstruct_row
from tactsense.io.recording import Recording, write_recording
from tactsense.sensor import Electronics, Grid, PadSpec, PointsSpec, Taxels, Transduction
from tactsense.stream.live import LiveContacts
from tactsense.stream.reader import StreamFrame
from tactsense.view import RecordingFeed, layout_message, view_locator
from tactsense.view.feed import MAX_FINE, SURFACE_STEPS, project_points

SOURCE = {"kind": "test", "name": "x"}


def _frame(counts, index=0):
    return StreamFrame(index, index, 0.0, 0.0, 0.0, np.asarray(counts))


def _pad(kind, **electronics):
    return PadSpec(
        name=f"{kind}pad",
        grid=Grid(
            rows=3,
            cols=4,
            row_pitch_mm=4.0,
            col_pitch_mm=2.5,
            electrode_x_mm=3.0,
            electrode_y_mm=2.0,
        ),
        transduction=Transduction(kind=kind, counts_per_strain=12000.0),
        electronics=Electronics(**electronics),
    )


def _baseline_frames(rng, v0, shape, n=5):
    """Untouched frames: the median of these is ``v0`` exactly at each taxel (odd n,
    symmetric offsets), while the mean is not (one frame carries an outlier)."""
    offsets = np.array([-2.0, -1.0, 0.0, 1.0, 40.0])[:n]  # median 0, mean 7.6
    perm = np.stack([rng.permutation(n) for _ in range(int(np.prod(shape)))], axis=1)
    return v0[None] + offsets[perm].reshape(n, *shape)


def test_resistive_pad_deflection_is_the_strain_above_the_baseline():
    spec = _pad("resistive", nominal_counts=100.0)
    rng = np.random.default_rng(1)
    v0 = 100.0 + rng.integers(-10, 10, spec.shape)  # each taxel its own untouched reading
    locator = view_locator(spec, baseline_frames=5)
    assert isinstance(locator, LiveContacts)
    for k, counts in enumerate(_baseline_frames(rng, v0, spec.shape)):
        assert locator(_frame(counts, k)) is None
        assert locator.last_deflection is None  # no deflection before the baseline
    # the median of the baseline frames, then followed through them (DriftBaseline, as
    # locate does): within a count of the median
    np.testing.assert_allclose(locator.baseline, v0, atol=1.0)
    base = locator.baseline.copy()
    strain = rng.uniform(0.0, 0.08, spec.shape)
    counts = v0 + 12000.0 * strain  # the resistive law of docs/sensors.md
    assert locator(_frame(counts, 5)) is not None  # the estimate of the first frame
    expected = (counts - base) / 12000.0
    np.testing.assert_allclose(locator.last_deflection, expected, rtol=0, atol=1e-12)
    np.testing.assert_allclose(locator.last_deflection, strain, rtol=0, atol=1e-4)


def test_capacitive_pad_deflection_is_eq_4():
    spec = _pad("capacitive", nominal_counts=2000.0)
    rng = np.random.default_rng(2)
    v0 = 2000.0 + rng.integers(-50, 50, spec.shape)
    locator = view_locator(spec, baseline_frames=5)
    for k, counts in enumerate(_baseline_frames(rng, v0, spec.shape)):
        locator(_frame(counts, k))
    np.testing.assert_allclose(locator.baseline, v0, atol=1.0)
    base = locator.baseline.copy()
    d = rng.uniform(0.0, 0.2, spec.shape)
    counts = v0 / (1.0 - d)  # eq. 4, (V - V0) / V = d, solved for V
    locator(_frame(counts, 5))
    np.testing.assert_allclose(locator.last_deflection, (counts - base) / counts, atol=1e-12)
    np.testing.assert_allclose(locator.last_deflection, d, rtol=0, atol=1e-3)
    # not the resistive law on the same counts
    assert not np.allclose(locator.last_deflection, (counts - v0) / 12000.0, atol=1e-3)


def test_pad_recording_feed_sends_deflection_contacts_and_rezeroes(tmp_path):
    spec = _pad("resistive", nominal_counts=100.0, scan_rate_hz=50.0)
    frames = np.full((16, *spec.shape), 100, dtype=np.uint16)
    frames[5:, 1, 2] = 700  # 600 counts = strain 0.05
    rec = Recording(frames=frames, time_s=np.arange(16) / 50.0,
                    sample_offset_s=np.zeros(spec.shape), sensor=spec)  # fmt: skip
    path = write_recording(tmp_path / "pad.h5", rec)
    feed = RecordingFeed(path, lambda s, f: view_locator(s, baseline_frames=5))
    sent = []
    feed._publish = sent.append
    try:
        for index in range(8):
            feed._show(index, 0.0)
        # the page's re-zero (its button, key z): the next 5 frames, still pressed,
        # make the baseline; the press then reads as nothing
        feed.command({"command": "rezero"})
        for index in range(8, 16):
            feed._show(index, 0.0)
        layout = feed.layout()
    finally:
        feed.stop()
    messages = [json.loads(t) for t in sent]
    assert [m["estimate"] is None for m in messages[:8]] == [True] * 5 + [False] * 3
    assert [m["deflection"] is None for m in messages[:8]] == [True] * 5 + [False] * 3
    d = np.asarray(messages[7]["deflection"])
    expected = np.zeros(spec.shape)
    expected[1, 2] = 600 / 12000.0
    np.testing.assert_allclose(d, expected, atol=1e-6)
    for m in messages[5:8]:  # one contact, at the taxel, with the same id
        (contact,) = m["estimate"]["contacts"]
        assert (round(contact["row"]), round(contact["col"])) == (1, 2)
        assert contact["id"] == 0
        # the page draws it at (u, v) = (x, y) [mm] (a pad seen from +z)
        assert contact["u_mm"] == pytest.approx(contact["x_mm"])
        assert contact["v_mm"] == pytest.approx(contact["y_mm"])
        assert m["estimate"]["n_contacts"] == 1
    # while re-zeroing the old baseline still applies; after it, no contact
    assert [m["estimate"]["rezeroing"] for m in messages[8:13]] == [True] * 4 + [False]
    assert all(m["estimate"]["n_contacts"] == 0 for m in messages[13:])
    np.testing.assert_allclose(np.asarray(messages[-1]["deflection"]), 0.0, atol=1e-9)
    assert layout["estimation"] is None and layout["multi_contact"] is True
    assert layout["kind"] == "pad" and layout["geometry"] == "plane"


def test_calibration_is_refused_for_a_pad():
    with pytest.raises(TactsenseInputError, match="a finger's calibration does not apply"):
        view_locator(ts.preset("pad16"), calibration=object())


def test_finger_layout_keeps_its_estimation():
    layout = layout_message(ts.preset("initial"), SOURCE)
    assert layout["estimation"] is None and layout["geometry"] == "finger"


def test_pad_layout_positions_are_the_grid_in_millimetres():
    spec = _pad("resistive")
    layout = layout_message(spec, SOURCE)
    rows, cols = np.meshgrid(np.arange(3), np.arange(4), indexing="ij")
    np.testing.assert_array_equal(layout["u_mm"], (rows * 4.0).ravel())
    np.testing.assert_array_equal(layout["v_mm"], (cols * 2.5).ravel())
    assert layout["bounds_mm"] == [-2.0, 10.0, -1.25, 8.75]  # half a pitch beyond
    assert "mm" in layout["u_label"] and "mm" in layout["v_label"]


@pytest.mark.parametrize("axis", ["rows", "cols"])
def test_pad_surface_is_the_one_dimensional_reconstruction_not_wrapped(axis):
    """Along each axis the pad's surface is eq. 46's row reconstruction (a separate
    implementation), which is not periodic: the wrapped weights of a closed finger
    differ from it by up to 0.015 on this profile (the bump leaks across the edge)."""
    spec = ts.preset("pad4")
    layout = layout_message(spec, SOURCE)
    s = layout["surface"]
    w_rows, w_cols = np.asarray(s["w_rows"]), np.asarray(s["w_cols"])
    profile = np.array([1.0, 0.3, 0.0, 0.0])
    z = np.zeros(spec.shape)
    if axis == "rows":
        z[:, 2] = profile
        f = (w_rows @ z @ w_cols.T)[:, np.flatnonzero(np.abs(np.asarray(s["col"]) - 2) < 1e-9)[0]]
        fine = np.asarray(s["row"])
    else:
        z[1, :] = profile
        f = (w_rows @ z @ w_cols.T)[np.flatnonzero(np.abs(np.asarray(s["row"]) - 1) < 1e-9)[0]]
        fine = np.asarray(s["col"])
    np.testing.assert_allclose(f, reconstruct_row(profile, fine), atol=2e-6)
    assert len(fine) == 4 * SURFACE_STEPS


def test_point_set_projection_is_x_y_when_the_normals_average_to_z():
    spec = ts.preset("dome12")
    layout = layout_message(spec, SOURCE)
    positions = spec.taxel_positions_mm()
    np.testing.assert_allclose(layout["u_mm"], positions[:, 0], atol=1e-12)
    np.testing.assert_allclose(layout["v_mm"], positions[:, 1], atol=1e-12)
    assert layout["u_label"] == "x [mm]" and layout["surface"] is None
    assert layout["estimation"] is None and layout["multi_contact"] is True


def test_point_set_projection_is_an_isometry_of_a_tilted_flat_set():
    """A flat 3 x 4 patch tilted and moved in space projects onto its own plane: distances
    between taxels are kept, and the view is from outside (not mirrored)."""
    x, y = np.meshgrid(np.arange(3) * 3.0, np.arange(4) * 2.0, indexing="ij")
    flat = np.column_stack([x.ravel(), y.ravel(), np.zeros(x.size)])
    a, b = np.radians(35.0), np.radians(-20.0)
    rx = np.array([[1, 0, 0], [0, np.cos(a), -np.sin(a)], [0, np.sin(a), np.cos(a)]])
    rz = np.array([[np.cos(b), -np.sin(b), 0], [np.sin(b), np.cos(b), 0], [0, 0, 1]])
    rot = rz @ rx
    positions = flat @ rot.T + np.array([5.0, -3.0, 7.0])
    normals = np.tile(rot @ np.array([0.0, 0.0, 1.0]), (12, 1))
    plane = project_points(positions, normals)
    uv = np.column_stack([plane["u_mm"], plane["v_mm"]])
    gaps = np.linalg.norm(uv[:, None] - uv[None], axis=-1)
    true_gaps = np.linalg.norm(flat[:, None] - flat[None], axis=-1)
    np.testing.assert_allclose(gaps, true_gaps, atol=1e-9)
    # right-handed seen from outside: the turn from taxel 0 to +x then +y is positive
    e1, e2 = uv[3] - uv[0], uv[1] - uv[0]  # +y neighbour, +x neighbour
    assert e2[0] * e1[1] - e2[1] * e1[0] > 0
    # and the layout of such a sensor uses it
    spec = PointsSpec(
        name="tilted",
        taxels=Taxels(
            positions_mm=tuple(map(tuple, positions)),
            normals=tuple(map(tuple, normals)),
            area_mm2=(1.0,) * 12,
        ),
    )
    layout = layout_message(spec, SOURCE)
    np.testing.assert_allclose(layout["u_mm"], plane["u_mm"])
    assert layout["u_label"].startswith("u [mm]")


def test_large_pad_surface_stays_bounded_and_passes_through_the_taxels():
    """A 64 x 48 pad: at most MAX_FINE surface points per axis (the page evaluates the
    surface every frame), still an odd number per pitch so that one band sits on each
    taxel, where the surface is the taxel's value."""
    spec = PadSpec(name="big", grid=Grid(rows=64, cols=48, row_pitch_mm=1.0, col_pitch_mm=1.0,
                                         electrode_x_mm=0.8, electrode_y_mm=0.8))  # fmt: skip
    layout = layout_message(spec, SOURCE)
    s = layout["surface"]
    rows, cols = np.asarray(s["row"]), np.asarray(s["col"])
    assert len(rows) <= MAX_FINE and len(cols) <= MAX_FINE
    z = np.random.default_rng(3).random(spec.shape)
    f = np.asarray(s["w_rows"]) @ z @ np.asarray(s["w_cols"]).T
    i = [int(np.flatnonzero(np.abs(rows - r) < 1e-9)[0]) for r in range(64)]
    j = [int(np.flatnonzero(np.abs(cols - c) < 1e-9)[0]) for c in range(48)]
    np.testing.assert_allclose(f[np.ix_(i, j)], z, atol=5e-6)
