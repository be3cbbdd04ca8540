"""Throughput of tactsense.locate against a straightforward per-frame implementation.

Run: ``python benchmarks/bench_locate.py``. On the same simulated 8x8 frames (single
50-g probes anywhere on the initial finger, quantized counts) it measures

* ``locate`` on a batch, from counts and from deflections (frames per second);
* the compiled kernel alone (Newton to 0.01 tactel, force, skew, second maximum);
* ``RealTimeLocator``: one frame at a time, counts to estimate (microseconds);
* the straightforward reference: eq. 48 evaluated directly and maximized per frame with
  ``scipy.optimize.minimize`` from the largest tactel, plus force and skew,

and reports the ratio and the largest disagreement in position.
"""

from __future__ import annotations

import time

import numpy as np
from scipy.optimize import minimize

import tactsense as ts
from tactsense.estimate.finger._fast import locate_frames
from tactsense.estimate.finger.realtime import RealTimeLocator
from tactsense.physics.array_response import deflection_batch
from tactsense.physics.transduction import deflection_to_counts, fractional_deflection


def eq48(z, x, y, periodic):
    """f(x, y) of eq. 48, term by term."""
    rows, cols = z.shape
    total = 0.0
    for i in range(rows):
        for j in range(cols):
            dx = x - i
            dy = y - j
            if periodic:
                dy = (dy + cols / 2) % cols - cols / 2
            wx = 0.5 * (1 + np.cos(2 * np.pi * dx / (rows - 1))) if abs(dx) <= 3.5 else 0.0
            wy = 0.5 * (1 + np.cos(2 * np.pi * dy / (cols - 1))) if abs(dy) <= 3.5 else 0.0
            total += z[i, j] * np.sinc(dx) * np.sinc(dy) * wx * wy
    return total


def straightforward(z, periodic):
    """Peak by scipy.optimize on eq. 48, then force (sum) and skew along the finger."""
    start = np.array(np.unravel_index(np.argmax(z), z.shape), float)
    simplex = start + np.array([[0.0, 0.0], [0.5, 0.0], [0.0, 0.5]])
    result = minimize(
        lambda p: -eq48(z, p[0], p[1], periodic),
        start,
        method="Nelder-Mead",
        options={"xatol": 0.001, "fatol": 1e-12, "initial_simplex": simplex},
    )
    x, y = result.x
    peak = -result.fun
    odd_best, even_best = 0.0, peak
    for t in np.arange(1, 9) * 0.25:
        if t > min(x - 1, z.shape[0] - 1 - x):
            break
        plus, minus = eq48(z, x + t, y, periodic), eq48(z, x - t, y, periodic)
        even_best = max(even_best, 0.5 * (plus + minus))
        if abs(0.5 * (plus - minus)) > abs(odd_best):
            odd_best = 0.5 * (plus - minus)
    return x, y, z[1:].sum(), odd_best / even_best


def frames(n, seed=0):
    spec = ts.fearing1990_initial()
    rng = np.random.default_rng(seed)
    states = [
        (ts.Probe(float(a), float(b), ts.grams_force(50)),)
        for a, b in zip(rng.uniform(5, 20, n), rng.uniform(-180, 180, n), strict=True)
    ]
    deflection = deflection_batch(spec, states)
    counts = np.rint(deflection_to_counts(spec, deflection, quantize=False)).astype(np.uint16)
    return spec, deflection, counts


def best_of(function, repeats=3):
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        function()
        times.append(time.perf_counter() - start)
    return min(times)


def main(n_batch: int = 500_000, n_slow: int = 100) -> None:
    spec, deflection, counts = frames(5000)
    reps = n_batch // 5000
    big_counts = np.tile(counts, (reps, 1, 1))
    big_deflection = np.tile(deflection, (reps, 1, 1))
    baseline = np.full(spec.shape, spec.electronics.nominal_counts)
    ts.locate(counts[:5], spec, baseline=baseline)  # compile
    t_counts = best_of(lambda: ts.locate(big_counts, spec, baseline=baseline))
    t_defl = best_of(lambda: ts.locate(big_deflection, spec, counts=False))
    valid = np.ones(len(big_deflection), bool)
    t_kernel = best_of(lambda: locate_frames(big_deflection, valid, True, 1, 0.01, 20, 0.5))
    locator = RealTimeLocator(spec, baseline)
    single = counts[:2000]
    t_single = best_of(lambda: [locator(f) for f in single]) / len(single)
    measured = fractional_deflection(counts[:n_slow].astype(float), baseline)
    start = time.perf_counter()
    reference = [straightforward(z, True) for z in measured]
    t_slow = (time.perf_counter() - start) / n_slow
    estimates = ts.locate(counts[:n_slow], spec, baseline=baseline)
    d_row = max(abs(r[0] - e) for r, e in zip(reference, estimates.row, strict=True))
    d_col = max(abs((r[1] - e + 4) % 8 - 4) for r, e in zip(reference, estimates.col, strict=True))
    print(f"frames                     : {len(big_counts):,} (8x8, single 50-g probes)")
    print(f"locate, from counts        : {len(big_counts) / t_counts:12,.0f} frames/s")
    print(f"locate, from deflections   : {len(big_counts) / t_defl:12,.0f} frames/s")
    print(f"compiled kernel alone      : {len(big_counts) / t_kernel:12,.0f} frames/s")
    print(f"RealTimeLocator, one frame : {1e6 * t_single:12.1f} us")
    print(f"straightforward reference  : {1 / t_slow:12,.0f} frames/s")
    print(f"ratio (locate from counts) : {t_slow / (t_counts / len(big_counts)):12,.0f} x")
    print(f"largest position difference: {max(d_row, d_col):.4f} tactel")


if __name__ == "__main__":
    main()
