"""A pad's Cramer-Rao bound for a probe at a point, checked against a Monte-Carlo of the
maximum-likelihood estimator; its blind-spot map, checked against the layer model
itself; and the lab's example: a 4 x 4 resistive pad at 5 mm pitch under 3 mm of rubber
does not see a 50-g press between taxels."""

import json

import numpy as np
import pytest
from scipy.optimize import least_squares
from typer.testing import CliRunner

import tactsense as ts
from tactsense._validation import TactsenseInputError
from tactsense.analysis import pad_bound as pb
from tactsense.cli import app
from tactsense.physics.contact import grams_force

runner = CliRunner()
FIFTY_G = grams_force(50.0)

LAB4_TOML = """name = "lab4"
extends = "pad16"
description = "A lab's 4x4 resistive pad, 5 mm pitch, 3 mm layer"

[grid]
rows = 4
cols = 4
row_pitch_mm = 5.0
col_pitch_mm = 5.0

[layer]
thickness_mm = 3.0
"""


@pytest.fixture(scope="module")
def lab4(tmp_path_factory):
    path = tmp_path_factory.mktemp("lab") / "lab4.toml"
    path.write_text(LAB4_TOML)
    return path


@pytest.mark.parametrize("name, x, y", [("pad4", 6.0, 6.0), ("pad16", 19.375, 18.125)])
def test_bound_matches_a_monte_carlo_of_the_maximum_likelihood_estimator(name, x, y):
    """100 frames with the bound's noise (Gaussian, variance read noise^2 + 1/12), each
    fitted by least squares (scipy, its own forward differences): the estimates' spread
    is the bound's within 20 % (the sampling error of a standard deviation from 100
    draws is about 7 %, so 20 % is three of it). Measured: within 3 % on pad4, 3-15 %
    on pad16."""
    spec = ts.preset(name)
    crb = pb.cramer_rao_bound(spec, x, y, FIFTY_G)
    sigma = np.sqrt(pb.noise_variance(spec))
    mu = pb.expected_counts(spec, x, y, FIFTY_G, 1.6).ravel()
    rng = np.random.default_rng(0)
    estimates = []
    for _ in range(100):
        frame = mu + rng.normal(0.0, sigma, mu.size)
        fit = least_squares(
            lambda p, frame=frame: (pb.expected_counts(spec, *p, 1.6).ravel() - frame) / sigma,
            [x + 0.05, y - 0.05, 1.02 * FIFTY_G],
            x_scale=[0.01, 0.01, 0.003],
            diff_step=1e-4,
        )
        estimates.append(fit.x)
    spread = np.std(estimates, axis=0, ddof=1)
    bound = np.array([crb["x_mm"], crb["y_mm"], crb["force_n"]])
    np.testing.assert_allclose(spread, bound, rtol=0.2)
    assert crb["position_mm"] == pytest.approx(np.sqrt(0.5 * (bound[0] ** 2 + bound[1] ** 2)))


def test_bound_scales_with_the_noise():
    """Fisher information is 1/sigma^2: twice the noise, twice every bound."""
    spec = ts.preset("pad4")
    quiet = pb.cramer_rao_bound(spec, 6.0, 6.0, FIFTY_G)
    noisy_spec = spec.replace(flaws__read_noise_counts=1.5)
    ratio = np.sqrt(pb.noise_variance(noisy_spec) / pb.noise_variance(spec))
    noisy = pb.cramer_rao_bound(noisy_spec, 6.0, 6.0, FIFTY_G)
    for key in ("x_mm", "y_mm", "force_n"):
        assert noisy[key] == pytest.approx(ratio * quiet[key], rel=1e-9)


