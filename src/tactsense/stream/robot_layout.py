"""How a board carries several patches on one line: one frame per scan, every patch's
taxels in it (``docs/robot.md``, "Capture from several devices").

A device (a board of :attr:`tactsense.robot.RobotSkin.devices`) scans at the rate of its
fastest patch; a patch whose rate is that divided by an integer ``k`` is read at every
``k``-th scan (scan number ``n`` with ``n % k == 0``, ``n`` counted by the device clock)
and holds its last reading in between. Each frame on the wire is an ordinary tactsense
frame (protocol version 1, unchanged): its taxels are every patch's, flattened row-major
in the skin's order, then zeros up to the frame's shape: ``cols = min(N, 255)`` and
``rows = ceil(N / cols)`` for ``N`` taxels in all (the protocol's frame is at most
255 x 255).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from tactsense._validation import TactsenseInputError
from tactsense.robot import RobotSkin
from tactsense.sensor import Grid, preset

MAX_SIDE = 255
"""Most rows or columns of a frame on the wire."""


class RobotSourceError(TactsenseInputError):
    """A skin's devices or sources that do not fit together."""


@dataclass(frozen=True)
class DeviceLayout:
    """Where each patch of one device lies in the device's frames.

    Attributes
    ----------
    device : str
    patches : tuple of str
        In the skin's order.
    shapes : tuple of (rows, cols)
        Each patch's frame shape.
    every : tuple of int
        Each patch is read at every ``every``-th scan of the device [-].
    rate_hz : float
        The device's scan rate: its fastest patch's [Hz].
    frame_shape : (rows, cols)
        The shape of the device's frames on the wire.
    """

    device: str
    patches: tuple[str, ...]
    shapes: tuple[tuple[int, int], ...]
    every: tuple[int, ...]
    rate_hz: float
    frame_shape: tuple[int, int]

    @classmethod
    def of(cls, skin: RobotSkin, device: str) -> DeviceLayout:
        """The layout of ``device`` of ``skin``, or an error saying why a board cannot
        scan its patches together."""
        devices = skin.devices
        if device not in devices:
            raise RobotSourceError(
                f"{skin.name!r} has no device {device!r}; its devices: {', '.join(devices)}"
            )
        names = devices[device]
        sensors = [skin.patch(name).sensor for name in names]
        rates = [float(s.electronics.scan_rate_hz) for s in sensors]
        fastest = max(rates)
        every = []
        for name, rate in zip(names, rates, strict=True):
            k = fastest / rate
            if not (rate > 0 and abs(k - round(k)) < 1e-6 * k):
                raise RobotSourceError(
                    f"device {device!r}: patch {name!r} scans at {rate:g} Hz, which does not "
                    f"divide its fastest patch's {fastest:g} Hz; a board reads every patch "
                    "at its own rate divided by a whole number"
                )
            every.append(round(k))
        total = sum(s.n_taxels for s in sensors)
        cols = min(total, MAX_SIDE)
        rows = math.ceil(total / cols)
        if rows > MAX_SIDE:
            raise RobotSourceError(
                f"device {device!r} reads {total} taxels; a frame on the wire holds at most "
                f"{MAX_SIDE * MAX_SIDE}: split its patches over more devices"
            )
        return cls(
            device=device,
            patches=tuple(names),
            shapes=tuple(tuple(s.shape) for s in sensors),
            every=tuple(every),
            rate_hz=fastest,
            frame_shape=(rows, cols),
        )

    @property
    def n_taxels(self) -> int:
        return sum(r * c for r, c in self.shapes)

    @property
    def scan_period_s(self) -> float:
        return 1.0 / self.rate_hz

    def spec(self):
        """A sensor description of the device's frames (a pad of ``frame_shape`` at
        ``rate_hz``, named after the device): what a reader of its line is given."""
        rows, cols = self.frame_shape
        spec = preset("pad16").replace(
            grid=Grid(rows=rows, cols=cols), electronics__scan_rate_hz=self.rate_hz
        )
        return dataclasses.replace(spec, name=self.device)

    def pack(self, frames: dict[str, np.ndarray]) -> np.ndarray:
        """One device frame (``frame_shape``, uint16) from a frame of each patch."""
        flat = [np.asarray(frames[name]).reshape(-1) for name in self.patches]
        out = np.zeros(self.frame_shape[0] * self.frame_shape[1], dtype=np.uint16)
        out[: self.n_taxels] = np.concatenate(flat)
        return out.reshape(self.frame_shape)

    def unpack(self, frame: np.ndarray, scan: int | None = None) -> dict[str, np.ndarray]:
        """Each patch's frame in a device frame: the patches read at scan number ``scan``
        (every patch when None) [counts]."""
        flat = np.asarray(frame).reshape(-1)
        out = {}
        start = 0
        for name, (rows, cols), k in zip(self.patches, self.shapes, self.every, strict=True):
            stop = start + rows * cols
            if scan is None or scan % k == 0:
                out[name] = flat[start:stop].reshape(rows, cols)
            start = stop
        return out

    def pack_streams(self, streams: dict[str, np.ndarray], scans: int | None = None) -> np.ndarray:
        """Device frames (T, rows, cols) from each patch's frames at its own rate
        ((T_p, rows, cols) each): scan ``n`` holds frame ``n // k`` of a patch read every
        ``k``-th scan (its frames repeat when they run out). ``scans``: how many
        (default: as many as the patch with the fewest scans' worth of frames fills)."""
        if scans is None:
            scans = min(len(streams[p]) * k for p, k in zip(self.patches, self.every, strict=True))
        out = np.zeros((scans, self.frame_shape[0] * self.frame_shape[1]), dtype=np.uint16)
        start = 0
        n = np.arange(scans)
        for name, (rows, cols), k in zip(self.patches, self.shapes, self.every, strict=True):
            stream = np.asarray(streams[name])
            if stream.ndim != 3 or stream.shape[1:] != (rows, cols) or not len(stream):
                raise RobotSourceError(
                    f"patch {name!r}: frames of shape {stream.shape}; expected (T > 0, "
                    f"{rows}, {cols})"
                )
            stop = start + rows * cols
            flat = np.clip(np.nan_to_num(stream.reshape(len(stream), -1)), 0, 65535)
            out[:, start:stop] = flat[(n // k) % len(stream)]
            start = stop
        return out.reshape(scans, *self.frame_shape)


def device_layouts(skin: RobotSkin) -> dict[str, DeviceLayout]:
    """Every device's layout, in the skin's order."""
    return {device: DeviceLayout.of(skin, device) for device in skin.devices}
