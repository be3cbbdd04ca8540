"""The pad fit's cost per contact before and after issue 34 (items 1, 2): ``find_contacts(
..., method="joint")`` (the joint fit of each contact's size and the model-order
selection) against ``method="fit"`` (the fixed-probe fit alone), in the same run; and
the joint fit's compiled Levenberg-Marquardt (closed-form Jacobian) against the
straightforward fit it replaced (SciPy's ``least_squares``, finite-difference Jacobian:
``_joint._fit_frame_reference``) on the same frames, with how often both find the same
number of contacts and their largest force difference.

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


def timed(spec, data, method="joint", reference=False):
    from tactsense.estimate.contacts import _joint

    fitter = _joint._fit_frame
    if reference:
        _joint._fit_frame = _joint._fit_frame_reference
    try:
        t = time.perf_counter()
        table = find_contacts(data, spec, counts=False, method=method)
        return time.perf_counter() - t, len(table), table
    finally:
        _joint._fit_frame = fitter


def agreement(a, b):
    """Frames where both tables hold as many contacts, and the largest relative force
    difference [%] over those frames' contacts (matched by order)."""
    fa, fb = np.asarray(a.frame), np.asarray(b.frame)
    same, worst = 0, 0.0
    for f in np.unique(np.concatenate([fa, fb])):
        ia, ib = np.flatnonzero(fa == f), np.flatnonzero(fb == f)
        if len(ia) != len(ib):
            continue
        same += 1
        xa = np.column_stack([a.x_mm[ia], a.y_mm[ia]])
        xb = np.column_stack([b.x_mm[ib], b.y_mm[ib]])
        order = np.argmin(np.hypot(*(xa[:, None] - xb[None]).transpose(2, 0, 1)), axis=1)
        d = np.abs(a.force_n[ia] / b.force_n[ib][order] - 1.0)
        worst = max(worst, float(d.max()))
    return same, 100.0 * worst


def main(n=200):
    rng = np.random.default_rng(0)
    print(f"| pad | contacts per frame | fit [ms per contact] | joint, SciPy reference "
          f"[ms per contact] | joint, compiled [ms per contact] | compiled frames/s | "
          f"speed-up over the reference | joint over fit | frames with as many contacts "
          f"| largest force difference [%] | ({n} frames) |")  # fmt: skip
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for name in ("pad16", "pad4"):
        spec = load_sensor(name)
        for k in (1, 2):
            data = frames(spec, n, k, rng)
            timed(spec, data[:2])  # compile, build the table
            now, found, mine = timed(spec, data)
            timed(spec, data[:2], reference=True)
            then, found_then, ref = timed(spec, data, reference=True)
            timed(spec, data[:2], "fit")
            before, found_before, _ = timed(spec, data, "fit")
            per_before, per_now, per_then = before / found_before, now / found, then / found_then
            same, worst = agreement(mine, ref)
            print(f"| {name} | {k} | {1e3 * per_before:.3f} | {1e3 * per_then:.2f} | "
                  f"{1e3 * per_now:.2f} | {n / now:.0f} | {per_then / per_now:.1f} | "
                  f"{per_now / per_before:.1f} | {same} of {n} | {worst:.2f} | |")  # fmt: skip


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 200)
