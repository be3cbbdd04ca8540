"""The reader of the wire formats that existing arrays speak (``docs/devices.md``).

Each format is a small module of this package (``textlines``, ``marker``,
``justfloat``) with one class: it parses its options, decodes bytes into frames while
counting what it can count, and encodes frames for the emulator. :class:`FormatReader`
runs any of them on a pyserial line with the interface of
:class:`~tactsense.stream.StreamReader` (``frames()``, ``read_batch()``, ``stats``,
``start``/``stop``/``close``); ``tactsense.stream.sources`` resolves a source string
through one table.

None of these formats carries a sequence number, a check or a device clock: ``lost``
and ``gaps`` stay 0 (a frame that never arrived is invisible), ``truncated`` counts
frames seen cut short, ``garbage`` runs of bytes (or lines) that were no frame, and
the device time of a frame is its host arrival time since the first frame.
"""

from __future__ import annotations

import dataclasses
import os
import select
import time
from collections import deque
from collections.abc import Iterator
from typing import ClassVar

import numpy as np
import serial

from tactsense._validation import TactsenseInputError
from tactsense.sensor import SensorSpec
from tactsense.stream.protocol import MAX_COMPONENTS
from tactsense.stream.reader import (
    ByteClock,
    LossCounters,
    StreamError,
    StreamFrame,
    open_port,
    stream_timeouts,
)

RAW_PORTS = ("serial.urlhandler.protocol_socket", "serial.serialposix")
"""pyserial port classes whose file descriptor carries the bytes as they are."""

SHAPE_EVIDENCE = 3
"""Runs of one wrong length in a row, before any frame, that make a shape error."""


class FormatError(TactsenseInputError):
    """A wire format's options are not valid."""


def parse_hex(name: str, value: str, *, max_bytes: int = 8) -> bytes:
    """Bytes from hex digits (``AA55``, ``0xAA55``, ``AA 55`` or ``aa:55``)."""
    digits = value.strip().lower().removeprefix("0x").replace(" ", "").replace(":", "")
    try:
        data = bytes.fromhex(digits)
    except ValueError:
        data = b""
    if not data or len(data) > max_bytes:
        raise FormatError(
            f"{name}={value!r} is not a marker of hex bytes; expected 1 to {max_bytes} bytes "
            "as hex digits, e.g. AA55"
        )
    return data


def parse_options(name: str, text: str, allowed: dict[str, str]) -> dict[str, str]:
    """``key=value`` pairs separated by commas, each key one of ``allowed``."""
    options: ClassVar[dict[str, str]] = {}
    for item in filter(None, (part.strip() for part in text.split(","))):
        key, equals, value = item.partition("=")
        key = key.strip().lower()
        if not equals or key not in allowed:
            known = ", ".join(f"{k}=<{v}>" for k, v in allowed.items()) or "none"
            raise FormatError(f"format {name}: unknown option {item!r}; its options: {known}")
        options[key] = value.strip()
    return options


def parse_components(name: str, value) -> int | None:
    """The ``components=N`` option of a format: 1 to 4 values per taxel (None: unset)."""
    if value is None:
        return None
    try:
        count = int(str(value).strip())
    except ValueError:
        count = 0
    if not 1 <= count <= MAX_COMPONENTS:
        raise FormatError(
            f"format {name}: components={value!r} must be a whole number of values per taxel "
            f"from 1 to {MAX_COMPONENTS} (3 for a three-axis taxel)"
        )
    return count


def parse_offset(name: str, value) -> int:
    """The ``offset=N`` option of a format: whole counts added to every value, -65535 to
    65535 (32768 puts a signed reading's zero at the middle of a 16-bit converter)."""
    try:
        number = float(str(value).strip())
    except ValueError:
        number = float("nan")
    if not (np.isfinite(number) and number == int(number) and abs(number) <= 65535):
        raise FormatError(
            f"format {name}: offset={value!r} must be whole counts from -65535 to 65535 "
            "(e.g. 32768 for signed readings on a 16-bit converter)"
        )
    return int(number)


def values_text(shape: tuple[int, ...]) -> str:
    """What a frame of ``shape`` holds, for messages: ``4x4 = 16 tactels`` or
    ``4x4 tactels x 3 components = 48 values``."""
    rows, cols = shape[:2]
    if len(shape) == 2:
        return f"{rows}x{cols} = {rows * cols} tactels"
    return f"{rows}x{cols} tactels x {shape[2]} components = {rows * cols * shape[2]} values"