def test_signal_map_is_the_layer_model_at_every_probe_position():
    """The map's shortcut (one strain map, shifted to every taxel) against the layer
    model run for the probe at each of a few positions: within 3 % (the two sample the
    probe's pressure on different grids)."""
    for name in ("pad4", "pad12x32"):
        spec = ts.preset(name)
        x, y, change, _ = pb.signal_map(spec, FIFTY_G)
        rest = pb.counts_from_strain(spec, 0.0)
        for i, j in [(3, 5), (len(x) // 2, len(y) // 2), (7, 11), (len(x) - 2, 4)]:
            direct = np.abs(pb.expected_counts(spec, x[i], y[j], FIFTY_G, 1.6) - rest).max()
            assert change[i, j] == pytest.approx(direct, rel=0.03, abs=0.05)


@pytest.mark.parametrize("rows, cols", [(20, 20), (13, 31), (40, 7)])
def test_a_large_pad_s_map_folded_from_a_small_one_is_the_same(rows, cols):
    spec = ts.preset("pad16").replace(grid__rows=rows, grid__cols=cols)
    *_, change, rise = pb.signal_map(spec, FIFTY_G)
    *_, change_all, rise_all = pb.signal_map(spec, FIFTY_G, fold=False)
    np.testing.assert_array_equal(change, change_all)
    np.testing.assert_array_equal(rise, rise_all)


def test_lab_pad_is_blind_between_taxels(lab4):
    spec = ts.load_sensor(lab4)
    found = pb.blind_spots(spec, FIFTY_G)
    centres = {tuple(np.round(r["centre_mm"], 1)) for r in found["regions"]}
    # the nine points between four taxels, each a blind region of its own
    for cx in (2.5, 7.5, 12.5):
        for cy in (2.5, 7.5, 12.5):
            assert (cx, cy) in centres
    inner = [r for r in found["regions"] if tuple(np.round(r["centre_mm"], 1)) == (7.5, 7.5)]
    assert 1.0 < inner[0]["area_mm2"] < 25.0  # a patch, smaller than the 5 x 5 mm cell
    # the layer model itself: a probe there moves no taxel; on a taxel it moves one a lot
    rest = pb.counts_from_strain(spec, 0.0)
    assert np.abs(pb.expected_counts(spec, 7.5, 7.5, FIFTY_G, 1.6) - rest).max() < 1.0
    assert (pb.expected_counts(spec, 5.0, 5.0, FIFTY_G, 1.6) - rest).max() > 100.0


@pytest.mark.parametrize("name", ["pad4", "pad16", "pad12x32"])
def test_presets_have_no_blind_spot_for_fifty_grams(name):
    found = pb.blind_spots(ts.preset(name), FIFTY_G)
    assert found["regions"] == [] and found["blind_fraction"] == 0.0
    assert found["weakest_change_counts"] > found["threshold_counts"]


def test_sensor_check_warns_where_and_how_big(lab4, tmp_path):
    result = runner.invoke(app, ["sensor", "check", str(lab4)])
    assert result.exit_code == 0, result.output
    assert "blind spots (50-g probe)" in result.output
    assert "warning: 'lab4' does not see a 50-g press" in result.output
    assert "(7.5, 7.5) mm" in result.output and "mm^2" in result.output
    good = tmp_path / "pad16.toml"
    ts.preset("pad16").to_toml(good)
    result = runner.invoke(app, ["sensor", "check", str(good)])
    assert result.exit_code == 0, result.output
    assert "warning" not in result.output and "none: every place" in result.output


def test_design_bound_on_a_pad_prints_the_analysis_numbers():
    result = runner.invoke(app, ["design", "bound", "--sensor", "pad4", "--x-mm", "6",
                                 "--y-mm", "6", "--json"])  # fmt: skip
    assert result.exit_code == 0, result.output
    data = json.loads(result.output)
    crb = pb.cramer_rao_bound(ts.preset("pad4"), 6.0, 6.0, FIFTY_G)
    assert data["bound"] == pytest.approx(crb)
    assert data["inputs"]["x_mm"] == 6.0 and data["inputs"]["probe_diameter_mm"] == 3.2


def test_a_probe_centred_on_a_taxel_of_a_thin_layer_is_not_identifiable():
    with pytest.raises(TactsenseInputError, match="not identifiable"):
        pb.cramer_rao_bound(ts.preset("pad16"), 5.0, 5.0, FIFTY_G)


def test_pads_only():
    with pytest.raises(TactsenseInputError, match="this bound is for pads"):
        pb.cramer_rao_bound(ts.preset("initial"), 1.0, 1.0, FIFTY_G)
    with pytest.raises(TactsenseInputError, match="blind spots are mapped on pads"):
        pb.blind_spots(ts.preset("dome12"), FIFTY_G)


def test_the_numbers_in_docs_sensors_md_are_the_code_s(lab4):
    """docs/sensors.md quotes the lab pad's blind spots, the presets' weakest places and
    pad4's bound: each as the code prints it now."""
    from pathlib import Path

    doc = " ".join((Path(__file__).parents[2] / "docs" / "sensors.md").read_text().split())
    found = pb.blind_spots(ts.load_sensor(lab4), FIFTY_G)
    assert (
        f"on {100 * found['blind_fraction']:.1f} % of its area "
        f"({found['blind_area_mm2']:.3g} mm^2) in {len(found['regions'])} regions" in doc
    )
    assert f"each {found['regions'][0]['area_mm2']:.3g} mm^2" in doc
    weakest = {
        name: f"{pb.blind_spots(ts.preset(name), FIFTY_G)['weakest_change_counts']:.3g}"
        for name in ("pad4", "pad16", "pad12x32")
    }
    assert (
        f"by {weakest['pad4']} counts on `pad4`, {weakest['pad16']} on `pad16` and "
        f"{weakest['pad12x32']} on `pad12x32`" in doc
    )
    crb = pb.cramer_rao_bound(ts.preset("pad4"), 6.0, 6.0, FIFTY_G)
    assert f"{1e3 * crb['x_mm']:.3g} um along x and y" in doc
    assert f"{100 * crb['force_relative']:.2g} % of the force" in doc
