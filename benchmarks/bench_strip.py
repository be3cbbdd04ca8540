"""Throughput of the strip capacitor gain: 1,000 designs in one call.

Run: ``python benchmarks/bench_strip.py``. Compares ``strip_capacitor_design``
(one vectorized call, mapped Gauss-Legendre rule) with a straightforward loop that
integrates eq. 35 for each design with ``scipy.integrate.quad``, on the same designs
(top-plate depth swept through the 3.8-mm skin), and reports their agreement.
"""

from __future__ import annotations

import time

import numpy as np
from scipy import integrate

from tactsense.analysis import strip_capacitor_design
from tactsense.physics import strip

E, NU, LOAD, WIDTH, H = 2.5e5, 0.5, 200.0, 3e-3, 3.8e-3


def straightforward_gain(separation: float) -> float:
    """Eq. 35-36 for one design by adaptive quadrature."""
    top = H - separation
    mu = E / (2 * (1 + NU))

    def integrand(s):
        return strip.parabolic_pressure_transform(s, LOAD, WIDTH) * strip.strip_kernel(
            s, top, H, NU, "plane_stress"
        )

    return 2 * integrate.quad(integrand, 0, np.inf, limit=500)[0] / (2 * mu) / separation


def main(n: int = 1000, repeats: int = 5) -> None:
    separation = np.linspace(0.1e-3, 3.5e-3, n)
    best = np.inf
    for _ in range(repeats):
        start = time.perf_counter()
        fast = strip_capacitor_design(H, separation, LOAD, WIDTH, poisson_ratio=NU)["gain"]
        best = min(best, time.perf_counter() - start)
    sample = separation[:: n // 50]
    start = time.perf_counter()
    slow = np.array([straightforward_gain(d) for d in sample])
    slow_time = (time.perf_counter() - start) / sample.size * n
    error = np.max(np.abs(slow - fast[:: n // 50]) / slow)
    print(
        f"strip_capacitor_design : {n} designs in {best * 1e3:8.1f} ms ({n / best:,.0f} designs/s)"
    )
    print(
        f"scipy.quad per design  : {n} designs in {slow_time * 1e3:8.1f} ms (extrapolated "
        f"from {sample.size})"
    )
    print(f"ratio                  : {slow_time / best:8.1f} x")
    print(f"max relative difference: {error:.1e}")


if __name__ == "__main__":
    main()
