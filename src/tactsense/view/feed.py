"""What the browser view shows, frame by frame: the layout once, then one message a frame.

A *feed* runs in a thread of its own. It reads frames (from a live stream or from a
recording), estimates the contact of each, and hands every frame's message (JSON
text) to a ``publish`` callable. The server (:mod:`tactsense.view.server`) passes the
messages on to the pages. Nothing here knows about HTTP.

The page draws the interpolated surface itself from weights sent once in the layout:
``surface = W_rows @ deflection[cylinder rows] @ W_cols.T`` is the windowed-sinc
reconstruction of eq. 48 (:func:`tactsense.estimate.interpolate.surface`) on a grid
``SURFACE_STEPS`` times finer than the tactels, periodic around a closed finger.
"""

from __future__ import annotations

import json
import math
import threading
import time
from collections import deque
from collections.abc import Callable
from pathlib import Path

import numpy as np
from matplotlib import colormaps

from tactsense._validation import TactsenseInputError
from tactsense.estimate import Flag
from tactsense.estimate.deflection import deflection_from_counts
from tactsense.estimate.interpolate import col_weights, row_weights
from tactsense.io.recording import RecordingReader
from tactsense.sensor import SensorSpec, SpecBase
from tactsense.stream.live import LiveContacts, LiveLocator
from tactsense.stream.reader import LOSS_KINDS, StreamError, StreamFrame, StreamReader

SURFACE_STEPS = 9
"""Points of the interpolated surface per tactel spacing, along and around: the centres
of bands 1/9 of a tactel wide (odd, so that one band is centred on each tactel)."""

HISTORY_S = 20.0
"""Seconds of recent frames a page receives when it connects (for its time traces)."""

MAX_HISTORY = 2000
"""At most this many recent frames are kept for new pages, whatever the frame rate."""

COLORMAP = "viridis"
"""Matplotlib colour map of the heat map: its lightness rises monotonically."""

Publish = Callable[[str], None]


def _finite(value):
    """JSON has no NaN: None stands for a value that does not exist (in lists and dicts
    too, e.g. the contacts of a pad's frame)."""
    if isinstance(value, float) and not math.isfinite(value):
        return None
    if isinstance(value, list):
        return [_finite(v) for v in value]
    if isinstance(value, dict):
        return {k: _finite(v) for k, v in value.items()}
    return value


def _finger_geometry(sensor: SensorSpec) -> dict:
    """The finger unwrapped: rows along it (the tip row apart), columns around it."""
    rows, cols = sensor.shape
    first = 1 if sensor.array.tip_row else 0
    cylinder = rows - first
    periodic = bool(sensor.closes_circumference)
    # fine rows over the cylinder rows' span, fine columns over the tactels' span (one
    # whole turn, seam included, when the finger closes)
    # (beyond the first and last rows the surface is held flat, not extrapolated)
    fine_rows = (np.arange(cylinder * SURFACE_STEPS) + 0.5) / SURFACE_STEPS - 0.5
    fine_rows = np.clip(fine_rows, 0.0, cylinder - 1.0)
    fine_cols = (np.arange(cols * SURFACE_STEPS) + 0.5) / SURFACE_STEPS - 0.5
    w_rows = row_weights(fine_rows, cylinder, derivatives=0)
    w_cols = col_weights(fine_cols, cols, periodic, derivatives=0)
    return {
        "geometry": "finger",
        "first_row": first,
        "tip_row": bool(sensor.array.tip_row),
        "closes": periodic,
        "row_axial_mm": [float(v) for v in sensor.row_axial_mm],
        "col_angle_deg": [float(v) for v in sensor.col_angle_deg],
        "spacing_mm": float(sensor.array.spacing_axial_mm),
        "spacing_deg": float(sensor.array.spacing_angle_deg),
        "surface": {
            "row": fine_rows.tolist(),
            "col": fine_cols.tolist(),
            "w_rows": np.round(w_rows, 6).tolist(),
            "w_cols": np.round(w_cols, 6).tolist(),
        },
    }


MAX_FINE = 288
"""At most this many surface points along an axis of a pad (32 taxels at
:data:`SURFACE_STEPS`); a larger pad gets fewer points per pitch (an odd number, at least
one), so the page's work per frame stays bounded."""


