"""The pad fit's cost per contact before and after issue 34 (items 1, 2): ``find_contacts(
..., method="joint")`` (the joint fit of each contact's size and the model-order
selection) against ``method="fit"`` (the fixed-probe fit alone), in the same run.

Frames: pad16 and pad4, one or two 50-g 1.6-mm spheres at random positions (pairs 3
pitches apart), from the kind's own tabulated model (the speed does not depend on the
truth), quantized; one core.

    PYTHONPATH=src python benchmarks/bench_padfit.py [N_FRAMES]
"""

from __future__ import annotations

import sys
import time

import numpy as np

from tactsense.estimate.contacts import find_contacts
from tactsense.kinds import kind_of
from tactsense.sensor.registry import load_sensor


def frames(spec, n, k, rng):
    model = kind_of(spec).contact_model(spec)
    g = spec.grid
    out = np.empty((n, *spec.shape))
    a = float(model.signal([[0.0, 0.0]], [0.49], [0.9]).max())  # warm up
    for i in range(n):
        c = (np.array([g.rows, g.cols]) / 2 - 0.5 + rng.uniform(-1, 1, 2)) * g.row_pitch_mm
        th = rng.uniform(0, np.pi)
        d = 1.5 * g.row_pitch_mm * np.array([np.cos(th), np.sin(th)])
        pos = [c] if k == 1 else [c + d, c - d]
        radius = (3 * 0.49e-3 * 1.6 / (4 * model.modulus_star_pa)) ** (1 / 3) * 1e3
        s = model.signal(pos, [0.49] * k, [radius] * k)
        out[i] = np.round(s * 20000) / 20000 if not model.capacitive else np.round(s * 2000) / 2000
    del a
    return out


def timed(spec, data, method="joint"):
    t = time.perf_counter()
    table = find_contacts(data, spec, counts=False, method=method)
    return time.perf_counter() - t, len(table)


def main(n=200):
    rng = np.random.default_rng(0)
    print(f"| pad | contacts per frame | fit [ms per contact] | joint [ms per contact] "
          f"| ratio | ({n} frames) |")  # fmt: skip
    print("|---|---|---|---|---|---|")
    for name in ("pad16", "pad4"):
        spec = load_sensor(name)
        for k in (1, 2):
            data = frames(spec, n, k, rng)
            timed(spec, data[:2])  # compile, build the table
            now, found = timed(spec, data)
            timed(spec, data[:2], "fit")
            before, found_before = timed(spec, data, "fit")
            per_before, per_now = before / found_before, now / found
            print(f"| {name} | {k} | {1e3 * per_before:.3f} | {1e3 * per_now:.2f} | "
                  f"{per_now / per_before:.0f} | |")  # fmt: skip


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 200)
