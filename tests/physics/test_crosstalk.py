"""Passive-matrix crosstalk (tactsense.physics.crosstalk) against direct solutions: the
2x2 matrix in closed form, and any small matrix by a node-voltage solve of its resistor
network with numpy.linalg.solve (one column grounded, a unit current into one row)."""

from __future__ import annotations

import numpy as np
import pytest

import tactsense as ts
from tactsense.physics.crosstalk import effective_conductance, scan_conductance
from tactsense.physics.indenters import SphereProbe
from tactsense.simulate import Scenario, Step

RTOL = 1e-5
"""The solver keeps the network connected with a leak of 1e-6 of the largest cell
(:data:`tactsense.physics.crosstalk.LEAK`): agreement to a few parts in a million."""


def _node_voltage_conductance(g: np.ndarray, i: int, j: int) -> float:
    """Conductance between row i and column j: Kirchhoff's current law at every node,
    column j at 0 V, 1 A into row i; G = 1 / V(row i)."""
    rows, cols = g.shape
    n = rows + cols
    lap = np.zeros((n, n))
    for r in range(rows):
        for c in range(cols):
            a, b, w = r, rows + c, g[r, c]
            lap[a, a] += w
            lap[b, b] += w
            lap[a, b] -= w
            lap[b, a] -= w
    keep = [k for k in range(n) if k != rows + j]
    current = np.zeros(n)
    current[i] = 1.0
    volts = np.linalg.solve(lap[np.ix_(keep, keep)], current[keep])
    return 1.0 / volts[keep.index(i)]


def test_two_by_two_ghost_is_the_three_cell_path_in_closed_form():
    a, b, c, d = 2.0, 1.0, 0.5, 3.0
    read = scan_conductance(np.array([[a, b], [c, d]]), 1.0)
    assert read[0, 0] == pytest.approx(a + 1.0 / (1.0 / b + 1.0 / c + 1.0 / d), rel=RTOL)
    assert read[1, 1] == pytest.approx(d + 1.0 / (1.0 / a + 1.0 / b + 1.0 / c), rel=RTOL)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_effective_conductance_matches_a_node_voltage_solve(seed):
    g = np.random.default_rng(seed).uniform(0.1, 2.0, (3, 4))
    solved = np.array([[_node_voltage_conductance(g, i, j) for j in range(4)] for i in range(3)])
    np.testing.assert_allclose(effective_conductance(g), solved, rtol=RTOL)
    # stacked frames give each frame's own
    stacked = effective_conductance(np.stack([g, 2.0 * g]))
    np.testing.assert_allclose(stacked[1], 2.0 * solved, rtol=RTOL)


def test_the_fourth_corner_of_a_loaded_rectangle_reads_a_ghost():
    g = np.zeros((4, 5))
    g[1, 1] = g[1, 3] = g[2, 3] = 0.9  # three corners of the rectangle rows 1-2, cols 1-3
    read = scan_conductance(g, 1.0)
    assert read[2, 1] == pytest.approx(0.3, rel=RTOL)  # three 0.9 cells in series
    assert read[2, 1] == pytest.approx(_node_voltage_conductance(g + 1e-12, 2, 1), rel=RTOL)
    half = scan_conductance(g, 0.5)
    assert half[2, 1] == pytest.approx(0.15, rel=RTOL)
    # cells off the rectangle's lines see no path; the loaded cells read what they conduct
    assert np.abs(read[0]).max() < 1e-5 and np.abs(read[:, 0]).max() < 1e-5
    np.testing.assert_allclose(read[g > 0], 0.9, rtol=RTOL)


def test_no_crosstalk_is_the_input_and_one_press_alone_gains_nothing():
    g = np.zeros((6, 6))
    g[2, 3] = 1.0
    np.testing.assert_array_equal(scan_conductance(g, 0.0), g)
    np.testing.assert_allclose(scan_conductance(g, 1.0), g, atol=1e-5)


def test_three_presses_ghost_at_the_fourth_corner_in_the_simulated_passive_matrix():
    """fsr16 is scanned with its lines floating (crosstalk = 1): presses at (4, 4),
    (4, 11) and (11, 11) make the fourth corner (11, 4) read, and (4, 11) alone with its
    diagonal partner would not; with an isolated scan the corner rests."""
    spec = ts.preset("fsr16")
    p = spec.grid.row_pitch_mm
    at = ((4, 4), (4, 11), (11, 11))
    probes = tuple(SphereProbe(r * p, c * p, 4.0) for r, c in at)
    scenario = Scenario((Step((), 0.1, "rest"), Step(probes, 0.2, "three presses")))
    ghost = ts.simulate(spec, scenario, flaws=["crosstalk"]).frames[-1]
    plain = ts.simulate(spec, scenario, flaws="none").frames[-1]
    assert plain[11, 4] == 0.0
    assert ghost[11, 4] > 200.0  # counts of 4095: a press the scan invents
    two = ts.simulate(spec, Scenario((Step((), 0.1, "rest"), Step(probes[::2], 0.2, "two"))),
                      flaws=["crosstalk"]).frames[-1]  # fmt: skip
    assert two[11, 4] < 1.0 and two[4, 11] < 1.0
    isolated = spec.replace(flaws__crosstalk=0.0)
    np.testing.assert_array_equal(ts.simulate(isolated, scenario, flaws=["crosstalk"]).frames,
                                  ts.simulate(isolated, scenario, flaws="none").frames)  # fmt: skip


def test_crosstalk_on_a_linear_resistive_pad_adds_the_parallel_paths():
    spec = ts.preset("pad16").replace(flaws__crosstalk=1.0)
    p = spec.grid.row_pitch_mm
    probes = tuple(SphereProbe(r * p, c * p, 0.5) for r, c in ((3, 3), (3, 10), (10, 10)))
    scenario = Scenario((Step((), 0.05, "rest"), Step(probes, 0.05, "three presses")))
    ghost = ts.simulate(spec, scenario, flaws=["crosstalk"]).frames[-1]
    plain = ts.simulate(spec, scenario, flaws="none").frames[-1]
    rest = spec.electronics.nominal_counts
    assert plain[10, 3] == rest and ghost[10, 3] > rest + 10.0
    assert np.all(ghost >= plain - 1e-9)
