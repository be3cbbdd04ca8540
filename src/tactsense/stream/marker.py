"""Marker-framed bytes: a fixed start marker, then rows x cols samples of 8 or 16 bits
(rows x cols x components for taxels of several components, component fastest)
(``docs/devices.md``), the framing of several open-hardware piezoresistive pads (e.g.
``AA 55`` then one ``uint8`` per taxel, row-major).

Decoded with :func:`numpy.frombuffer`; framed by
:class:`~tactsense.stream.framed.DelimitedFramer` (pyserial's ``FramedPacket`` takes a
one-byte start and a one-byte stop, not a multi-byte marker and a length).
"""

from __future__ import annotations

from typing import ClassVar

import numpy as np

from tactsense.stream.framed import (
    DelimitedFramer,
    FormatError,
    WireFormat,
    parse_components,
    parse_hex,
    values_text,
)
from tactsense.stream.reader import LossCounters, StreamError

ORDERS = {"little": "<", "big": ">"}


class MarkerFrames(WireFormat):
    """A start marker, then rows x cols unsigned samples.

    Parameters (``marker,start=AA55,width=16,order=big``)
    ----------
    start : str
        The marker as hex digits, 1 to 8 bytes [default ``AA55``].
    width : {'8', '16'}
        Bits per sample [default 8].
    order : {'little', 'big'}
        Byte order of 16-bit samples [default little].
    components : int
        Samples per taxel (1..4; default the sensor's: 3 for a three-axis taxel).
    signed : {'no', 'yes'}
        Two's-complement samples (a magnetometer's signed field): read as offset-binary
        counts, sample + 2**(width - 1) [default no].
    """

    name = "marker"
    options: ClassVar[dict[str, str]] = {
        "start": "hex bytes",
        "width": "8|16",
        "order": "little|big",
        "components": "1..4 values per taxel",
        "signed": "no|yes",
    }

    def __init__(
        self,
        start: str = "AA55",
        width: str | int = 8,
        order: str = "little",
        components: str | int | None = None,
        signed: str = "no",
    ):
        self.marker = parse_hex("format marker: start", str(start))
        if str(width).strip() not in ("8", "16"):
            raise FormatError(f"format marker: width={width!r} must be 8 or 16 bits a sample")
        self.width = int(width)
        self.sample_bits = self.width
        if order not in ORDERS:
            raise FormatError(f"format marker: order={order!r} must be little or big")
        self.order = order
        if str(signed).strip().lower() not in ("no", "yes"):
            raise FormatError(f"format marker: signed={signed!r} must be no or yes")
        self.signed = str(signed).strip().lower() == "yes"
        kind = "i" if self.signed else "u"
        byte_order = "" if self.width == 8 else ORDERS[order]
        self.dtype = np.dtype(f"{byte_order}{kind}{self.width // 8}")
        self.zero = 1 << (self.width - 1) if self.signed else 0
        """The count of a sample 0 (offset binary): 2**(width - 1) for signed samples."""
        self.noise_excluded = bytes(set(self.marker))
        self.components = parse_components("marker", components)

    def spec(self) -> str:
        order = f",order={self.order}" if self.width == 16 else ""
        signed = ",signed=yes" if self.signed else ""
        return (
            f"marker,start={self.marker.hex().upper()},width={self.width}{order}{signed}"
            + self._components_spec()
        )

    def decoder(self, shape, stats: LossCounters, url: str) -> MarkerDecoder:
        return MarkerDecoder(self, tuple(shape), stats, url)

    # ---- the emulator's side ------------------------------------------------------

    def prepare(self, frames: np.ndarray, adc_bits: int = 16) -> np.ndarray:
        """8 bits: the top 8 of the converter's ``adc_bits`` bits (an 8-bit converter on
        the same range), whatever the frames hold; 16: as they are."""
        if self.width == 16:
            return frames
        shift = max(min(int(adc_bits), 16) - 8, 0)
        return (frames >> shift).astype(np.uint16)

    def encode(self, counts: np.ndarray) -> bytes:
        return self.marker + (np.asarray(counts, np.int64) - self.zero).astype(self.dtype).tobytes()

    def truncate(self, wire: bytes, rng: np.random.Generator) -> bytes:
        """The marker and the first samples, fewer than a frame's."""
        return wire[: int(rng.integers(len(self.marker), len(wire)))]


class MarkerDecoder:
    def __init__(self, fmt: MarkerFrames, shape, stats, url):
        self.shape, self.dtype, self.url, self.zero = shape, fmt.dtype, url, fmt.zero
        self.fmt = fmt
        length = int(np.prod(shape)) * fmt.dtype.itemsize
        self.framer = DelimitedFramer(
            fmt.marker, length, leading=True, stats=stats, on_shape=self._shape_error
        )

    def _frames(self, raws):
        if not raws:
            return []
        joined = np.frombuffer(b"".join(raw for raw, _ in raws), self.dtype)
        joined = (joined.astype(np.int32) + self.zero).astype(np.uint16)  # offset binary
        return list(zip(joined.reshape(-1, *self.shape), (end for _, end in raws), strict=True))

    def feed_ends(self, data: bytes) -> list[tuple[np.ndarray, int]]:
        """Frames completed by ``data``, each with the bytes fed up to its last byte."""
        return self._frames(self.framer.feed_ends(data))

    def finish_ends(self) -> list[tuple[np.ndarray, int]]:
        return self._frames(self.framer.finish_ends())

    def feed(self, data: bytes) -> list[np.ndarray]:
        return [counts for counts, _ in self.feed_ends(data)]

    def finish(self) -> list[np.ndarray]:
        return [counts for counts, _ in self.finish_ends()]

    def _shape_error(self, size: int) -> None:
        samples = size / self.dtype.itemsize
        raise StreamError(
            f"{self.url}: the device sends {samples:g} samples of {self.fmt.width} bits between "
            f"markers, but the sensor has {values_text(self.shape)}; give the sensor of the "
            "device (--sensor) or its width"
        )
