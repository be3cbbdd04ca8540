"""Contacts on a 16x16 pad from counts: throughput of find_contacts (and the tracker)
against a straightforward implementation measured in the same run.

Frames: pad16's layer response (tactsense.estimate.contacts.pad_force_kernel, the same
tabulated physics) to 1 or 3 probes of 0.3-0.7 N at random positions moving slowly,
turned into resistive counts (100 + 20000 x strain) with 0.3 counts of read noise and
quantized to uint16. The reference: scipy.ndimage.label (8-connected) + centre of
pressure and summed signal per region with np.bincount, frame by frame (what taxel-array
middleware does today, in its fastest straightforward form: np.bincount over the labels
rather than three calls of scipy.ndimage.sum, which the table shows too).

    python benchmarks/bench_contacts.py [N_FRAMES]
"""

from __future__ import annotations

import sys
import time

import numpy as np
from scipy import ndimage

from tactsense.estimate.contacts import find_contacts, pad_force_kernel
from tactsense.estimate.contacts.track import ContactTracker, ReferenceTracker
from tactsense.sensor.registry import load_sensor


def make_frames(spec, n, n_probes, rng):
    kernel, step, half = pad_force_kernel(spec)
    rows, cols = spec.shape
    strain = np.zeros((n, rows, cols))
    # slowly moving probes, kept 4 taxels apart
    centres = np.array(
        [[4.0 + 4 * (k % 2) + 3.5 * (k // 2), 3.0 + 5.0 * k] for k in range(n_probes)]
    )
    t = np.arange(n)
    for k in range(n_probes):
        u = centres[k, 0] + 1.5 * np.sin(2 * np.pi * t / 5000 + k)
        v = centres[k, 1] + 1.5 * np.cos(2 * np.pi * t / 7000 + k)
        force = 0.5 + 0.2 * np.sin(2 * np.pi * t / 3000 + k)
        r0, c0 = np.floor(u).astype(int), np.floor(v).astype(int)
        a = np.round((u - r0) / step).astype(int)
        b = np.round((v - c0) / step).astype(int)
        for i in range(2 * half + 1):
            for j in range(2 * half + 1):
                r, c = r0 + i - half, c0 + j - half
                ok = (r >= 0) & (r < rows) & (c >= 0) & (c < cols)
                np.add.at(strain, (t[ok], r[ok], c[ok]), force[ok] * kernel[a[ok], b[ok], i, j])
    counts = 100 + 20000 * strain + rng.normal(0, 0.3, strain.shape)
    return np.clip(np.round(counts), 0, 65535).astype(np.uint16)


def reference(frames, baseline, per_count, threshold):
    """scipy.ndimage.label + centre of pressure per region (np.bincount), frame by frame."""
    out = []
    structure = np.ones((3, 3))
    rows, cols = np.mgrid[0 : frames.shape[1], 0 : frames.shape[2]]
    rows, cols = rows.ravel(), cols.ravel()
    for frame in frames:
        signal = (frame.astype(float) - baseline) * per_count
        labels, n = ndimage.label(signal > threshold, structure=structure)
        labels, signal = labels.ravel(), signal.ravel()
        total = np.bincount(labels, signal, n + 1)[1:]
        r = np.bincount(labels, signal * rows, n + 1)[1:] / total
        c = np.bincount(labels, signal * cols, n + 1)[1:] / total
        out.append((r, c, total))
    return out


def reference_ndimage_sum(frames, baseline, per_count, threshold):
    """The same with scipy.ndimage.sum per region (slower: shown for comparison)."""
    out = []
    structure = np.ones((3, 3))
    rows, cols = np.mgrid[0 : frames.shape[1], 0 : frames.shape[2]]
    for frame in frames:
        signal = (frame.astype(float) - baseline) * per_count
        labels, n = ndimage.label(signal > threshold, structure=structure)
        index = np.arange(1, n + 1)
        total = ndimage.sum(signal, labels, index)
        r = ndimage.sum(signal * rows, labels, index) / total
        c = ndimage.sum(signal * cols, labels, index) / total
        out.append((r, c, total))
    return out


def best_of(repeats, work):
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        work()
        times.append(time.perf_counter() - start)
    return min(times)


def measure(spec, frames, n_probes, baseline, per_count, threshold):
    """One row of the table, and the other methods' rates, for frames of n_probes."""
    n = len(frames)
    find_contacts(frames[:100], spec, baseline=baseline)  # compile
    k = 1 if n_probes == 1 else 8
    t_find = best_of(7, lambda: find_contacts(frames, spec, baseline=baseline, max_contacts=k))
    table = find_contacts(frames, spec, baseline=baseline, max_contacts=k)

    def tracked():
        found = find_contacts(frames, spec, baseline=baseline, max_contacts=k)
        ContactTracker(spec.scan_period_s).update(found)

    t_track = best_of(7, tracked)
    t_tracker_only = best_of(7, lambda: ContactTracker(spec.scan_period_s).update(table))
    m = min(n, 20_000)
    part = find_contacts(frames[:m], spec, baseline=baseline, max_contacts=k)
    t_ref_tracker = best_of(1, lambda: ReferenceTracker(spec.scan_period_s).update(part)) * n / m
    t_ref = best_of(5, lambda: reference(frames[:m], baseline, per_count, threshold)) * n / m
    t_sum = (
        best_of(3, lambda: reference_ndimage_sum(frames[:m], baseline, per_count, threshold))
        * n
        / m
    )
    # the two references agree (regions, centres and sums)
    for mine, theirs in zip(
        reference(frames[:200], baseline, per_count, threshold),
        reference_ndimage_sum(frames[:200], baseline, per_count, threshold),
        strict=True,
    ):
        for a, b in zip(mine, theirs, strict=True):
            np.testing.assert_allclose(a, b, rtol=1e-12, atol=1e-15)
    found = np.bincount(table.per_frame_counts())
    row = (n_probes, n / t_find, n / t_track, n / t_ref, t_ref / t_find, found,
           n / t_tracker_only, n / t_ref_tracker, n / t_sum)  # fmt: skip
    timed = []
    for method in ("cop", "fit"):
        find_contacts(frames[:10], spec, baseline=baseline, method=method)  # compile
        t = best_of(1, lambda method=method: find_contacts(
            frames[:m], spec, baseline=baseline, max_contacts=k, method=method))  # fmt: skip
        timed.append((n_probes, method, m / t))
    return row, timed


def main(n=100_000):
    spec = load_sensor("pad16")
    rng = np.random.default_rng(0)
    baseline = np.full(spec.shape, 100.0)
    per_count = 1 / spec.transduction.counts_per_strain
    threshold = 10 * per_count
    rows = []
    methods = []
    for n_probes in (1, 3):
        frames = make_frames(spec, n, n_probes, rng)
        row, timed = measure(spec, frames, n_probes, baseline, per_count, threshold)
        rows.append(row)
        methods += timed
    print(
        f"{n:,} frames of 16 x 16 counts, one core (best of 7; references best of 5 and 3 "
        "on 20,000 frames)"
    )
    print(
        "| probes | find_contacts [frames/s] | find_contacts + ContactTracker [frames/s] "
        "| reference: ndimage.label + centre of pressure (bincount) [frames/s] | ratio | "
        "the same with ndimage.sum [frames/s] | "
        "ContactTracker alone [frames/s] | ReferenceTracker (scipy each frame) [frames/s] "
        "| contacts per frame found |"
    )
    print("|---|---|---|---|---|---|---|---|---|")
    for n_probes, fast, track_rate, ref, ratio, found, tracker, ref_tracker, ref_sum in rows:
        print(
            f"| {n_probes} | {fast:,.0f} | {track_rate:,.0f} | {ref:,.0f} | {ratio:.1f}x | "
            f"{ref_sum:,.0f} | {tracker:,.0f} | {ref_tracker:,.0f} | "
            f"{dict(enumerate(found.tolist()))} |"
        )
    print("\nOther position methods (find_contacts only, 20,000 frames):\n")
    print("| probes | method | frames/s |")
    print("|---|---|---|")
    for n_probes, method, rate in methods:
        print(f"| {n_probes} | {method} | {rate:,.0f} |")


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 100_000)
