"""The pad robustness study on frames from the shared layer truth (issue 34 item 4):
its chain from strain to counts, and a small re-run that checks the direction of the
effects docs/accuracy.md reports (scripts/pad_robustness_truth_numbers.py)."""

import re
from pathlib import Path

import numpy as np
import pytest

from tactsense.analysis import pad_robustness_truth as study
from tactsense.sensor.registry import load_sensor

DOC = Path(__file__).resolve().parents[2] / "docs" / "accuracy.md"


def test_cases_name_each_change_and_crosstalk_only_on_resistive_pads():
    pad4, pad16 = load_sensor("pad4"), load_sensor("pad16")
    assert not any(c.crosstalk for c in study.cases(pad4))
    assert any(c.crosstalk for c in study.cases(pad16))
    thick = next(c for c in study.cases(pad16) if c.name == "layer 15 % thicker")
    layer = study.true_layer(pad16, thick)
    assert layer.thickness_mm == pytest.approx(2.3)
    assert layer.sensing_depth_mm == pytest.approx(1.725)


@pytest.mark.parametrize("name", ["pad4", "pad16"])
def test_true_counts_rest_rise_and_noise(name):
    spec = load_sensor(name)
    case = study.Case("x")
    rng = np.random.default_rng(1)
    rest = study.true_counts(spec, np.zeros((200, *spec.shape)), case, 1.0, rng)
    pressed = study.true_counts(spec, np.full((1, *spec.shape), 2e-3), case, 1.0, rng)
    assert np.all(pressed > rest.mean(axis=0) + 5)  # rising pads: compression reads up
    noisy = study.Case("n", noise_fs=0.01)
    spread = study.true_counts(spec, np.zeros((200, *spec.shape)), noisy, 1.0, rng).std()
    # 1 % of 4095 counts, within the sampling error of 200 x taxels draws (and the
    # converter's floor at 0 on a resistive pad resting at 100 counts: a one-sided clip)
    assert spread == pytest.approx(40.95, rel=0.15)


def test_crosstalk_adds_to_the_fourth_corner():
    spec = load_sensor("pad16")
    strain = np.zeros((1, *spec.shape))
    strain[0, 3, 3] = strain[0, 3, 9] = strain[0, 9, 3] = 5e-3
    rng = np.random.default_rng(0)
    quiet = study.Case("q", noise_fs=0.0)
    ghost = study.Case("g", noise_fs=0.0, crosstalk=True)
    a = study.true_counts(spec, strain, quiet, 1.0, rng)[0]
    b = study.true_counts(spec, strain, ghost, 1.0, rng)[0]
    assert a[9, 9] == spec.electronics.nominal_counts
    assert b[9, 9] > a[9, 9] + 10


def _doc_row(pad, case, method):
    for line in DOC.read_text().splitlines():
        cells = [c.strip() for c in line.strip("|").split("|")]
        if len(cells) in (9, 10) and cells[:3] == [pad, case, method]:
            return cells
    raise AssertionError(f"no row {pad} / {case} / {method} in docs/accuracy.md")


def _numbers(cell):
    return [float(v) for v in re.findall(r"[-+]?\d*\.?\d+", cell)]


def test_small_rerun_shows_the_docs_directions():
    # pad4 (capacitive: information in every taxel), the fixed-probe fit, 6 positions:
    # the truth as described is estimated near its bound, the twin's gain spread spoils
    # position and force until the sweep's gains take it out; the doc's rows (12
    # positions, another draw) must show the same directions
    spec = load_sensor("pad4")
    by_name = {c.name: c for c in study.cases(spec)}
    described = study.run_case(
        spec, by_name["as described (1.6-mm sphere, 50 g)"], n_positions=6, seed=5,
        methods=("fit",),
    ).before["fit"]  # fmt: skip
    spread = study.run_case(
        spec, by_name["gain spread (twin's)"], n_positions=6, seed=5, methods=("fit",)
    )
    assert described.found_pct == 100.0
    assert described.position_mean < 0.05 and described.force_median < 5.0
    before, after = spread.before["fit"], spread.after["fit"]
    assert before.position_mean > 3 * described.position_mean
    assert before.force_median > 2 * described.force_median
    assert after.position_mean < 0.05 and after.force_median < 0.5 * before.force_median
    doc_described = _doc_row("pad4", "as described (1.6-mm sphere, 50 g)", "fit")
    doc_spread = _doc_row("pad4", "gain spread (twin's)", "fit")
    d_pos, s_pos, s_pos_after = (_numbers(doc_described[4])[0], _numbers(doc_spread[4])[0],
                                 _numbers(doc_spread[7])[0])  # fmt: skip
    assert s_pos > 3 * d_pos and s_pos_after < 0.5 * s_pos
    assert _numbers(doc_spread[5])[0] > 2 * _numbers(doc_described[5])[0]


def test_efficiency_column_is_rms_over_the_bound_where_one_applies():
    # a made-up row: RMS 0.02 pitch and 3 % against a bound of 0.01 pitch and 2 %:
    # efficiency 2 and 1.5; no column when no row has a bound
    from tactsense.analysis.pad_robustness_truth import Case, Row, Score, bound_applies

    score = Score(100.0, 0.015, 0.04, 2.0, 5.0, 0.02, 3.0)
    described = Case("as described")
    row = Row("pad4", described, {"joint": score}, {"joint": score}, bound=(0.01, 2.0))
    table = study.markdown_table([row])
    assert table.splitlines()[2].endswith("| 2 / 1.5; 2 / 1.5 |")
    assert "efficiency" not in study.markdown_table([Row("pad4", described, {"joint": score},
                                                       {"joint": score})])  # fmt: skip
    assert bound_applies(described) and bound_applies(Case("n", noise_fs=0.01))
    for other in (Case("d", "disc"), Case("t", thickness_factor=1.15), Case("g", gain_spread=True),
                  Case("nu", poisson_ratio=0.45), Case("x", crosstalk=True)):  # fmt: skip
        assert not bound_applies(other)
