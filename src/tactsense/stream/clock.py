"""A device's clock mapped onto the host's: offset and drift from (device stamp, arrival)
pairs, by the lower envelope of the arrivals.

A frame scanned at device time ``d`` arrives on the host at
``h = offset + d / (1 + drift) + delay`` with a delay that is never negative (the line,
the device's buffer, the host's scheduler) and often long (a USB poll, a busy host). A
least-squares line would carry the mean delay and bend with its bursts; the frames that
came fastest lie on the lower convex hull of the points, and the line under every point
that lies closest to them (the linear programme "maximise the line's mean height, staying
under every point") is the hull's edge above the points' mean device time. Its error is the
line's shortest delay (constant: it shifts every device alike), plus how far the fastest
frames near the hull's two ends are from that floor.

The hull is kept online as the frames arrive (device time only increases: Andrew's
monotone chain, amortised O(1) a point); memory is bounded by ``max_vertices`` (past it,
every other vertex of the older half is dropped; with random delays the hull holds
O(log n) vertices, so this is a guard for clocks that wander, not the rule).
"""

from __future__ import annotations

import math

import numpy as np

from tactsense._validation import TactsenseInputError

RESIDUALS_KEPT = 4096
"""Points kept (a uniform reservoir sample) to describe the delays above the fit."""


class ClockFitError(TactsenseInputError):
    """Stamps a clock fit cannot take (not finite, or device time going back)."""