class WireFormat:
    """What every format module provides (subclasses fill it in)."""

    name = ""
    options: ClassVar[dict[str, str]] = {}
    """Option names and what each takes (for messages and docs)."""
    noise_excluded = b""
    """Bytes the emulator's line noise avoids (so that injected faults count exactly)."""

    def spec(self) -> str:
        """The format and its options as a source prefix (``marker,start=AA55,...``)."""
        raise NotImplementedError

    sample_bits: int | None = None
    """Bits a sample carries (None: any count, as text or floats)."""

    def check_shape(self, shape: tuple[int, int]) -> None:
        """Raise :class:`FormatError` if frames of this shape cannot be carried."""

    components: int | None = None
    """Values per taxel on the line, from the option ``components=N`` (1..4; a line
    carries a taxel's components one after the other, the taxels row-major); None:
    the sensor's (``SensorSpec.components``)."""

    def check_components(self, sensor: SensorSpec) -> None:
        """Raise :class:`FormatError` if ``components=N`` disagrees with the sensor."""
        if self.components is None or self.components == sensor.components:
            return
        names = ", ".join(sensor.component_names[: sensor.components])
        raise FormatError(
            f"format {self.name}: components={self.components}, but the sensor "
            f"{sensor.name!r} reports {sensor.components} per taxel"
            f"{f' ({names})' if sensor.components > 1 else ''}; give the sensor of the "
            f"device (--sensor) or components={sensor.components}"
        )

    def _components_spec(self) -> str:
        return "" if self.components is None else f",components={self.components}"

    def sensor_as_sent(self, sensor: SensorSpec) -> SensorSpec:
        """The sensor as a device of this format sends it: with samples narrower than its
        converter, a converter of the samples' bits on the same range (``adc_bits`` the
        sample's, ``nominal_counts`` scaled by the bits dropped); otherwise as it is."""
        bits, width = int(sensor.electronics.adc_bits), self.sample_bits
        if width is None or bits <= width:
            return sensor
        el = sensor.electronics
        scaled = dataclasses.replace(
            el, adc_bits=width, nominal_counts=el.nominal_counts / 2 ** (bits - width)
        )
        return dataclasses.replace(sensor, electronics=scaled)

    def check_converter(self, sensor: SensorSpec, url: str = "") -> None:
        """Raise :class:`~tactsense.stream.StreamError` if the samples cannot carry the
        counts of the sensor's converter (``adc_bits`` above ``sample_bits``): read as
        the described converter's counts, the device's would be silently too small."""
        bits, width = int(sensor.electronics.adc_bits), self.sample_bits
        if width is None or bits <= width:
            return
        scale = 2 ** (bits - width)
        nominal = sensor.electronics.nominal_counts
        raise StreamError(
            f"{url or self.spec()}: the device sends {width}-bit samples, but the sensor "
            f"{sensor.name!r} describes a {bits}-bit converter (nominal {nominal:g} counts): "
            f"read against it, every count would be {scale}x too small. Describe the device as "
            "it sends: "
            f"a sensor TOML with [electronics] adc_bits = {width} and nominal_counts = "
            f'{nominal / scale:g} (docs/devices.md, "Samples narrower than the converter")'
        )

    def decoder(self, shape: tuple[int, int], stats: LossCounters, url: str):
        """A new decoder: ``feed(bytes) -> list[ndarray]`` and ``finish() -> list``, and
        ``feed_ends``/``finish_ends``, which pair each frame with the number of bytes fed
        up to and including its last byte (for its time stamp)."""
        raise NotImplementedError

    # ---- the emulator's side ------------------------------------------------------

    def prepare(self, frames: np.ndarray, adc_bits: int = 16) -> np.ndarray:
        """The frames (uint16 counts of an ``adc_bits`` converter) as this format carries
        them (default: as they are)."""
        return frames

    def preamble(self) -> bytes:
        """Bytes the device sends once when a host connects (e.g. a header line)."""
        return b""

    def encode(self, counts: np.ndarray) -> bytes:
        """One frame on the wire."""
        raise NotImplementedError

    def truncate(self, wire: bytes, rng: np.random.Generator) -> bytes:
        """A frame's bytes cut short, as a reader sees a frame that lost its end."""
        raise NotImplementedError


