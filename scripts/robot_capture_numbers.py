"""The figures of docs/robot.md, "Capture from several devices": clock alignment over a
simulated hour, and a real run of emulated devices (hand4's five boards on 127.0.0.1).

    PYTHONPATH=src python scripts/robot_capture_numbers.py [--seconds 30]
"""

from __future__ import annotations

import argparse
import shutil
import tempfile
import time
from pathlib import Path

import numpy as np
from docblock import replace_block

from tactsense.io.robot_recording import aligned_times, read_manifest, read_robot_recording
from tactsense.robot import load_skin
from tactsense.stream.clock import ClockFit
from tactsense.stream.robot import RobotSources
from tactsense.stream.robot_emulator import device_emulators, start_device_emulators
from tactsense.stream.robot_recorder import record_robot

DOC = Path(__file__).resolve().parent.parent / "docs" / "robot.md"
BEGIN, END = "<!-- r7-capture numbers -->", "<!-- /r7-capture numbers -->"
RATE_HZ = 250.0


def delays(kind: str, n: int, rng) -> np.ndarray:
    """Transport delays [s] (the same models as tests/stream/test_robot_clock.py)."""
    if kind == "usb":
        delay = 0.25e-3 + rng.uniform(0, 1e-3, n) + rng.lognormal(np.log(50e-6), 1.0, n)
        stalls = rng.random(n) < 0.002
        delay[stalls] += rng.uniform(5e-3, 50e-3, stalls.sum())
    elif kind == "network":
        delay = 0.1e-3 + rng.exponential(0.4e-3, n)
        burst = np.repeat(rng.random(n // 250) < 0.01, 250)[:n]
        delay[: len(burst)][burst] += rng.exponential(20e-3, burst.sum())
    else:
        delay = 0.2e-3 + rng.gamma(2.0, 2e-3, n)
    return delay


MODELS = {
    "usb": "USB CDC: 0.25 ms + 1 ms poll + log-normal scheduling, 0.2 % stalls of 5-50 ms",
    "network": "Ethernet: 0.1 ms + exponential (0.4 ms), 1 % of seconds with 20 ms bursts",
    "loaded": "a loaded host: 0.2 ms + gamma (shape 2, 2 ms): every frame late",
}


def simulated_hour(seed: int = 0) -> list[str]:
    rows = []
    for i, (kind, text) in enumerate(MODELS.items()):
        rng = np.random.default_rng(seed + i)
        n = int(3600 * RATE_HZ)
        device = 1234.5 + np.arange(n) / RATE_HZ
        truth = 1.79e9 + (device - device[0]) / (1 + 50e-6)
        arrival = truth + delays(kind, n, rng)
        fit = ClockFit()
        start = time.perf_counter()
        fit.add_many(device, arrival)
        per_pair_us = (time.perf_counter() - start) / n * 1e6
        error = fit.to_host(device) - truth
        squares = np.polyfit(device - device[0], arrival - truth[0], 1)
        ls_error = truth[0] + np.polyval(squares, device - device[0]) - truth
        rows.append(
            f"| {text} | {np.median(arrival - truth) * 1e3:.2f} | "
            f"{np.max(np.abs(error)) * 1e3:.3f} | {np.ptp(error) * 1e3:.3f} | "
            f"{abs(fit.drift_ppm - 50.0):.3f} | {np.max(np.abs(ls_error)) * 1e3:.2f} | "
            f"{len(fit._hull)} | {per_pair_us:.1f} |"
        )
    return rows


def real_run(seconds: float, seed: int = 1) -> list[str]:
    skin = load_skin("hand4")
    emulators = device_emulators(skin, drift_ppm=50.0, seed=seed)
    running = start_device_emulators(emulators)
    folder = Path(tempfile.mkdtemp())
    try:
        sources = RobotSources(skin, {d: r.url for d, r in running.items()})
        start = time.process_time()
        out = record_robot(sources, folder / "run", duration_s=seconds)
        cpu = time.process_time() - start
    finally:
        for device in running.values():
            device.stop()
    manifest = read_manifest(out)
    recording = read_robot_recording(out)
    rows = []
    for device, entry in manifest["devices"].items():
        errors = []
        for name in entry["patches"]:
            truth = emulators[device].scheduled_host_time(recording.streams[name].device_time_us)
            errors.append(aligned_times(out, name) - truth - sources.wall_offset_s)
        error = np.concatenate(errors)
        clock, losses = entry["clock"], entry["losses"]
        rows.append(
            f"| {device} ({len(entry['patches'])} patches, "
            f"{sum(skin.patch(p).n_taxels for p in entry['patches'])} taxels) | "
            f"{entry['rate_hz']:g} | {losses['frames']} | {losses['lost']} | "
            f"{clock['drift_ppm']:+.1f} | {clock['residual_s'] * 1e3:.2f} | "
            f"{clock['residual_p99_s'] * 1e3:.2f} | {np.max(np.abs(error)) * 1e3:.3f} |"
        )
    shutil.rmtree(folder)
    rows.append(
        f"\nCPU of the process (the recorder and the {len(emulators)} emulators): "
        f"{cpu / seconds * 100:.0f} % of one core."
    )
    return rows


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--seconds", type=float, default=30.0)
    args = parser.parse_args()
    hand4_taxels = load_skin("hand4").n_taxels
    hour = simulated_hour()
    run = real_run(args.seconds)
    text = "\n".join(
        [
            BEGIN,
            "",
            "An hour of device time at 250 Hz, the device clock 50 ppm fast, simulated "
            "(`scripts/robot_capture_numbers.py`; error = aligned time minus the true scan "
            "time, in ms):",
            "",
            "| delays | median delay | max error | error spread | drift error [ppm] | "
            "least squares' max error | hull vertices | us a pair |",
            "|---|---|---|---|---|---|---|---|",
            *hour,
            "",
            f"A real run: `hand4`'s boards ({hand4_taxels} taxels) emulated on 127.0.0.1 for "
            f"{args.seconds:g} s, "
            "every clock 50 ppm fast, recorded with `record_robot` on this 2-core machine "
            "(error against each emulator's own send schedule, in ms; delays = arrival "
            "minus aligned time):",
            "",
            "| device | rate [Hz] | frames | lost | fitted drift [ppm] | delay median | "
            "delay p99 | max error |",
            "|---|---|---|---|---|---|---|---|",
            *run,
            "",
            END,
        ]
    )
    replace_block(DOC, BEGIN, END, text)
    print(text)


if __name__ == "__main__":
    main()
