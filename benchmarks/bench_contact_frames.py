"""Speed of ``frames_from_contacts``: frames from arrays of contacts (issue 38, item 1).

Run: ``python benchmarks/bench_contact_frames.py [--frames N]``. One process, one core
(the kernels are not parallel). For the 16x16 pad (``pad16``), a 32x32 pad (``pad16``'s
pitch, layer and cells on a 32x32 grid), ``pad12x32`` and the paper's finger: N frames,
every frame its own one to three sphere contacts (a third of the contacts missing,
forces 0.05-3 N, Hertz radius from the force on a 1.6-mm sphere), with every per-frame
flaw (noise included) and without flaws:

* the fast path, ``frames_from_contacts(spec, batch)`` (the kind's
  ``contact_forward``; the finger's: its 2-D twin compiled over the batch's contacts);
* today's path in the same run, against which the ratio is given: the same frames as a
  scenario of one step per frame through ``simulate`` (the scan loop, the pad's
  ``layer_strain`` per frame), on a sample of the frames (it is slow).

Two more measurements (r9-fastpath): the one-off table build against reading it back
from the disk cache and against today's path on the same frames (hand4's 18 x 18 palm
pad under a 40-mm sphere, round 7's 21-s case; and pad16), and the rate of contacts
wider than the tables (summed in the layer's spectrum) against today's path.

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


def palm_pad():
    """hand4's 18 x 18 palm pad (2-mm pitch, pad16's layer and cells)."""
    from tactsense.robot.presets import _hand4_pad

    return _hand4_pad(18, 18)


def big_sphere_contacts(spec, n: int, seed: int = 0) -> ContactBatch:
    """N frames of one 40-mm sphere (radius 20 mm) anywhere on the pad, 0.05-2.5 N:
    Hertz radii 1.3-4.8 mm (tables up to 5 mm)."""
    rng = np.random.default_rng(seed)
    g = spec.grid
    extent = np.array([(g.rows - 1) * g.row_pitch_mm, (g.cols - 1) * g.col_pitch_mm])
    position = rng.uniform(0.0, 1.0, (n, 1, 2)) * extent
    return ContactBatch(position, rng.uniform(0.05, 2.5, (n, 1)), radius_mm=20.0)


def measure_builds(n_frames: int = 200) -> list[dict]:
    """Per pad: the first call on a cold cache (the table built), the first call of a
    new process with the table on disk (read back), a later call (in memory), and
    today's path on the same frames [s, CPU and wall]."""
    import os
    import tempfile

    from tactsense.physics._hertz_table import cached_response_table, layer_response_table

    rows = []
    for name, make in (("hand4 palm_0 (18x18, 2 mm)", palm_pad), ("pad16", pad16)):
        spec = make()
        batch = big_sphere_contacts(spec, n_frames)
        saved = os.environ.get("TACTSENSE_CACHE_DIR")
        with tempfile.TemporaryDirectory() as folder:
            os.environ["TACTSENSE_CACHE_DIR"] = folder
            try:
                cached_response_table.cache_clear()
                layer_response_table.cache_clear()  # nor in the process: built
                call = lambda s=spec, b=batch: frames_from_contacts(s, b, flaws="none")  # noqa: E731
                cold = timed(call)
                cached_response_table.cache_clear()  # a new process: the table on disk
                disk = timed(call)
                memory = timed(call, repeats=3)
            finally:
                cached_response_table.cache_clear()
                if saved is None:
                    os.environ.pop("TACTSENSE_CACHE_DIR")
                else:
                    os.environ["TACTSENSE_CACHE_DIR"] = saved
        today = timed(lambda s=spec, b=batch: frames_from_contacts(s, b, flaws="none", fast=False))
        rows.append(
            {
                "sensor": name,
                "frames": n_frames,
                "cold": cold[:2],
                "disk": disk[:2],
                "memory": memory[:2],
                "today": today[:2],
            }
        )
    return rows


def wide_contacts(spec, n: int, seed: int = 0) -> ContactBatch:
    """N frames of one disc of radius 6-18 mm (wider than the tables) anywhere on the
    pad, 0.5-5 N."""
    rng = np.random.default_rng(seed)
    g = spec.grid
    extent = np.array([(g.rows - 1) * g.row_pitch_mm, (g.cols - 1) * g.col_pitch_mm])
    position = rng.uniform(0.0, 1.0, (n, 1, 2)) * extent
    force = rng.uniform(0.5, 5.0, (n, 1))
    return ContactBatch(position, force, radius_mm=rng.uniform(6.0, 18.0, (n, 1)), shape="disc")


def measure_wide(n_frames: int = 200) -> dict:
    """pad16 frames of one contact wider than the tables: the spectral sum against
    today's path on the same frames [frames/s, CPU]."""
    spec = pad16()
    batch = wide_contacts(spec, n_frames)
    fast_cpu, fast_wall, _ = timed(lambda: frames_from_contacts(spec, batch, flaws="all", rng=1), 3)
    ref_cpu, _, _ = timed(lambda: frames_from_contacts(spec, batch, flaws="all", rng=1, fast=False))
    return {
        "frames": n_frames,
        "frames_per_s": n_frames / fast_cpu,
        "wall_frames_per_s": n_frames / fast_wall,
        "reference_frames_per_s": n_frames / ref_cpu,
        "ratio": ref_cpu / fast_cpu,
    }


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
    for row in measure_builds():
        print(
            f"{row['sensor']}: {row['frames']} frames, first call (table built) "
            f"{row['cold'][0]:.2f} s CPU, table read from disk {row['disk'][0]:.3f} s, "
            f"in memory {row['memory'][0]:.3f} s, today's path {row['today'][0]:.2f} s"
        )
    wide = measure_wide()
    print(
        f"pad16, one disc of 6-18 mm per frame: {wide['frames_per_s']:,.0f} frames/s, "
        f"today's path {wide['reference_frames_per_s']:,.0f} frames/s, ratio {wide['ratio']:.1f}x"
    )


if __name__ == "__main__":
    main()
