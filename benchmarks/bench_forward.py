"""Throughput of the forward model against a straightforward implementation.

Run: ``python benchmarks/bench_forward.py``. Prints frames per second of
``deflection_batch`` (vectorized, exact cell integrals) and of a per-tactel loop
that evaluates the same model with ``halfplane.strain_from_pressure`` along the
finger and ``scipy.integrate.quad`` around it, on the same probe contacts, and
checks that both agree.
"""

from __future__ import annotations

import time

import numpy as np
from scipy import integrate

import tactsense as ts
from tactsense.physics import halfplane
from tactsense.physics.array_response import deflection_batch, probe_response, ring_kernel


def straightforward(spec, probe):
    """One frame, tactel by tactel, from the model's definitions."""
    half = probe.contact_diameter_mm / 2 * 1e-3
    edges = np.linspace(-half, half, 201)
    lo, hi = edges[:-1], edges[1:]
    total = 0.75 * ((hi - hi**3 / (3 * half**2)) - (lo - lo**3 / (3 * half**2))) / half
    pressure = probe.force_n * total / np.diff(edges)  # N/m per m of width, parabola
    flex = spec.ring_flexural_length_mm * 1e-3
    frame = np.zeros(spec.shape)
    for i, (axial, depth) in enumerate(zip(spec.row_axial_mm, spec.row_depth_mm, strict=True)):
        eps = halfplane.strain_from_pressure(
            (axial - probe.axial_mm) * 1e-3,
            depth * 1e-3,
            edges,
            pressure,
            youngs_modulus=spec.elastic.youngs_modulus_pa,
            poisson_ratio=spec.elastic.effective_poisson_ratio,
        )
        r_ring = spec.ring_radius_mm * np.cos(np.clip(-axial / spec.radius_mm, 0, np.pi / 2))
        half_arc = r_ring * half / (spec.radius_mm * 1e-3) * 1e-3
        for j, angle in enumerate(spec.col_angle_deg):
            delta = np.deg2rad((angle - probe.angle_deg + 180) % 360 - 180) * r_ring * 1e-3
            weight = integrate.quad(
                lambda t, d=delta, h=half_arc: (
                    0.75 / h * (1 - (t / h) ** 2) * ring_kernel(d - t, flex)
                ),
                -half_arc,
                half_arc,
            )[0]
            frame[i, j] = -eps * weight
    return frame


def main(n_fast: int = 100_000, n_slow: int = 40) -> None:
    spec = ts.fearing1990_initial()
    rng = np.random.default_rng(0)
    probes = [
        ts.Probe(float(a), float(b), 0.5)
        for a, b in zip(rng.uniform(0, 25, n_fast), rng.uniform(-180, 180, n_fast), strict=True)
    ]
    start = time.perf_counter()
    fast = deflection_batch(spec, [(p,) for p in probes])
    fast_rate = n_fast / (time.perf_counter() - start)
    start = time.perf_counter()
    slow = np.array([straightforward(spec, p) for p in probes[:n_slow]])
    slow_rate = n_slow / (time.perf_counter() - start)
    error = np.max(np.abs(slow - fast[:n_slow])) / np.max(np.abs(fast[:n_slow]))
    axial = np.array([p.axial_mm for p in probes])
    angle = np.array([p.angle_deg for p in probes])
    force = np.array([p.force_n for p in probes])
    probe_response(spec, axial[:5], angle[:5], force[:5])  # compile
    best = np.inf
    for _ in range(3):
        start = time.perf_counter()
        arrays = probe_response(spec, axial, angle, force)
        best = min(best, time.perf_counter() - start)
    assert np.allclose(arrays, fast, atol=1e-15)
    print(f"probe_response   : {n_fast / best:12,.0f} frames/s (arrays in, compiled)")
    print(f"deflection_batch : {fast_rate:12,.0f} frames/s (Probe objects in)")
    print(f"straightforward  : {slow_rate:12,.1f} frames/s")
    print(f"ratio            : {fast_rate / slow_rate:12,.0f} x")
    print(f"max difference   : {error:.2e} of the largest deflection")

    scene = ts.repeated_load(spec, repeats=500, on_s=1.0, off_s=1.0)
    start = time.perf_counter()
    recording = ts.simulate(spec, scene, rng=0)
    elapsed = time.perf_counter() - start
    print(
        f"simulate (all flaws): {len(recording) / elapsed:,.0f} frames/s ({len(recording)} frames)"
    )


if __name__ == "__main__":
    main()
