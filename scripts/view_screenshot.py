"""Regenerate docs/images/view.png: the browser view of an emulated finger, as a user sees it.

Run: ``python scripts/view_screenshot.py`` (needs Debian's chromium). The twin plays the
paper's Fig. 13 sweep around the finger at row 4 on a loopback socket with 2 % of its
frames dropped, ``tactsense.view`` shows it, and headless Chromium takes the picture
after 12 s (the probe then sits near 60 deg; the trail shows where it came from).

``python scripts/view_screenshot.py --contacts`` writes docs/images/view_contacts.png: the
twin of ``pad16`` under two 50-g spheres, one still and one sliding along y, played back
with every contact tracked (ids, rings, trails, the contacts' table).

``python scripts/view_screenshot.py --sensor pad16`` writes docs/images/view_pad.png
instead (``--sensor dome12``: view_points.png): a recording of that pad or point set
pressed by a 5-mm sphere (1 N, ramped over 0.5 s, then held), its strains from the
three-dimensional layer model (``tactsense.physics.pad_response``), played back.
"""

from __future__ import annotations

import argparse
import contextlib
import shutil
import tempfile
import time
from pathlib import Path

import numpy as np
from playwright.sync_api import sync_playwright

import tactsense as ts
from tactsense.stream import Emulator, FaultRates, LiveLocator, StreamReader
from tactsense.view import LiveFeed, RecordingFeed, ViewServer, view_locator

IMAGES = Path(__file__).resolve().parents[1] / "docs" / "images"
OUT = IMAGES / "view.png"


@contextlib.contextmanager
def browser_page(server):
    """Start ``server``, open its page in Chromium (1180 x 860), yield the page; stop the
    server whatever happens."""
    server.start()
    try:
        with sync_playwright() as playwright:
            browser = playwright.chromium.launch(
                executable_path=shutil.which("chromium") or "/usr/bin/chromium"
            )
            page = browser.new_page(viewport={"width": 1180, "height": 860})
            page.goto(server.url)
            yield page
            browser.close()
    finally:
        server.stop()


def shoot(page, out: Path) -> None:
    """Let the page settle for a second, then save it to ``out``."""
    time.sleep(1.0)
    page.screenshot(path=str(out))


def main() -> None:
    spec = ts.fearing1990_initial()
    rec = ts.simulate(spec, ts.probe_sweep(spec, along="around", dwell_s=0.3), rng=11)
    emulator = Emulator.from_recording(rec, speed=2.0, faults=FaultRates(drop=0.02), rng=1)
    _, port = emulator.start_tcp()
    reader = StreamReader(f"socket://127.0.0.1:{port}", start=False)
    server = ViewServer(LiveFeed(reader, LiveLocator(reader.sensor, keep_deflection=True)))
    try:
        with browser_page(server) as page:
            page.wait_for_function("() => window.tactsenseView.touching === true")
            time.sleep(12.0)
            page.mouse.click(*page.evaluate(
                "() => { const r = document.getElementById('map').getBoundingClientRect();"
                " const [x, y] = window.tactsenseView.cellCentre(4, 2);"
                " return [r.left + x, r.top + y]; }"
            ))  # fmt: skip
            shoot(page, OUT)
    finally:
        emulator.stop()
    print(f"wrote {OUT}")


