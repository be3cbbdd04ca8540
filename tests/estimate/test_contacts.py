"""Contacts on any array: segmentation, positions, force, extents; the finger's single
contact equal to ``locate``; pads and point sets from the simulator."""

import numpy as np
import pytest
from scipy import ndimage
from skimage.morphology import local_maxima

import tactsense as ts
from tactsense import flat_scenarios as fs
from tactsense._validation import TactsenseInputError
from tactsense.estimate import locate
from tactsense.estimate.contacts import ContactTable, find_contacts
from tactsense.physics.indenters import SphereProbe
from tactsense.physics.pad_response import pad_strain
from tactsense.sensor.registry import load_sensor
from tests._layer_truth import hankel_hertz_strain


@pytest.fixture(scope="module")
def pad16():
    return load_sensor("pad16")


@pytest.fixture(scope="module")
def thick():
    """pad16 under a 6-mm layer read 4 mm deep: a response several taxels wide, so that
    sub-taxel positions are observable (on the preset's 2-mm layer a probe near a
    taxel's centre moves no neighbour: docs/sensors.md)."""
    return load_sensor("pad16").replace(layer__thickness_mm=6.0, layer__sensing_depth_mm=4.0)


def _bumps(shape, centres, sigma=1.0, height=0.05):
    r, c = np.mgrid[0 : shape[0], 0 : shape[1]]
    return sum(height * np.exp(-((r - u) ** 2 + (c - v) ** 2) / (2 * sigma**2)) for u, v in centres)


def test_regions_are_the_local_maxima_of_a_random_frame(pad16):
    """With merging off (saddle 1, threshold tiny, no ridge groups: ring 0), each
    contact is one strict local maximum (8-connected, as skimage finds them) and the
    regions cover every taxel above the threshold."""
    rng = np.random.default_rng(3)
    for _ in range(20):
        frame = ndimage.gaussian_filter(rng.uniform(0, 1, (16, 16)), 1.0)
        table = find_contacts(frame, pad16, counts=False, threshold=1e-9, saddle=1.0,
                              max_contacts=64, method="cop", ring=0.0)  # fmt: skip
        maxima = local_maxima(frame, connectivity=2, allow_borders=True)
        assert len(table) == maxima.sum()
        assert table.taxels.sum() == 256


@pytest.mark.parametrize(
    ("separation", "expected"),
    [(6.0, 2), (2.0, 1)],
)
def test_two_bumps_split_or_merge_by_the_saddle_rule(pad16, separation, expected):
    """Two equal Gaussian bumps (sigma 1 taxel): the dip midway is 2 exp(-d^2/8) of a
    peak; 6 taxels apart it is 0.022 (two contacts), 2 apart 1.21 (no dip: one)."""
    frame = _bumps((16, 16), [(8, 8 - separation / 2), (8, 8 + separation / 2)])
    table = find_contacts(frame, pad16, counts=False)
    assert len(table) == expected
    if expected == 2:
        np.testing.assert_allclose(
            np.sort(table.col), [8 - separation / 2, 8 + separation / 2], atol=0.02
        )
        np.testing.assert_allclose(table.row, 8.0, atol=0.02)


def test_a_shallow_dip_merges_and_a_deep_one_splits(pad16):
    """The saddle rule alone (ring 0): peaks 4 taxels apart, sigma 1.2: dip =
    2 exp(-16/(8 1.44)) = 0.50 of a peak (< 0.8: two); sigma 1.6: 2 exp(-16/(8 2.56)) =
    0.92 (>= 0.8: one). (With the far-ends rule on, the sigma-1.2 pair is one contact on
    pad16: two point loads 4 taxels apart on its layer leave no ridge at half their
    height between them, ``test_far_ends_are_one_only_beyond_point_loads_reach``.)"""
    frame = _bumps((16, 16), [(8, 6), (8, 10)], sigma=1.2)
    assert len(find_contacts(frame, pad16, counts=False, ring=0.0)) == 2
    frame = _bumps((16, 16), [(8, 6), (8, 10)], sigma=1.6)
    assert len(find_contacts(frame, pad16, counts=False, ring=0.0)) == 1
    assert len(find_contacts(frame, pad16, counts=False)) == 1


