"""Throughput of MuJoCo in, taxel frames out (``tactsense.interop.mujoco``).

Run: ``python benchmarks/bench_mujoco.py [SECONDS] [--doc]`` (default 10: the example's
whole motion, 10,000 MuJoCo steps of 1 ms and 1,000 pad16 frames at 100 Hz); ``--doc``
also writes the table into docs/performance.md (its MuJoCo block). On the example
model (a finger with a 16 x 16 pad pressing on and sliding across a ball and a rod),
one core, in the same run:

* ``mj_step`` alone with the controls applied (MuJoCo's own cost);
* the same and the sensor's contacts read at every frame (``MujocoSensor.read``);
* the same and the frames made (``frame_blocks``), with ``frames_from_contacts``'s fast
  forward (``fast=True``) and with its reference (``fast=False``, the kind's
  frame-by-frame path: the straightforward way), each after an untimed first pass (the
  fast path's one-off start is printed apart);
* the contacts read at every MuJoCo step (1 kHz: what a learning environment reading
  touch at every control step pays);

printing steps/s, frames/s, taxel readings/s and the real-time factor (simulated
seconds per wall-clock second), and the ratio of the two frame paths.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import mujoco
import numpy as np

from tactsense.interop import mujoco as adapter
from tactsense.sensor import load_sensor


def _setup():
    spec = load_sensor("pad16")
    model = adapter.load_model(adapter.example_model_path())
    controls = adapter.read_controls(adapter.example_controls_path(), model)
    return spec, model, controls, adapter.MujocoSensor(model, spec, geom="pad")


def _steps_only(model, controls, seconds: float, read=None) -> tuple[float, int]:
    data = mujoco.MjData(model)
    n = round(seconds / model.opt.timestep)
    start = time.perf_counter()
    for _ in range(n):
        data.ctrl[:] = controls.at(data.time)
        mujoco.mj_step(model, data)
        if read is not None:
            read(data)
    return time.perf_counter() - start, n


def _reads_per_frame(spec, model, controls, sensor, seconds: float) -> tuple[float, int]:
    data = mujoco.MjData(model)
    n = adapter.frame_count(spec, seconds)
    period, dt = spec.scan_period_s, model.opt.timestep
    start = time.perf_counter()
    for j in range(n):
        while data.time + 0.5 * dt < (j + 0.5) * period:
            data.ctrl[:] = controls.at(data.time)
            mujoco.mj_step(model, data)
        sensor.read(data)
    return time.perf_counter() - start, n


def _frames(spec, model, controls, sensor, seconds: float, fast: bool):
    data = mujoco.MjData(model)
    n = adapter.frame_count(spec, seconds)
    start = time.perf_counter()
    blocks = list(
        adapter.frame_blocks(
            sensor, data, n_frames=n, controls=controls, flaws="all", rng=0, fast=fast
        )
    )
    elapsed = time.perf_counter() - start
    return elapsed, n, np.concatenate([b[2] for b in blocks])


def main(seconds: float = 10.0) -> None:
    spec, model, controls, sensor = _setup()
    # a first pass of each path, untimed: the fast path's tables (one per process for
    # the largest contacts) and compilation, which the timed passes then reuse
    t_first, _, _ = _frames(spec, model, controls, sensor, seconds, True)
    _frames(spec, model, controls, sensor, seconds, False)
    taxels = spec.shape[0] * spec.shape[1]
    t_step, steps = _steps_only(model, controls, seconds)
    t_read, frames = _reads_per_frame(spec, model, controls, sensor, seconds)
    t_fast, n_fast, fast = _frames(spec, model, controls, sensor, seconds, True)
    t_ref, n_ref, reference = _frames(spec, model, controls, sensor, seconds, False)
    t_every, _ = _steps_only(model, controls, seconds, read=sensor.read)
    same = float(np.max(np.abs(fast - reference)))
    rows = [
        ("`mj_step` alone, controls applied", steps / t_step, "steps/s", seconds / t_step),
        ("+ contacts read at every frame (100 Hz)", steps / t_read, "steps/s", seconds / t_read),
        ("+ contacts read at every step (1 kHz)", steps / t_every, "steps/s", seconds / t_every),
        ("+ frames, `frames_from_contacts` fast", n_fast / t_fast, "frames/s", seconds / t_fast),
        ("+ frames, its reference (`fast=False`)", n_ref / t_ref, "frames/s", seconds / t_ref),
    ]
    lines = [
        f"Example model, {seconds:g} s simulated: {steps} MuJoCo steps of "
        f"{model.opt.timestep * 1e3:g} ms, {frames} pad16 frames (16 x 16) at 100 Hz, every "
        "per-frame flaw on; one core.",
        "",
        "| what | throughput | taxel readings/s | real-time factor |",
        "|---|---|---|---|",
    ]
    for label, rate, unit, factor in rows:
        readings = f"{rate * taxels:.3g}" if unit == "frames/s" else ""
        lines.append(f"| {label} | {rate:,.0f} {unit} | {readings} | {factor:.1f}x |")
    lines += [
        "",
        f"Fast against reference in the same run: {t_ref / t_fast:.2f}x (largest difference "
        f"between their frames: {same:g} counts; the read noise is drawn in another order). "
        f"The fast path's first pass, with its one-off start (tables, compilation): "
        f"{t_first:.1f} s; the table above times a second pass.",
    ]
    text = "\n".join(lines)
    print(text)
    if "--doc" in sys.argv:
        sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "scripts"))
        from docblock import replace_block

        begin, end = "<!-- begin bench_mujoco -->", "<!-- end bench_mujoco -->"
        doc = Path(__file__).resolve().parents[1] / "docs" / "performance.md"
        replace_block(doc, begin, end, f"{begin}\n{text}\n{end}")


if __name__ == "__main__":
    numbers = [a for a in sys.argv[1:] if not a.startswith("--")]
    main(float(numbers[0]) if numbers else 10.0)
