"""The finger on the Lab Streaming Layer: two outlets (frames, contacts) and an inlet.

Outlets (``tactsense live SOURCE --lsl``):

* **frames**: name ``<sensor>-frames``, type ``Tactile``, one float32 channel per
  tactel (rows x cols, row-major: channel ``r * cols + c``), at the sensor's nominal
  rate. Each channel's metadata follows the XDF meta-data conventions
  (github.com/sccn/xdf/wiki/Meta-Data): ``label`` (``r3c5``), ``unit`` (counts),
  ``type`` (Tactile), ``location/X,Y,Z`` [mm] (the taxel's point on the skin, the
  sensor's frame), and, for tactsense's own reader, row, column and (a finger) axial
  position [mm] and angle [deg]. ``acquisition/manufacturer``, ``model`` and
  ``serial_number`` name the device; the stream's metadata also holds the whole
  sensor description (TOML) under ``tactsense/sensor_toml``, so an inlet knows the
  finger without asking. A sensor whose taxels report several components (a three-axis
  taxel) has one channel per taxel and component, the component fastest (channel
  ``(r * cols + c) * 3 + k``), labelled ``r3c5x``, ``r3c5y``, ``r3c5z``, each with its
  ``component`` (x, y, z: the pad's axes) beside the taxel's location, row and column.
* **contacts**: name ``<sensor>-contacts``, type ``TactileContact``, double channels
  ``axial_mm, angle_deg, force_n, skew, peak_deflection, flags, row, col, latency_ms``
  (NaN without a contact), one sample per frame; each channel has a ``label``, a
  ``unit`` and a ``type`` (:data:`CONTACT_UNITS`, :data:`CONTACT_TYPES`).

A pad or a point set (several contacts a frame, tracked) gets a contacts outlet of fixed
width instead: ``n_contacts, force_n, flags, latency_ms`` (the frame: how many contacts,
their summed force [N], the flags of the frame, the latency) then :data:`SLOTS` slots of
``id, x_mm, y_mm, z_mm, force_n`` (slot ``k``'s channels are labelled ``c<k>_id`` ...),
filled in the order of the estimate (largest force first), NaN in the slots left over;
a contact keeps its ``id`` from frame to frame, not its slot (:data:`SLOT_CHANNELS`). A
kind that senses shear (three-axis taxels) has two more channels per slot after these,
``c<k>_shear_x_n``, ``c<k>_shear_y_n``: the contact's tangential force [N].

Both carry a ``source_id`` made from the device's serial number (``tactsense:<serial>:
frames``), so a consumer recovers the stream after the device or tactsense restarts.
Sample timestamps are LSL's clock at the frame's arrival.

The inlet (:class:`LslReader`, ``tactsense record lsl:NAME``) resolves a frames outlet
by name or source_id and reads it like a device.
"""

from __future__ import annotations

import os
import tempfile
import time
from collections.abc import Iterator
from pathlib import Path

import numpy as np

from tactsense._validation import TactsenseInputError
from tactsense.kinds import kind_of
from tactsense.sensor import SensorSpec, SensorSpecError
from tactsense.stream.reader import LossCounters, StreamError, StreamFrame

CONTACT_CHANNELS = (
    "axial_mm",
    "angle_deg",
    "force_n",
    "skew",
    "peak_deflection",
    "flags",
    "row",
    "col",
    "latency_ms",
)
CONTACT_UNITS = ("mm", "deg", "N", "1", "1", "1", "tactel", "tactel", "ms")
"""Units of the contact channels (``1``: a dimensionless number; ``tactel``: an index)."""
CONTACT_TYPES = (
    "Position",
    "Position",
    "Force",
    "Skew",
    "Deflection",
    "Flags",
    "Index",
    "Index",
    "Latency",
)
"""XDF channel ``type`` of each contact channel."""


