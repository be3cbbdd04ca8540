"""Round three, helper `tools` (issue 31, items 11-12): what the help and the pad design
map say must be what the code does. Each case failed before its fix.

The firmware's undefined symbols are checked in tests/firmware/test_freestanding.py, the
view's speed selector and "ended" in tests/view/test_playback.py."""

from __future__ import annotations

import numpy as np
import pytest
from typer.testing import CliRunner

import tactsense as ts
from tactsense.analysis.pad_design import VARIABLES, design_point
from tactsense.cli import app
from tactsense.view.feed import LOCATORS, PLURAL


def test_view_help_does_not_deny_contacts_the_view_estimates():
    """`view --help` said contacts on pads and point sets were not estimated; the view
    runs a contact estimator for every built-in kind (a kind another package registers,
    such as the kind suite's toy, is not in tactsense's own help text)."""
    result = CliRunner().invoke(app, ["view", "--help"], terminal_width=200)
    assert result.exit_code == 0
    text = " ".join(result.output.split())
    assert "not estimated" not in text
    for kind in ("finger", "pad", "points"):
        assert kind in LOCATORS
        assert PLURAL[kind].split()[0].rstrip("s") in text  # finger, pad, point (sets)


@pytest.fixture(scope="module")
def pad_map_designs(tmp_path_factory):
    """The designs `design sweep --sensor pad16 --plot` marks, on a grid of 2 x 2 designs
    through pad16's and pad4's points, and the map itself."""
    import xarray as xr

    import tactsense.analysis.sweep as sweep

    seen = {}

    def record(dataset, path, *, designs, note=None):
        seen.update(designs=dict(designs), note=note)
        path.write_bytes(b"")

    folder = tmp_path_factory.mktemp("padmap")
    out = folder / "map.nc"
    original, sweep.plot_map = sweep.plot_map, record
    try:
        result = CliRunner().invoke(
            app,
            ["design", "sweep", "--sensor", "pad16", "--depth", "1.5,2", "--spacing", "2.5,5",
             "--out", str(out), "--plot", str(folder / "map.png")],
        )  # fmt: skip
    finally:
        sweep.plot_map = original
    assert result.exit_code == 0, result.output
    return seen, xr.open_dataset(out, engine="scipy").load()


def test_pad_map_marks_only_designs_whose_values_it_shows(pad_map_designs):
    """pad4 (capacitive, a 4-mm layer) was marked on pad16's map, in its blank "not
    observable" region, though pad4's own bound there is finite: every design marked on
    the map must have the map's values at its point."""
    seen, dataset = pad_map_designs
    view = dataset.isel(poisson_ratio=0, load_g=0)
    nu, grams = float(view["poisson_ratio"]), float(view["load_g"])
    assert "pad16" in seen["designs"]
    checked = 0
    for name, (depth, pitch) in seen["designs"].items():
        if depth not in view["depth_mm"].values or pitch not in view["spacing_mm"].values:
            continue
        own = design_point(ts.preset(name), depth, pitch, nu, grams)
        shown = view.sel(depth_mm=depth, spacing_mm=pitch)
        for variable in VARIABLES:
            np.testing.assert_allclose(float(shown[variable]), own[variable], rtol=1e-9)
        checked += 1
    assert checked >= 1
    # the pads left out are named under the map, with the reason
    assert "pad4" not in seen["designs"] and "pad4 (other" in seen["note"]
    assert "pad12x32" not in seen["designs"] and "layer thickness" in seen["note"]


def _pad_dataset():
    """A map on the command's default pad grid (values do not matter for the names)."""
    import xarray as xr

    depths, pitches = np.linspace(0.5, 4.0, 8), np.linspace(1.5, 5.0, 8)
    shape = (len(depths), len(pitches), 1, 1)
    values = np.linspace(1.0, 2.0, np.prod(shape)).reshape(shape)
    dims = ("depth_mm", "spacing_mm", "poisson_ratio", "load_g")
    return xr.Dataset(
        {name: (dims, values) for name in ("counts_per_gram", "xi", "crb_position_mm")},
        coords={"depth_mm": depths, "spacing_mm": pitches, "poisson_ratio": [0.5],
                "load_g": [50.0]},
    )  # fmt: skip


@pytest.mark.parametrize(
    "designs",
    [
        {"pad4": (2.0, 5.0), "pad16": (1.5, 2.5), "pad12x32": (1.0, 2.0)},  # the old map's
        {"a": (1.0, 2.0), "b": (1.1, 2.1), "c": (1.5, 2.5), "d": (0.5, 1.5), "e": (4.0, 5.0)},
    ],
)
def test_names_on_the_pad_map_are_whole_and_apart(designs):
    """The label pad12x32 was cut by pad16's (its white ground over the name): every
    name's box, ground included, must meet no other name or star and stay in its panel."""
    import matplotlib.pyplot as plt

    from tactsense.analysis.sweep import draw_map

    fig = draw_map(_pad_dataset(), designs=designs)
    try:
        fig.canvas.draw()
        renderer = fig.canvas.get_renderer()
        panels = [ax for ax in fig.axes if ax.texts]
        assert len(panels) == 3
        for ax in panels:
            assert sorted(t.get_text() for t in ax.texts) == sorted(designs)
            boxes = [t.get_bbox_patch().get_window_extent(renderer) for t in ax.texts]
            stars = [ax.transData.transform((s, d)) for d, s in designs.values()]
            inside = ax.get_window_extent(renderer)
            for i, (text, box) in enumerate(zip(ax.texts, boxes, strict=True)):
                assert inside.x0 <= box.x0 and box.x1 <= inside.x1, text.get_text()
                assert inside.y0 <= box.y0 and box.y1 <= inside.y1, text.get_text()
                for other in boxes[i + 1 :]:
                    assert not box.overlaps(other), text.get_text()
                own = designs[text.get_text()]
                for (x, y), point in zip(stars, designs.values(), strict=True):
                    if point != own:
                        assert not box.contains(x, y), (text.get_text(), point)
    finally:
        plt.close(fig)
