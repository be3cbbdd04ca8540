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

``--starts``: the two solvers from the same starts (lmcheck, round 10). On pad4 pairs
from the Hankel-transform layer solution (``analysis.layer_truth``, quantized; 50-g
1.6-mm spheres 1-3 pitches apart at 0-90 deg, one seeded sub-taxel offset per cell),
every start the joint search gives its fit (``_joint._fit_frame``: first fits, splits,
prunes, re-seeds) is refitted by the reference from the same start; the table counts
the starts where one solver's residual exceeds the other's by more than 10 %, and the
first-order condition at each solver's ends (the largest projected gradient of the
cost in the step units of ``_joint_lm.step_units``, a bound's outward push excluded,
over the cost).

    PYTHONPATH=src python benchmarks/bench_padfit.py [N_FRAMES] [--write]
    PYTHONPATH=src python benchmarks/bench_padfit.py --starts [--write]

``--write`` replaces the table's block in docs/performance.md.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

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


ROOT = Path(__file__).resolve().parents[1]
DOC = ROOT / "docs" / "performance.md"


def write_block(name, lines):
    """Put ``lines`` in the block ``name`` of docs/performance.md."""
    sys.path.insert(0, str(ROOT / "scripts"))
    from docblock import replace_block

    begin, end = f"<!-- begin {name} -->", f"<!-- end {name} -->"
    replace_block(DOC, begin, end, "\n".join([begin, *lines, end]))


def main(n=200, write=False):
    rng = np.random.default_rng(0)
    lines = [
        "| pad | contacts per frame | fit [ms per contact] | joint, SciPy reference "
        "[ms per contact] | joint, compiled [ms per contact] | compiled frames/s | "
        "speed-up over the reference | joint over fit | frames with as many contacts "
        "| largest force difference [%] |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    print(f"({n} frames per row)")
    print(lines[0])
    print(lines[1])
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
            lines.append(
                f"| {name} | {k} | {1e3 * per_before:.3f} | {1e3 * per_then:.2f} | "
                f"{1e3 * per_now:.2f} | {n / now:.0f} | {per_then / per_now:.1f} | "
                f"{per_now / per_before:.1f} | {same} of {n} | {worst:.2f} |"
            )
            print(lines[-1], flush=True)
    if write:
        write_block("bench_padfit", lines)


SEPARATIONS = (1.0, 1.5, 2.0, 2.5, 3.0)
"""The pairs' separations in ``--starts`` [pitch]."""

ORIENTATIONS = (0.0, 22.5, 45.0, 67.5, 90.0)
"""The pairs' orientations in ``--starts`` [deg from the rows]."""


def first_order(model, frame, q, sigma):
    """Largest projected gradient of the joint fit's cost at ``q`` (k, 5) in the step
    units of ``_joint_lm.step_units``, over the cost [-]."""
    from tactsense.estimate.contacts import _joint
    from tactsense.estimate.contacts._joint_lm import residual_jacobian, step_units, tables_of

    k = len(q)
    lo, hi = _joint._bounds(model, frame, k)
    p = np.clip(q.ravel(), lo, hi)
    n = frame.size
    prior = np.array(
        [0.0 if sigma is None else sigma, _joint.PRIOR_WIDTH, _joint.PRIOR_RADIUS_MM,
         model.modulus_star_pa]
    )  # fmt: skip
    m = n + (k if prior[0] > 0 else 0)
    r, jac = np.empty(n + k), np.empty((n + k, 5 * k))
    residual_jacobian(
        p, np.ravel(frame), model.x_taxel, model.y_taxel, tables_of(model),
        not model.capacitive, float(model.scale), prior, r, jac,
    )  # fmt: skip
    grad = jac[:m].T @ r[:m]
    tol = 1e-9 * np.maximum(1.0, np.abs(p))
    pinned = ((p <= lo + tol) & (grad > 0)) | ((p >= hi - tol) & (grad < 0))
    step = grad * step_units(p, model.x_taxel, model.y_taxel) * ~pinned
    return float(np.abs(step).max() / max(float(np.sum(r[:m] ** 2)), 1e-300))


def starts(write=False):
    """The compiled and the reference fit from the estimator's own starts on pad4 pairs
    (Hankel truth, quantized): the table of ``--starts``."""
    from tactsense.analysis.layer_truth import hankel_hertz_strain
    from tactsense.estimate.contacts import _joint

    spec = load_sensor("pad4")
    model = kind_of(spec).contact_model(spec)
    g = spec.grid
    per = spec.electronics.nominal_counts
    rng = np.random.default_rng(1)
    calls = []
    compiled = _joint._fit_frame

    def logged(model, frame, x0, y0, f0, a0, w0=None, sigma=None):
        q, rss = compiled(model, frame, x0, y0, f0, a0, w0, sigma)
        calls.append((np.array(frame, float), x0, y0, f0, a0, w0, sigma, q, rss))
        return q, rss

    _joint._fit_frame = logged
    try:
        for sep in SEPARATIONS:
            for angle in ORIENTATIONS:
                centre = (
                    np.array([g.rows, g.cols]) / 2 - 0.5 + rng.uniform(size=2)
                ) * g.row_pitch_mm
                th = np.radians(angle)
                half = 0.5 * sep * g.row_pitch_mm * np.array([np.cos(th), np.sin(th)])
                strain = sum(
                    hankel_hertz_strain(spec, x, y, 0.49) for x, y in (centre + half, centre - half)
                )
                signal = np.round(spec.transduction.strain_gain * strain * per) / per
                find_contacts(signal, spec, counts=False, method="joint")
    finally:
        _joint._fit_frame = compiled
    rows = {}
    for frame, x0, y0, f0, a0, w0, sigma, q, rss in calls:
        ref, rss_ref = _joint._fit_frame_reference(model, frame, x0, y0, f0, a0, w0, sigma)
        row = rows.setdefault(len(q), [])
        row.append(
            (
                rss,
                rss_ref,
                first_order(model, frame, q, sigma),
                first_order(model, frame, ref, sigma),
            )
        )
    lines = [
        "| contacts per fit | starts | compiled worse by > 10 % | reference worse by > 10 % "
        "| within 1 % of each other | first-order condition, compiled: median / 90th "
        "percentile | reference: median / 90th percentile |",
        "|---|---|---|---|---|---|---|",
    ]
    for k in sorted(rows):
        v = np.array(rows[k])
        same = np.abs(v[:, 0] - v[:, 1]) <= 0.01 * np.maximum(v[:, 0], v[:, 1]) + 1e-15
        lines.append(
            f"| {k} | {len(v)} | {np.sum(v[:, 0] > 1.1 * v[:, 1])} | "
            f"{np.sum(v[:, 1] > 1.1 * v[:, 0])} | {np.sum(same)} | "
            f"{np.median(v[:, 2]):.1e} / {np.percentile(v[:, 2], 90):.1e} | "
            f"{np.median(v[:, 3]):.1e} / {np.percentile(v[:, 3], 90):.1e} |"
        )
    print("\n".join(lines))
    if write:
        write_block("bench_padfit starts", lines)


if __name__ == "__main__":
    args = [a for a in sys.argv[1:] if not a.startswith("--")]
    if "--starts" in sys.argv:
        starts("--write" in sys.argv)
    else:
        main(int(args[0]) if args else 200, "--write" in sys.argv)