SLOTS = 8
"""Contact slots of a pad's or point set's contacts outlet (the estimate's default
``max_contacts``)."""
SLOT_FRAME = ("n_contacts", "force_n", "flags", "latency_ms")
SLOT_FRAME_UNITS = ("1", "N", "1", "ms")
SLOT_FRAME_TYPES = ("Count", "Force", "Flags", "Latency")
SLOT_FIELDS = ("id", "x_mm", "y_mm", "z_mm", "force_n")
SLOT_UNITS = ("1", "mm", "mm", "mm", "N")
SLOT_TYPES = ("Id", "Position", "Position", "Position", "Force")
SLOT_CHANNELS = SLOT_FRAME + tuple(f"c{k}_{name}" for k in range(SLOTS) for name in SLOT_FIELDS)
"""Channels of the fixed-width contacts outlet of a pad or point set."""


SHEAR_SLOT_FIELDS = ("shear_x_n", "shear_y_n")
"""A shear-sensing kind's slot fields after :data:`SLOT_FIELDS`: the contact's tangential
force along the sensor's x and y [N] (r8-triinterop)."""


def slot_sample(estimate: dict, fields: tuple[str, ...] = SLOT_FIELDS) -> list[float]:
    """One sample of the fixed-width contacts outlet from a :class:`LiveContacts` estimate
    (``fields`` of each slot: :data:`SLOT_FIELDS`, and :data:`SHEAR_SLOT_FIELDS` after
    them for a kind that senses shear)."""
    sample = [float(estimate[name]) for name in SLOT_FRAME]
    contacts = estimate["contacts"][:SLOTS]
    for contact in contacts:
        sample += [_slot_number(contact.get(name)) for name in fields]
    sample += [float("nan")] * (len(fields) * (SLOTS - len(contacts)))
    return sample


def _slot_number(value) -> float:
    """A slot's number; NaN for a value the estimate has not (None)."""
    return float("nan") if value is None else float(value)


def _acquisition(desc, identity: dict) -> None:
    """The XDF ``acquisition`` block: who made the device and which model it is."""
    acquisition = desc.append_child("acquisition")
    acquisition.append_child_value("manufacturer", str(identity.get("manufacturer", "tactsense")))
    acquisition.append_child_value("model", str(identity.get("device", "tactsense twin")))
    if identity.get("serial"):
        acquisition.append_child_value("serial_number", str(identity["serial"]))


def _pylsl():
    """pylsl, with liblsl's log kept to errors (its INFO lines would fill a terminal)."""
    if "LSLAPICFG" not in os.environ:
        config = Path(tempfile.gettempdir()) / "tactsense-lsl_api.cfg"
        if not config.exists():
            try:
                config.write_text("[log]\nlevel = -3\n")
            except OSError:
                pass
        if config.exists():
            os.environ["LSLAPICFG"] = str(config)
    try:
        import pylsl
    except ImportError:
        raise TactsenseInputError(
            'the Lab Streaming Layer needs the lsl extra: pip install "tactsense[lsl]"'
        ) from None
    return pylsl


def source_id(identity: dict, sensor: SensorSpec, kind: str) -> str:
    """A stable id for a stream: the device's serial number, else the sensor's name."""
    serial = identity.get("serial") or sensor.name
    return f"tactsense:{serial}:{kind}"


def frames_info(sensor: SensorSpec, identity: dict, rate_hz: float):
    """The ``StreamInfo`` of the frames outlet, with per-channel metadata."""
    pylsl = _pylsl()
    rows, cols = sensor.shape
    parts = sensor.component_names if sensor.components > 1 else ("",)
    info = pylsl.StreamInfo(
        f"{sensor.name}-frames",
        "Tactile",
        rows * cols * len(parts),  # a channel per taxel and component
        float(rate_hz),
        pylsl.cf_float32,
        source_id(identity, sensor, "frames"),
    )
    desc = info.desc()
    _acquisition(desc, identity)
    channels = desc.append_child("channels")
    positions = sensor.taxel_positions_mm()
    fields = kind_of(sensor).lsl_taxel_fields(sensor)  # a finger: axial_mm, angle_deg
    for r in range(rows):
        for c in range(cols):
            for part in parts:
                channel = channels.append_child("channel")
                channel.append_child_value("label", f"r{r}c{c}{part}")
                channel.append_child_value("unit", "counts")
                channel.append_child_value("type", "Tactile")
                location = channel.append_child("location")
                for axis, value in zip("XYZ", positions[r * cols + c], strict=True):
                    location.append_child_value(axis, f"{value:.6g}")
                channel.append_child_value("row", str(r))
                channel.append_child_value("col", str(c))
                if part:
                    channel.append_child_value("component", part)
                for field, values in fields.items():
                    channel.append_child_value(field, f"{values[r * cols + c]:.6g}")
    meta = desc.append_child("tactsense")
    meta.append_child_value("sensor_toml", sensor.to_toml_string())
    if sensor.components > 1:
        meta.append_child_value(
            "layout", f"row-major, component fastest: channel = (row * cols + col) * "
            f"{sensor.components} + component ({', '.join(sensor.component_names)})",
        )  # fmt: skip
    else:
        meta.append_child_value("layout", "row-major: channel = row * cols + col")
    return info


