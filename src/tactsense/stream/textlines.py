"""Text lines: one frame per line of numbers, as hand-built arrays print them
(``Serial.println`` on an Arduino; ``docs/devices.md``).

A line is rows x cols numbers (rows x cols x components for taxels of several
components, a taxel's components one after the other), row-major, separated by commas,
spaces, tabs or semicolons (any mix), optionally after a fixed prefix, ended by ``\\n`` (a ``\\r``
before it is dropped). Blank lines are skipped; the first ``header`` lines are skipped
too. The lines are split by pyserial's :class:`serial.threaded.Packetizer`.
"""

from __future__ import annotations

from typing import ClassVar

import numpy as np
from serial.threaded import Packetizer

from tactsense.stream.framed import (
    SHAPE_EVIDENCE,
    FormatError,
    WireFormat,
    parse_components,
    parse_offset,
    values_text,
)
from tactsense.stream.reader import LossCounters, StreamError

SEPARATORS = {"comma": ",", "space": " ", "tab": "\t", "semicolon": ";"}
"""The separator the emulator prints, by name (the reader takes any of them)."""

MAX_LINE_BYTES = 1 << 16
"""A line longer than this (or 24 bytes a value) without its newline is garbage."""

_TO_SPACE = bytes.maketrans(b",;\t", b"   ")


class TextLines(WireFormat):
    """One frame per line of numbers.

    Parameters (``text,sep=tab,prefix=F:,header=1``)
    ----------
    sep : {'comma', 'space', 'tab', 'semicolon'}
        What the emulator prints between values (the reader accepts any of them).
    prefix : str
        Every frame line starts with this (stripped; a line without it is garbage).
    header : int
        Lines the device prints first that are not frames (a header row of names).
    components : int
        Values per taxel (1..4; default the sensor's: 3 for a three-axis taxel).
    offset : int
        Counts added to every value (-65535..65535; default 0): 32768 reads the signed
        readings of a magnetometer as offset-binary counts of a 16-bit converter.
    """

    name = "text"
    options: ClassVar[dict[str, str]] = {
        "sep": "comma|space|tab|semicolon",
        "prefix": "text",
        "header": "lines",
        "components": "1..4 values per taxel",
        "offset": "counts added",
    }
    noise_excluded = bytes(range(0x80))  # line noise: bytes no ASCII parser takes

    def __init__(
        self,
        sep: str = "comma",
        prefix: str = "",
        header: str | int = 0,
        components: str | int | None = None,
        offset: str | int = 0,
    ):
        if sep not in SEPARATORS:
            raise FormatError(
                f"format text: sep={sep!r} is not a separator; expected one of "
                f"{', '.join(SEPARATORS)}"
            )
        try:
            header = int(header)
        except ValueError:
            header = -1
        if header < 0:
            raise FormatError(f"format text: header={header!r} must be a number of lines >= 0")
        if not prefix.isascii() or "\n" in prefix or "\r" in prefix:
            raise FormatError(f"format text: prefix={prefix!r} must be ASCII on one line")
        self.sep, self.prefix, self.header = sep, prefix, header
        self.components = parse_components("text", components)
        self.offset = parse_offset("text", offset)

    def spec(self) -> str:
        parts = ["text"]
        if self.sep != "comma":
            parts.append(f"sep={self.sep}")
        if self.prefix:
            parts.append(f"prefix={self.prefix}")
        if self.header:
            parts.append(f"header={self.header}")
        if self.offset:
            parts.append(f"offset={self.offset}")
        return ",".join(parts) + self._components_spec()

    def decoder(self, shape, stats: LossCounters, url: str) -> TextDecoder:
        return TextDecoder(shape, stats, url, self.prefix.encode(), self.header, self.offset)

    # ---- the emulator's side ------------------------------------------------------

    def preamble(self) -> bytes:
        return b"".join(f"# header line {k + 1}\r\n".encode() for k in range(self.header))

    def encode(self, counts: np.ndarray) -> bytes:
        sep = SEPARATORS[self.sep]
        values = (np.asarray(counts, np.int64) - self.offset).ravel().tolist()
        return (self.prefix + sep.join(map(str, values)) + "\r\n").encode()

    def truncate(self, wire: bytes, rng: np.random.Generator) -> bytes:
        """The line cut before its last separator (at least one value lost)."""
        body = wire[:-2]
        last = body.rfind(SEPARATORS[self.sep].encode())
        start = len(self.prefix) + 1
        cut = int(rng.integers(start, last + 1)) if last >= start else len(self.prefix)
        return body[:cut] + b"\r\n"