def test_far_ends_are_one_only_beyond_point_loads_reach(pad16):
    """Two narrow bumps (sigma 0.6 taxel, pad16's point-load width) joined by a ridge at
    0.4 of their height: 3 taxels apart (under point_reach, 3.6 on pad16) they stay two;
    5 apart (beyond it) they are one contact, a cylinder's two ends. The same bumps
    without the ridge stay two at both distances."""
    r, c = np.mgrid[0:16, 0:16].astype(float)
    for apart, expected in ((3, 2), (5, 1)):
        a, b = 8 - apart / 2, 8 + apart / 2
        bumps = _bumps((16, 16), [(8, a), (8, b)], sigma=0.6)
        ridge = 0.02 * ((np.abs(r - 8) < 0.5) & (c > a) & (c < b))
        assert len(find_contacts(np.maximum(bumps, ridge), pad16, counts=False)) == expected
        assert len(find_contacts(bumps, pad16, counts=False)) == 2


def test_centre_of_pressure_equals_scipy_on_separate_blobs(pad16):
    frame = _bumps((16, 16), [(3.3, 4.6), (11.2, 10.7), (4.0, 12.4)], sigma=0.8)
    threshold = 0.005
    table = find_contacts(frame, pad16, counts=False, method="cop", threshold=threshold)
    labels, n = ndimage.label(frame > threshold, structure=np.ones((3, 3)))
    assert n == 3 and len(table) == 3
    centres = ndimage.center_of_mass(np.where(labels > 0, frame, 0), labels, range(1, n + 1))
    sums = ndimage.sum(frame, labels, range(1, n + 1))
    order = np.argsort(-np.asarray(sums))
    np.testing.assert_allclose(table.row, [centres[k][0] for k in order], atol=1e-9)
    np.testing.assert_allclose(table.col, [centres[k][1] for k in order], atol=1e-9)
    assert list(table.contact) == [0, 1, 2]


def test_extent_of_an_elongated_blob(pad16):
    """A Gaussian ridge with sd 2 taxels along x and 0.7 across, turned 30 degrees: the
    second moments give major ~ 2 x 2.5 mm, minor ~ 0.7 x 2.5 mm (sampling and the
    threshold trim the tails: 10 %), orientation 30 deg (2 deg)."""
    r, c = np.mgrid[0:16, 0:16].astype(float)
    t = np.radians(30)
    u = (r - 8) * np.cos(t) + (c - 8) * np.sin(t)
    v = -(r - 8) * np.sin(t) + (c - 8) * np.cos(t)
    frame = 0.05 * np.exp(-(u**2) / (2 * 2.0**2) - v**2 / (2 * 0.7**2))
    table = find_contacts(frame, pad16, counts=False, threshold=1e-4)
    assert len(table) == 1
    np.testing.assert_allclose(table.major_mm[0], 2.0 * 2.5, rtol=0.1)
    np.testing.assert_allclose(table.minor_mm[0], 0.7 * 2.5, rtol=0.1)
    np.testing.assert_allclose(table.orientation_deg[0], 30.0, atol=2.0)


