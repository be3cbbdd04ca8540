"""The joint fit's compiled Levenberg-Marquardt (issue 34 item 1, speed): its forward
against the pad model's own superposition, its closed-form Jacobian against central
differences, and its fit against SciPy's trust-region fit (the reference) on frames
from the Hankel-transform layer solution (tests/_layer_truth.py)."""

import numpy as np
import pytest

from tactsense.estimate.contacts import _joint, find_contacts
from tactsense.estimate.contacts._joint_lm import residual_jacobian, tables_of
from tactsense.kinds import kind_of
from tactsense.sensor.registry import load_sensor
from tests._layer_truth import hankel_hertz_strain


@pytest.fixture(scope="module")
def thick():
    """pad16 under a 6-mm layer read 4 mm deep (a contact reads on 10-18 taxels)."""
    return load_sensor("pad16").replace(layer__thickness_mm=6.0, layer__sensing_depth_mm=4.0)


def _evaluate(model, p, clip, sigma=0.0):
    n, k = model.x_taxel.size * model.y_taxel.size, p.size // 5
    r, jac = np.empty(n + k), np.empty((n + k, 5 * k))
    prior = np.array([sigma, _joint.PRIOR_WIDTH, _joint.PRIOR_RADIUS_MM, model.modulus_star_pa])
    residual_jacobian(
        p, np.zeros(n), model.x_taxel, model.y_taxel, tables_of(model), clip,
        float(model.scale), prior, r, jac,
    )  # fmt: skip
    return r, jac


# two contacts, each a at 0.37 of a table step from a node (the model is linear in a
# between nodes: a central difference across a node would see the kink)
P = np.array([9.13, 10.61, 0.4, 0.837, 0.3, 17.2, 13.9, 0.2, 1.237, 0.6])


def test_forward_is_the_models_superposition(thick):
    """The compiled residual (target zero) is the model's signed signal, to round-off
    (1e-12 of its peak), for two contacts mixing sphere and disc pressures."""
    model = kind_of(thick).contact_model(thick)
    r, _ = _evaluate(model, P, clip=False)
    q = P.reshape(2, 5)
    want = model.signal(q[:, :2], q[:, 2], q[:, 3], q[:, 4], signed=True).ravel()
    assert np.abs(r[: want.size] - want).max() < 1e-12 * np.abs(want).max()


@pytest.mark.parametrize("clip", [False, True])
def test_jacobian_is_the_derivative(thick, clip):
    """Every column of the closed-form Jacobian (data and prior rows) against a central
    difference of the compiled residual (step 1e-6 of each parameter's scale): within
    1e-4 of the column's largest entry (a wrong sign or factor is off by 100 %)."""
    model = kind_of(thick).contact_model(thick)
    _, jac = _evaluate(model, P, clip=clip, sigma=1e-4)
    for q in range(P.size):
        h = 1e-6 * max(abs(P[q]), 1.0)
        up, down = P.copy(), P.copy()
        up[q] += h
        down[q] -= h
        numeric = _evaluate(model, up, clip, 1e-4)[0] - _evaluate(model, down, clip, 1e-4)[0]
        numeric /= 2 * h
        scale = np.abs(numeric).max()
        assert scale > 0
        assert np.abs(jac[:, q] - numeric).max() < 1e-4 * scale, q


@pytest.mark.parametrize(
    ("shape", "size", "load"),
    [("sphere", 1.0, 0.098), ("sphere", 10.0, 4.9), ("disc", 3.75, 0.49)],
)
def test_compiled_fit_is_the_reference_fit(thick, shape, size, load):
    """On frames that determine the contact (the thick pad, Hankel truth, quantized) the
    compiled fit and SciPy's reach the same answer from the same poor start (0.5 mm
    off, force 20 % low, radius 1 mm): force within 0.2 % of each other and of the truth
    within 2 %, position within 0.01 pitch of each other; and its residual is no
    larger than the reference's (times 1.01)."""
    g = thick.grid
    model = kind_of(thick).contact_model(thick)
    x, y = 7.3 * g.row_pitch_mm, 8.6 * g.col_pitch_mm
    strain = hankel_hertz_strain(thick, x, y, load, radius_mm=size, shape=shape)
    frame = np.round(np.maximum(strain, 0) * 20000) / 20000
    sigma = 0.5 / 20000
    start = ([x + 0.5], [y - 0.3], [0.8 * load], [1.0])
    mine, rss = _joint._fit_frame(model, frame, *start, sigma=sigma)
    ref, rss_ref = _joint._fit_frame_reference(model, frame, *start, sigma=sigma)
    assert mine[0, 2] == pytest.approx(ref[0, 2], rel=2e-3)
    assert mine[0, 2] == pytest.approx(load, rel=0.02)
    assert np.hypot(*(mine[0, :2] - ref[0, :2])) < 0.01 * g.row_pitch_mm
    assert rss <= 1.01 * rss_ref + 1e-30


