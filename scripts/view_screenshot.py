"""Regenerate docs/images/view.png: the browser view of an emulated finger, as a user sees it.

Run: ``python scripts/view_screenshot.py`` (needs Debian's chromium). The twin plays the
paper's Fig. 13 sweep around the finger at row 4 on a loopback socket with 2 % of its
frames dropped, ``tactsense.view`` shows it, and headless Chromium takes the picture
after 12 s (the probe then sits near 60 deg; the trail shows where it came from).
"""

from __future__ import annotations

import shutil
import time
from pathlib import Path

from playwright.sync_api import sync_playwright

import tactsense as ts
from tactsense.stream import Emulator, FaultRates, LiveLocator, StreamReader
from tactsense.view import LiveFeed, ViewServer

OUT = Path(__file__).resolve().parents[1] / "docs" / "images" / "view.png"


def main() -> None:
    spec = ts.fearing1990_initial()
    rec = ts.simulate(spec, ts.probe_sweep(spec, along="around", dwell_s=0.3), rng=11)
    emulator = Emulator.from_recording(rec, speed=2.0, faults=FaultRates(drop=0.02), rng=1)
    _, port = emulator.start_tcp()
    reader = StreamReader(f"socket://127.0.0.1:{port}", start=False)
    server = ViewServer(LiveFeed(reader, LiveLocator(reader.sensor, keep_deflection=True)))
    server.start()
    try:
        with sync_playwright() as playwright:
            browser = playwright.chromium.launch(
                executable_path=shutil.which("chromium") or "/usr/bin/chromium"
            )
            page = browser.new_page(viewport={"width": 1180, "height": 860})
            page.goto(server.url)
            page.wait_for_function("() => window.tactsenseView.touching === true")
            time.sleep(12.0)
            page.mouse.click(*page.evaluate(
                "() => { const r = document.getElementById('map').getBoundingClientRect();"
                " const [x, y] = window.tactsenseView.cellCentre(4, 2);"
                " return [r.left + x, r.top + y]; }"
            ))  # fmt: skip
            time.sleep(1.0)
            page.screenshot(path=str(OUT))
            browser.close()
    finally:
        server.stop()
        emulator.stop()
    print(f"wrote {OUT}")


if __name__ == "__main__":
    main()