@pytest.mark.parametrize("load", [0.2, 0.49, 0.98])
@pytest.mark.parametrize("offset", [(0.0, 0.0), (0.25, 0.0), (0.5, 0.5), (0.3, 0.7)])
def test_pad_round_trip_from_an_independent_layer_solution(thick, offset, load):
    """Frames from the Hankel-transform solution of the bonded layer (not the FFT grid
    the estimator's table was made on), noise-free, at the table's load (0.49 N) and at
    20 g and 100 g, whose Hertz contacts are 26 % narrower and wider: the ML fit places
    the probe within 0.02 taxel (measured 0.004), the sinc interpolation within 0.1
    (0.08), the centre of pressure within 0.05 (0.025). The fit's force is within 1 % at
    the table's load (measured 0.6 %: the two layer solutions differ by 0.56 % of the
    peak) and within 3 % at the other two (measured +2.7 % and -2.5 %: the table's shape
    is a 0.49-N contact's; issue 34 item 1)."""
    g = thick.grid
    x, y = (7 + offset[0]) * g.row_pitch_mm, (8 + offset[1]) * g.col_pitch_mm
    strain = np.maximum(hankel_hertz_strain(thick, x, y, load), 0.0)
    for method, tol in (("fit", 0.02), ("interpolate", 0.1), ("cop", 0.05)):
        table = find_contacts(strain, thick, counts=False, method=method)
        assert len(table) == 1
        error = np.hypot(table.x_mm[0] - x, table.y_mm[0] - y) / g.row_pitch_mm
        assert error < tol, (method, error)
    fit = find_contacts(strain, thick, counts=False, method="fit")
    np.testing.assert_allclose(fit.force_n, load, rtol=0.01 if load == 0.49 else 0.03)


@pytest.mark.xfail(
    strict=True,
    reason="finding (issue 34 item 1): the fit's table is one 0.49-N contact's shape; "
    "at 20 g and 100 g its force misses by +2.7 % and -2.5 % on independent frames "
    "(method 'joint' meets it: test_joint_force_within_two_percent_at_any_load)",
)
@pytest.mark.parametrize("load", [0.2, 0.98])
def test_pad_fit_force_within_two_percent_at_any_load(thick, load):
    """Issue 34 item 1's goal: noise-free force within 2 % at any load (10-500 g)."""
    g = thick.grid
    x, y = 7.3 * g.row_pitch_mm, 8.7 * g.col_pitch_mm
    strain = np.maximum(hankel_hertz_strain(thick, x, y, load), 0.0)
    fit = find_contacts(strain, thick, counts=False, method="fit")
    np.testing.assert_allclose(fit.force_n, load, rtol=0.02)


@pytest.mark.parametrize("load", [0.2, 0.98])
def test_joint_force_within_two_percent_at_any_load(thick, load):
    """Issue 34 item 1's goal, met by method 'joint' (each contact's size fitted):
    noise-free force within 2 % at 20 and 100 g on independent frames."""
    g = thick.grid
    x, y = 7.3 * g.row_pitch_mm, 8.7 * g.col_pitch_mm
    strain = np.maximum(hankel_hertz_strain(thick, x, y, load), 0.0)
    fit = find_contacts(strain, thick, counts=False, method="joint")
    np.testing.assert_allclose(fit.force_n, load, rtol=0.02)


def test_force_is_linear_in_the_load(thick):
    """Twice the load, about twice the force. Twice the signal is exactly twice the
    force (the fit's amplitude is linear: 1e-9); twice the LOAD is not twice the signal,
    as the Hertz contact widens as F^(1/3) (26 %) while the fit's table keeps a 0.49-N
    contact's shape: the force doubles within 4 % (measured 1.943 = -2.9 %), and each
    force is within 3 % of its load (0.0 % and -2.9 %)."""
    g = thick.grid
    x, y = 7.3 * g.row_pitch_mm, 8.6 * g.col_pitch_mm
    strain = np.maximum(pad_strain(thick, [SphereProbe(x, y, 0.49)]), 0)
    one = find_contacts(strain, thick, counts=False)
    two = find_contacts(2 * strain, thick, counts=False, threshold=0.01)
    np.testing.assert_allclose(two.force_n, 2 * one.force_n, rtol=1e-9)
    heavier = np.maximum(pad_strain(thick, [SphereProbe(x, y, 0.98)]), 0)
    assert np.abs(heavier - 2 * strain).max() > 0.01 * strain.max()  # not the same frame
    double = find_contacts(heavier, thick, counts=False)
    assert len(double) == len(one) == 1
    np.testing.assert_allclose(double.force_n / one.force_n, 2.0, rtol=0.04)
    np.testing.assert_allclose(one.force_n, 0.49, rtol=0.03)
    np.testing.assert_allclose(double.force_n, 0.98, rtol=0.03)