class TextDecoder(Packetizer):
    """Lines into frames; counts what is no frame (pyserial's packetizer splits)."""

    TERMINATOR = b"\n"

    def __init__(
        self, shape, stats: LossCounters, url: str, prefix: bytes, header: int, offset: int = 0
    ):
        super().__init__()
        self.offset = offset
        self.shape = tuple(shape)  # (rows, cols) or (rows, cols, components)
        self.size = int(np.prod(self.shape))
        self.stats = stats
        self.url = url
        self.prefix = prefix
        self.skip = header
        self.limit = max(MAX_LINE_BYTES, 24 * self.size)
        self._out: list[tuple[np.ndarray, int]] = []
        self._pending: list[tuple[list[bytes], int, int]] = []  # (tokens, size, end)
        self._base = 0  # bytes fed before the line being split
        self._closing = False
        self._framed = False
        self._wrong = (-1, 0)

    def feed(self, data: bytes) -> list[np.ndarray]:
        return [counts for counts, _ in self.feed_ends(data)]

    def finish(self) -> list[np.ndarray]:
        return [counts for counts, _ in self.finish_ends()]

    def feed_ends(self, data: bytes) -> list[tuple[np.ndarray, int]]:
        """Frames completed by ``data``, each with the bytes fed up to its newline."""
        self.data_received(data)
        self._parse()
        if len(self.buffer) > self.limit:  # no newline in sight
            self._garbage(len(self.buffer))
            self._base += len(self.buffer)
            self.buffer.clear()
        out, self._out = self._out, []
        return out

    def finish_ends(self) -> list[tuple[np.ndarray, int]]:
        """The line closed: a last line without its newline is taken as it is."""
        if self.buffer.strip():
            self._closing = True
            self.handle_packet(bytes(self.buffer))
        self.buffer.clear()
        self._parse()
        out, self._out = self._out, []
        return out

    def _garbage(self, size: int) -> None:
        self.stats.garbage += 1
        self.stats.garbage_bytes += size

    def handle_packet(self, packet) -> None:
        # the line's last byte: its newline (none on the last line of a closed line)
        end = self._base + len(packet) + (not self._closing)
        self._base = end
        line = bytes(packet).rstrip(b"\r")
        if self.skip:
            self.skip -= 1
            return
        if not line.strip():
            return
        size = len(line)  # the line ending (\r\n or \n) is no garbage, as no delimiter is
        if self.prefix:
            if not line.startswith(self.prefix):
                self._garbage(size)
                return
            line = line[len(self.prefix) :]
        if b"_" in line:  # Python's float() takes 1_000; a device prints no such number
            self._garbage(size)
            return
        tokens = line.translate(_TO_SPACE).split()
        if len(tokens) == self.size:
            self._framed = True  # the right length: parsed with the others of this read
            self._pending.append((tokens, size, end))
            return
        try:
            np.array(tokens, dtype=np.float64)
        except ValueError:
            self._garbage(size)
            return
        self._wrong_length(len(tokens))
        if len(tokens) < self.size:
            self.stats.truncated += 1
        else:
            self._garbage(size)

    def _parse(self) -> None:
        """The lines of the right length, all at once (one float conversion); a line
        whose values are not counts (fractions, negatives, inf, nan, words) is garbage."""
        pending, self._pending = self._pending, []
        if not pending:
            return
        try:
            values = np.array([t for tokens, _, _ in pending for t in tokens], dtype=np.float64)
            values = values.reshape(len(pending), self.size)
        except ValueError:  # a word among them: line by line
            rows = []
            for tokens, _, _ in pending:
                try:
                    rows.append(np.array(tokens, dtype=np.float64))
                except ValueError:
                    rows.append(np.full(self.size, np.nan))
            values = np.stack(rows)
        counts = np.rint(values)
        with np.errstate(invalid="ignore"):
            whole = (counts == values).all(1)
            counts += self.offset  # offset=N: signed readings as offset-binary counts
            good = whole & (counts >= 0).all(1) & (counts <= 65535).all(1)
        for (_, size, _), ok in zip(pending, good, strict=True):
            if not ok:
                self._garbage(size)
        ends = [end for (_, _, end), ok in zip(pending, good, strict=True) if ok]
        frames = counts[good].astype(np.uint16).reshape(-1, *self.shape)
        self._out.extend(zip(frames, ends, strict=True))

    def _wrong_length(self, n: int) -> None:
        if self._framed:
            return
        size, times = self._wrong
        times = times + 1 if size == n else 1
        self._wrong = (n, times)
        if times >= SHAPE_EVIDENCE:
            raise StreamError(
                f"{self.url}: the device prints lines of {n} values, but the sensor has "
                f"{values_text(self.shape)}; give the sensor of the device (--sensor)"
            )
