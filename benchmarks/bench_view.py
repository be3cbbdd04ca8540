"""The browser view under load: a stream at 10x the paper's frame rate, three pages, 60 s.

Run: ``python benchmarks/bench_view.py [--seconds 60] [--pages 3] [--speed 10]``.

Three processes, as a user runs them: ``tactsense emulate --port 0 --loop --speed 10``
(70 frames/s: the paper's finger scanned at 7 Hz), ``tactsense view socket://...`` and
one headless Chromium (Debian's) with three pages on the view. Every 5 s the server's
``/api/health`` gives its resident memory, the frames it received and published and
what each page missed; at the end each page says how many frames it received and the
emulator how many it sent. Memory is judged from 10 s on (after start-up and after
the history buffer of 20 s has filled) to the end: a bounded server does not grow.
"""

from __future__ import annotations

import argparse
import json
import shutil
import signal
import subprocess
import sys
import time
import urllib.request

CLI = [sys.executable, "-m", "tactsense.cli"]


def _health(url: str) -> dict:
    with urllib.request.urlopen(url + "api/health", timeout=5) as response:
        return json.loads(response.read())


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=60.0, help="length of the run [s]")
    parser.add_argument("--pages", type=int, default=3, help="pages open on the view")
    parser.add_argument("--speed", type=float, default=10.0, help="multiple of 7 frames/s")
    args = parser.parse_args()
    chromium = shutil.which("chromium") or "/usr/bin/chromium"

    from playwright.sync_api import sync_playwright

    emulate = subprocess.Popen(
        [*CLI, "emulate", "--port", "0", "--loop", "--speed", str(args.speed)],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    device = emulate.stdout.readline().strip()
    view = subprocess.Popen(
        [*CLI, "view", device], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True
    )
    url = view.stdout.readline().strip()
    samples = []
    try:
        with sync_playwright() as playwright:
            browser = playwright.chromium.launch(executable_path=chromium)
            pages = [browser.new_page() for _ in range(args.pages)]
            for page in pages:
                page.goto(url)
            start = time.perf_counter()
            next_sample = 0.0
            while (elapsed := time.perf_counter() - start) < args.seconds:
                if elapsed >= next_sample:
                    health = _health(url)
                    samples.append((elapsed, health))
                    print(
                        f"{elapsed:5.1f} s: rss {health['rss_mb']:6.1f} MB, frames in "
                        f"{health['feed']['frames_in']}, published {health['published']}, "
                        f"pages dropped {[p['dropped'] for p in health['pages']]}",
                        flush=True,
                    )
                    next_sample += 5.0
                time.sleep(0.2)
            health = _health(url)
            samples.append((time.perf_counter() - start, health))
            seen = [
                page.evaluate(
                    "() => { const s = window.tactsenseView;"
                    " return [s.framesReceived, s.lastSerial - s.firstSerial + 1]; }"
                )
                for page in pages
            ]
            browser.close()
    finally:
        for process in (view, emulate):
            process.send_signal(signal.SIGINT)
        view_err = view.communicate(timeout=20)[1]
        emulate_err = emulate.communicate(timeout=20)[1]

    stream = health["feed"]["stream"]
    steady = [(t, h["rss_mb"]) for t, h in samples if t >= 10.0]
    rss_start, rss_end = steady[0][1], steady[-1][1]
    rss_max = max(r for _, r in steady)
    (t0, first), (t1, last) = samples[0], samples[-1]
    rate = (last["feed"]["frames_in"] - first["feed"]["frames_in"]) / (t1 - t0)
    published = last["published"] - first["published"]
    print()
    print(
        f"run: {samples[-1][0]:.0f} s, {args.pages} pages, emulator at {7 * args.speed:g} frames/s"
    )
    print(f"server received {stream['frames']} frames ({rate:.1f} frames/s), lost {stream['lost']}")
    print(f"server published {published} frame messages while the pages were open")
    dropped = [p["dropped"] for p in health["pages"]]
    for k, (received, sent) in enumerate(seen):
        print(f"page {k + 1}: received {received} of the {sent} frames sent since it connected")
    print(f"the server dropped for the pages {dropped}")
    print(f"server memory from 10 s on: {rss_start:.1f} -> {rss_end:.1f} MB (max {rss_max:.1f})")
    print("emulator:", " ".join(emulate_err.split()[-14:]))
    print("view:", " ".join(view_err.split()[-5:]))


if __name__ == "__main__":
    main()
