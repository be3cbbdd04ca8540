"""Time of one pad frame through the 3-D elastic layer (``tactsense.physics.layer``).

Run: ``python benchmarks/bench_layer.py``. A pressure map on 4 samples per pitch
(16x16 and 32x32 taxels at 2 mm pitch, 3-mm rubber layer, nu = 0.5, sensing depth
2 mm, 1.5-mm electrodes) to taxel strains with ``TaxelPad`` (precomputed transfer
functions, two real FFTs per frame), against the straightforward implementation in
the same run: recomputing the transfer functions for every frame (a new
``TaxelPad`` per frame). Also a batch of 64 frames in one call.
"""

from __future__ import annotations

import time

import numpy as np

from tactsense.physics import layer

LAYER = dict(thickness=3e-3, youngs_modulus=2.5e5, poisson_ratio=0.5)


def best_time(fn, repeats):
    best = np.inf
    for _ in range(repeats):
        start = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - start)
    return best


def main() -> None:
    rng = np.random.default_rng(0)
    for size in (16, 32):
        args = (size, size, 2e-3, 1.5e-3, 2e-3)
        pad = layer.TaxelPad(*args, subsamples=4, **LAYER)
        frame = rng.uniform(0, 1e4, pad.grid_shape)
        frames = rng.uniform(0, 1e4, (64, *pad.grid_shape))
        pad(frame)  # warm up the FFT plans
        n = 200
        cached = best_time(lambda p=pad, f=frame, m=n: [p(f) for _ in range(m)], 5) / n
        batch = best_time(lambda p=pad, f=frames: p(f), 5) / 64
        single = layer.TaxelPad(*args, subsamples=4, precision="single", **LAYER)
        single(frame)
        cached32 = best_time(lambda p=single, f=frame, m=n: [p(f) for _ in range(m)], 5) / n
        fresh = best_time(lambda a=args, f=frame: layer.TaxelPad(*a, subsamples=4, **LAYER)(f), 5)
        print(
            f"{size}x{size} taxels, grid {pad.grid_shape} padded to {pad.response.padded_shape}: "
            f"cached {cached * 1e6:7.1f} us/frame ({1 / cached:,.0f} frames/s), "
            f"64-frame batch {batch * 1e6:7.1f} us/frame, "
            f"single precision {cached32 * 1e6:7.1f} us/frame, "
            f"kernel recomputed per frame {fresh * 1e6:8.1f} us/frame, "
            f"ratio {fresh / cached:5.1f}x"
        )


if __name__ == "__main__":
    main()
