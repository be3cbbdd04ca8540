"""The pads' robustness study (tactsense.analysis.pad_robustness): a pad read as it is
described finds the three probes of every placement; a passive matrix the description
calls isolated adds the fourth corner of the rectangle as a ghost."""

from __future__ import annotations

import pytest

import tactsense as ts
from tactsense.analysis.pad_robustness import markdown_table, pad_robustness_study, perturbations


@pytest.fixture(scope="module")
def rows():
    return pad_robustness_study(
        ts.preset("pad16"),
        n_placements=4,
        habits=["as described", "passive-matrix crosstalk"],
    )


def test_as_described_every_probe_is_found_and_nothing_else(rows):
    described = rows[0]
    assert described.exact_pct == 100.0 and described.ghosts == 0 and described.missed == 0
    # a 0.5-N sphere on a 2.5-mm pitch: within a third of a taxel on average
    assert described.position_taxel < 0.35


def test_crosstalk_of_a_passive_matrix_shows_the_fourth_corner(rows):
    ghost = rows[1]
    assert ghost.habit == "passive-matrix crosstalk"
    assert ghost.ghosts == pytest.approx(1.0) and ghost.exact_pct == 0.0
    assert ghost.missed == 0


def test_the_piezoresistive_habits_are_studied_only_where_they_apply():
    assert "hysteresis 0.2" in perturbations(ts.preset("fsr16"))
    assert "hysteresis 0.2" not in perturbations(ts.preset("pad16"))
    assert "passive-matrix crosstalk" in perturbations(ts.preset("pad16"))


def test_the_table_has_a_row_per_true_pad(rows):
    table = markdown_table(rows).splitlines()
    assert len(table) == 2 + len(rows) and "| pad16 | as described | 100 |" in table[2]