def test_pairs_on_pad4_in_every_orientation():
    """Issue 34 item 2 on the preset pad4 (5-mm pitch, capacitive): two equal 50-g
    1.6-mm spheres 1.5 pitches apart (Hankel truth, quantized to one A/D count) at five
    orientations (0-90 deg) and four seeded sub-taxel offsets each: at least 18 of the
    20 are resolved (exactly two contacts, each truth within half the separation of its
    own; measured 20 of 20 with the split seeds and the pruning, 7 of 20 before them),
    and the contacts are numbered 0, 1 in each frame (the pruning renumbers)."""
    spec = load_sensor("pad4")
    g = spec.grid
    rng = np.random.default_rng(5)
    per = spec.electronics.nominal_counts
    resolved = 0
    for angle in (0.0, 22.5, 45.0, 67.5, 90.0):
        for _ in range(4):
            centre = (np.array([g.rows, g.cols]) / 2 - 0.5 + rng.uniform(size=2)) * g.row_pitch_mm
            th = np.radians(angle)
            half = 0.75 * g.row_pitch_mm * np.array([np.cos(th), np.sin(th)])
            truth = np.array([centre + half, centre - half])
            strain = sum(hankel_hertz_strain(spec, x, y, 0.49) for x, y in truth)
            signal = np.round(spec.transduction.strain_gain * strain * per) / per
            fit = find_contacts(signal, spec, counts=False, method="joint")
            assert list(fit.contact) == list(range(len(fit)))
            if len(fit) != 2:
                continue
            est = np.column_stack([fit.x_mm, fit.y_mm])
            d = np.hypot(*(truth[:, None, :] - est[None, :, :]).transpose(2, 0, 1))
            pair = min(max(d[0, 0], d[1, 1]), max(d[0, 1], d[1, 0]))
            resolved += pair < 0.75 * g.row_pitch_mm
    assert resolved >= 18


def test_tables_kept_on_disk(tmp_path, monkeypatch):
    """The fit's tables come from the shared disk cache of the frames' tables
    (``_hertz_table.cached_response_table``): written once to the cache folder and read
    back exactly (every factor equal) by a new process (the in-process copy cleared)
    without building it again; an unwritable folder is no error."""
    from tactsense.physics import _hertz_table, _pad_model

    assert _pad_model.cached_response_table is _hertz_table.cached_response_table
    cached = _hertz_table.cached_response_table
    layer = load_sensor("pad16").layer
    monkeypatch.setenv("TACTSENSE_CACHE_DIR", str(tmp_path / "cache"))
    cached.cache_clear()
    built = cached(layer, (1.0, 1.0), "sphere", 1.0, 0.1)
    assert len(list((tmp_path / "cache").glob("frames_table_*.npz"))) == 1

    def no_build(*args, **kwargs):
        raise AssertionError("built again")

    cached.cache_clear()
    monkeypatch.setattr(_hertz_table, "layer_response_table", no_build)
    read = cached(layer, (1.0, 1.0), "sphere", 1.0, 0.1)
    np.testing.assert_array_equal(read.x_factors, built.x_factors)
    np.testing.assert_array_equal(read.y_factors, built.y_factors)
    assert (read.step_mm, read.a_step_mm, read.peak) == (built.step_mm, built.a_step_mm, built.peak)
    monkeypatch.undo()
    cached.cache_clear()
    blocked = tmp_path / "file"
    blocked.write_text("")
    monkeypatch.setenv("TACTSENSE_CACHE_DIR", str(blocked / "cache"))  # under a file
    again = cached(layer, (1.0, 1.0), "sphere", 1.0, 0.1)
    cached.cache_clear()
    np.testing.assert_array_equal(again.x_factors, built.x_factors)


def _pair_frame(spec, truth):
    """A pad4 frame of two 50-g 1.6-mm spheres at ``truth`` (2, 2) [mm] by the
    Hankel-transform layer solution, quantized to one A/D count [-]."""
    per = spec.electronics.nominal_counts
    strain = sum(hankel_hertz_strain(spec, x, y, 0.49) for x, y in truth)
    return np.round(spec.transduction.strain_gain * strain * per) / per


def _best_of_reseeds(fit, model, frame, q, sigma):
    """Residuals [-^2] of ``fit`` from each of the pair re-seeds ``_joint._polish``
    tries about ``q``."""
    return np.array(
        [fit(model, frame, *s.T, sigma=sigma)[1] for s in _joint._pair_seeds(model, q, 0, 1)]
    )


