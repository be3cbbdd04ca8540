"""Float frames with a tail marker: rows x cols little-endian float32 values (x components
per taxel, component fastest, for taxels of several), then the
4-byte tail ``00 00 80 7F`` (VOFA+ "JustFloat"; ``docs/devices.md``).

Decoded with :func:`numpy.frombuffer`; framed by
:class:`~tactsense.stream.framed.DelimitedFramer`. A frame with a value that is no count
once scaled (``value * scale`` not finite, below 0 or above 65535, checked before any
rounding) is garbage; the others become counts as ``floor(value * scale + 0.5)``, the
nearest count with halves rounded up.
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
    parse_offset,
    values_text,
)
from tactsense.stream.reader import LossCounters, StreamError

TAIL = bytes.fromhex("0000807f")
"""VOFA+ JustFloat's tail: float32 +inf, little-endian."""
FLOAT = np.dtype("<f4")


class JustFloat(WireFormat):
    """Little-endian float32 values, then a tail.

    Parameters (``justfloat,tail=0000807F,scale=1``)
    ----------
    tail : str
        The tail as hex digits [default ``0000807F``].
    scale : float
        Counts per unit of the values sent [default 1: the values are counts].
    components : int
        Values per taxel (1..4; default the sensor's: 3 for a three-axis taxel).
    offset : int
        Counts added after scaling (-65535..65535; default 0): counts =
        value * scale + offset, so that signed readings (a magnetometer's field in uT)
        become offset-binary counts (32768 at zero on a 16-bit converter).
    """

    name = "justfloat"
    options: ClassVar[dict[str, str]] = {
        "tail": "hex bytes",
        "scale": "counts per unit",
        "components": "1..4 values per taxel",
        "offset": "counts added",
    }

    def __init__(
        self,
        tail: str = "0000807F",
        scale: str | float = 1.0,
        components: str | int | None = None,
        offset: str | int = 0,
    ):
        self.tail = parse_hex("format justfloat: tail", str(tail))
        try:
            self.scale = float(scale)
        except ValueError:
            self.scale = float("nan")
        if not (np.isfinite(self.scale) and self.scale > 0):
            raise FormatError(
                f"format justfloat: scale={scale!r} must be a finite number above 0 "
                "(counts per unit)"
            )
        self.noise_excluded = bytes(set(self.tail))
        self.components = parse_components("justfloat", components)
        self.offset = parse_offset("justfloat", offset)

    def spec(self) -> str:
        parts = ["justfloat"]
        if self.tail != TAIL:
            parts.append(f"tail={self.tail.hex().upper()}")
        if self.scale != 1.0:
            parts.append(f"scale={self.scale:g}")
        if self.offset:
            parts.append(f"offset={self.offset}")
        return ",".join(parts) + self._components_spec()

    def decoder(self, shape, stats: LossCounters, url: str) -> JustFloatDecoder:
        return JustFloatDecoder(self, tuple(shape), stats, url)

    # ---- the emulator's side ------------------------------------------------------

    def encode(self, counts: np.ndarray) -> bytes:
        values = (np.asarray(counts, np.float64) - self.offset) / self.scale
        return values.astype(FLOAT).tobytes() + self.tail

    def truncate(self, wire: bytes, rng: np.random.Generator) -> bytes:
        """Fewer values than a frame's, then the tail."""
        body = wire[: -len(self.tail)]
        return body[: int(rng.integers(0, len(body)))] + self.tail


class JustFloatDecoder:
    def __init__(self, fmt: JustFloat, shape, stats: LossCounters, url):
        self.shape, self.url, self.stats, self.scale = shape, url, stats, fmt.scale
        self.offset = fmt.offset
        self.framer = DelimitedFramer(
            fmt.tail, int(np.prod(shape)) * 4, leading=False, stats=stats,
            on_shape=self._shape_error,
        )  # fmt: skip

    def _frames(self, raws):
        if not raws:
            return []
        values = np.frombuffer(b"".join(raw for raw, _ in raws), FLOAT).reshape(len(raws), -1)
        values = values.astype(np.float64) * self.scale + self.offset
        with np.errstate(invalid="ignore"):  # the range is checked before rounding
            good = np.isfinite(values).all(1) & (values >= 0).all(1) & (values <= 65535).all(1)
        bad = int(len(raws) - good.sum())
        if bad:  # values that are no counts: not finite, or outside [0, 65535]
            self.stats.garbage += bad
            self.stats.garbage_bytes += bad * len(raws[0][0])
        counts = np.floor(values[good] + 0.5).astype(np.uint16)  # half up
        ends = [end for (_, end), ok in zip(raws, good, strict=True) if ok]
        return list(zip(counts.reshape(-1, *self.shape), ends, strict=True))

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
        raise StreamError(
            f"{self.url}: the device sends {size / 4:g} floats between tails, but the sensor "
            f"has {values_text(self.shape)}; give the sensor of the device (--sensor)"
        )
