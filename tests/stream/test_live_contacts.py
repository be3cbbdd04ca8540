"""``tactsense live`` on a pad: every contact of every frame, tracked, as JSON lines or
one CSV row per contact; re-zero by SIGUSR1; the LSL contacts outlet's fixed slots."""

import csv
import io
import json
import signal
import subprocess
import time

import numpy as np

import tactsense as ts
from tactsense import flat_scenarios as fs

from .test_record import CLI, emulator  # noqa: F401  (the fixture)


def _truth_two_probes():
    pad = ts.preset("pad16")
    rec = ts.simulate(pad, fs.two_probes(pad), rng=0)
    return rec


def test_live_pad_two_probes_jsonl_and_csv(emulator, tmp_path):  # noqa: F811
    url = emulator("--sensor", "pad16", "--scenario", "two-probes", "--speed", "1e6")
    done = subprocess.run([*CLI, "live", url], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    rows = [json.loads(line) for line in done.stdout.splitlines()]
    truth = _truth_two_probes()
    assert len(rows) == truth.frames.shape[0] - 5  # every frame after the baseline
    n_true = np.asarray(truth.truth["step_n_contacts"])[truth.truth["frame_step"]][5:]
    n_seen = np.array([r["n_contacts"] for r in rows])
    assert n_seen.max() == 2
    # both probes pressing (0.25-0.65 s, away from the steps): two contacts with the
    # same two ids in every frame, 5 mm apart as two_probes places them
    pressed = [r for r in rows if 0.25 < r["device_time_s"] < 0.65]
    assert pressed and all(r["n_contacts"] == 2 for r in pressed)
    assert {c["id"] for r in pressed for c in r["contacts"]} == {0, 1}
    # (after the lift the skin's creep keeps both visible for a few frames: no bound there)
    assert np.mean(n_seen[n_true == 2] == 2) > 0.95
    # frame by frame as it arrives = the recording located in one go (batch.contacts_file:
    # other pieces, the same baseline rule): the same ids, positions and forces
    import pandas as pd

    from tactsense.batch import contacts_file

    ts.write_recording(tmp_path / "two.h5", truth)
    contacts_file(tmp_path / "two.h5", tmp_path / "two.parquet", drift_s=2.0)
    batch = pd.read_parquet(tmp_path / "two.parquet")
    live = pd.DataFrame([{"frame": r["sequence"], **c} for r in rows for c in r["contacts"]])
    assert len(live) == len(batch)
    np.testing.assert_array_equal(live["frame"], batch["frame"])
    np.testing.assert_array_equal(live["id"], batch["id"])
    for column in ("x_mm", "y_mm", "force_n"):
        np.testing.assert_allclose(live[column], batch[column], rtol=1e-9, atol=1e-12)
    # CSV: one row per contact, a frame without contact one row with n_contacts 0
    url = emulator("--sensor", "pad16", "--scenario", "two-probes", "--speed", "1e6")
    done = subprocess.run([*CLI, "live", url, "--format", "csv"], capture_output=True,
                          text=True, timeout=120)  # fmt: skip
    assert done.returncode == 0, done.stderr
    table = list(csv.DictReader(io.StringIO(done.stdout)))
    per_frame = {}
    for row in table:
        per_frame.setdefault(row["sequence"], []).append(row)
    assert len(per_frame) == len(rows)
    for group in per_frame.values():
        n = int(group[0]["n_contacts"])
        assert len(group) == max(n, 1)
        assert (group[0]["id"] == "") == (n == 0)


def test_live_rezero_on_sigusr1(emulator):  # noqa: F811
    """A press held for 20 s at 100 Hz, played in real time: after SIGUSR1 the next 5
    frames (still pressed) make the baseline, and the press reads as no contact."""
    url = emulator("--sensor", "pad4", "--scenario", "hold", "--dwell-s", "20")
    process = subprocess.Popen([*CLI, "live", url], stdout=subprocess.PIPE,
                               stderr=subprocess.PIPE, text=True)  # fmt: skip
    try:
        seen = []
        deadline = time.monotonic() + 60
        while time.monotonic() < deadline:
            row = json.loads(process.stdout.readline())
            seen.append(row)
            if row["n_contacts"] >= 1 and row["device_time_s"] > 1.0:
                break
        assert seen[-1]["n_contacts"] >= 1
        process.send_signal(signal.SIGUSR1)
        after = []
        while time.monotonic() < deadline and len(after) < 60:
            after.append(json.loads(process.stdout.readline()))
        assert any(r["rezeroing"] for r in after)
        settled = [r for r in after if not r["rezeroing"]][10:]
        assert settled and all(r["n_contacts"] == 0 for r in settled)
    finally:
        process.send_signal(signal.SIGINT)
        _, err = process.communicate(timeout=20)
    assert "re-zeroing" in err and "Traceback" not in err


def test_lsl_slots_of_a_pad_estimate():
    from tactsense.interop.lsl import SLOT_CHANNELS, SLOTS, slot_sample

    first = {"id": 4, "x_mm": 1.0, "y_mm": 2.0, "z_mm": 0.0, "force_n": 0.2}
    second = {"id": 7, "x_mm": 5.0, "y_mm": 6.0, "z_mm": 0.0, "force_n": 0.1}
    estimate = {"n_contacts": 2, "force_n": 0.3, "flags": 0, "latency_ms": 0.1,
                "contacts": [first, second]}  # fmt: skip
    sample = slot_sample(estimate)
    assert len(sample) == len(SLOT_CHANNELS) == 4 + 5 * SLOTS
    named = dict(zip(SLOT_CHANNELS, sample, strict=True))
    assert named["c0_id"] == 4 and named["c1_id"] == 7 and named["c1_y_mm"] == 6.0
    assert np.isnan(named["c2_id"]) and np.isnan(named[f"c{SLOTS - 1}_force_n"])
