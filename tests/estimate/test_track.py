"""Tracking contacts over frames: ids, births, deaths, merges, splits, velocity, slip."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays
from scipy.optimize import linear_sum_assignment

import tactsense as ts
from tactsense import flat_scenarios as fs
from tactsense._validation import TactsenseInputError
from tactsense.estimate.contacts import ContactTable, find_contacts
from tactsense.estimate.contacts.track import _FAR, ContactTracker, ReferenceTracker, assign, track
from tactsense.sensor.registry import load_sensor

PERIOD = 0.01


def table_of(rows, n_frames):
    """A ContactTable from (frame, x, y, force) rows."""
    rows = sorted(rows, key=lambda r: r[0])
    n = len(rows)
    frame = np.array([r[0] for r in rows], np.int64)
    rank = np.zeros(n, np.int64)
    for k in range(1, n):
        rank[k] = rank[k - 1] + 1 if frame[k] == frame[k - 1] else 0
    col = lambda i: np.array([r[i] for r in rows], float)  # noqa: E731
    zeros = np.zeros(n)
    return ContactTable(
        frame=frame, contact=rank, x_mm=col(1), y_mm=col(2), z_mm=zeros, row=zeros, col=zeros,
        force_n=col(3), peak=zeros, major_mm=zeros, minor_mm=zeros, orientation_deg=zeros,
        taxels=np.ones(n, np.int64), flags=np.zeros(n, np.int64), n_frames=n_frames,
    )  # fmt: skip


@settings(max_examples=200, deadline=None)
@given(
    arrays(
        np.float64,
        st.tuples(st.integers(1, 6), st.integers(1, 6)),
        elements=st.floats(0, 100, allow_nan=False),
    ),
    st.floats(1, 120),
)
def test_assignment_matches_scipy(cost, limit):
    """The compiled exhaustive search finds an assignment of scipy's cost and size."""
    pairs = assign(cost, limit)
    capped = np.where(cost < limit, cost, _FAR)
    rows, cols = linear_sum_assignment(capped)
    ref = [(i, j) for i, j in zip(rows, cols, strict=True) if capped[i, j] < _FAR]
    assert len(pairs) == len(ref)
    assert sum(cost[i, j] for i, j in pairs) == pytest.approx(sum(cost[i, j] for i, j in ref))
    assert all(cost[i, j] < limit for i, j in pairs)


def test_crossing_paths_keep_their_ids():
    """Two contacts pass each other along x at 100 mm/s, 1 mm apart in y at the
    crossing: the velocity prediction keeps each on its own line."""
    rows = []
    for f in range(40):
        rows.append((f, f * 1.0, 0.0, 1.0))
        rows.append((f, 39 - f * 1.0, 1.0, 1.0))
    out, events = track(table_of(rows, 40), PERIOD, gate_mm=3.0)
    ids_a = out.id[out.y_mm == 0.0]
    ids_b = out.id[out.y_mm == 1.0]
    assert len(set(ids_a)) == 1 and len(set(ids_b)) == 1 and ids_a[0] != ids_b[0]
    assert [e.kind for e in events] == ["birth", "birth"]
    # the smoothed velocity starts at 0 and approaches 100 mm/s by (1 - 0.3)^k: 0.1 %
    # after 20 frames
    np.testing.assert_allclose(out.vx_mm_s[(out.y_mm == 0.0) & (out.frame > 20)], 100.0, rtol=1e-3)


def test_birth_death_and_grace():
    """A contact missing for max_missing frames keeps its id; one frame more ends it; a
    track still alive when the table ends is not dead (the next piece may continue it)."""
    rows = [(f, 5.0, 5.0, 1.0) for f in (0, 1, 2, 5, 6)] + [(f, 5.0, 5.0, 1.0) for f in (10, 11)]
    out, events = track(table_of(rows, 12), PERIOD, max_missing=2)
    assert list(out.id) == [0, 0, 0, 0, 0, 1, 1]
    assert [(e.frame, e.kind, e.id) for e in events] == [
        (0, "birth", 0), (9, "death", 0), (10, "birth", 1),
    ]  # fmt: skip


def test_merge_and_split():
    """Two contacts 4 mm apart come together into one (a merge naming the survivor),
    then part again (a split naming the parent)."""
    rows = []
    for f in range(10):
        rows += [(f, 0.0, 0.0, 1.0), (f, 4.0, 0.0, 1.0)]
    for f in range(10, 20):
        rows.append((f, 2.0, 0.0, 2.0))
    for f in range(20, 30):
        rows += [(f, 0.0, 0.0, 1.0), (f, 4.0, 0.0, 1.0)]
    out, events = track(table_of(rows, 30), PERIOD, gate_mm=5.0, max_missing=2, smoothing=1.0)
    kinds = [(e.frame, e.kind) for e in events]
    assert (10, "merge") in kinds and (20, "split") in kinds
    merge = next(e for e in events if e.kind == "merge")
    split = next(e for e in events if e.kind == "split")
    survivor = merge.others[0]
    assert set(out.id[out.frame == 15]) == {survivor}
    assert split.others == (survivor,)
    assert split.id not in (0, 1)