def test_two_probes_on_pad16_from_counts(pad16):
    """The simulated two-probes scenario (every flaw on): two contacts in each loaded
    frame, 5 mm apart along y (2 taxels), each nearer its own probe than the other and
    within 0.6 taxel (1.5 mm) of it (measured up to 1.28 mm, 0.51 taxel): the preset's
    35 % gain spread is not calibrated out, so positions are good to about half a taxel,
    not better. Both contacts at the pair's midpoint (1 taxel off each) fail."""
    import json

    rec = ts.simulate(pad16, fs.two_probes(pad16), rng=0)
    base = np.median(rec.frames[:5], axis=0)
    table = find_contacts(rec.frames, pad16, baseline=base)
    counts = table.per_frame_counts()
    assert table.n_frames == len(rec.frames)
    loaded = counts[25:75]
    assert (loaded == 2).all()
    steps = rec.truth["frame_step"]
    per_step = json.loads(str(rec.truth["step_contacts_json"]))
    checked = [f for f in range(25, 75, 5) if per_step[steps[f]]]  # the probes are down
    assert len(checked) >= 8
    for f in checked:
        probes = per_step[steps[f]]
        truth = np.array([[p["x_mm"], p["y_mm"]] for p in probes])
        assert len(truth) == 2 and np.ptp(truth[:, 1]) == pytest.approx(5.0, abs=0.1)
        rows = table.frame == f
        found = np.column_stack([table.x_mm[rows], table.y_mm[rows]])
        distance = np.linalg.norm(found[:, None] - truth[None], axis=-1)  # found x truth
        nearest = distance.argmin(axis=1)
        assert sorted(nearest) == [0, 1], (f, found, truth)
        assert distance[[0, 1], nearest].max() < 1.5, (f, found, truth)


def test_finger_single_contact_equals_locate(initial):
    rec = ts.simulate(initial, ts.probe_sweep(initial), rng=0)
    base = np.median(rec.frames[:5], axis=0)
    est = locate(rec.frames, initial, baseline=base)
    table = find_contacts(rec.frames, initial, baseline=base)
    single = np.flatnonzero(table.per_frame_counts() == 1)
    assert len(single) > 100
    rows = np.isin(table.frame, single)
    frames = table.frame[rows]
    np.testing.assert_array_equal(table.row[rows], est.row[frames])
    np.testing.assert_array_equal(table.extra["axial_mm"][rows], est.axial_mm[frames])
    np.testing.assert_array_equal(table.force_n[rows], est.force_n[frames])
    # frames locate calls contact-free have no row
    none = np.flatnonzero(np.isnan(est.row))
    assert not np.isin(table.frame, none).any()


def _dome12_press(flaws):
    """dome12 pressed with 50 g on taxel 5: the contacts of the loaded frames (the
    truth's loaded steps, not a frame window that reaches into the lift), the press's
    force [N] and the taxel positions [mm]."""
    spec = load_sensor("dome12")
    positions = spec.taxel_positions_mm()
    rec = ts.simulate(
        spec,
        fs.press(spec, x_mm=float(positions[5, 0]), y_mm=float(positions[5, 1])),
        rng=0,
        flaws=flaws,
    )
    base = np.median(rec.frames[:5], axis=0)
    table = find_contacts(rec.frames, spec, baseline=base)
    loaded = np.flatnonzero(rec.truth["step_n_contacts"][rec.truth["frame_step"]] > 0)
    assert len(loaded) >= 10
    rows = np.isin(table.frame, loaded) & (table.contact == 0)
    assert np.array_equal(np.unique(table.frame[rows]), loaded)  # one contact in each
    force = float(rec.truth["step_force_n"][rec.truth["frame_step"][loaded[0]]])
    return table, rows, force, positions