def _slot_channels(shear: bool = False):
    """(label, unit, type) of each channel of the fixed-width contacts outlet (with each
    slot's tangential force [N] for a kind that senses shear)."""
    out = list(zip(SLOT_FRAME, SLOT_FRAME_UNITS, SLOT_FRAME_TYPES, strict=True))
    fields = list(zip(SLOT_FIELDS, SLOT_UNITS, SLOT_TYPES, strict=True))
    if shear:
        fields += [(name, "N", "Force") for name in SHEAR_SLOT_FIELDS]
    for k in range(SLOTS):
        out += [(f"c{k}_{n}", u, t) for n, u, t in fields]
    return out


def contacts_info(sensor: SensorSpec, identity: dict, rate_hz: float):
    """The ``StreamInfo`` of the contacts outlet: the finger's one contact, or the slots
    of a pad's or point set's contacts."""
    pylsl = _pylsl()
    slots = kind_of(sensor).multi_contact  # several contacts a frame, tracked: slots
    shear = bool(kind_of(sensor).senses_shear)
    if slots:
        described = _slot_channels(shear)
    else:
        described = list(zip(CONTACT_CHANNELS, CONTACT_UNITS, CONTACT_TYPES, strict=True))
    info = pylsl.StreamInfo(
        f"{sensor.name}-contacts",
        "TactileContact",
        len(described),
        float(rate_hz),
        pylsl.cf_double64,
        source_id(identity, sensor, "contacts"),
    )
    desc = info.desc()
    _acquisition(desc, identity)
    if slots:
        meta = desc.append_child("tactsense")
        meta.append_child_value("slots", str(SLOTS))
        meta.append_child_value(
            "layout", "n_contacts, force_n, flags, latency_ms, then per slot k: "
            "c<k>_id, c<k>_x_mm, c<k>_y_mm, c<k>_z_mm, c<k>_force_n"
            + (", c<k>_shear_x_n, c<k>_shear_y_n" if shear else "") + " (NaN when empty)",
        )  # fmt: skip
    channels = desc.append_child("channels")
    for name, unit, kind in described:
        channel = channels.append_child("channel")
        channel.append_child_value("label", name)
        channel.append_child_value("unit", unit)
        channel.append_child_value("type", kind)
    return info


class LslOutlets:
    """Publish frames and contact estimates of one sensor on two LSL outlets."""

    def __init__(self, sensor: SensorSpec, identity: dict | None = None, rate_hz: float = 0.0):
        pylsl = _pylsl()
        identity = identity or {}
        rate = float(rate_hz or sensor.electronics.scan_rate_hz)
        self.sensor = sensor
        self._slot_fields = SLOT_FIELDS + (
            SHEAR_SLOT_FIELDS if kind_of(sensor).senses_shear else ()
        )
        self.frames = pylsl.StreamOutlet(frames_info(sensor, identity, rate))
        self.contacts = pylsl.StreamOutlet(contacts_info(sensor, identity, rate))
        self._clock = pylsl.local_clock
        self._offset = pylsl.local_clock() - time.perf_counter()

    def push(self, frame: StreamFrame, estimate: dict | None) -> None:
        """One frame (and its estimate, if any), stamped with its arrival on LSL's clock."""
        stamp = frame.arrival + self._offset
        self.frames.push_sample(np.asarray(frame.counts, dtype=np.float32).ravel(), stamp)
        if estimate is not None:
            if "contacts" in estimate:
                sample = slot_sample(estimate, self._slot_fields)
            else:
                sample = [float(estimate[name]) for name in CONTACT_CHANNELS]
            self.contacts.push_sample(sample, stamp)

    def close(self) -> None:
        del self.frames, self.contacts