def flat_steps(n: int) -> int:
    """Surface points per pitch along a pad's axis of ``n`` taxels (odd, 1 to 9)."""
    steps = min(SURFACE_STEPS, max(1, MAX_FINE // max(n, 1)))
    return steps if steps % 2 else steps - 1


def _flat_weights(n: int) -> tuple[np.ndarray, np.ndarray]:
    """Fine positions [taxel] over ``n`` taxels' span and the windowed-sinc weights (eq. 48's
    kernel, not periodic: the edges are not wrapped) at them, held flat beyond the outer
    taxels; an axis of one taxel is constant."""
    steps = flat_steps(n)
    fine = (np.arange(n * steps) + 0.5) / steps - 0.5
    if n < 2:
        return np.zeros_like(fine), np.ones((fine.size, 1))
    fine = np.clip(fine, 0.0, n - 1.0)
    return fine, row_weights(fine, n, derivatives=0)


def _transduction(sensor) -> dict:
    """How a reading follows from the deflection (the page's counts mode needs it)."""
    t = sensor.transduction
    return {
        "kind": t.kind,
        "counts_per_strain": float(t.counts_per_strain),
        "falling": t.polarity == "falling",
    }


def _pad_geometry(sensor) -> dict:
    """A pad: a flat grid in millimetres, x with the row, y with the column
    (``docs/nomenclature.md``), and the separable interpolated surface."""
    rows, cols = sensor.shape
    g = sensor.grid
    positions = sensor.taxel_positions_mm()
    fine_x, w_x = _flat_weights(rows)
    fine_y, w_y = _flat_weights(cols)
    return {
        "geometry": "plane",
        "u_mm": positions[:, 0].tolist(),
        "v_mm": positions[:, 1].tolist(),
        "u_label": f"x [mm] (rows, {g.row_pitch_mm:g} mm apart)",
        "v_label": f"y [mm] (columns, {g.col_pitch_mm:g} mm apart)",
        "bounds_mm": [
            -0.5 * g.row_pitch_mm,
            (rows - 0.5) * g.row_pitch_mm,
            -0.5 * g.col_pitch_mm,
            (cols - 0.5) * g.col_pitch_mm,
        ],
        "spacing_mm": float(min(g.row_pitch_mm, g.col_pitch_mm)),
        "dot_mm": 0.32 * float(min(g.row_pitch_mm, g.col_pitch_mm)),
        "projection": "the pad seen from outside (its normal +z toward you)",
        "transduction": _transduction(sensor),
        "surface": {
            "row": fine_x.tolist(),
            "col": fine_y.tolist(),
            "w_rows": np.round(w_x, 6).tolist(),
            "w_cols": np.round(w_y, 6).tolist(),
        },
    }


def project_points(positions_mm: np.ndarray, normals: np.ndarray) -> dict:
    """Taxels projected onto the plane normal to their mean normal, seen from outside.

    An orthographic projection along the mean outward normal ``m`` (``+z`` when the
    normals cancel out): ``u = p . e_u``, ``v = p . e_v`` with ``e_u`` the direction of
    ``+x`` in that plane (``+y`` when ``m`` is along ``x``) and ``e_v = m x e_u``. When
    ``m`` is ``+z`` this is simply ``(x, y)``. Distances within the plane are true [mm];
    distances along a curved surface shrink by the cosine of its slope.

    Parameters
    ----------
    positions_mm : ndarray, shape (N, 3)
        Taxel surface points [mm].
    normals : ndarray, shape (N, 3)
        Outward unit normals [-].

    Returns
    -------
    dict
        ``u_mm``, ``v_mm`` (N,) [mm], the unit vectors ``normal``, ``e_u``, ``e_v`` [-].
    """
    positions = np.asarray(positions_mm, dtype=float).reshape(-1, 3)
    mean = np.asarray(normals, dtype=float).reshape(-1, 3).sum(axis=0)
    size = float(np.linalg.norm(mean))
    m = mean / size if size > 1e-6 * len(positions) else np.array([0.0, 0.0, 1.0])
    e_u = np.array([1.0, 0.0, 0.0]) - m[0] * m
    if np.linalg.norm(e_u) < 1e-6:
        e_u = np.array([0.0, 1.0, 0.0]) - m[1] * m
    e_u /= np.linalg.norm(e_u)
    e_v = np.cross(m, e_u)
    return {
        "u_mm": positions @ e_u,
        "v_mm": positions @ e_v,
        "normal": m,
        "e_u": e_u,
        "e_v": e_v,
    }


def _points_geometry(sensor) -> dict:
    """Any taxel set: dots at their positions projected onto the plane normal to the mean
    normal (:func:`project_points`); no surface between scattered points. Asks the sensor
    only where its taxels are, so a kind without a drawing of its own shows this way."""
    plane = project_points(sensor.taxel_positions_mm(), sensor.taxel_normals())
    u, v = plane["u_mm"], plane["v_mm"]
    points = np.column_stack([u, v])
    if len(points) > 1:
        gaps = np.linalg.norm(points[:, None] - points[None, :], axis=-1)
        np.fill_diagonal(gaps, np.inf)
        spacing = float(np.median(gaps.min(axis=1)))
    else:
        spacing = 1.0
    if not spacing > 0:
        spacing = 1.0
    areas = getattr(sensor, "areas_mm2", None)
    dot = 0.32 * spacing
    if areas is not None:  # the electrode's own size where it is smaller than that
        dot = min(dot, float(np.sqrt(np.median(areas) / np.pi)))
    margin = max(spacing, 2.0 * dot)
    m = plane["normal"]
    along_z = bool(m[2] > 1.0 - 1e-9)
    return {
        "geometry": "plane",
        "u_mm": u.tolist(),
        "v_mm": v.tolist(),
        "u_label": "x [mm]" if along_z else "u [mm] (in the plane normal to the mean normal)",
        "v_label": "y [mm]" if along_z else "v [mm]",
        "bounds_mm": [
            float(u.min() - margin),
            float(u.max() + margin),
            float(v.min() - margin),
            float(v.max() + margin),
        ],
        "spacing_mm": spacing,
        "dot_mm": dot,
        "projection": (
            "x-y, seen from +z (the mean normal)"
            if along_z
            else "projected along the mean normal "
            f"({m[0]:.2f}, {m[1]:.2f}, {m[2]:.2f}), seen from outside"
        ),
        "transduction": _transduction(sensor),
        "surface": None,
    }


GEOMETRY: dict[str, Callable[[SpecBase], dict]] = {
    "finger": _finger_geometry,
    "pad": _pad_geometry,
    "points": _points_geometry,
}
"""How the page draws each kind; a kind not listed is drawn as dots at its taxels'
positions (:func:`_points_geometry` asks only ``taxel_positions_mm`` and ``taxel_normals``)."""

PLURAL = {"finger": "fingers", "pad": "pads", "points": "point sets"}


def estimates(sensor: SpecBase) -> bool:
    """Whether contacts on this kind of sensor are estimated (:data:`LOCATORS`: fingers,
    pads and point sets)."""
    return sensor.kind in LOCATORS


def not_estimated_note(sensor: SpecBase) -> str | None:
    """The page's one line where there is no contact estimate for the sensor's kind."""
    if estimates(sensor):
        return None
    return f"contact estimation: not yet for {PLURAL.get(sensor.kind, sensor.kind)}"


def layout_message(sensor: SpecBase, source: dict) -> dict:
    """Everything a page needs once: geometry, surface weights, colour map, source."""
    rows, cols = sensor.shape
    lut = (colormaps[COLORMAP](np.linspace(0.0, 1.0, 256))[:, :3] * 255).round().astype(int)
    message = {
        "type": "layout",
        "sensor": sensor.name,
        "kind": sensor.kind,
        "rows": rows,
        "cols": cols,
        "estimation": not_estimated_note(sensor),
        # several tracked contacts a frame (pads, point sets), or the finger's one
        "multi_contact": LOCATORS.get(sensor.kind) is LiveContacts,
    }
    message.update(GEOMETRY.get(sensor.kind, _points_geometry)(sensor))
    message.update(
        {
            "full_scale": int(2**sensor.electronics.adc_bits - 1),
            "colormap": {"name": COLORMAP, "lut": lut.tolist()},
            "loss_kinds": list(LOSS_KINDS),
            "flags": {flag.name: int(flag) for flag in Flag if flag},
            "source": source,
        }
    )
    return message


def _capacitive_deflection(counts, baseline, sensor) -> np.ndarray:
    # eq. 4, (counts - baseline) / counts; 0 where a taxel reads nothing usable
    if sensor.transduction.polarity == "falling":  # the mirrored reading's eq. 4
        from tactsense.estimate.contacts import signal_from_counts

        counts = np.asarray(counts, dtype=float)
        return signal_from_counts(counts, baseline, sensor)[0].reshape(counts.shape)
    return deflection_from_counts(counts, baseline, sensor)[0]


def _resistive_deflection(counts, baseline, sensor) -> np.ndarray:
    # the compressive strain: the reading moves by counts_per_strain per unit strain
    strain = (np.asarray(counts, dtype=float) - baseline) / sensor.transduction.counts_per_strain
    if sensor.transduction.polarity == "falling":
        strain = -strain
    return np.where(np.isfinite(strain), strain, 0.0)


DEFLECTION = {
    "capacitive": _capacitive_deflection,
    "resistive": _resistive_deflection,
    "piezoresistive": _resistive_deflection,
}
"""Transduction kind -> the deflection [-] of a frame from its counts and the baseline."""


class DeflectionOnly:
    """The deflection of every frame of a sensor whose contacts are not estimated yet.

    The same interface as :class:`~tactsense.stream.live.LiveLocator` for a feed: called
    with a frame it returns no estimate (None) and keeps the frame's deflection in
    :attr:`last_deflection` once the baseline is known. The baseline is the median of the
    first ``baseline_frames`` frames (untouched), or given. The deflection follows the
    sensor's transduction (:data:`DEFLECTION`): a capacitive taxel's is eq. 4,
    ``(counts - baseline) / counts``; a resistive taxel's ``(counts - baseline) /
    counts_per_strain``.
    """

    calibration = None

    def __init__(self, sensor: SpecBase, *, baseline_frames: int = 5, baseline=None):
        self.sensor = sensor
        self._deflection = DEFLECTION[sensor.transduction.kind]
        self._baseline_frames = max(1, int(baseline_frames))
        self._collected: list[np.ndarray] = []
        self._baseline = None if baseline is None else np.asarray(baseline, dtype=float)
        self.last_deflection: np.ndarray | None = None
        """Deflection of the last frame [-] (None until the baseline is known)."""

    @property
    def ready(self) -> bool:
        return self._baseline is not None

    def reset(self) -> None:
        """Nothing to forget (no creep compensation)."""

    def __call__(self, frame: StreamFrame) -> None:
        counts = np.asarray(frame.counts, dtype=float)
        if self._baseline is None:
            self._collected.append(counts)
            if len(self._collected) >= self._baseline_frames:
                self._baseline = np.median(np.stack(self._collected), axis=0)
                self._collected = []
            return None
        self.last_deflection = self._deflection(counts, self._baseline, self.sensor)
        return None


LOCATORS = {"finger": LiveLocator, "pad": LiveContacts, "points": LiveContacts}
"""Sensor kind -> what estimates its contacts frame by frame: the paper's finger its one
contact (:class:`LiveLocator`), pads and point sets every contact, tracked
(:class:`LiveContacts`); a kind not listed gets :class:`DeflectionOnly`."""


def view_locator(
    sensor: SpecBase,
    *,
    calibration=None,
    baseline_frames: int = 5,
    threshold: float | None = None,
    frame_period_s: float | None = None,
    baseline=None,
):
    """What the view runs on each frame of ``sensor``: a contact locator where one exists
    for its kind, else :class:`DeflectionOnly` (which takes no calibration yet).
    ``threshold`` None: the sensor's default (0.005 on the finger)."""
    locator = LOCATORS.get(sensor.kind)
    if locator is LiveContacts:
        return LiveContacts(
            sensor,
            baseline_frames=baseline_frames,
            threshold=threshold,
            frame_period_s=frame_period_s,
            baseline=baseline,
            keep_deflection=True,
            calibration=calibration,
        )
    if locator is not None and calibration is not None and not hasattr(calibration, "apply"):
        raise TactsenseInputError(
            f"an array's calibration does not apply to {sensor.name!r}, a finger: "
            "calibrate it with 'tactsense calibrate' on a probe sweep of the finger"
        )
    if locator is not None:
        if threshold is None:
            threshold = 0.005
        return locator(
            sensor,
            calibration=calibration,
            baseline_frames=baseline_frames,
            threshold=threshold,
            frame_period_s=frame_period_s,
            baseline=baseline,
            keep_deflection=True,
        )
    if calibration is not None:
        raise TactsenseInputError(
            f"--calibration applies to fingers, not to {PLURAL.get(sensor.kind, sensor.kind)} "
            f"(sensor {sensor.name!r}), whose calibration does not exist yet: leave "
            "--calibration out"
        )
    return DeflectionOnly(sensor, baseline_frames=baseline_frames, baseline=baseline)


class _Rate:
    """Frames per second over the last second of arrivals."""

    def __init__(self) -> None:
        self._times: deque[float] = deque(maxlen=4096)

    def __call__(self, now: float) -> float:
        self._times.append(now)
        while self._times and now - self._times[0] > 1.0:
            self._times.popleft()
        if len(self._times) < 2:
            return 0.0
        span = self._times[-1] - self._times[0]
        return (len(self._times) - 1) / span if span > 0 else 0.0


class Feed:
    """Base of the two feeds: frame messages, a thread, a bounded history for new pages."""

    kind = "feed"

    def __init__(self, sensor: SensorSpec, locator: LiveLocator, name: str):
        self.sensor = sensor
        self.locator = locator
        self.name = name
        self.frames_in = 0
        self.status = "starting"
        self.error: str | None = None
        self._publish: Publish = lambda text: None
        self._history: deque[tuple[float, str]] = deque(maxlen=MAX_HISTORY)
        self._history_s = HISTORY_S
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None
        self._rate = _Rate()
        self._lock = threading.Lock()
        self._plane = None
        if LOCATORS.get(sensor.kind) is LiveContacts:  # contacts drawn on the plane
            plane = project_points(sensor.taxel_positions_mm(), sensor.taxel_normals())
            self._plane = (plane["e_u"], plane["e_v"])

    # ---- what pages receive --------------------------------------------------------

    def source_info(self) -> dict:
        return {
            "kind": self.kind,
            "name": self.name,
            "calibrated": self.locator.calibration is not None,
        }

    def layout(self) -> dict:
        message = layout_message(self.sensor, self.source_info())
        with self._lock:
            message["history"] = [json.loads(text) for _, text in self._history]
        message["status"] = self.status_message()
        return message

    def status_message(self) -> dict:
        return {"type": "status", "status": self.status, "error": self.error}

    def frame_message(self, frame: StreamFrame, estimate: dict | None, health: dict) -> dict:
        deflection = self.locator.last_deflection
        message = {
            "type": "frame",
            "serial": self.frames_in,
            "index": int(frame.index),
            "sequence": int(frame.sequence),
            "time_s": float(frame.device_time_s),
            "host_time_s": float(frame.host_time_s),
            "counts": np.asarray(frame.counts).astype(int).tolist(),
            "deflection": None if deflection is None else np.round(deflection, 6).tolist(),
            "estimate": None
            if estimate is None
            else {k: _finite(v) for k, v in estimate.items() if k != "sequence"},
            "health": health,
        }
        if self._plane is not None and message["estimate"] is not None:
            e_u, e_v = self._plane
            for contact in message["estimate"].get("contacts", []):
                xyz = [contact.get(k) for k in ("x_mm", "y_mm", "z_mm")]
                if xyz[0] is None or xyz[1] is None:
                    contact["u_mm"] = contact["v_mm"] = None
                    continue
                p = np.array([v if v is not None else 0.0 for v in xyz], dtype=float)
                contact["u_mm"] = round(float(p @ e_u), 4)
                contact["v_mm"] = round(float(p @ e_v), 4)
        return message

    def _emit(self, message: dict, *, keep: bool = True) -> None:
        text = json.dumps(message, allow_nan=False)
        if keep:
            t = message["time_s"]
            with self._lock:
                if self._history and t < self._history[-1][0]:
                    self._history.clear()  # a seek back: the traces start over
                self._history.append((t, text))
                while self._history and self._history[0][0] < t - self._history_s:
                    self._history.popleft()
        self._publish(text)

    def _set_status(self, status: str, error: str | None = None) -> None:
        self.status, self.error = status, error
        self._publish(json.dumps(self.status_message()))

    # ---- the thread ----------------------------------------------------------------

    def start(self, publish: Publish) -> None:
        """Run the feed in a thread; every message goes to ``publish`` (thread-safe)."""
        self._publish = publish
        self._thread = threading.Thread(target=self._guarded, name=f"tactsense-{self.kind}")
        self._thread.daemon = True
        self._thread.start()

    def stop(self, wait_s: float = 2.0) -> None:
        self._stop.set()
        if self._thread is not None:
            self._thread.join(wait_s)

    def _guarded(self) -> None:
        try:
            self._run()
        except StreamError as error:
            self._set_status("error", str(error))
        except Exception as error:  # shown on the page and by /api/health, not lost
            self._set_status("error", f"{type(error).__name__}: {error}")

    def _run(self) -> None:
        raise NotImplementedError

    def command(self, message: dict) -> None:
        """A control message from a page: ``{"command": "rezero"}`` takes the baseline
        anew from the next frames (the sensor must be untouched); a recording also
        takes playback commands."""
        if message.get("command") == "rezero":
            self.rezero()

    def rezero(self) -> None:
        """Take the baseline anew from the next frames, where the locator can."""
        rezero = getattr(self.locator, "rezero", None)
        if rezero is not None:
            with self._lock:
                rezero()

    def health(self) -> dict:
        return {"frames_in": self.frames_in, "status": self.status, "error": self.error}


class LiveFeed(Feed):
    """Frames of a device as they arrive (:class:`~tactsense.stream.StreamReader`)."""

    kind = "live"

    def __init__(self, reader: StreamReader, locator: LiveLocator):
        super().__init__(reader.sensor, locator, str(reader.url))
        self.reader = reader
        self._last_latency = float("nan")

    def source_info(self) -> dict:
        info = super().source_info()
        info["rate_hz"] = 1.0 / self.reader.frame_period_s if self.reader.frame_period_s else 0
        info["identity"] = {k: v for k, v in self.reader.identity.items() if k != "sensor_toml"}
        return info

    def _health(self, rate: float, latency: float) -> dict:
        stats = self.reader.stats
        health = {"rate_hz": round(rate, 3), "received": stats.frames}
        health.update({kind: getattr(stats, kind) for kind in LOSS_KINDS})
        health["latency_ms"] = _finite(round(latency, 4))
        return health

    def _run(self) -> None:
        reader = self.reader
        reader.start()
        self._set_status("streaming")
        last = time.perf_counter()
        while not self._stop.is_set():
            batch = reader.read_batch(256, wait_s=0.1)
            now = time.perf_counter()
            if not batch:
                if reader.ended:
                    self._set_status("ended", reader.stats.summary())
                    return
                if now - last > reader.timeout_s:
                    reader.stats.timeouts += 1  # as StreamReader.frames counts them
                    last = now
                continue
            last = now
            for frame in batch:
                self.frames_in += 1
                rate = self._rate(frame.arrival)
                estimate = self.locator(frame)
                latency = estimate["latency_ms"] if estimate else float("nan")
                self._emit(self.frame_message(frame, estimate, self._health(rate, latency)))

    def stop(self, wait_s: float = 2.0) -> None:
        super().stop(wait_s)
        self.reader.close()

    def health(self) -> dict:
        health = super().health()
        health["stream"] = self.reader.stats.as_dict()
        return health


class RecordingFeed(Feed):
    """Frames of a recording played back: play, pause, step, seek and speed from the page.

    The playback state is shared by every page (one recording, one position). Frames
    are read from the file a block at a time, so memory does not grow with its length.
    With a creep calibration the compensation restarts at every seek or backward step
    (its state is the recent past, which a jump skips).
    """

    kind = "recording"
    BLOCK = 1024

    def __init__(self, path: str | Path, locator_factory, *, speed: float = 1.0):
        self.file = RecordingReader(path)
        sensor = self.file.sensor
        super().__init__(sensor, locator_factory(sensor, self.file), str(path))
        self.n_frames = self.file.n_frames
        self.losses = self.file.losses
        self.speed = float(speed)
        self.position = 0
        self.playing = True
        self._block_start = -1
        self._block: np.ndarray | None = None
        self._times: np.ndarray | None = None
        self._wake = threading.Event()
        self._jumped = False
        self._pending_show = True  # show the frame at the position now (start, seek, step)
        self._finished = False  # played to the last frame (status "ended")
        times = self.file.time_s(0, min(self.n_frames, 2))
        self.period_s = float(np.diff(times)[0]) if len(times) > 1 else sensor.scan_period_s
        if not self.period_s > 0:
            self.period_s = sensor.scan_period_s

    def source_info(self) -> dict:
        info = super().source_info()
        info.update(n_frames=self.n_frames, rate_hz=1.0 / self.period_s, losses=self.losses)
        return info

    def _frame(self, index: int) -> tuple[np.ndarray, float]:
        if self._block is None or not self._block_start <= index < self._block_start + self.BLOCK:
            self._block_start = (index // self.BLOCK) * self.BLOCK
            stop = self._block_start + self.BLOCK
            self._block = self.file.frames(self._block_start, stop)
            self._times = self.file.time_s(self._block_start, stop)
        offset = index - self._block_start
        return self._block[offset], float(self._times[offset])

    def layout(self) -> dict:
        message = super().layout()
        with self._lock:  # the state now: the history's frames carry the state then
            message["playback"] = self._playback()
        return message

    def _playback(self) -> dict:
        return {
            "position": self.position,
            "n_frames": self.n_frames,
            "playing": self.playing,
            "speed": self.speed,
        }

    def _show(self, index: int, rate: float) -> None:
        counts, t = self._frame(index)
        frame = StreamFrame(
            index % 65536, index, t, time.time(), time.perf_counter(), np.asarray(counts)
        )
        self.frames_in += 1
        estimate = self.locator(frame)
        health = {"rate_hz": round(rate, 3), "received": self.n_frames}
        health.update({kind: int(self.losses.get(kind, 0)) for kind in LOSS_KINDS})
        health["latency_ms"] = _finite(round(estimate["latency_ms"], 4)) if estimate else None
        message = self.frame_message(frame, estimate, health)
        message["playback"] = self._playback()
        self._emit(message)

    def command(self, message: dict) -> None:
        """``{"command": "play"|"pause"|"step"|"seek"|"speed"|"rezero", "value": ...}``."""
        command = message.get("command")
        value = message.get("value")
        if command == "rezero":
            self.rezero()
            return
        with self._lock:
            if command in ("play", "step", "seek"):
                self._finished = False
            if command == "play":
                if self.position >= self.n_frames - 1:
                    self.position, self._jumped = 0, True
                self.playing = True
            elif command == "pause":
                self.playing = False
            elif command == "step":
                step = int(value) if isinstance(value, int | float) else 1
                self.playing = False
                self._jumped = step < 0
                self.position = min(max(self.position + step, 0), self.n_frames - 1)
                self._pending_show = True
            elif command == "seek":
                if not isinstance(value, int | float) or not math.isfinite(value):
                    return
                self.position = min(max(int(value), 0), self.n_frames - 1)
                self._jumped = True
                self._pending_show = True
            elif command == "speed":
                if isinstance(value, int | float) and 0 < value <= 1000:
                    self.speed = float(value)
            else:
                return
            playback = self._playback()
        # every page shows the new state at once, even while paused
        self._publish(json.dumps({"type": "playback", **playback}))
        self._wake.set()

    def _run(self) -> None:
        self._set_status("playing")
        next_due = time.perf_counter()
        while not self._stop.is_set():
            with self._lock:
                show_now = self._pending_show
                self._pending_show = False
                if self._jumped:
                    self.locator.reset()
                    self._jumped = False
                playing, position = self.playing, self.position
            now = time.perf_counter()
            if show_now:
                self._show(position, 0.0 if not playing else self._rate(now))
                next_due = now + self.period_s / self.speed
                if playing and position < self.n_frames - 1:
                    with self._lock:
                        self.position += 1
                continue
            if not playing:
                # played to the last frame: ended, not paused (play starts it over)
                self._status_if("ended" if self._finished else "paused")
                self._wake.wait(0.25)
                self._wake.clear()
                continue
            if now < next_due:
                self._wake.wait(min(next_due - now, 0.25))
                self._wake.clear()
                continue
            self._status_if("playing")
            self._show(position, self._rate(now))
            next_due = max(next_due + self.period_s / self.speed, now - 0.5)
            finished = None
            with self._lock:
                if self.position == position:  # not moved by a command meanwhile
                    if position >= self.n_frames - 1:
                        self.playing = False
                        self._finished = True
                        finished = self._playback()
                    else:
                        self.position = position + 1
            if finished is not None:  # every page's play button says "play" now
                self._publish(json.dumps({"type": "playback", **finished}))

    def _status_if(self, status: str) -> None:
        if self.status != status:
            self._set_status(status)

    def stop(self, wait_s: float = 2.0) -> None:
        super().stop(wait_s)
        self._wake.set()
        self.file.close()

    def health(self) -> dict:
        health = super().health()
        health["playback"] = self._playback()
        return health
