"""Regenerate the numbers of the view's block in docs/triaxial.md (issue 35 item 5), and
with ``--screenshot`` docs/images/view_triaxial.png.

How far the arrows the view draws on a three-axis pad (``mag4x4``, the twin) point from
the simulated shear: a 5-mm sphere pressed with 0.5 N, then pushed tangentially with
Q/P = 0.2 and 0.4 (friction 1: no slip) in 12 directions (every 30 deg), at the pad's
centre (between four magnets) and right over a magnet (taxel (1, 1)). Two arrows:

* the taxels' arrows summed (what the page draws from the frames alone,
  :class:`tactsense.view.vectors.VectorReading`): the tangential field change of every
  taxel, where a press alone also pushes magnets sideways (radially from the contact);
* the contact's estimated shear (the kind's estimator,
  :class:`tactsense.estimate.triaxial.LiveShearContacts`, as the view runs it): the
  arrow drawn from the contact.

Each without flaws and with the preset's flaws (gains, read noise, quantization; five
seeds), averaged over the last 10 frames of the hold. Run:
``python scripts/triview_numbers.py [--screenshot]``.
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "scripts"))

from docblock import replace_block  # noqa: E402

from tactsense.physics.indenters import SphereProbe  # noqa: E402
from tactsense.sensor import preset  # noqa: E402
from tactsense.simulate import Scenario, Step, simulate  # noqa: E402
from tactsense.stream.reader import StreamFrame  # noqa: E402
from tactsense.view import view_locator  # noqa: E402
from tactsense.view.vectors import decorate_frame  # noqa: E402

DOC = ROOT / "docs" / "triaxial.md"
BEGIN, END = "<!-- triview-numbers -->", "<!-- /triview-numbers -->"
FORCE_N = 0.5
PLACES = {"pad centre (between 4 magnets)": (7.05, 7.05), "over a magnet": (4.7, 4.7)}
RATIOS = (0.2, 0.4)
DIRECTIONS_DEG = np.arange(0, 360, 30)
SEEDS = range(5)
LAST = 10


def _off(a: float, b: float) -> float:
    return abs((a - b + 180.0) % 360.0 - 180.0)


def _run(spec, place, ratio, direction_deg, flaws, rng):
    q = ratio * FORCE_N
    sx, sy = q * math.cos(math.radians(direction_deg)), q * math.sin(math.radians(direction_deg))
    probe = SphereProbe(*place, force_n=FORCE_N, radius_mm=5.0)
    pushed = SphereProbe(*place, force_n=FORCE_N, radius_mm=5.0, shear_x_n=sx, shear_y_n=sy,
                         friction=1.0)  # fmt: skip
    scenario = Scenario((Step((), 0.1), Step((probe,), 0.1), Step((pushed,), 0.2)))
    rec = simulate(spec, scenario, rng=rng, flaws=flaws)
    reading = view_locator(spec, baseline_frames=5)
    taxels, contact = [], []
    for k, counts in enumerate(rec.frames):
        frame = StreamFrame(k, k, float(rec.time_s[k]), 0.0, 0.0, counts)
        estimate = reading(frame)
        if k < len(rec.frames) - LAST:
            continue
        taxels.append(reading.last_tangential.reshape(-1, 2).sum(axis=0))
        message = {"estimate": estimate}
        decorate_frame(message, reading, spec)
        found = (estimate or {}).get("contacts") or []
        if found:
            c = max(found, key=lambda c: c.get("force_n") or 0.0)
            if c.get("shear_u_n") is not None:
                contact.append((c["shear_u_n"], c["shear_v_n"]))
    u, v = np.mean(taxels, axis=0)
    off_taxels = _off(math.degrees(math.atan2(v, u)), direction_deg)
    if not contact:
        return off_taxels, float("nan")
    u, v = np.mean(contact, axis=0)
    return off_taxels, _off(math.degrees(math.atan2(v, u)), direction_deg)


def measure() -> list[tuple]:
    spec = preset("mag4x4")
    rows = []
    for name, place in PLACES.items():
        for ratio in RATIOS:
            for label, flaws, seeds in (("none", (), [0]), ("the preset's", "all", SEEDS)):
                errors = np.array([
                    _run(spec, place, ratio, d, flaws, seed)
                    for d in DIRECTIONS_DEG for seed in seeds
                ])  # fmt: skip
                rows.append((name, ratio, label, errors[:, 0], errors[:, 1]))
    return rows


def _cell(errors: np.ndarray) -> str:
    if np.isnan(errors).any():
        return f"{np.isnan(errors).sum()} of {errors.size} without a contact"
    return f"{np.median(errors):.1f} / {errors.max():.1f}"


def block(rows) -> str:
    lines = [
        BEGIN,
        "| contact | Q/P | flaws | taxels' arrows summed: median / max [deg] | "
        "contact's estimated shear: median / max [deg] |",
        "|---|---|---|---|---|",
    ]
    for name, ratio, label, taxels, contact in rows:
        lines.append(f"| {name} | {ratio:g} | {label} | {_cell(taxels)} | {_cell(contact)} |")
    lines.append(
        f"\n(`scripts/triview_numbers.py`: {len(DIRECTIONS_DEG)} directions every 30 deg, "
        f"{FORCE_N:g} N on a 5-mm sphere; with flaws {len(SEEDS)} seeds each; the mean of "
        f"the last {LAST} frames of the hold.)"
    )
    lines.append(END)
    return "\n".join(lines)


def screenshot(out: Path) -> None:
    """The view of a mag4x4 recording: a 5-mm sphere at 0.5 N pushed with Q/P 0.3 toward
    -x, +y (150 deg), the kind's estimator running."""
    import shutil
    import tempfile
    import time

    from playwright.sync_api import sync_playwright

    from tactsense.io.recording import write_recording
    from tactsense.view import RecordingFeed, ViewServer

    spec = preset("mag4x4")
    q = 0.3 * FORCE_N
    a = math.radians(150.0)
    place = (6.0, 8.0)
    probe = SphereProbe(*place, force_n=FORCE_N, radius_mm=5.0)
    pushed = SphereProbe(*place, force_n=FORCE_N, radius_mm=5.0, shear_x_n=q * math.cos(a),
                         shear_y_n=q * math.sin(a), friction=1.0)  # fmt: skip
    scenario = Scenario((Step((), 0.1), Step((probe,), 0.1), Step((pushed,), 0.3)))
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "shear.h5"
        write_recording(path, simulate(spec, scenario, rng=0))
        feed = RecordingFeed(path, lambda s, f: view_locator(s, baseline_frames=5), speed=1.0)
        server = ViewServer(feed)
        server.start()
        try:
            with sync_playwright() as playwright:
                browser = playwright.chromium.launch(
                    executable_path=shutil.which("chromium") or "/usr/bin/chromium"
                )
                page = browser.new_page(viewport={"width": 1180, "height": 860})
                page.goto(server.url)
                page.wait_for_function(
                    "() => { const s = window.tactsenseView;"
                    " return s.latest && document.getElementById('play').textContent === 'play'"
                    " && s.drawnIndex === s.lastIndex && s.lastIndex > 0; }",
                    timeout=30000,
                )
                time.sleep(1.0)
                out.parent.mkdir(parents=True, exist_ok=True)
                tmp_png = out.with_suffix(".tmp.png")
                page.screenshot(path=str(tmp_png))
                tmp_png.replace(out)
                browser.close()
        finally:
            server.stop()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--screenshot", action="store_true", help="also the page's picture")
    args = parser.parse_args()
    text = block(measure())
    print(text)
    replace_block(DOC, BEGIN, END, text)
    if args.screenshot:
        screenshot(ROOT / "docs" / "images" / "view_triaxial.png")


if __name__ == "__main__":
    main()
