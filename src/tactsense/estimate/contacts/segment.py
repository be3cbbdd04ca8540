"""Which taxels make a contact: the compiled segmentation of a grid's frames, the dip
that keeps two maxima apart, and a contact's extent."""

from __future__ import annotations

import math

import numpy as np

from tactsense._signals import deferred_interrupts
from tactsense.estimate._kind import kind_or_none
from tactsense.estimate.reading import signal_noise_variance

# ---- finding the contacts of a batch of frames ---------------------------------------

SADDLE_RATIO = 0.8
"""Two maxima of a frame are two contacts only if the signal between them dips below
this share of the lower one (and by more than the contact threshold) [-]; otherwise the
lower is a bump on the same contact and the two regions are merged."""

NOISE_DIP = 3.0
"""... and only if that dip exceeds this many standard deviations of the difference of
two taxels' read noise (``NOISE_DIP * sqrt(2) * sigma``, sigma from the sensor's
``read_noise_counts``; :func:`signal_noise_variance`) [-]: a noisy plateau's bumps are
not contacts."""

RING_RATIO = 0.1
"""Maxima joined by ridges (saddles of at least this share of the lower one) into a
group of three or more are one contact [-]: a flat stamp on a layer reads its rim
(its corners highest), a punch its ring, each split into bumps by the taxels' gains;
two probes make two maxima, and stay two. 0 switches the rule off."""

WEAK_SHARE = 0.4
"""Taxels above this share of the threshold (but below it) that touch two regions join
them for :data:`RING_RATIO`'s ridges (a rim broken by a low-gain taxel) [-]; they stay
out of every contact's taxels."""

PAIR_RIDGE = 0.15
"""Two maxima farther apart than two point loads' tails reach (:func:`point_reach`) that
are joined by a ridge of at least this share of their summed heights are one contact
[-] (a cylinder lying across a pad reads its two ends highest; the tails of two loads
that far apart read less than 0.1 of each one's peak between them, 0.15 with a taxel's
gain half as high again)."""

METHODS = ("interpolate", "cop", "fit", "joint")
"""``interpolate``: the paper's method on the grid (Hann-windowed sinc over 3 taxels on
each side of the maximum, Newton to 0.01 taxel); ``cop``: the centre of pressure (the
signal-weighted mean position of the contact's taxels); ``fit`` (pads): the maximum-
likelihood position and force under white noise, fitting the layer's tabulated response
(:func:`pad_force_kernel`) to the taxels around the contact."""

BLOCK = 4096
"""Frames per block of the compiled passes."""


def dip_floor(sensor, threshold: float) -> float:
    """Smallest dip from the lower maximum to the saddle that keeps two maxima apart
    [-]: the threshold, or :data:`NOISE_DIP` standard deviations of two taxels' read
    noise difference when that is more (the kinds whose contacts are many: pads and
    point sets; the finger keeps the paper's threshold)."""
    kind = kind_or_none(sensor)
    if kind is None or not kind.multi_contact:
        return float(threshold)
    noise = NOISE_DIP * math.sqrt(2.0 * signal_noise_variance(sensor))
    return max(float(threshold), noise)


def _segment(
    signal, threshold, saddle, periodic, max_contacts, refine, floor=None, ring=0.0,
    far=math.inf, cover=1 << 30,
):  # fmt: skip
    """The compiled segmentation of (N, rows, cols) signal, block by block."""
    from tactsense.estimate.contacts._fast import segment_into
    from tactsense.estimate.finger.localize import MAX_ITERATIONS, TOLERANCE

    n, rows, cols = signal.shape
    k = max_contacts
    count = np.zeros(n, np.int64)
    peak_row = np.empty((n, k), np.int64)
    peak_col = np.empty((n, k), np.int64)
    out = {name: np.empty((n, k)) for name in ("row", "col", "value", "total", "rr", "cc", "rc")}
    taxels = np.empty((n, k), np.int64)
    converged = np.empty((n, k), np.bool_)
    root = np.empty((n, k), np.int64)
    wide = np.zeros((n, k), np.bool_)
    labels = np.empty((n, rows, cols), np.int64)
    with deferred_interrupts():
        for lo in range(0, n, BLOCK):
            hi = min(lo + BLOCK, n)
            segment_into(
                signal[lo:hi], float(threshold), float(saddle), bool(periodic), k, bool(refine),
                TOLERANCE, MAX_ITERATIONS, count[lo:hi], peak_row[lo:hi], peak_col[lo:hi],
                out["row"][lo:hi], out["col"][lo:hi], out["value"][lo:hi], out["total"][lo:hi],
                out["rr"][lo:hi], out["cc"][lo:hi], out["rc"][lo:hi], taxels[lo:hi],
                converged[lo:hi], root[lo:hi], labels[lo:hi],
                float(threshold if floor is None else floor), float(ring),
                float(WEAK_SHARE * threshold if ring > 0 else threshold), wide[lo:hi],
                float(far), PAIR_RIDGE, int(cover),
            )  # fmt: skip
    keep = np.arange(k)[np.newaxis, :] < count[:, np.newaxis]
    frame = np.broadcast_to(np.arange(n)[:, np.newaxis], (n, k))[keep]
    rank = np.broadcast_to(np.arange(k)[np.newaxis, :], (n, k))[keep]
    rows_out = {name: value[keep] for name, value in out.items()}
    rows_out.update(
        frame=frame.astype(np.int64),
        contact=rank.astype(np.int64),
        taxels=taxels[keep],
        converged=converged[keep],
        root=root[keep],
        peak_row=peak_row[keep],
        peak_col=peak_col[keep],
        wide=wide[keep],
    )
    return rows_out, labels


def _extent(rr, cc, rc, scale_r: float, scale_c: float):
    """Principal extents [mm] and the major axis' angle from the row axis [deg] of second
    moments given in taxels^2 (scaled by the pitches)."""
    a = rr * scale_r**2
    b = cc * scale_c**2
    c = rc * scale_r * scale_c
    mean = 0.5 * (a + b)
    half = np.sqrt((0.5 * (a - b)) ** 2 + c**2)
    major = np.sqrt(np.maximum(mean + half, 0.0))
    minor = np.sqrt(np.maximum(mean - half, 0.0))
    angle = 0.5 * np.degrees(np.arctan2(2.0 * c, a - b))
    angle = np.where(angle <= -90.0, angle + 180.0, angle)
    return major, minor, angle