def flat_recording(name: str, path: Path) -> Path:
    """A pad or point set pressed by a sphere (through the layer model), untouched first."""
    from tactsense.io.recording import Recording, write_recording
    from tactsense.physics.indenters import SphereProbe
    from tactsense.physics.pad_response import deflection_batch_flat, resistive_counts

    spec = ts.preset(name)
    positions = spec.taxel_positions_mm()
    # off the middle: near the point 20 % (x) and 15 % (y) of the span from the middle,
    # 0.4 and 0.3 mm off the nearest taxel (between taxels, not on one)
    x = positions[:, 0].mean() + 0.2 * np.ptp(positions[:, 0])
    y = positions[:, 1].mean() + 0.15 * np.ptp(positions[:, 1])
    target = positions[np.argmin(np.hypot(positions[:, 0] - x, positions[:, 1] - y))]
    rate = spec.electronics.scan_rate_hz
    n_still, n_ramp, n_hold = int(0.2 * rate), int(0.5 * rate), int(2.0 * rate)
    forces = np.concatenate([np.zeros(n_still), np.linspace(0.0, 1.0, n_ramp), np.ones(n_hold)])
    applied = [
        (SphereProbe(x_mm=float(target[0]) + 0.4, y_mm=float(target[1]) + 0.3,
                     force_n=float(f), radius_mm=5.0),) if f > 0 else ()
        for f in forces
    ]  # fmt: skip
    deflection = deflection_batch_flat(spec, applied)
    v0 = spec.electronics.nominal_counts
    if spec.transduction.kind == "resistive":
        counts = resistive_counts(spec, deflection)
    else:
        counts = v0 / (1.0 - deflection)  # eq. 4 solved for the reading
    counts = counts + np.random.default_rng(3).normal(
        0.0, spec.flaws.read_noise_counts, counts.shape
    )
    rec = Recording(
        frames=np.clip(np.round(counts), 0, 2**spec.electronics.adc_bits - 1).astype(np.uint16),
        time_s=np.arange(len(forces)) / rate,
        sample_offset_s=np.zeros(spec.shape),
        sensor=spec,
        scenario={"description": "5-mm sphere, 1 N, ramped over 0.5 s and held"},
    )
    write_recording(path, rec)
    return path


def flat_main(name: str) -> None:
    out = IMAGES / ("view_pad.png" if ts.preset(name).kind == "pad" else "view_points.png")
    with tempfile.TemporaryDirectory() as folder:
        path = flat_recording(name, Path(folder) / f"{name}.h5")
        feed = RecordingFeed(path, lambda spec, file: view_locator(spec), speed=1.0)
        with browser_page(ViewServer(feed)) as page:
            page.wait_for_function(
                f"() => window.tactsenseView.drawnIndex >= {feed.n_frames - 1}", timeout=30000
            )
            # follow the most deflected taxel in the trace (click it, as a person would)
            page.mouse.click(*page.evaluate(
                "() => { const s = window.tactsenseView, d = s.latest.deflection;"
                " let best = [0, 0];"
                " d.forEach((row, r) => row.forEach((v, c) => {"
                "   if (v > d[best[0]][best[1]]) best = [r, c]; }));"
                " const rect = document.getElementById('map').getBoundingClientRect();"
                " const [x, y] = s.cellCentre(best[0], best[1]);"
                " return [rect.left + x, rect.top + y]; }"
            ))  # fmt: skip
            shoot(page, out)
    print(f"wrote {out}")


def contacts_main() -> None:
    """Two contacts on pad16, one sliding: their ids, rings and trails."""
    from tactsense.physics.indenters import SphereProbe
    from tactsense.simulate import Scenario, Step

    spec = ts.preset("pad16")
    out = IMAGES / "view_contacts.png"
    still = SphereProbe(12.0, 10.0, 0.49)
    steps = [Step((), 0.3, "untouched")]
    for k in range(60):  # 0.02 s a step: 10 mm along y in 1.2 s
        steps.append(Step((still, SphereProbe(26.0, 12.0 + k / 6.0, 0.49)), 0.02, ""))
    rec = ts.simulate(spec, Scenario(tuple(steps)), rng=5)
    with tempfile.TemporaryDirectory() as folder:
        path = ts.write_recording(Path(folder) / "contacts.h5", rec)
        feed = RecordingFeed(path, lambda s, file: view_locator(s), speed=0.5)
        with browser_page(ViewServer(feed)) as page:
            page.wait_for_function(
                f"() => window.tactsenseView.drawnIndex >= {feed.n_frames - 1}", timeout=60000
            )
            shoot(page, out)
    print(f"wrote {out}")


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--sensor",
        default=None,
        help="a pad or point-set preset (pad16, dome12, ...): its picture instead of the finger's",
    )
    parser.add_argument(
        "--contacts", action="store_true", help="two tracked contacts on pad16 instead"
    )
    args = parser.parse_args()
    if args.contacts:
        contacts_main()
    elif args.sensor is None:
        main()
    else:
        flat_main(args.sensor)
