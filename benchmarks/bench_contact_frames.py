"""Speed of ``frames_from_contacts``: frames from arrays of contacts (issue 38, item 1).

Run: ``python benchmarks/bench_contact_frames.py [--frames N]``. One process, one core
(the kernels are not parallel). For the 16x16 pad (``pad16``), a 32x32 pad (``pad16``'s
pitch, layer and cells on a 32x32 grid), ``pad12x32`` and the paper's finger: N frames,
every frame its own one to three sphere contacts (a third of the contacts missing,
forces 0.05-3 N, Hertz radius from the force on a 1.6-mm sphere), with every per-frame
flaw (noise included) and without flaws:

* the fast path, ``frames_from_contacts(spec, batch)`` (the kind's
  ``contact_forward``; the finger has none and runs the reference);
* today's path in the same run, against which the ratio is given: the same frames as a
  scenario of one step per frame through ``simulate`` (the scan loop, the pad's
  ``layer_strain`` per frame), on a sample of the frames (it is slow).

Times are the process's CPU time (``time.process_time``) over the whole call, best of
three calls, the one-off table build excluded (the first call, its time printed); the
best wall time is printed beside it (other jobs share this machine's two cores). Today's
path: one call.
"""

from __future__ import annotations

import argparse
import dataclasses
import time

import numpy as np

from tactsense.kinds import kind_of
from tactsense.sensor.registry import fearing1990_improved, pad12x32, pad16
from tactsense.simulate import ContactBatch, Scenario, Step, frames_from_contacts, simulate


def pad32():
    """``pad16`` on a 32x32 grid (the same pitch, electrodes, layer and cells)."""
    spec = pad16()
    grid = dataclasses.replace(spec.grid, rows=32, cols=32)
    return dataclasses.replace(spec, name="pad32", grid=grid)


SENSORS = {"pad16": pad16, "pad32 (32x32)": pad32, "pad12x32": pad12x32,
           "finger (improved)": fearing1990_improved}  # fmt: skip


def random_contacts(spec, n: int, seed: int = 0) -> ContactBatch:
    """N frames of one to three sphere contacts anywhere on the sensor (a third of the
    contacts missing; at least one per frame), forces 0.05-3 N, 1.6-mm spheres."""
    rng = np.random.default_rng(seed)
    k = 3
    if kind_of(spec).name == "finger":
        axial = rng.uniform(0.0, float(spec.row_axial_mm.max()), (n, k))
        around = rng.uniform(-np.pi / 2, np.pi / 2, (n, k)) * spec.radius_mm
        position = np.stack([axial, around], axis=-1)
    else:
        g = spec.grid
        extent = np.array([(g.rows - 1) * g.row_pitch_mm, (g.cols - 1) * g.col_pitch_mm])
        position = rng.uniform(0.0, 1.0, (n, k, 2)) * extent
    force = rng.uniform(0.05, 3.0, (n, k))
    missing = rng.random((n, k)) < 1.0 / 3.0
    missing[:, 0] = False
    force[missing] = 0.0
    return ContactBatch(position, force, radius_mm=1.6)


def timed(function, repeats: int = 1):
    """(CPU seconds, wall seconds, result) of the call: the best of ``repeats`` runs (other
    jobs share this machine's cores; the best run is the least disturbed)."""
    best_cpu = best_wall = float("inf")
    for _ in range(repeats):
        cpu, wall = time.process_time(), time.perf_counter()
        result = function()
        best_cpu = min(best_cpu, time.process_time() - cpu)
        best_wall = min(best_wall, time.perf_counter() - wall)
    return best_cpu, best_wall, result


def todays_path(spec, batch: ContactBatch, flaws: str):
    """The same frames through ``simulate``: one step of one scan period per frame."""
    kind = kind_of(spec)
    steps = [
        Step(kind.contact_state(spec, batch.frame(i)), spec.scan_period_s)
        for i in range(batch.n_frames)
    ]
    return simulate(spec, Scenario(steps), flaws=flaws, rng=1).frames


def measure(n_frames: int = 200_000, n_reference: int = 200) -> list[dict]:
    """One row per sensor and flaw setting."""
    rows = []
    for name, make in SENSORS.items():
        spec = make()
        fast_available = kind_of(spec).contact_forward(spec) is not None
        n = n_frames if fast_available else min(n_frames, 2000)
        batch = random_contacts(spec, n)
        sample = ContactBatch(
            batch.position_mm[:n_reference], batch.normal_force_n[:n_reference], radius_mm=1.6
        )
        warm, _, _ = timed(lambda s=spec, b=sample: frames_from_contacts(s, b, rng=0))
        for flaws in ("all", "none"):
            cpu, wall, _ = timed(lambda s=spec, b=batch, f=flaws: frames_from_contacts(
                s, b, flaws=f, rng=1), repeats=3)  # fmt: skip
            ref_cpu, _, _ = timed(lambda s=spec, b=sample, f=flaws: todays_path(s, b, f))
            rate, ref_rate = n / cpu, n_reference / ref_cpu
            rows.append(
                {
                    "sensor": name,
                    "taxels": spec.n_taxels,
                    "flaws": flaws,
                    "frames": n,
                    "fast_path": fast_available,
                    "frames_per_s": rate,
                    "wall_frames_per_s": n / wall,
                    "readings_per_s": rate * spec.n_taxels,
                    "reference_frames_per_s": ref_rate,
                    "ratio": rate / ref_rate,
                    "warm_up_s": warm,
                }
            )
    return rows


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--frames", type=int, default=200_000, help="frames per run [-]")
    args = parser.parse_args()
    for row in measure(args.frames):
        print(
            f"{row['sensor']:18s} {row['taxels']:5d} taxels  flaws={row['flaws']:4s} "
            f"{row['frames_per_s']:>12,.0f} frames/s (wall {row['wall_frames_per_s']:,.0f})  "
            f"{row['readings_per_s']:>14,.0f} readings/s  today's path "
            f"{row['reference_frames_per_s']:,.0f} frames/s  ratio {row['ratio']:,.0f}x  "
            f"(first call {row['warm_up_s']:.1f} s)"
        )


if __name__ == "__main__":
    main()