def test_point_set_press_at_a_taxel():
    """dome12: a 50-g probe on taxel 5 is found nearest to taxel 5 (the weighted
    quadratic fit on its neighbours) in every loaded frame, every flaw on; without the
    gain spread (read noise and quantization only) its force is within 2 % of the load
    (measured -0.7 %)."""
    table, rows, _, positions = _dome12_press("all")
    points = np.column_stack([table.x_mm[rows], table.y_mm[rows], table.z_mm[rows]])
    nearest = np.argmin(np.linalg.norm(points[:, None, :] - positions[None], axis=-1), axis=1)
    assert (nearest == 5).all()
    assert np.all(np.isnan(table.row[rows]))
    table, rows, force, _ = _dome12_press(["noise", "quantization"])
    np.testing.assert_allclose(table.force_n[rows], force, rtol=0.02)


@pytest.mark.xfail(
    strict=True,
    reason="finding (issue 34 item 7): the test promised a force within 35 % with the "
    "gains uncalibrated and never asserted it; with every flaw the force is 41-51 % low "
    "(the preset's gain draw alone: 37 % low)",
)
def test_point_set_press_force_within_35_percent_uncalibrated():
    table, rows, force, _ = _dome12_press("all")
    np.testing.assert_allclose(table.force_n[rows], force, rtol=0.35)


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"method": "bogus"}, "method 'bogus'"),
        ({"max_contacts": 0}, "max_contacts"),
        ({"saddle": 0.0}, "saddle"),
        ({"threshold": float("nan")}, "threshold"),
        ({"threshold": -1.0}, "threshold"),
    ],
)
def test_bad_arguments(pad16, kwargs, message):
    with pytest.raises(TactsenseInputError, match=message):
        find_contacts(np.zeros((16, 16)), pad16, counts=False, **kwargs)


def test_bad_shapes_and_inputs(pad16, initial):
    with pytest.raises(TactsenseInputError, match=r"expected \(\.\.\., 16, 16\)"):
        find_contacts(np.zeros((8, 8)), pad16, counts=False)
    with pytest.raises(TactsenseInputError, match="baseline"):
        find_contacts(np.zeros((16, 16)), pad16)
    with pytest.raises(TactsenseInputError, match="works on pads"):
        find_contacts(np.zeros((8, 8)), initial, counts=False, method="fit")
    frame = _bumps((16, 16), [(8, 8)])
    frame[0, 0] = np.nan
    table = find_contacts(frame, pad16, counts=False)
    assert len(table) == 1 and table.flags[0] & ts.estimate.Flag.NAN_INPUT


def test_empty_table():
    table = ContactTable.empty(4)
    assert len(table) == 0 and list(table.per_frame_counts()) == [0, 0, 0, 0]


def test_finger_contacts_sharing_a_total_below_zero_have_no_force(initial):
    """Two contacts on the finger whose frame sums to zero or less (tension around them,
    as the solid 3-D skin gives): no shared force, NaN and NEGATIVE_FORCE on each, as one
    contact alone gets from locate; positions still given."""
    from tactsense.estimate import Flag

    frame = np.full(initial.shape, -0.01)
    frame[2, 1] = 0.03
    frame[5, 5] = 0.03
    assert frame[1:].sum() < 0
    table = find_contacts(frame[None], initial, counts=False, threshold=0.005)
    assert len(table) == 2
    assert np.all(np.isnan(table.force_n))
    assert np.all(table.flags & int(Flag.NEGATIVE_FORCE))
    assert np.all(np.isfinite(table.row))
    positive = np.where(frame > 0, frame, 0.0)
    ok = find_contacts(positive[None], initial, counts=False, threshold=0.005)
    assert len(ok) == 2 and np.all(ok.force_n > 0)
    assert not np.any(ok.flags & int(Flag.NEGATIVE_FORCE))
