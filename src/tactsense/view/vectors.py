"""Taxels of several components in the view (three-axis pads, issue 35): the normal
component as the map, the tangential ones as an arrow per taxel, and each contact's
estimated shear and slip where the estimate carries them.

A frame of such a sensor is ``(rows, cols, components)`` (``spec.frame_shape``), the
components named by ``spec.component_names``: ``x`` along rows, ``y`` along columns,
``z`` the outward normal (``sensor/pad.py``). Nothing here asks which kind the sensor is:
what a count means follows the sensor's transduction (:data:`PER_COUNT`), and which
component is normal follows the component names.

What the page gets, per frame (:class:`VectorReading`):

* ``deflection`` (rows, cols): the change of the normal component since the baseline, in
  the layout's ``vector.unit`` (uT for a magnetic skin), signed so that pressing in reads
  positive (:func:`taxel_vectors`);
* ``tangential`` (rows, cols, 2): the change of the tangential components, projected on
  the page's plane (``u``, ``v``: ``x``, ``y`` on a flat pad), in the same unit. On a
  magnetic skin it points where the magnet was pushed: a +x shear moves the magnet +x and
  raises Bx (with the magnets' moments along the outward normal; the sign of each
  taxel's rest field turns it round where they point inward).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from tactsense.stream.reader import StreamFrame
from tactsense.view.plane import project_points

NORMAL_NAME = "z"
"""The name of the normal component (``spec.component_names``, the pad's axes)."""

TANGENTIAL_NAMES = ("x", "y")
"""The names of the two tangential components, along the pad's x (rows) and y (columns)."""


def _magnetic_per_count(sensor) -> np.ndarray:
    # the Hall sensor's field per count [uT], per component
    return np.asarray(sensor.lsb_t, dtype=float) * 1e6


PER_COUNT: dict[str, tuple[Callable[[object], np.ndarray], str, str]] = {
    "magnetic": (_magnetic_per_count, "uT", "field change"),
}
"""Transduction kind -> (what one count is per component, its unit, what the change is
called). A transduction not listed is shown in counts."""


def is_vector(sensor) -> bool:
    """Whether each taxel of ``sensor`` reports several components (a three-axis pad)."""
    return int(getattr(sensor, "components", 1)) > 1


def component_roles(sensor) -> tuple[int | None, tuple[int, int] | None]:
    """Index of the normal component and of the two tangential ones in a frame's last
    axis; None where the sensor's component names do not say (the map then shows the
    first component and no arrows are drawn)."""
    names = tuple(getattr(sensor, "component_names", ()))
    normal = names.index(NORMAL_NAME) if NORMAL_NAME in names else None
    if all(name in names for name in TANGENTIAL_NAMES):
        tangential = (names.index(TANGENTIAL_NAMES[0]), names.index(TANGENTIAL_NAMES[1]))
    else:
        tangential = None
    return normal, tangential


def unit_of(sensor) -> tuple[np.ndarray, str, str]:
    """One count of each component in the unit shown, the unit, and the change's name."""
    per_count, unit, name = PER_COUNT.get(
        sensor.transduction.kind, (lambda s: np.ones(s.components), "counts", "change")
    )
    return np.broadcast_to(per_count(sensor), (sensor.components,)).astype(float), unit, name


def taxel_vectors(counts, baseline, sensor) -> np.ndarray:
    """The change of every component since the baseline, in the unit shown, oriented.

    Parameters
    ----------
    counts, baseline : array_like, shape (rows, cols, components)
        A frame and the untouched reading [counts].
    sensor : SpecBase
        Gives the converter's zero (``electronics.nominal_counts``: offset binary) and
        what a count is (:func:`unit_of`).

    Returns
    -------
    ndarray, shape (rows, cols, components)
        ``(counts - baseline) * per_count`` [the unit of :func:`unit_of`], times the sign
        of each taxel's rest reading of the normal component about the converter's zero
        (+1 where it is zero): pressing a magnet toward its sensor raises the field along
        its moment whichever way the moment points, and a shear moves it (and the field's
        tangential part, in the moment's sense) the way the surface is pushed. 0 where a
        reading is not finite.
    """
    counts = np.asarray(counts, dtype=float)
    baseline = np.asarray(baseline, dtype=float)
    per_count, _, _ = unit_of(sensor)
    change = (counts - baseline) * per_count
    normal, _ = component_roles(sensor)
    if normal is not None:
        rest = baseline[..., normal] - float(sensor.electronics.nominal_counts)
        change = change * np.where(rest < 0, -1.0, 1.0)[..., None]
    return np.where(np.isfinite(change), change, 0.0)


def plane_axes(sensor) -> tuple[np.ndarray, np.ndarray]:
    """The page's plane axes ``e_u``, ``e_v`` (:func:`tactsense.view.plane.project_points`)."""
    plane = project_points(sensor.taxel_positions_mm(), sensor.taxel_normals())
    return plane["e_u"], plane["e_v"]


def _on_plane(x, y, e_u, e_v) -> tuple[np.ndarray, np.ndarray]:
    """A tangential vector (x, y) along the pad's axes, projected on the page's plane."""
    x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    return x * e_u[0] + y * e_u[1], x * e_v[0] + y * e_v[1]


class VectorReading:
    """The view's reading of a sensor whose taxels have several components.

    Wraps the contact estimator of its kind where one exists (``inner``: called with
    every frame, its estimate passed on, its calibration and re-zeroing kept) and
    computes what the map and the arrows show from the frame itself
    (:func:`taxel_vectors`), so the page draws the taxels' arrows whether or not the
    contacts are estimated. The baseline is the median of the first ``baseline_frames``
    frames (untouched), or given.
    """

    def __init__(self, sensor, inner=None, *, baseline_frames: int = 5, baseline=None):
        self.sensor = sensor
        self.inner = inner
        self._baseline_frames = max(1, int(baseline_frames))
        self._collected: list[np.ndarray] = []
        self._baseline = None if baseline is None else np.asarray(baseline, dtype=float)
        if self._baseline is not None and self._baseline.shape != tuple(sensor.frame_shape):
            from tactsense._validation import TactsenseInputError

            raise TactsenseInputError(
                f"baseline has shape {self._baseline.shape}; expected {sensor.frame_shape}"
            )
        self.normal, self.tangential = component_roles(sensor)
        self.e_u, self.e_v = plane_axes(sensor)
        self.last_deflection: np.ndarray | None = None
        """The normal component's change of the last frame, (rows, cols) [unit shown]."""
        self.last_tangential: np.ndarray | None = None
        """The tangential change of the last frame on the page's plane, (rows, cols, 2)
        [unit shown]; None without tangential components."""

    @property
    def calibration(self):
        return getattr(self.inner, "calibration", None)

    @property
    def ready(self) -> bool:
        return self._baseline is not None

    def reset(self) -> None:
        """The estimator's memory is forgotten (a seek); the baseline is kept."""
        if self.inner is not None:
            self.inner.reset()

    def rezero(self) -> None:
        """Take the baseline anew from the next frames (the sensor untouched)."""
        self._baseline, self._collected = None, []
        self.last_deflection = self.last_tangential = None
        rezero = getattr(self.inner, "rezero", None)
        if rezero is not None:
            rezero()

    def __call__(self, frame: StreamFrame):
        counts = np.asarray(frame.counts, dtype=float)
        estimate = self.inner(frame) if self.inner is not None else None
        if self._baseline is None and getattr(self.inner, "baseline", None) is not None:
            # the estimator's (a calibration's, or its first frames): one baseline
            self._baseline = np.asarray(self.inner.baseline, dtype=float)
            self._collected = []
        if self._baseline is None:
            self._collected.append(counts)
            if len(self._collected) >= self._baseline_frames:
                self._baseline = np.median(np.stack(self._collected), axis=0)
                self._collected = []
            return estimate
        change = taxel_vectors(counts, self._baseline, self.sensor)
        self.last_deflection = change[..., 0 if self.normal is None else self.normal]
        if self.tangential is not None:
            u, v = _on_plane(
                change[..., self.tangential[0]], change[..., self.tangential[1]], self.e_u, self.e_v
            )
            self.last_tangential = np.stack([u, v], axis=-1)
        return estimate

    def __getattr__(self, name: str):
        # what else a feed or a wrapper asks of a locator is the estimator's
        inner = self.__dict__.get("inner")
        if inner is None:
            raise AttributeError(name)
        return getattr(inner, name)


SLIP_STATES = {0: "stick", 1: "partial", 2: "gross"}
"""A contact's slip as an estimator may give it (0, 1, 2) -> the page's word."""


def slip_state(value) -> str | None:
    """A contact's ``slip`` as the page marks it: ``"stick"``, ``"partial"`` (incipient
    slip, spreading from the contact's edge) or ``"gross"`` (the contact slides); a yes/no
    slip (a tracked contact moving under a steady load) is ``"slip"``; None if unknown."""
    if value is None or value == "":
        return None
    if isinstance(value, bool | np.bool_):
        return "slip" if value else "stick"
    if isinstance(value, int | np.integer | float | np.floating):
        return SLIP_STATES.get(int(value)) if np.isfinite(value) else None
    text = str(value).strip().lower()
    for word in ("partial", "gross", "stick"):
        if text.startswith(word):
            return word
    return "slip" if text in ("slip", "true", "1") else None


def decorate_frame(message: dict, locator, sensor) -> None:
    """Add what the page draws for a sensor of several components to a frame message:
    ``tangential`` (the taxels' arrows), and on each estimated contact its shear on the
    page's plane (``shear_u_n``, ``shear_v_n`` [N], from ``shear_x_n``, ``shear_y_n``
    where the estimate has them) and its ``slip_state`` (:func:`slip_state`)."""
    tangential = getattr(locator, "last_tangential", None)
    message["tangential"] = None if tangential is None else np.round(tangential, 4).tolist()
    estimate = message.get("estimate")
    if not estimate:
        return
    e_u, e_v = getattr(locator, "e_u", None), getattr(locator, "e_v", None)
    if e_u is None or e_v is None:
        e_u, e_v = plane_axes(sensor)
    for contact in estimate.get("contacts") or []:
        given = contact.get("slip_state")
        contact["slip_state"] = slip_state(contact.get("slip") if given is None else given)
        x, y = contact.get("shear_x_n"), contact.get("shear_y_n")
        if x is None or y is None:
            continue
        u, v = _on_plane(x, y, e_u, e_v)
        contact["shear_u_n"], contact["shear_v_n"] = round(float(u), 6), round(float(v), 6)


DIVERGING = "RdBu_r"
"""Matplotlib colour map of a normal change that goes both ways: blue below 0 (a magnet
beside a press, lifted or pushed aside), white at 0, red above (pressed toward its sensor)."""


def _lut(name: str) -> list:
    from matplotlib import colormaps

    return (colormaps[name](np.linspace(0.0, 1.0, 256))[:, :3] * 255).round().astype(int).tolist()


def vector_layout(sensor) -> dict:
    """What the layout message says of a sensor of several components: which component
    the map shows and in what unit, whether arrows are drawn, and the smallest arrow
    scale (ten counts of a tangential component, so that noise alone stays short)."""
    per_count, unit, name = unit_of(sensor)
    normal, tangential = component_roles(sensor)
    names = list(sensor.component_names)
    shown = 0 if normal is None else normal
    floor = 10.0 * float(per_count[tangential[0]]) if tangential is not None else 0.0
    return {
        "vector": {
            "components": names,
            "normal_index": shown,
            "tangential_index": None if tangential is None else list(tangential),
            "unit": unit,
            "map_label": f"{names[shown]} {name} [{unit}]",
            "arrow_label": (
                None
                if tangential is None
                else f"{names[tangential[0]]}, {names[tangential[1]]} {name} [{unit}]"
            ),
            "arrow_floor": floor,
        },
        # the normal change goes both ways: a diverging map, 0 in its middle
        "colormap": {"name": DIVERGING, "lut": _lut(DIVERGING)},
        # counts mode: the dots in counts of the normal component, no surface
        "transduction": {
            "kind": sensor.transduction.kind,
            "counts_per_strain": float(1.0 / per_count[shown]),
            "falling": False,
        },
    }


def baseline_of(frames, n_frames: int) -> np.ndarray:
    """The untouched reading: the median of the first ``n_frames`` frames, any frame shape
    (``(T, rows, cols)`` or ``(T, rows, cols, components)``) [counts]."""
    from tactsense._validation import TactsenseInputError

    frames = np.asarray(frames, dtype=float)
    if frames.ndim < 3 or not 1 <= n_frames <= frames.shape[0]:
        raise TactsenseInputError(
            f"need {n_frames} untouched frames for a baseline; got frames of shape {frames.shape}"
        )
    return np.nanmedian(frames[:n_frames], axis=0)


def warmed(estimator_class, sensor) -> None:
    """Run a contact estimator of taxels of several components once, on an untouched
    frame, before the stream starts: its first estimate builds the sensor's response
    table (seconds on a three-axis pad; cached per sensor description), which would
    otherwise hold the first real frames back and leave a live stream behind."""
    import time

    rest = np.full(tuple(sensor.frame_shape), float(sensor.electronics.nominal_counts))
    estimator = estimator_class(sensor, baseline_frames=1, baseline=rest)
    estimator(StreamFrame(0, 0, 0.0, 0.0, time.perf_counter(), rest))