class ClockFit:
    """The line ``host = offset_s + device / (1 + drift_ppm * 1e-6)`` under every
    (device time, host arrival) pair, fitted online.

    Parameters
    ----------
    max_vertices : int
        Most vertices of the lower hull kept (memory bound).
    rng : int or Generator, optional
        Seed of the reservoir sample of residuals (:attr:`residuals_s`).

    Examples
    --------
    >>> fit = ClockFit()
    >>> for d, h in pairs:                                 # doctest: +SKIP
    ...     fit.add(d, h)
    >>> fit.to_host(d)                                     # doctest: +SKIP
    """

    def __init__(self, max_vertices: int = 4096, rng=0):
        if int(max_vertices) < 8:
            raise ClockFitError(f"max_vertices must be at least 8; got {max_vertices!r}")
        self.max_vertices = int(max_vertices)
        self.count = 0
        """Pairs added."""
        self._x0 = 0.0  # first device time [s]
        self._y0 = 0.0  # first host time [s]
        self._sum_x = 0.0
        self._last_x = -math.inf
        self._hull: list[tuple[float, float]] = []  # (x, y): x = d - d0, y = h - h0 - x
        self._kept = np.empty((RESIDUALS_KEPT, 2))  # reservoir of (device, host) [s]
        self._rng = np.random.default_rng(rng)

    # ---- adding pairs ----------------------------------------------------------
    def add(self, device_s: float, host_s: float) -> None:
        """One frame: its scan's start on the device clock and its arrival on the host's
        [s]. Device times must increase (a repeated one is ignored)."""
        device_s, host_s = float(device_s), float(host_s)
        if not (math.isfinite(device_s) and math.isfinite(host_s)):
            raise ClockFitError(f"clock stamps must be finite; got ({device_s}, {host_s})")
        if self.count == 0:
            self._x0, self._y0 = device_s, host_s
        x = device_s - self._x0
        if x <= self._last_x:
            if x == self._last_x:
                return
            raise ClockFitError(
                f"device time went back from {self._last_x + self._x0} s to {device_s} s"
            )
        self._last_x = x
        y = host_s - self._y0 - x
        hull = self._hull
        while len(hull) >= 2:
            (x1, y1), (x2, y2) = hull[-2], hull[-1]
            # keep the middle point only if it lies strictly below the chord to the new one
            if (y2 - y1) * (x - x1) >= (y - y1) * (x2 - x1):
                hull.pop()
            else:
                break
        hull.append((x, y))
        if len(hull) > self.max_vertices:
            half = len(hull) // 2
            self._hull = hull[:half:2] + hull[half:]
        self._sum_x += x
        if self.count < RESIDUALS_KEPT:
            self._kept[self.count] = (device_s, host_s)
        else:
            slot = int(self._rng.integers(self.count + 1))
            if slot < RESIDUALS_KEPT:
                self._kept[slot] = (device_s, host_s)
        self.count += 1

    def add_many(self, device_s, host_s) -> None:
        """Many pairs at once, in order [s]."""
        for d, h in zip(np.asarray(device_s, float), np.asarray(host_s, float), strict=True):
            self.add(d, h)

    # ---- the fit ---------------------------------------------------------------
    def _line(self) -> tuple[float, float]:
        """(a, b) of ``y = a + b x`` in the internal coordinates."""
        hull = self._hull
        if not hull:
            raise ClockFitError("no clock stamps yet: the fit needs at least one frame")
        if len(hull) == 1:
            return hull[0][1], 0.0
        mean_x = self._sum_x / self.count
        lo, hi = 0, len(hull) - 1
        while hi - lo > 1:  # the edge whose span holds the mean device time
            mid = (lo + hi) // 2
            if hull[mid][0] <= mean_x:
                lo = mid
            else:
                hi = mid
        (x1, y1), (x2, y2) = hull[lo], hull[hi]
        b = (y2 - y1) / (x2 - x1)
        return y1 - b * x1, b

    @property
    def host_per_device(self) -> float:
        """Host seconds per device second [-] (1 / (1 + drift))."""
        return 1.0 + self._line()[1]

    @property
    def drift_ppm(self) -> float:
        """How much faster the device clock runs than the host's [ppm]."""
        return (1.0 / self.host_per_device - 1.0) * 1e6

    @property
    def offset_s(self) -> float:
        """The host time at device time 0 [s]."""
        a, b = self._line()
        return self._y0 + a - self._x0 * (1.0 + b)

    def to_host(self, device_s):
        """Device times [s] on the host clock [s] (scalar or array)."""
        a, b = self._line()
        x = np.asarray(device_s, dtype=float) - self._x0
        out = self._y0 + a + x * (1.0 + b)
        return float(out) if np.ndim(out) == 0 else out

    @property
    def span_s(self) -> float:
        """Device time covered by the pairs [s]."""
        return max(self._last_x, 0.0) if self.count else 0.0

    def residuals_s(self) -> np.ndarray:
        """Arrival minus fitted host time of a uniform sample of the pairs (at most
        :data:`RESIDUALS_KEPT`) [s]: the delays the alignment removed, all >= 0 up to
        rounding for the pairs of the final fit."""
        kept = self._kept[: min(self.count, RESIDUALS_KEPT)]
        if not len(kept):
            return np.empty(0)
        return kept[:, 1] - self.to_host(kept[:, 0])

    def as_dict(self) -> dict:
        """The fit for a manifest: ``offset_s``, ``drift_ppm`` (host =
        offset_s + device / (1 + drift_ppm 1e-6)), ``residual_s`` (median delay above the
        line), ``residual_p99_s``, ``pairs``, ``span_s``; empty when no pair came."""
        if not self.count:
            return {}
        residuals = self.residuals_s()
        median, p99 = np.percentile(residuals, [50, 99])
        return {
            "offset_s": self.offset_s,
            "drift_ppm": self.drift_ppm,
            "residual_s": float(median),
            "residual_p99_s": float(p99),
            "pairs": self.count,
            "span_s": self.span_s,
            "hull_vertices": len(self._hull),
        }


def to_host_time(clock: dict, device_s):
    """Device times [s] on the host clock [s] from a manifest's clock fit
    (:meth:`ClockFit.as_dict`)."""
    if not clock:
        raise ClockFitError("no clock fit: the device sent no frame")
    return clock["offset_s"] + np.asarray(device_s, float) / (1.0 + clock["drift_ppm"] * 1e-6)
