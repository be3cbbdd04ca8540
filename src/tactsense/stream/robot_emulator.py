"""Several boards of one robot skin as emulated devices: one port each, each with its own
clock (an offset and a drift), its own scan rate and its own faults.

A board's frames carry every patch it reads (:mod:`tactsense.stream.robot_layout`). Its
clock runs ``drift_ppm`` faster than the host's: it sends a frame every scan period of its
own clock, ``1 / (1 + drift)`` host seconds, stamped with its own time, which starts
``offset_s`` (rounded to whole scans) ahead of zero.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from tactsense._validation import TactsenseInputError
from tactsense.robot import RobotSkin
from tactsense.stream.emulator import Emulator, FaultRates
from tactsense.stream.robot_layout import DeviceLayout, RobotSourceError, device_layouts

DEFAULT_DRIFT_PPM = 30.0
"""Scale of the drift drawn per device when none is given [ppm]: uniform in +-this (a
crystal's tolerance is tens of ppm)."""

MAX_DRIFT_PPM = 1000.0
"""Largest drift an emulated device takes [ppm]."""


class DeviceEmulator(Emulator):
    """One board: :class:`~tactsense.stream.Emulator` of its packed frames, its clock
    ``drift_ppm`` fast and ``offset_s`` ahead.

    Parameters
    ----------
    layout : DeviceLayout
    frames : ndarray, shape (T, rows, cols)
        Device frames (:meth:`DeviceLayout.pack_streams`) [counts].
    drift_ppm : float
        How much faster the device clock runs than the host's [ppm], in +-1000.
    offset_s : float
        The device clock when it starts to stream for the first time [s], >= 0; rounded
        down to whole scans (the device stamps scan ``n`` at ``n`` scan periods).
    **options
        As :class:`~tactsense.stream.Emulator` (``faults``, ``repeat``, ``rng``...).
    """

    def __init__(
        self,
        layout: DeviceLayout,
        frames,
        *,
        drift_ppm: float = 0.0,
        offset_s: float = 0.0,
        **options,
    ):
        if not (np.isfinite(drift_ppm) and abs(drift_ppm) <= MAX_DRIFT_PPM):
            raise TactsenseInputError(
                f"device {layout.device!r}: drift {drift_ppm!r} ppm; expected a number in "
                f"+-{MAX_DRIFT_PPM:g} ppm"
            )
        if not (np.isfinite(offset_s) and 0 <= offset_s <= 1e7):
            raise TactsenseInputError(
                f"device {layout.device!r}: clock offset {offset_s!r} s; expected 0 to 1e7 s"
            )
        options.setdefault("serial_number", layout.device)
        super().__init__(layout.spec(), frames, speed=1.0 + drift_ppm * 1e-6, **options)
        self.layout = layout
        self.drift_ppm = float(drift_ppm)
        self._next = self._start = int(offset_s * layout.rate_hz)
        self.started_at: float | None = None
        """When the current run's first frame was due on :func:`time.perf_counter` [s]."""
        self.started_scan = self._next
        """The scan number (device clock in scans) of that first frame."""

    def rewind(self) -> None:
        super().rewind()
        self.started_at = time.perf_counter()
        self.started_scan = self._next

    def identity(self) -> dict:
        body = super().identity()
        body["robot_device"] = self.layout.device
        body["patches"] = list(self.layout.patches)
        return body

    def scheduled_host_time(self, device_time_us) -> np.ndarray:
        """When the device sent the frames stamped ``device_time_us`` in the current run,
        on :func:`time.perf_counter` [s]: the truth its clock fit aims at."""
        if self.started_at is None:
            raise TactsenseInputError(f"device {self.layout.device!r} has not streamed yet")
        scans = np.asarray(device_time_us, float) * 1e-6 / self.scan_period_s
        return self.started_at + (scans - self.started_scan) * self.scan_period_s / self.speed


def rest_streams(skin: RobotSkin, frames: int = 50, *, rng=None) -> dict[str, np.ndarray]:
    """Untouched frames of every patch (the twin's read noise only), (frames, rows, cols)
    each [counts]."""
    from tactsense.simulate import ContactBatch, frames_from_contacts

    generator = np.random.default_rng(rng)
    out = {}
    for patch in skin.patches:
        spec = patch.sensor
        flat = frames_from_contacts(
            spec, ContactBatch(np.zeros((frames, 1, 2)), np.zeros((frames, 1))), rng=generator
        )
        out[patch.name] = np.asarray(flat).reshape(frames, *spec.shape)
    return out


@dataclass
class RunningDevice:
    """An emulated device serving TCP on 127.0.0.1 in a thread."""

    emulator: DeviceEmulator
    thread: threading.Thread
    port: int

    @property
    def url(self) -> str:
        return f"socket://127.0.0.1:{self.port}"

    def stop(self) -> None:
        self.emulator.stop()
        self.thread.join(timeout=2.0)


def device_emulators(
    skin: RobotSkin,
    streams: Mapping[str, np.ndarray] | None = None,
    *,
    drift_ppm: Mapping[str, float] | float | None = None,
    offset_s: Mapping[str, float] | float | None = None,
    seed: int = 0,
    faults: Mapping[str, FaultRates] | FaultRates | None = None,
    repeat: bool = True,
) -> dict[str, DeviceEmulator]:
    """An emulator per device of ``skin``.

    Parameters
    ----------
    streams : mapping of patch -> ndarray (T_p, rows, cols), optional
        Each patch's frames at its own rate [counts]; default: 50 untouched frames each
        (:func:`rest_streams`).
    drift_ppm, offset_s : float or mapping of device -> float, optional
        Each device's clock: drift [ppm] and offset [s]. Default: drawn per device with
        ``seed``, drift uniform in +-:data:`DEFAULT_DRIFT_PPM`, offset uniform in 0-100 s.
    faults : FaultRates or mapping of device -> FaultRates, optional
    repeat : bool
        Start the frames over when they run out.
    """
    rng = np.random.default_rng(seed)
    layouts = device_layouts(skin)
    if streams is None:
        streams = rest_streams(skin, rng=rng)
    out = {}
    for device, layout in layouts.items():
        drawn_drift = rng.uniform(-DEFAULT_DRIFT_PPM, DEFAULT_DRIFT_PPM)
        drawn_offset = rng.uniform(0.0, 100.0)
        missing = [p for p in layout.patches if p not in streams]
        if missing:
            raise RobotSourceError(f"device {device!r}: no frames for {', '.join(missing)}")
        out[device] = DeviceEmulator(
            layout,
            layout.pack_streams({p: streams[p] for p in layout.patches}),
            drift_ppm=_per_device(drift_ppm, device, drawn_drift),
            offset_s=_per_device(offset_s, device, drawn_offset),
            faults=_per_device(faults, device, None),
            repeat=repeat,
            rng=int(rng.integers(2**31)),
        )
    return out


def _per_device(value, device: str, default):
    if value is None:
        return default
    if isinstance(value, Mapping):
        return value.get(device, default)
    return value


def start_device_emulators(emulators: Mapping[str, DeviceEmulator]) -> dict[str, RunningDevice]:
    """Serve each emulator on its own TCP port of 127.0.0.1, in a thread each."""
    running = {}
    try:
        for device, emulator in emulators.items():
            thread, port = emulator.start_tcp()
            running[device] = RunningDevice(emulator, thread, port)
    except BaseException:
        for device in running.values():
            device.stop()
        raise
    return running
