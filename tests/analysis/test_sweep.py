"""The design map (tactsense.analysis.sweep, `tactsense design sweep`)."""

import numpy as np
import pytest
import xarray as xr
from typer.testing import CliRunner

import tactsense as ts
from tactsense.analysis.aliasing import reconstruction_error
from tactsense.analysis.bound import cramer_rao_bound
from tactsense.analysis.sweep import design_sweep
from tactsense.cli import app

runner = CliRunner()


def test_the_paper_design_on_the_map_is_the_finger_itself():
    """At depth 3.8 mm, spacing 3.8 mm, nu 0.4 the map must give what the initial finger
    gives through the other public routes: eq. 45, the bound, and by hand the counts of
    the centred probe through eq. 4 (2000 d / (1 - d) units)."""
    spec = ts.fearing1990_initial()
    ds = design_sweep(spec, [3.0, 3.8], [3.3, 3.8], poisson_ratios=[0.4], grams=[50.0])
    point = ds.sel(depth_mm=3.8, spacing_mm=3.8).isel(poisson_ratio=0, load_g=0)
    assert float(point["xi"]) == pytest.approx(reconstruction_error(3.8, 3.8, 0.4), rel=1e-12)
    axial, angle = float(spec.row_axial_mm[4]), float(spec.col_angle_deg[0])
    bound = cramer_rao_bound(spec, axial, angle, ts.grams_force(50))
    assert float(point["crb_axial_mm"]) == pytest.approx(bound["axial_mm"], rel=1e-9)
    peak = float(ts.tactel_deflection(spec, [ts.Probe(axial, angle, ts.grams_force(50))])[4, 0])
    by_hand = 2000 * peak / (1 - peak) / 50  # eq. 4; C_S/C_L moves it by about 1 %
    assert float(point["counts_per_gram"]) == pytest.approx(by_hand, rel=0.02)
    # the trade-off the map exists to show: shallower is more sensitive and aliases more
    shallow = ds.sel(depth_mm=3.0, spacing_mm=3.8).isel(poisson_ratio=0, load_g=0)
    assert float(shallow["counts_per_gram"]) > float(point["counts_per_gram"])
    assert float(shallow["xi"]) > float(point["xi"])
    assert ds["crb_axial_mm"].attrs["units"] == "mm"


def test_the_readme_sentence_about_the_map():
    """README: at the paper's spacing a thinner skin than about 3 mm makes the attainable
    position worse; closer spacing improves it and the aliasing."""
    spec = ts.fearing1990_initial()
    ds = design_sweep(spec, [2.0, 3.8], [2.0, 3.8]).isel(poisson_ratio=0, load_g=0)
    crb, xi = ds["crb_axial_mm"], ds["xi"]
    assert float(crb.sel(depth_mm=2.0, spacing_mm=3.8)) > float(
        crb.sel(depth_mm=3.8, spacing_mm=3.8)
    )
    for depth in (2.0, 3.8):
        assert float(crb.sel(depth_mm=depth, spacing_mm=2.0)) < float(
            crb.sel(depth_mm=depth, spacing_mm=3.8)
        )
        assert float(xi.sel(depth_mm=depth, spacing_mm=2.0)) < float(
            xi.sel(depth_mm=depth, spacing_mm=3.8)
        )


def test_designs_that_do_not_fit_are_nan():
    # 7 rings 6 mm apart do not fit on the 25-mm cylinder
    ds = design_sweep(ts.fearing1990_initial(), [3.8], [6.0])
    assert np.isnan(ds["xi"].values).all()


def test_command_writes_netcdf_and_plot(tmp_path):
    out, plot = tmp_path / "map.nc", tmp_path / "map.png"
    result = runner.invoke(
        app,
        [
            "design",
            "sweep",
            "--depth",
            "3:4:2",
            "--spacing",
            "3.3,3.8",
            "--out",
            str(out),
            "--plot",
            str(plot),
        ],
    )
    assert result.exit_code == 0, result.output
    ds = xr.open_dataset(out)
    assert dict(ds.sizes) == {"depth_mm": 2, "spacing_mm": 2, "poisson_ratio": 1, "load_g": 1}
    assert plot.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    ds.close()


@pytest.mark.parametrize(
    "args, message",
    [
        (["--depth", "a:b:c"], "expected START:STOP:COUNT"),
        (["--depth", "0:3:4"], "every value must lie in [0.5, 20]"),
        (["--spacing", "3:4:0"], "COUNT 1-10000"),
        (["--poisson", "0.7"], "--poisson"),
        (["--force-g", "nan"], "--force-g"),
        (["--workers", "-1"], "--workers"),
    ],
)
def test_bad_grids_are_refused(tmp_path, args, message):
    out = tmp_path / "never.nc"
    result = runner.invoke(app, ["design", "sweep", *args, "--out", str(out)])
    assert result.exit_code == 2, result.output
    assert message in " ".join(result.output.split())
    assert not out.exists()
