"""Speed of the pad twin: one frame from a pressure map, and ``simulate`` per frame.

Run: ``python benchmarks/bench_pad.py``. For the 16x16 (``pad16``) and a 32x32 pad it
times

* the layer response of one frame from a pressure map already on the grid
  (:func:`tactsense.physics.pad_response.strain_map`: two real FFTs and the cached
  transfer function, electrode averaging included), against a straightforward
  implementation in the same run that computes the transfer function afresh every frame
  (what caching saves) and against direct summation of the spatial kernel over the
  loaded cells (what the FFT saves), checking that all three agree;
* a whole frame from indenters (pressure map included): ``pad_strain``;
* ``tactsense.simulate`` of a press-and-lift scenario with every flaw, per frame.

Prints a table; figures go to ``docs/performance.md``.
"""

from __future__ import annotations

import time

import numpy as np
import scipy.fft

import tactsense as ts
from tactsense.flat_scenarios import centre_mm, press
from tactsense.physics.indenters import SphereProbe
from tactsense.physics.pad_response import (
    _pad_grid,
    modulus_star_pa,
    pad_strain,
    strain_map,
    strain_transfer,
)


def best_of(function, repeats: int = 7, number: int = 20) -> float:
    """Best mean time of ``number`` calls over ``repeats`` runs [s]."""
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        for _ in range(number):
            function()
        times.append((time.perf_counter() - start) / number)
    return min(times)


def _size(pressure, spacing, layer):
    """The FFT size strain_map pads to (four layer thicknesses, at least 8 cells)."""
    m, n = pressure.shape
    pad_m = min(m, max(8, int(np.ceil(4.0 * layer.thickness_mm / spacing[0]))))
    pad_n = min(n, max(8, int(np.ceil(4.0 * layer.thickness_mm / spacing[1]))))
    return (
        scipy.fft.next_fast_len(m + pad_m, real=True),
        scipy.fft.next_fast_len(n + pad_n, real=True),
    )


def uncached(pressure, spacing, layer, electrode):
    """The same response, the transfer function recomputed for the frame."""
    m, n = pressure.shape
    size = _size(pressure, spacing, layer)
    kx = np.fft.fftfreq(size[0], d=spacing[0])[:, None]
    ky = np.fft.rfftfreq(size[1], d=spacing[1])[None, :]
    transfer = strain_transfer(kx, ky, layer.sensing_depth_mm, layer)
    transfer = transfer * np.sinc(kx * electrode[0]) * np.sinc(ky * electrode[1])
    return scipy.fft.irfft2(scipy.fft.rfft2(pressure, s=size) * transfer, s=size)[:m, :n]


def direct(pressure, spacing, layer, electrode, targets):
    """Direct summation at the taxel centres: the spatial kernel of the same discrete
    convolution (the inverse transform of the transfer function, once) times every loaded
    cell."""
    size = _size(pressure, spacing, layer)
    kx = np.fft.fftfreq(size[0], d=spacing[0])[:, None]
    ky = np.fft.rfftfreq(size[1], d=spacing[1])[None, :]
    transfer = strain_transfer(kx, ky, layer.sensing_depth_mm, layer)
    transfer = transfer * np.sinc(kx * electrode[0]) * np.sinc(ky * electrode[1])
    kernel = scipy.fft.irfft2(transfer, s=size)
    rows, cols = np.nonzero(pressure)
    loads = pressure[rows, cols]
    out = np.empty(len(targets))
    for t, (i, j) in enumerate(targets):
        out[t] = np.sum(loads * kernel[(i - rows) % size[0], (j - cols) % size[1]])
    return out


def main() -> None:
    print(f"{'pad':>10} {'cells':>9} {'map->frame':>11} {'uncached':>9} {'direct':>9} "
          f"{'ratio':>7} {'indenters':>10} {'simulate/frame':>15}")  # fmt: skip
    for spec in (ts.preset("pad16"), ts.preset("pad16").replace(grid__rows=32, grid__cols=32)):
        x, y, hx, hy, _ = _pad_grid(spec)
        cx, cy = centre_mm(spec)
        probe = SphereProbe(cx + 0.3, cy - 0.7, 0.5, radius_mm=1.6)
        pressure = probe.pressure_pa(x, y, modulus_star_pa=modulus_star_pa(spec.layer))
        g = spec.grid
        electrode = (g.electrode_x_mm, g.electrode_y_mm)
        fast = strain_map(pressure, (hx, hy), spec.layer, electrode_mm=electrode)
        slow = uncached(pressure, (hx, hy), spec.layer, electrode)
        assert np.allclose(fast, slow, rtol=1e-9, atol=1e-15)
        # direct summation at a few taxels (it is slow), against the FFT at the same cells
        first = (round(-x[0] / hx), round(-y[0] / hy))
        step = round(g.row_pitch_mm / hx)
        targets = [(first[0] + step * i, first[1] + step * j) for i, j in ((7, 7), (8, 9))]
        summed = direct(pressure, (hx, hy), spec.layer, electrode, targets)
        assert np.allclose(summed, [fast[t] for t in targets], rtol=1e-6, atol=1e-12)
        t_fast = best_of(lambda: strain_map(pressure, (hx, hy), spec.layer, electrode_mm=electrode))
        t_uncached = best_of(lambda: uncached(pressure, (hx, hy), spec.layer, electrode))
        t_direct = best_of(
            lambda: direct(pressure, (hx, hy), spec.layer, electrode, targets), 3, 1
        ) * (g.rows * g.cols) / len(targets)  # per frame of every taxel
        t_indenters = best_of(lambda: pad_strain(spec, [probe.moved(0.01, 0.0)]), 5, 5)
        scene = press(spec, repeats=3, dwell_s=0.2, lift_s=0.2)
        start = time.perf_counter()
        recording = ts.simulate(spec, scene, rng=1)
        per_frame = (time.perf_counter() - start) / len(recording.frames)
        print(f"{g.rows:>4}x{g.cols:<5} {pressure.size:>9,} {t_fast * 1e3:>8.3f} ms "
              f"{t_uncached * 1e3:>6.2f} ms {t_direct * 1e3:>6.0f} ms "
              f"{t_uncached / t_fast:>6.1f}x {t_indenters * 1e3:>7.2f} ms "
              f"{per_frame * 1e3:>12.2f} ms")  # fmt: skip


if __name__ == "__main__":
    main()
