"""The pad design map: its variables against independent evaluations and physics."""

import itertools

import numpy as np
import pytest

import tactsense as ts
from tactsense.analysis.pad_design import aliasing, design_point, design_variant


def test_sensitivity_is_what_the_simulator_reads():
    """counts_per_gram from the design code equals the rise of the taxel under a 50-g
    probe in a simulated recording without flaws (a different path: scenario, simulate,
    the resistive transducer)."""
    from tactsense.flat_scenarios import press

    spec = ts.preset("pad16")
    point = design_point(spec, 1.5, 2.5, 0.5, 50.0)
    variant = design_variant(spec, 1.5, 2.5, 0.5)
    centre = 3 * 2.5  # the middle taxel of the 7 x 7 variant
    scene = press(variant, x_mm=centre, y_mm=centre, force_n=ts.grams_force(50.0))
    recording = ts.simulate(variant, scene, flaws="none")
    rise = recording.frames.max() - variant.electronics.nominal_counts
    assert point["counts_per_gram"] * 50.0 == pytest.approx(rise, rel=1e-9)


def test_aliasing_falls_with_depth_and_rises_with_pitch():
    """Section 6: a deeper sensor low-passes the strain more; a coarser array samples it
    worse (eq. 45 in two dimensions)."""
    spec = ts.preset("pad16")
    by_depth = [aliasing(design_variant(spec, d, 2.5, 0.5)) for d in (0.5, 1.0, 2.0, 4.0)]
    assert all(a > b for a, b in itertools.pairwise(by_depth))
    by_pitch = [aliasing(design_variant(spec, 1.5, p, 0.5)) for p in (1.5, 2.5, 4.0)]
    assert all(a < b for a, b in itertools.pairwise(by_pitch))
    assert 0.0 <= min(by_depth) and max(by_pitch) <= 1.0


def test_aliasing_quadrature_agrees_with_a_finer_grid():
    """The trapezoid rules converge: 4x more samples change xi by < 1e-4 (measured 3e-6)."""
    variant = design_variant(ts.preset("pad16"), 1.5, 2.5, 0.5)
    assert aliasing(variant, samples=1025) == pytest.approx(aliasing(variant), abs=1e-4)


def test_cramer_rao_bound_scales_with_the_noise():
    """The bound is sqrt(noise variance / Fisher): doubling the read noise's variance
    (quantization included) multiplies the position bound by sqrt(2)."""
    spec = ts.preset("pad12x32")
    base = design_point(spec, 1.0, 2.0, 0.5, 50.0)
    variance = spec.flaws.read_noise_counts**2 + 1 / 12
    noisier = spec.replace(flaws__read_noise_counts=float(np.sqrt(2 * variance - 1 / 12)))
    worse = design_point(noisier, 1.0, 2.0, 0.5, 50.0)
    assert worse["crb_position_mm"] / base["crb_position_mm"] == pytest.approx(np.sqrt(2), 1e-6)
    assert worse["crb_force_pct"] / base["crb_force_pct"] == pytest.approx(np.sqrt(2), 1e-6)


@pytest.mark.parametrize(("depth", "pitch"), [(1.0, 2.0), (2.0, 3.0)])
def test_cramer_rao_bound_against_an_independent_jacobian(depth, pitch):
    """The bound from a Jacobian that shares nothing with the design code: the taxels'
    strain from the Hankel transform of the layer's transfer function (not the FFT grid;
    smooth in the probe's position: its central differences at 0.01 and 0.002 pitch
    agree to 1e-4), through the resistive transducer (counts_per_strain, tension clipped),
    read noise and quantization; the covariance (J^T J)^-1 sigma^2 by a QR solve. The
    design code's bound agrees within 10 % (measured 6.7 % and 0.2 % on position, 0.6 %
    and 1.1 % on force). Not tighter: its central differences on the FFT grid move its
    position bound by 25 % between steps of 0.02 and 0.001 pitch (the Hertz cap sampled
    on the grid is not smooth in the position at the micrometre scale)."""
    from tactsense.analysis.pad_design import PROBE_RADIUS_MM
    from tests._layer_truth import hankel_hertz_strain

    spec = ts.preset("pad12x32")
    design = design_point(spec, depth, pitch, 0.5, 50.0)
    variant = design_variant(spec, depth, pitch, 0.5)
    assert variant.transduction.kind == "resistive"
    force = ts.grams_force(50.0)

    def counts(x, y, f):
        strain = hankel_hertz_strain(variant, x, y, f, radius_mm=PROBE_RADIUS_MM)
        return variant.transduction.counts_per_strain * np.maximum(strain, 0.0).ravel()

    x0 = y0 = 3.25 * pitch
    h, hf = 0.01 * pitch, 0.01 * force
    jacobian = np.column_stack(
        [
            (counts(x0 + h, y0, force) - counts(x0 - h, y0, force)) / (2 * h),
            (counts(x0, y0 + h, force) - counts(x0, y0 - h, force)) / (2 * h),
            (counts(x0, y0, force + hf) - counts(x0, y0, force - hf)) / (2 * hf),
        ]
    )
    _, r = np.linalg.qr(jacobian)
    r_inv = np.linalg.solve(r, np.eye(3))
    covariance = (variant.flaws.read_noise_counts**2 + 1 / 12) * r_inv @ r_inv.T
    position = np.sqrt(0.5 * (covariance[0, 0] + covariance[1, 1]))
    force_pct = 100 * np.sqrt(covariance[2, 2]) / force
    assert design["crb_position_mm"] == pytest.approx(position, rel=0.1)
    assert design["crb_force_pct"] == pytest.approx(force_pct, rel=0.1)


def test_design_sweep_of_a_pad_from_the_command_line(tmp_path):
    from typer.testing import CliRunner

    from tactsense.cli import app

    out, plot = tmp_path / "map.nc", tmp_path / "map.png"
    result = CliRunner().invoke(
        app,
        ["design", "sweep", "--sensor", "pad16", "--depth", "1,2", "--spacing", "2,3",
         "--out", str(out), "--plot", str(plot)],
    )  # fmt: skip
    assert result.exit_code == 0, result.output
    import xarray as xr

    dataset = xr.open_dataset(out, engine="scipy")
    assert set(dataset.data_vars) == {"counts_per_gram", "xi", "crb_position_mm", "crb_force_pct"}
    assert plot.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    dot = ts.preset("dome12")
    assert dot.kind == "points"
    refused = CliRunner().invoke(app, ["design", "sweep", "--sensor", "dome12", "--out",
                                       str(tmp_path / "x.nc")])  # fmt: skip
    assert refused.exit_code == 2 and "fingers and pads" in refused.output