class DelimitedFramer:
    """Frames of ``length`` bytes, each next to a fixed delimiter: a start marker before
    it (``leading``) or a tail after it.

    In step, the framer only checks that the delimiter is where it must be (so a
    delimiter's bytes inside a frame do no harm); out of step, it looks for the next
    delimiter and classifies the run of bytes before it: exactly a frame, shorter
    (``truncated``) or longer (``garbage``). With a start marker a frame is confirmed
    by the next frame's marker, so it is delivered when that marker arrives (or when
    the line closes), but its last byte is that of its own samples: the frame is
    stamped when ``length`` bytes after its marker were complete, not when the next
    marker came.

    :meth:`feed_ends` returns each frame with the number of bytes fed up to and
    including its last byte (the tail, with a tail; the last sample, with a marker).
    """

    def __init__(
        self, delimiter: bytes, length: int, *, leading: bool, stats: LossCounters, on_shape
    ):
        self.delimiter = delimiter
        self.length = length
        self.leading = leading
        self.stats = stats
        self._on_shape = on_shape  # called with a run length seen repeatedly before any frame
        self._buffer = bytearray()
        self._base = 0  # bytes fed before buffer[0]
        self._in_step = False
        self._first = True
        self._framed = False  # a frame was delivered
        self._wrong: tuple[int, int] = (-1, 0)  # (run length, times in a row)
        self._limit = 2 * (length + len(delimiter)) + (1 << 16)

    def feed(self, data: bytes) -> list[bytes]:
        return [frame for frame, _ in self.feed_ends(data)]

    def _drop(self, size: int) -> None:
        del self._buffer[:size]
        self._base += size

    def feed_ends(self, data: bytes) -> list[tuple[bytes, int]]:
        """Frames completed by ``data``, each with the bytes fed up to its last byte."""
        buffer, delimiter, length = self._buffer, self.delimiter, self.length
        buffer.extend(data)
        out: list[tuple[bytes, int]] = []
        width = len(delimiter)
        tail = 0 if self.leading else width  # a tail belongs to its frame, a marker not
        while True:
            if self._in_step:
                if len(buffer) < length + width:
                    break
                if buffer[length : length + width] == delimiter:
                    out.append((bytes(buffer[:length]), self._base + length + tail))
                    self._drop(length + width)
                    self._framed = True
                    continue
                self._in_step = False
            at = buffer.find(delimiter)
            if at < 0:
                if len(buffer) > self._limit:  # no delimiter in sight: one run of garbage
                    keep = width - 1
                    self._garbage(len(buffer) - keep)
                    self._drop(len(buffer) - keep)
                break
            run = bytes(buffer[:at])
            end = self._base + at + tail
            self._drop(at + width)
            first, self._first = self._first, False
            self._in_step = True
            if self.leading and first:
                if run:
                    self._garbage(len(run))  # before the first marker: no frame
                continue
            frame = self._classify(run, first)
            if frame is not None:
                out.append((frame, end))
        return out

    def finish(self) -> list[bytes]:
        return [frame for frame, _ in self.finish_ends()]

    def finish_ends(self) -> list[tuple[bytes, int]]:
        """The line closed: what is left is a last frame (after a marker) or a cut one."""
        rest, self._buffer = bytes(self._buffer), bytearray()
        end = self._base + len(rest)
        self._base = end
        if not rest:
            return []
        if self._first:  # no delimiter yet: joined mid-frame, as before a first delimiter
            self._garbage(len(rest))
            return []
        if self.leading and self._in_step and len(rest) == self.length:
            return [(rest, end)]
        if len(rest) < self.length:
            self.stats.truncated += 1
        else:
            self._garbage(len(rest))
        return []

    def _garbage(self, size: int) -> None:
        self.stats.garbage += 1
        self.stats.garbage_bytes += size

    def _classify(self, run: bytes, first: bool) -> bytes | None:
        if len(run) == self.length:
            self._framed = True
            return run
        if not self._framed and not first:
            size, times = self._wrong
            times = times + 1 if size == len(run) else 1
            self._wrong = (len(run), times)
            if times >= SHAPE_EVIDENCE:
                self._on_shape(len(run))
        if first:  # joined mid-frame
            self._garbage(len(run))
        elif len(run) < self.length:
            self.stats.truncated += 1
        else:
            self._garbage(len(run))
        return None