def test_compiled_reaches_the_reference_minimum_on_the_37_percent_frame():
    """Round 9's frame (benchmarks/bench_padfit.py, pad4, pair 4 of ten, the kind's own
    model, a = 1.208 mm, quantized): in the ten-frame batch the first fit lands in a
    poor minimum (contacts 0.48 and 0.67 N, residual 1.4e-5) and the pair is re-seeded
    twenty ways. SciPy's fit reached the frame's minimum (9.3e-8: both forces 0.49 N)
    from 4 of the 20; the compiled fit of round 9 from none (best 3.9e-5, so it
    reported forces 37 % apart); now from 7. Asserted: the compiled best within
    1 % of the reference's best, and its forces within 1 % of the truth's 0.49 N."""
    spec = load_sensor("pad4")
    model = kind_of(spec).contact_model(spec)
    truth = [[15.54667044, 17.30042308], [5.49094114, 6.17018012]]
    per = 2000.0  # the benchmark's quantization of a capacitive pad's signal [1/-]
    frame = np.round(model.signal(truth, [0.49] * 2, [1.2082761235960553] * 2) * per) / per
    poor = np.array([[5.0993, 6.002, 0.4763, 1.5863, 0.0], [17.0585, 15.766, 0.6655, 3.792, 1.0]])
    sigma = 0.006212447173848624  # the batch's noise plus the model's error, as measured
    mine = _best_of_reseeds(_joint._fit_frame, model, frame, poor, sigma)
    ref = _best_of_reseeds(_joint._fit_frame_reference, model, frame, poor, sigma)
    assert mine.min() <= 1.01 * ref.min()
    seed = list(_joint._pair_seeds(model, poor, 0, 1))[int(np.argmin(mine))]
    q, _ = _joint._fit_frame(model, frame, *seed.T, sigma=sigma)
    assert np.abs(q[:, 2] / 0.49 - 1).max() < 0.01


def test_compiled_against_reference_from_the_same_starts():
    """pad4 pairs (Hankel truth, quantized) 1.5 and 2 pitches apart at 22.5 and 67.5
    deg, each fitted from the twenty re-seeds ``_joint._polish`` makes about a poor pair
    (both contacts at the pair's middle, 0.3 pitch across its axis): both solvers are
    local, so from one start each may settle in another minimum. Asserted: (1) on
    every frame the compiled fit's best residual is within 1 % of the reference's best
    (what the estimator keeps); (2) over the 80 starts the compiled residual exceeds the
    reference's by more than 10 % from at most 28 (measured 19 with both descents, 22
    with the trust region's alone, 42 with round 9's kernel); (3) where it ends, the
    first-order condition holds to the tables' resolution: the largest projected
    gradient in step units (each parameter's unit step's first-order share of the
    cost, components on a bound pushing outward excluded) is below 0.06 of the cost
    (the model is piecewise linear in a between the table's nodes, so a minimum at a
    node keeps a one-sided slope)."""
    from tactsense.estimate.contacts._joint_lm import step_units

    spec = load_sensor("pad4")
    model = kind_of(spec).contact_model(spec)
    g = spec.grid
    px = g.row_pitch_mm
    per = spec.electronics.nominal_counts
    worse = 0
    for sep in (1.5, 2.0):
        for angle in (22.5, 67.5):
            th = np.radians(angle)
            centre = np.array([(g.rows / 2 - 0.3) * px, (g.cols / 2 + 0.2) * px])
            half = 0.5 * sep * px * np.array([np.cos(th), np.sin(th)])
            frame = _pair_frame(spec, np.array([centre + half, centre - half]))
            sigma = 0.5 / per + _joint.MODEL_ERROR * np.abs(frame).max()
            across = 0.3 * px * np.array([-np.sin(th), np.cos(th)])
            poor = np.array(
                [[*(centre + across), 0.3, 1.0, 0.5], [*(centre - across), 0.7, 1.0, 0.5]]
            )
            ref = _best_of_reseeds(_joint._fit_frame_reference, model, frame, poor, sigma)
            mine = []
            for seed in _joint._pair_seeds(model, poor, 0, 1):
                q, rss = _joint._fit_frame(model, frame, *seed.T, sigma=sigma)
                mine.append(rss)
                assert _first_order(model, frame, q, sigma, step_units) < 0.06
            mine = np.array(mine)
            assert mine.min() <= 1.01 * ref.min() + 1e-15, (sep, angle)
            worse += int(np.sum(mine > 1.1 * ref))
    assert worse <= 28


def _first_order(model, frame, q, sigma, step_units):
    """Largest projected gradient of the fit's cost at ``q`` in step units, over the
    cost [-]."""
    k = len(q)
    lo, hi = _joint._bounds(model, frame, k)
    p = np.clip(q.ravel(), lo, hi)
    n = frame.size
    prior = np.array([sigma, _joint.PRIOR_WIDTH, _joint.PRIOR_RADIUS_MM, model.modulus_star_pa])
    r, jac = np.empty(n + k), np.empty((n + k, 5 * k))
    residual_jacobian(
        p, frame.ravel(), model.x_taxel, model.y_taxel, tables_of(model),
        not model.capacitive, float(model.scale), prior, r, jac,
    )  # fmt: skip
    grad = jac.T @ r
    tol = 1e-9 * np.maximum(1.0, np.abs(p))
    pinned = ((p <= lo + tol) & (grad > 0)) | ((p >= hi - tol) & (grad < 0))
    step = grad * step_units(p, model.x_taxel, model.y_taxel) * ~pinned
    return float(np.abs(step).max() / max(float(np.sum(r**2)), 1e-300))