class LslReader:
    """Frames from an LSL frames outlet, with the interface :func:`~tactsense.stream.record`
    uses (``sensor``, ``url``, ``stats``, ``frames()``).

    Parameters
    ----------
    name : str
        The outlet's name (``fearing1990_initial-frames``) or source_id.
    timeout_s : float
        How long to look for the outlet [s].
    """

    def __init__(self, name: str, *, sensor: SensorSpec | None = None, timeout_s: float = 5.0):
        pylsl = _pylsl()
        self.url = f"lsl:{name}"
        self.stats = LossCounters()
        self.identity: dict = {}
        self.ended = False
        found = pylsl.resolve_byprop("name", name, timeout=timeout_s) or pylsl.resolve_byprop(
            "source_id", name, timeout=0.5
        )
        if not found:
            raise StreamError(
                f"no Lab Streaming Layer outlet named {name!r} (name or source_id) within "
                f"{timeout_s:g} s"
            )
        self.inlet = pylsl.StreamInlet(found[0], max_buflen=60, recover=True)
        info = self.inlet.info(timeout=timeout_s)
        if sensor is None:
            toml = info.desc().child("tactsense").child_value("sensor_toml")
            if not toml:
                raise StreamError(
                    f"{self.url}: the outlet does not describe its sensor (not tactsense's); "
                    "pass the sensor"
                )
            try:
                sensor = SensorSpec.from_toml_string(toml)
            except SensorSpecError as error:
                raise StreamError(f"{self.url}: its sensor description: {error}") from None
        from tactsense.interop.components import describe_values, value_count

        if info.channel_count() != value_count(sensor):  # a channel per taxel and component
            raise StreamError(
                f"{self.url} has {info.channel_count()} channels; the sensor has "
                f"{describe_values(sensor)}"
            )
        self.sensor = sensor
        rate = info.nominal_srate()
        self.frame_period_s = 1.0 / rate if rate > 0 else 0.0
        self.timeout_s = 3 * self.frame_period_s + 0.05 if rate > 0 else 1.0
        self._index = -1
        self._first_stamp: float | None = None
        self._offset = time.perf_counter() - pylsl.local_clock()
        self.inlet.open_stream(timeout=timeout_s)

    def read_batch(self, max_frames: int, wait_s: float = 0.1) -> list[StreamFrame]:
        """Up to ``max_frames`` frames that have arrived, waiting up to ``wait_s`` for one."""
        samples, stamps = self.inlet.pull_chunk(timeout=wait_s, max_samples=max_frames)
        shape = self.sensor.frame_shape
        batch = []
        for sample, stamp in zip(samples, stamps, strict=True):
            if self._first_stamp is None:
                self._first_stamp = stamp
            self._index += 1
            self.stats.frames += 1
            counts = np.rint(np.asarray(sample, dtype=np.float64)).reshape(shape)
            batch.append(
                StreamFrame(
                    self._index % 65536,
                    self._index,
                    stamp - self._first_stamp,
                    time.time(),
                    stamp + self._offset,
                    counts.astype(np.uint16),
                )
            )
        return batch

    def frames(
        self, *, max_frames: int | None = None, duration_s: float | None = None
    ) -> Iterator[StreamFrame]:
        """Yield frames as they arrive, until ``max_frames`` or ``duration_s``."""
        deadline = None if duration_s is None else time.perf_counter() + duration_s
        delivered = 0
        while max_frames is None or delivered < max_frames:
            wait = self.timeout_s
            if deadline is not None:
                wait = min(wait, deadline - time.perf_counter())
                if wait <= 0:
                    return
            want = 1024 if max_frames is None else min(1024, max_frames - delivered)
            batch = self.read_batch(want, wait)
            if not batch:
                self.stats.timeouts += 1
                continue
            yield from batch
            delivered += len(batch)

    def start(self) -> None:
        """An outlet streams by itself: nothing to ask (for the interface of a device)."""

    def close(self) -> None:
        self.inlet.close_stream()

    def __enter__(self) -> LslReader:
        return self

    def __exit__(self, *exc) -> None:
        self.close()
