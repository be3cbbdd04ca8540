"""Throughput of MuJoCo in, taxel frames out (``tactsense.interop.mujoco``).

Run: ``python benchmarks/bench_mujoco.py [SECONDS]`` (default 10: the example's whole
motion, 10,000 MuJoCo steps of 1 ms and 1,000 pad16 frames at 100 Hz). On the example
model (a finger with a 16 x 16 pad pressing on and sliding across a ball and a rod),
one core, in the same run:

* ``mj_step`` alone with the controls applied (MuJoCo's own cost);
* the same and the sensor's contacts read at every frame (``MujocoSensor.read``);
* the same and the frames made (``frame_blocks``), with ``frames_from_contacts``'s fast
  forward (``fast=True``) and with its reference (``fast=False``, the kind's
  frame-by-frame path: the straightforward way);
* the contacts read at every MuJoCo step (1 kHz: what a learning environment reading
  touch at every control step pays);

printing steps/s, frames/s, taxel readings/s and the real-time factor (simulated
seconds per wall-clock second), and the ratio of the two frame paths.
"""

from __future__ import annotations

import sys
import time

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
    taxels = spec.shape[0] * spec.shape[1]
    t_step, steps = _steps_only(model, controls, seconds)
    t_read, frames = _reads_per_frame(spec, model, controls, sensor, seconds)
    t_fast, n_fast, fast = _frames(spec, model, controls, sensor, seconds, True)
    t_ref, n_ref, reference = _frames(spec, model, controls, sensor, seconds, False)
    t_every, _ = _steps_only(model, controls, seconds, read=sensor.read)
    same = float(np.max(np.abs(fast - reference)))
    print(f"example model, {seconds:g} s simulated: {steps} MuJoCo steps, {frames} pad16 frames")
    print(f"mj_step alone:                {steps / t_step:10.0f} steps/s  "
          f"real-time x{seconds / t_step:.1f}")  # fmt: skip
    print(f"+ contacts read per frame:    {steps / t_read:10.0f} steps/s  "
          f"real-time x{seconds / t_read:.1f}")  # fmt: skip
    print(f"+ contacts read every step:   {steps / t_every:10.0f} steps/s  "
          f"real-time x{seconds / t_every:.1f}")  # fmt: skip
    for label, t, n in (("fast", t_fast, n_fast), ("reference", t_ref, n_ref)):
        print(f"+ frames ({label:9s}):       {n / t:10.0f} frames/s "
              f"{n * taxels / t:12.3g} readings/s  real-time x{seconds / t:.1f}")  # fmt: skip
    print(
        f"fast / reference: {t_ref / t_fast:.2f}x; largest difference {same:g} counts "
        "(the noise is drawn in another order when the paths differ)"
    )


if __name__ == "__main__":
    main(float(sys.argv[1]) if len(sys.argv) > 1 else 10.0)
