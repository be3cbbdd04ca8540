"""The design map's labels (issue 21, item 9): the paper's two fingers are 0.5 mm apart
at the same depth, and their names wrote over each other."""

import pytest

import tactsense as ts
from tactsense.analysis.sweep import design_sweep, draw_map


@pytest.fixture(scope="module")
def dataset():
    return design_sweep(ts.fearing1990_initial(), [3.0, 3.8, 4.5], [3.0, 3.3, 3.8])


def _boxes(fig):
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    return [[text.get_window_extent(renderer) for text in ax.texts] for ax in fig.axes if ax.texts]


@pytest.mark.parametrize(
    "designs",
    [
        {"initial": (3.8, 3.8), "improved": (3.8, 3.3)},  # the command's two fingers
        {"a": (3.8, 3.0), "b": (3.8, 3.3), "c": (3.8, 3.8)},  # three in a row
    ],
)
def test_the_names_of_designs_do_not_overlap(dataset, designs):
    import matplotlib.pyplot as plt

    fig = draw_map(dataset, designs=designs)
    try:
        panels = _boxes(fig)
        assert len(panels) == 3
        for boxes in panels:
            assert len(boxes) == len(designs)
            for i, first in enumerate(boxes):
                for second in boxes[i + 1 :]:
                    assert not first.overlaps(second), (first, second)
            # and each name stays inside the figure
            width, height = fig.canvas.get_width_height()
            for box in boxes:
                assert box.x0 >= 0 and box.x1 <= width and box.y0 >= 0 and box.y1 <= height
    finally:
        plt.close(fig)