def test_chunks_give_the_same_result():
    rng = np.random.default_rng(0)
    rows = []
    for f in range(200):
        for k in range(3):
            if rng.uniform() < 0.9:
                rows.append((f, 10 * k + np.sin(f / 20) + rng.normal(0, 0.1), k * 3.0, 1.0))
    whole, events = track(table_of(rows, 200), PERIOD)
    tracker = ContactTracker(PERIOD)
    ids, evs = [], []
    for lo in range(0, 200, 37):
        hi = min(lo + 37, 200)
        piece = table_of([r for r in rows if lo <= r[0] < hi], hi - lo)
        out, e = tracker.update(piece, first_frame=lo)
        ids.append(out.id)
        evs += e
    np.testing.assert_array_equal(np.concatenate(ids), whole.id)
    assert evs == events


def _slide_and_hold():
    """pad16, from counts: the tracked main contact of a 50-g probe sliding at 10 mm/s
    along +y, and of a press and hold; with the truth's step of each frame."""
    spec = load_sensor("pad16")
    out = {}
    for name, scenario in (("slide", fs.slide(spec)), ("hold", fs.hold(spec))):
        rec = ts.simulate(spec, scenario, rng=0)
        base = np.median(rec.frames[:5], axis=0)
        table = find_contacts(rec.frames, spec, baseline=base)
        tracked, _ = track(table, spec.scan_period_s)
        main = tracked.contact == 0
        labels = [step.label for step in scenario.steps]
        step_of = rec.truth["frame_step"][tracked.frame[main]]
        out[name] = (tracked, main, [labels[k] for k in step_of])
    return out


def test_slide_slips_and_hold_does_not():
    """A probe sliding at 10 mm/s under 50 g is flagged as slip in some frames, and
    only WHEN it slides: every flagged frame lies within the slide after its first
    position (not the settling, not the lift) and moves along the slide (+y); a press
    and hold is flagged in none. The slide's id stays one for most of the path (the gate
    is 5 mm; the taxel pitch 2.5 mm)."""
    runs = _slide_and_hold()
    tracked, main, labels = runs["slide"]
    slip = tracked.slip[main]
    assert slip.any()
    flagged = [label for label, s in zip(labels, slip, strict=True) if s]
    assert all(label.startswith("slide ") and label != "slide 0" for label in flagged), flagged
    assert np.all(tracked.vy_mm_s[main][slip] > 0)
    hold, hold_main, _ = runs["hold"]
    assert not hold.slip[hold_main].any()
    for out, m, _ in runs.values():
        _, counts = np.unique(out.id[m], return_counts=True)
        assert counts.max() >= 0.9 * m.sum()


@pytest.mark.xfail(
    strict=True,
    reason="finding (issue 34 item 7): on a steady 10-mm/s slide slip is flagged in 12 "
    "of 325 sliding frames (3.7 %): the pad's force estimate ripples as the probe crosses "
    "taxels (median |dF/dt| / F = 5.7 /s) far beyond slip_force_rate (0.5 /s)",
)
def test_a_steady_slide_is_slip_in_most_of_its_frames():
    tracked, main, labels = _slide_and_hold()["slide"]
    sliding = np.array([label.startswith("slide ") and label != "slide 0" for label in labels])
    assert tracked.slip[main][sliding].mean() >= 0.5


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"frame_period_s": 0}, "frame_period_s"),
        ({"frame_period_s": float("nan")}, "frame_period_s"),
        ({"frame_period_s": 0.01, "gate_mm": -1}, "gate_mm"),
        ({"frame_period_s": 0.01, "smoothing": 2}, "smoothing"),
        ({"frame_period_s": 0.01, "max_missing": -1}, "max_missing"),
    ],
)
def test_bad_options(kwargs, message):
    with pytest.raises(TactsenseInputError, match=message):
        ContactTracker(**kwargs)


def test_frames_going_backwards():
    tracker = ContactTracker(PERIOD)
    tracker.update(table_of([(0, 1.0, 1.0, 1.0)], 10))
    with pytest.raises(TactsenseInputError, match="backwards"):
        tracker.update(table_of([(3, 1.0, 1.0, 1.0)], 10), first_frame=3)
    with pytest.raises(TactsenseInputError, match="outside"):
        tracker.update(table_of([(30, 1.0, 1.0, 1.0)], 5))


def test_compiled_tracker_equals_the_reference():
    """The compiled tracker gives the ids, velocities, slip flags and events of the
    plain-Python reference (scipy's assignment each frame), on random contacts that
    appear, vanish, wander and cross, tracked in pieces."""
    rng = np.random.default_rng(5)
    rows = []
    for f in range(600):
        for k in range(4):
            if rng.uniform() < 0.8:
                x = 6 * k + 3 * np.sin(f / 30 + k) + rng.normal(0, 0.3)
                rows.append((f, x, 2.0 * np.cos(f / 50 + k), 0.5 + 0.1 * k))
    table = table_of(rows, 600)
    fast, ref = ContactTracker(PERIOD, max_missing=1), ReferenceTracker(PERIOD, max_missing=1)
    for lo in range(0, 600, 128):
        hi = min(lo + 128, 600)
        piece = table_of([r for r in rows if lo <= r[0] < hi], hi - lo)
        a, ea = fast.update(piece, first_frame=lo)
        b, eb = ref.update(piece, first_frame=lo)
        np.testing.assert_array_equal(a.id, b.id)
        np.testing.assert_allclose(a.vx_mm_s, b.vx_mm_s, atol=1e-12)
        np.testing.assert_array_equal(a.slip, b.slip)
        assert ea == eb
    assert len(table) > 1000 and fast.next_id > 4
