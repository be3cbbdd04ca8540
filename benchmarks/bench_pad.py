"""Speed of the pad twin: a frame from indenters, and ``simulate`` per frame.

Run: ``python benchmarks/bench_pad.py``. For the 16x16 (``pad16``) and a 32x32 pad:

* ``pad_strain``: one frame from indenters (pressure map on a 0.5-mm grid, the layer
  model of ``tactsense.physics.layer`` with its cached transfer function, electrode
  averaging), against the straightforward way in the same run: the same pressure map
  through :class:`~tactsense.physics.layer.LayerResponse` built afresh for the frame;
* ``simulate`` of a press-and-lift scenario per frame, without flaws and with every
  flaw, against the straightforward simulation in the same run: every frame's strain
  computed from its own indenters (no sharing between the frames of a step).

(The layer alone, from a pressure map already on the grid: ``benchmarks/bench_layer.py``.)
Figures go to ``docs/performance.md``.
"""

from __future__ import annotations

import time

import numpy as np

import tactsense as ts
from tactsense.flat_scenarios import centre_mm, press
from tactsense.physics.indenters import SphereProbe
from tactsense.physics.layer import LayerResponse
from tactsense.physics.pad_response import _pad_grid, modulus_star_pa, pad_strain


def best_of(function, repeats: int = 5, number: int = 5) -> float:
    """Best mean time of ``number`` calls over ``repeats`` runs [s]."""
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        for _ in range(number):
            function()
        times.append((time.perf_counter() - start) / number)
    return min(times)


def fresh_frame(spec, probe) -> np.ndarray:
    """One frame with the layer's transfer function computed for it."""
    x, y, hx, hy, _ = _pad_grid(spec)
    pressure = probe.pressure_pa(x, y, modulus_star_pa=modulus_star_pa(spec.layer))
    g, layer = spec.grid, spec.layer
    response = LayerResponse(
        pressure.shape, (hx * 1e-3, hy * 1e-3), layer.sensing_depth_mm * 1e-3,
        thickness=layer.thickness_mm * 1e-3, youngs_modulus=layer.youngs_modulus_pa,
        poisson_ratio=layer.poisson_ratio,
        electrode=(g.electrode_x_mm * 1e-3, g.electrode_y_mm * 1e-3),
    )  # fmt: skip
    strain = -response(pressure)["eps_zz"]
    n = round(g.row_pitch_mm / hx)
    first = (round(-x[0] / hx), round(-y[0] / hy))
    return strain[first[0] :: n, first[1] :: n][: g.rows, : g.cols]


def naive_simulation(spec, scene) -> int:
    """Every frame from its own indenters (no flaws): the straightforward simulation."""
    boundaries = np.cumsum([0.0] + [s.duration_s for s in scene.steps])
    n = int(np.floor(scene.duration_s / spec.scan_period_s + 1e-9))
    for k in range(n):
        step = np.searchsorted(boundaries, (k + 0.5) * spec.scan_period_s, side="right") - 1
        contacts = scene.steps[min(step, len(scene.steps) - 1)].contacts
        if contacts:
            pad_strain(spec, contacts)
    return n


def main() -> None:
    print(f"{'pad':>8} {'frame':>9} {'fresh':>9} {'ratio':>6} {'sim none':>10} {'naive':>10} "
          f"{'ratio':>6} {'sim all flaws':>14}")  # fmt: skip
    for spec in (ts.preset("pad16"), ts.preset("pad16").replace(grid__rows=32, grid__cols=32)):
        cx, cy = centre_mm(spec)
        probe = SphereProbe(cx + 0.3, cy - 0.7, 0.5, radius_mm=1.6)
        assert np.allclose(pad_strain(spec, [probe]), fresh_frame(spec, probe), rtol=1e-9,
                           atol=1e-15)  # fmt: skip
        t_frame = best_of(lambda s=spec, p=probe: pad_strain(s, [p.moved(1e-3, 0.0)]))
        t_fresh = best_of(lambda s=spec, p=probe: fresh_frame(s, p), 3, 2)
        scene = press(spec, repeats=3, dwell_s=0.2, lift_s=0.2)
        start = time.perf_counter()
        frames = len(ts.simulate(spec, scene, flaws="none").frames)
        t_none = (time.perf_counter() - start) / frames
        start = time.perf_counter()
        naive_frames = naive_simulation(spec, scene)
        t_naive = (time.perf_counter() - start) / naive_frames
        start = time.perf_counter()
        ts.simulate(spec, scene, flaws="all", rng=1)
        t_all = (time.perf_counter() - start) / frames
        g = spec.grid
        print(f"{g.rows:>3}x{g.cols:<4} {t_frame * 1e3:>6.2f} ms {t_fresh * 1e3:>6.2f} ms "
              f"{t_fresh / t_frame:>5.1f}x {t_none * 1e3:>7.2f} ms {t_naive * 1e3:>7.2f} ms "
              f"{t_naive / t_none:>5.1f}x {t_all * 1e3:>11.2f} ms")  # fmt: skip


if __name__ == "__main__":
    main()