class FormatReader:
    """Frames of a device speaking one of the formats of ``docs/devices.md``.

    Parameters
    ----------
    url : str or pyserial port
        The line (any pyserial URL, as for :class:`~tactsense.stream.StreamReader`).
    wire_format : WireFormat
    sensor : SensorSpec
        The array on the line: these formats do not describe it (rows x cols from here).
    timeout_s : float, optional
        A frame later than this after the previous one counts as a timeout [s].
        Default: 3 scan periods of the sensor plus 50 ms.
    start : bool
        Kept for the interface of ``StreamReader``: these devices stream by themselves.
    first_frame_timeout_s : float, optional
        No intact frame this long after opening is an error [s]. Default: the larger
        of 5 s and ``timeout_s``.
    """

    def __init__(
        self,
        url,
        wire_format: WireFormat,
        *,
        sensor: SensorSpec | None,
        timeout_s: float | None = None,
        start: bool = True,
        first_frame_timeout_s: float | None = None,
    ):
        name = url if isinstance(url, str) else getattr(url, "port", repr(url))
        self.url = f"{wire_format.spec()}:{name}"
        self.format = wire_format
        if sensor is None:
            raise StreamError(
                f"{self.url}: {wire_format.name} frames do not say which sensor sent them; "
                "give the sensor (--sensor: a preset such as pad16, or a TOML file)"
            )
        wire_format.check_shape(sensor.shape)
        wire_format.check_components(sensor)
        wire_format.check_converter(sensor, self.url)
        self.sensor = sensor
        self.stats = LossCounters()
        self.identity: dict = {"device": f"{wire_format.name} device", "format": wire_format.spec()}
        self.ended = False
        self.unused = 0
        """Intact frames that arrived after the caller stopped taking them (not kept)."""
        self.frame_period_s = sensor.scan_period_s
        self.timeout_s, self.first_frame_timeout_s = stream_timeouts(
            timeout_s, first_frame_timeout_s, self.frame_period_s
        )
        # the decoders cut frames of the sensor's frame_shape: (rows, cols[, components])
        self._decoder = wire_format.decoder(tuple(sensor.frame_shape), self.stats, self.url)
        self._clock = ByteClock()
        self._ready: deque[StreamFrame] = deque()
        self._index = -1
        self._first_arrival: float | None = None
        self._finished = False
        self._started_at: float | None = None
        self.port = open_port(url) if isinstance(url, str) else url
        try:
            self._fileno = self.port.fileno()
        except (AttributeError, OSError, serial.SerialException):
            self._fileno = None
        # pyserial's socket read drops what it has read when the peer closes in the same
        # call; on a plain socket or serial device the descriptor is read directly
        self._raw = self._fileno is not None and type(self.port).__module__ in RAW_PORTS
        self._clock.start(time.perf_counter())  # the device streams once the line opens
        if start:
            self.start()

    # ---- receiving ---------------------------------------------------------------

    def _receive(self, wait_s: float) -> tuple[bytes | None, float | None]:
        """Bytes that arrived within ``wait_s`` (None: the line closed), and when the
        wait for them ended (None: they were waiting already)."""
        if self._fileno is not None:
            woke = None
            ready, _, _ = select.select([self._fileno], [], [], 0)
            if not ready:
                ready, _, _ = select.select([self._fileno], [], [], max(wait_s, 0.0))
                if not ready:
                    return b"", None
                woke = time.perf_counter()
            if self._raw:  # an empty read is the end of the line
                try:
                    return os.read(self._fileno, 1 << 16) or None, woke
                except OSError:  # a pty whose other side closed: EIO
                    return None, woke
            try:
                data = self.port.read(1 << 16)
            except serial.SerialException:  # pyserial's word for a peer that hung up
                return None, woke
            return (data if data else None), woke
        deadline = time.perf_counter() + wait_s
        woke = None
        while True:  # ports without a file descriptor (loop://): poll
            waiting = self.port.in_waiting
            if waiting:
                return self.port.read(waiting), woke
            if time.perf_counter() >= deadline:
                return b"", None
            time.sleep(0.0005)
            woke = time.perf_counter()

    def _pump(self, wait_s: float) -> bool:
        if self.ended:
            return False
        try:
            data, woke = self._receive(wait_s)
        except (serial.SerialException, OSError) as error:
            raise StreamError(f"{self.url}: {error}") from None
        if data is None:  # no END in these formats: the line closing ends the stream
            self.ended = True
            self._accept(self._decoder.finish_ends())
            if self._first_arrival is None:
                seen = self.stats.summary().removeprefix("0 frames")
                raise StreamError(
                    f"{self.url}: the line closed before any frame arrived"
                    f"{'; seen' + seen if seen else ''}; is the device sending "
                    f"{self.format.name} frames of "
                    f"{values_text(tuple(self.sensor.frame_shape))}?"
                )
            return True
        if not data:
            return False
        self._clock.add(len(data), time.perf_counter(), woke)
        self._accept(self._decoder.feed_ends(data))
        return True

    def _accept(self, frames: list[tuple[np.ndarray, int]]) -> None:
        for counts, end in frames:
            if self._finished:
                self.unused += 1
                continue
            arrival, host_time = self._clock.stamp(end)
            if self._first_arrival is None:
                self._first_arrival = arrival
            self._index += 1
            self._ready.append(
                StreamFrame(
                    self._index % 65536,
                    self._index,
                    arrival - self._first_arrival,
                    host_time,
                    arrival,
                    counts,
                )
            )

    def _deliver(self) -> StreamFrame:
        self.stats.frames += 1
        return self._ready.popleft()

    def _check_streaming(self, now: float) -> None:
        if self._first_arrival is not None or self._started_at is None:
            return
        if now - self._started_at >= self.first_frame_timeout_s:
            seen = self.stats.summary().removeprefix("0 frames")
            raise StreamError(
                f"{self.url}: no frame arrived within {self.first_frame_timeout_s:g} s"
                f"{'; seen' + seen if seen else ''}; is the device sending "
                f"{self.format.name} frames of {values_text(tuple(self.sensor.frame_shape))}? "
                "(--timeout sets a longer wait)"
            )

    # ---- the interface of StreamReader -------------------------------------------

    def frames(
        self, *, max_frames: int | None = None, duration_s: float | None = None
    ) -> Iterator[StreamFrame]:
        """Yield frames as they arrive, until ``max_frames``, ``duration_s`` or the line
        closes."""
        deadline = None if duration_s is None else time.perf_counter() + duration_s
        delivered = 0
        last_frame = time.perf_counter()
        while max_frames is None or delivered < max_frames:
            while self._ready and (max_frames is None or delivered < max_frames):
                yield self._deliver()
                delivered += 1
                last_frame = time.perf_counter()
            if max_frames is not None and delivered >= max_frames:
                return
            if self.ended:
                return
            now = time.perf_counter()
            if deadline is not None and now >= deadline:
                return
            self._check_streaming(now)
            wait = self.timeout_s - (now - last_frame)
            if deadline is not None:
                wait = min(wait, deadline - now)
            if wait <= 0:
                self.stats.timeouts += self._first_arrival is not None  # not while booting
                last_frame = now
                continue
            self._pump(wait)

    __iter__ = frames

    def read_batch(self, max_frames: int, wait_s: float = 0.1) -> list[StreamFrame]:
        """Up to ``max_frames`` frames that have arrived, waiting up to ``wait_s`` for one."""
        if not self._ready:
            self._pump(wait_s)
        while len(self._ready) < max_frames and self._pump(0.0):
            pass
        return [self._deliver() for _ in range(min(max_frames, len(self._ready)))]

    def start(self) -> None:
        """These devices stream by themselves: the wait for a first frame starts now."""
        self._started_at = time.perf_counter()

    def stop(self, wait_s: float = 0.0) -> None:
        """Take no more frames (those waiting count in :attr:`unused`); nothing to send."""
        if self._finished:
            return
        self._finished = True
        self.unused += len(self._ready)
        self._ready.clear()

    def close(self) -> None:
        if self.port.is_open:
            self.port.close()

    def __enter__(self) -> FormatReader:
        return self

    def __exit__(self, *exc) -> None:
        self.close()
