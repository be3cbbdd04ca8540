"""Read frames from a tactile device speaking the tactsense protocol, over any pyserial URL.

Every frame that does not arrive is counted: by the kind of damage seen on the line
(bad check, truncated, garbage), and in total from the gaps in the sequence counter
(and, when the device ends the stream, from its END packet). ``frames + lost`` is
the number of frames the device sent up to the last one delivered.

``frames`` counts the frames delivered to the caller (written, estimated), not those
that arrived: a fast device sends more than ``max_frames`` before it sees STOP, and
those are dropped, neither counted as frames nor as losses (:attr:`StreamReader.unused`
says how many).
"""

from __future__ import annotations

import select
import time
from collections import deque
from collections.abc import Iterator
from dataclasses import asdict, dataclass

import numpy as np
import serial

from tactsense._validation import TactsenseInputError
from tactsense.sensor import SensorSpec, SensorSpecError
from tactsense.stream.protocol import (
    SEQUENCE_MODULUS,
    ControlPacket,
    EndPacket,
    FramePacket,
    Kind,
    PacketSplitter,
    ProtocolError,
    decode_packet,
    encode_control,
    encoded_frame_size,
)

LOSS_KINDS = (
    "lost",
    "gaps",
    "bad_check",
    "truncated",
    "garbage",
    "garbage_bytes",
    "timeouts",
    "duplicates",
)
"""Counters of :class:`LossCounters` written with a recording, in this order."""


class StreamError(TactsenseInputError):
    """Raised when a stream cannot be opened or does not speak the protocol."""


@dataclass
class LossCounters:
    """What the reader received and what it lost, by kind."""

    frames: int = 0
    """Frames received intact and delivered to the caller."""
    lost: int = 0
    """Frames missing from the sequence (every gap, and the tail reported by END)."""
    gaps: int = 0
    """Breaks in the sequence (one gap may lose many frames)."""
    bad_check: int = 0
    """Whole packets whose CRC-32 failed."""
    truncated: int = 0
    """Frames cut short before their delimiter."""
    garbage: int = 0
    """Runs of bytes between delimiters that were no packet: the reader resynchronised."""
    garbage_bytes: int = 0
    """Bytes in those runs (delimiters and line endings not included)."""
    timeouts: int = 0
    """Intervals of ``timeout_s`` with no frame."""
    duplicates: int = 0
    """Frames whose sequence number was not newer than the last one (dropped)."""

    def as_dict(self) -> dict:
        return asdict(self)

    def summary(self, frames: int | None = None) -> str:
        """One line for a terminal: every counter that is not zero (``frames``: the
        number of frames kept, when the caller knows it better)."""
        parts = [f"{self.frames if frames is None else frames} frames"]
        for kind in LOSS_KINDS:
            value = getattr(self, kind)
            if value:
                parts.append(f"{kind.replace('_', ' ')} {value}")
        return ", ".join(parts)


STAMP_STEP_S = 1e-6
"""The least step between the time stamps of consecutive frames [s]: a stamp that would
not be later than the one before is raised to it plus this step."""

MAX_READS_KEPT = 4096
"""Reads whose times :class:`ByteClock` keeps (for a frame completed by an earlier read)."""


class ByteClock:
    """When each byte of a line arrived, from the times of the reads that returned it;
    a frame is stamped at its last byte (``docs/recordings.md``, "Time stamps").

    A read returning ``N`` bytes at ``t_read`` (:func:`time.perf_counter`) holds bytes
    that arrived in the window ``(t_lo, t_read]``: ``t_lo`` is the moment the reader's
    wait for the read's first byte ended, or, when the bytes were already waiting, the
    end of the previous read (before the first read: the moment the line opened, or
    START was sent). Byte ``j`` of the read (1 to ``N``) is stamped
    ``t_lo + (t_read - t_lo) * j / N``: the read's last byte at ``t_read``, the others
    spread evenly by position over the window, as a line at a steady rate delivers
    them. Stamps increase strictly: one not later than the stamp before it is raised to
    that stamp plus :data:`STAMP_STEP_S`. The error of a stamp is at most the width of
    its read's window (plus the step for each frame clamped); the window is as long as
    the reader was away from the line (busy, or the data came in a burst).

    The wall-clock stamp is the :func:`time.perf_counter` stamp plus the offset between
    the two clocks at the first read, so it increases strictly too (a step of the
    system clock during a run is not followed).
    """

    def __init__(self):
        self.received = 0
        """Bytes received so far."""
        self._reads: deque[tuple[int, int, float, float]] = deque(maxlen=MAX_READS_KEPT)
        self._last_read: float | None = None
        self._last_stamp = -np.inf
        self.wall_offset: float | None = None
        """``time.time() - time.perf_counter()`` at the first read [s]."""

    def start(self, t: float) -> None:
        """The line is open (or the device was asked to stream) at ``t``: bytes read
        later arrived after it (the first read's window starts here)."""
        self._last_read = t if self._last_read is None else max(self._last_read, t)

    def add(self, size: int, t_read: float, woke: float | None = None) -> None:
        """A read of ``size`` bytes that returned at ``t_read``; ``woke``: when the wait
        for its first byte ended (None: the bytes were waiting when the reader asked)."""
        if self.wall_offset is None:
            self.wall_offset = time.time() - time.perf_counter()
        t_lo = woke if woke is not None else self._last_read
        if t_lo is None or t_lo > t_read:
            t_lo = t_read
        self._last_read = t_read
        if size <= 0:
            return
        self._reads.append((self.received, self.received + size, t_lo, t_read))
        self.received += size

    def byte_time(self, end: int) -> float:
        """The arrival of the ``end``-th byte received (counting from 1) [s,
        perf_counter], spread by position over its read's window."""
        reads = self._reads
        while len(reads) > 1 and reads[0][1] < end:
            reads.popleft()  # frames are stamped in order: earlier reads are done with
        if not reads:
            return time.perf_counter()
        start, stop, t_lo, t_read = reads[0]
        j = min(max(end - start, 0), stop - start)
        return t_lo + (t_read - t_lo) * j / (stop - start)

    def stamp(self, end: int) -> tuple[float, float]:
        """The stamps of a frame whose last byte is the ``end``-th received: (arrival
        on :func:`time.perf_counter`, Unix time) [s], later than the frame before."""
        t = max(self.byte_time(end), self._last_stamp + STAMP_STEP_S)
        self._last_stamp = t
        return t, t + (self.wall_offset or 0.0)


@dataclass(frozen=True)
class StreamFrame:
    """One frame as it arrived."""

    sequence: int
    """Sequence number on the wire (wraps at 65536)."""
    index: int
    """Frames the device sent before this one since the first frame received (unwrapped)."""
    device_time_s: float
    """Start of the frame's scan on the device clock [s]."""
    host_time_s: float
    """Arrival of the frame's last byte on the host's wall clock, Unix time [s]."""
    arrival: float
    """Arrival on :func:`time.perf_counter` [s], for latency measurements."""
    counts: np.ndarray
    """(rows, cols) readings [counts]; (rows, cols, components) for taxels of several
    components (the sensor's ``frame_shape``)."""
    device_time_us: int = -1
    """Start of the frame's scan on the device clock, exactly as sent [us] (-1: unknown,
    a frame that did not come over the wire protocol)."""


def _shape_text(shape: tuple[int, ...]) -> str:
    """``4x4 tactels`` or ``4x4 tactels x 3 components``, for messages."""
    text = f"{shape[0]}x{shape[1]} tactels"
    return text if len(shape) == 2 else f"{text} x {shape[2]} components"


def stream_timeouts(
    timeout_s: float | None, first_frame_timeout_s: float | None, frame_period_s: float
) -> tuple[float, float]:
    """The timeouts of a reader [s]: between frames (default three frame periods plus
    50 ms) and before the first frame (default the longer of 5 s and that)."""
    timeout = float(timeout_s) if timeout_s is not None else 3 * frame_period_s + 0.05
    if not timeout > 0:
        raise StreamError(f"timeout_s must be positive; got {timeout_s!r}")
    first = float(first_frame_timeout_s) if first_frame_timeout_s is not None else max(5.0, timeout)
    return timeout, first


def open_port(url: str, *, baudrate: int = 921600) -> serial.SerialBase:
    """Open a pyserial port (device path, pty path, ``socket://HOST:PORT``, ``loop://``)."""
    _check_socket_url(url)
    try:
        return serial.serial_for_url(url, baudrate=baudrate, timeout=0)
    except (serial.SerialException, ValueError, OSError) as error:
        raise StreamError(f"cannot open {url}: {error}") from None


def _check_socket_url(url: str) -> None:
    """One clear line for a malformed ``socket://HOST:PORT`` (pyserial answers with its
    whole URL grammar, log levels included)."""
    if not url.lower().startswith("socket://"):
        return
    address = url[len("socket://") :].split("?", 1)[0]
    host, colon, port = address.rpartition(":")
    if not colon or not host:
        raise StreamError(f"{url}: expected socket://HOST:PORT, e.g. socket://127.0.0.1:5000")
    if not port.isdigit():
        raise StreamError(f"{url}: port {port!r} is not a number; expected 1-65535")
    if not 1 <= int(port) <= 65535:
        raise StreamError(f"{url}: port {int(port)} is out of range 1-65535")


class StreamReader:
    """Frames from one device, with their losses counted.

    Parameters
    ----------
    url : str
        Any pyserial URL: ``/dev/ttyUSB0``, a pty path, ``socket://127.0.0.1:PORT``,
        ``loop://``; or an open pyserial port.
    sensor : SensorSpec, optional
        The finger on the line. Default: ask the device (IDENTIFY) and use the sensor
        description it returns.
    timeout_s : float, optional
        A frame later than this after the previous one counts as a timeout [s].
        Default: 3 frame periods plus 50 ms.
    start : bool
        Send START once open (a device streams only after START); pass False to
        prepare first (e.g. compile an estimator) and call :meth:`start` after.
    identify_timeout_s : float
        How long to wait for the device's IDENT answer [s].
    first_frame_timeout_s : float, optional
        A device that sends no intact frame this long after START is an error
        (:class:`StreamError`) [s]. Default: the larger of 5 s and ``timeout_s``.

    Examples
    --------
    >>> with StreamReader("socket://127.0.0.1:5000") as stream:   # doctest: +SKIP
    ...     for frame in stream.frames(max_frames=100):
    ...         print(frame.sequence, frame.counts.max())
    ...     print(stream.stats.summary())
    """

    def __init__(
        self,
        url,
        *,
        sensor: SensorSpec | None = None,
        timeout_s: float | None = None,
        start: bool = True,
        identify_timeout_s: float = 3.0,
        first_frame_timeout_s: float | None = None,
    ):
        self.url = url if isinstance(url, str) else getattr(url, "port", repr(url))
        self.port = open_port(url) if isinstance(url, str) else url
        self.stats = LossCounters()
        self.identity: dict = {}
        self.ended = False
        self.frames_sent: int | None = None
        self._splitter = PacketSplitter()
        self._clock = ByteClock()
        self._ready: deque[tuple[StreamFrame, int]] = deque()  # (frame, sequence step)
        self.unused = 0
        """Intact frames that arrived after the caller stopped taking them (not kept)."""
        self._finished = False
        self._end_sequence: int | None = None  # END's last sequence, until settled
        self._received_any = False
        self._started_at: float | None = None
        self._last_seq: int | None = None
        self._last_time_us = 0
        self._index = -1
        self._fileno = self._fileno_of(self.port)
        self.sensor: SensorSpec | None = None
        self.frame_period_s = 0.0
        self._scan_period_s = 0.0
        self._frame_bytes: int | None = None
        try:
            if sensor is None:
                sensor = self._identify(identify_timeout_s)
            self.sensor = sensor
            rows, cols = sensor.shape
            self._frame_bytes = encoded_frame_size(rows, cols, sensor.components) - 1
            rate = float(self.identity.get("frame_rate_hz") or sensor.electronics.scan_rate_hz)
            self.frame_period_s = 1.0 / rate if rate > 0 else 0.0
            self._scan_period_s = sensor.scan_period_s
            self.timeout_s, self.first_frame_timeout_s = stream_timeouts(
                timeout_s, first_frame_timeout_s, self.frame_period_s
            )
            if start:
                self.start()
        except BaseException:
            self.port.close()
            raise

    @staticmethod
    def _fileno_of(port) -> int | None:
        try:
            return port.fileno()
        except (AttributeError, OSError, serial.SerialException):
            return None

    # ---- receiving ---------------------------------------------------------------

    def _receive(self, wait_s: float) -> tuple[bytes, float | None]:
        """Bytes that arrived, waiting up to ``wait_s`` for the first, and when the wait
        for them ended (None: they were waiting already)."""
        if self._fileno is not None:
            woke = None
            ready, _, _ = select.select([self._fileno], [], [], 0)
            if not ready:
                ready, _, _ = select.select([self._fileno], [], [], max(wait_s, 0.0))
                if not ready:
                    return b"", None
                woke = time.perf_counter()
            data = self.port.read(1 << 16)
            if not data:
                raise StreamError(f"{self.url}: the device closed the line")
            return data, woke
        deadline = time.perf_counter() + wait_s
        woke = None
        while True:  # ports without a file descriptor (loop://): poll
            waiting = self.port.in_waiting
            if waiting:
                return self.port.read(waiting), woke
            now = time.perf_counter()
            if now >= deadline:
                return b"", None
            time.sleep(0.0005)
            woke = time.perf_counter()

    def _pump(self, wait_s: float) -> bool:
        """Receive and decode what arrives within ``wait_s``; True if anything came."""
        try:
            data, woke = self._receive(wait_s)
        except (serial.SerialException, OSError) as error:
            raise StreamError(f"{self.url}: {error}") from None
        if not data:
            return False
        self._clock.add(len(data), time.perf_counter(), woke)
        for raw, end in self._splitter.feed_ends(data):
            self._handle(raw, end)
        return True

    def _handle(self, raw: bytes, end: int) -> None:
        try:
            packet = decode_packet(raw, self._frame_bytes)
        except ProtocolError as error:
            setattr(self.stats, error.reason, getattr(self.stats, error.reason) + 1)
            if error.reason == "garbage":
                self.stats.garbage_bytes += len(raw)
            return
        if isinstance(packet, FramePacket):
            self._accept(packet, end)
        elif isinstance(packet, EndPacket):
            self._end_sequence = packet.last_sequence
            self.frames_sent = packet.frames_sent
            self.ended = True
        elif isinstance(packet, ControlPacket) and packet.kind == Kind.IDENT:
            self.identity = packet.body

    def _accept(self, packet: FramePacket, end: int) -> None:
        if self.sensor is not None and packet.counts.shape != self.sensor.frame_shape:
            raise StreamError(
                f"{self.url}: the device sends frames of {_shape_text(packet.counts.shape)}, "
                f"but the sensor {self.sensor.name} has {_shape_text(self.sensor.frame_shape)}; "
                "give the device's own sensor description (--sensor) or fix its IDENT"
            )
        self._received_any = True
        if self._finished:
            self.unused += 1  # arrived after the caller stopped: not kept, not lost
            return
        if self._last_seq is None:
            step = 1
        elif packet.device_time_us <= self._last_time_us:
            self.stats.duplicates += 1  # the device clock only moves forward
            return
        else:
            step = (packet.sequence - self._last_seq) % SEQUENCE_MODULUS
            if self._scan_period_s > 0:
                # the device clock (one scan period per frame) tells how many times the
                # counter wrapped in a long gap
                elapsed = (packet.device_time_us - self._last_time_us) * 1e-6
                wraps = round((elapsed / self._scan_period_s - step) / SEQUENCE_MODULUS)
                step += SEQUENCE_MODULUS * max(wraps, 0)
            if step == 0:
                self.stats.duplicates += 1
                return
        self._last_seq = packet.sequence
        self._last_time_us = packet.device_time_us
        self._index += step
        arrival, host_time = self._clock.stamp(end)
        frame = StreamFrame(
            packet.sequence,
            self._index,
            packet.device_time_us * 1e-6,
            host_time,
            arrival,
            packet.counts,
            int(packet.device_time_us),
        )
        self._ready.append((frame, step))

    def _settle_end(self) -> None:
        """Count the frames the device sent after the last one received as lost, once
        every frame received has been delivered: unless the caller stopped taking
        frames before them (then they do not belong to its run)."""
        if self._end_sequence is None or self._ready:
            return
        last, self._end_sequence = self._end_sequence, None
        if self._last_seq is not None and not self.unused:
            tail = (last - self._last_seq) % SEQUENCE_MODULUS
            if tail:
                self.stats.lost += tail
                self.stats.gaps += 1

    def _deliver(self) -> StreamFrame:
        """The next frame for the caller; the frame and the gap before it count now."""
        frame, step = self._ready.popleft()
        self.stats.frames += 1
        if step > 1:
            self.stats.lost += step - 1
            self.stats.gaps += 1
        return frame

    def _check_streaming(self, now: float) -> None:
        """Raise if nothing intact came within ``first_frame_timeout_s`` of START."""
        if self._received_any or self._started_at is None:
            return
        if now - self._started_at >= self.first_frame_timeout_s:
            seen = self.stats.summary().removeprefix("0 frames")
            raise StreamError(
                f"{self.url}: no frame arrived within {self.first_frame_timeout_s:g} s of "
                f"START{'; seen' + seen if seen else ''}; is the device streaming? "
                "(--timeout sets a longer wait)"
            )

    def _identify(self, timeout_s: float) -> SensorSpec:
        self.port.write(encode_control(Kind.IDENTIFY))
        deadline = time.perf_counter() + timeout_s
        while not self.identity and time.perf_counter() < deadline:
            self._pump(min(0.05, timeout_s))
        if not self.identity:
            raise StreamError(
                f"{self.url}: no answer to IDENTIFY within {timeout_s:g} s; is a device "
                "speaking the tactsense protocol on this line? (pass a sensor to skip IDENTIFY)"
            )
        try:
            sensor = SensorSpec.from_toml_string(str(self.identity.get("sensor_toml", "")))
        except SensorSpecError as error:
            raise StreamError(f"{self.url}: the device's sensor description: {error}") from None
        said = self.identity.get("components", 1)
        if said != sensor.components:  # IDENT's count against its own description
            raise StreamError(
                f"{self.url}: the device says {said!r} components per taxel, but its sensor "
                f"description {sensor.name!r} has {sensor.components}; fix its IDENT or give "
                "the sensor (--sensor)"
            )
        self._ready.clear()  # frames before START belong to nobody's run
        self._last_seq = None
        self._index = -1
        self.stats = LossCounters()
        return sensor

    # ---- the public iteration ----------------------------------------------------

    def frames(
        self, *, max_frames: int | None = None, duration_s: float | None = None
    ) -> Iterator[StreamFrame]:
        """Yield frames as they arrive, until ``max_frames``, ``duration_s`` or END."""
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
            if self.ended and not self._ready:
                self._settle_end()
                return
            now = time.perf_counter()
            if deadline is not None and now >= deadline:
                return
            self._check_streaming(now)
            wait = self.timeout_s - (now - last_frame)
            if deadline is not None:
                wait = min(wait, deadline - now)
            if wait <= 0:
                self.stats.timeouts += 1
                last_frame = now
                continue
            self._pump(wait)

    __iter__ = frames

    def read_batch(self, max_frames: int, wait_s: float = 0.1) -> list[StreamFrame]:
        """Up to ``max_frames`` frames that have arrived, waiting up to ``wait_s`` for one."""
        if not self._ready:
            self._pump(wait_s)
        while self._pump(0.0) and len(self._ready) < max_frames:
            pass
        batch = [self._deliver() for _ in range(min(max_frames, len(self._ready)))]
        if self.ended:
            self._settle_end()
        return batch

    def start(self) -> None:
        """Ask the device to stream (sent by the constructor unless ``start=False``)."""
        try:
            self.port.write(encode_control(Kind.START))
        except (serial.SerialException, OSError) as error:
            raise StreamError(f"{self.url}: cannot send START: {error}") from None
        self._started_at = time.perf_counter()
        self._clock.start(self._started_at)

    def stop(self, wait_s: float = 1.0) -> None:
        """Ask the device to stop and account for the frames it sent before END.

        The caller takes no more frames: those waiting and those still arriving are
        dropped (counted in :attr:`unused`, not in ``stats``). Waits up to ``wait_s``
        [s] for END, whose count of frames sent tells whether the last frames before
        the stop were lost on the line. Calling it again does nothing.
        """
        if self._finished:
            return
        self._finished = True
        self.unused += len(self._ready)
        self._ready.clear()
        if not self.ended and self.port.is_open:
            try:
                self.port.write(encode_control(Kind.STOP))
                deadline = time.perf_counter() + wait_s
                while not self.ended and time.perf_counter() < deadline:
                    self._pump(min(0.05, wait_s))
            except (serial.SerialException, OSError, StreamError):
                pass
        self.unused += len(self._ready)  # a frame sent before STOP and after the last taken
        self._ready.clear()
        self._settle_end()

    def close(self) -> None:
        """Tell the device to stop streaming (if it still is) and close the line."""
        if self.port.is_open:
            if not self.ended and not self._finished:
                try:
                    self.port.write(encode_control(Kind.STOP))
                    self.port.flush()
                except (serial.SerialException, OSError):
                    pass
            self.port.close()

    def __enter__(self) -> StreamReader:
        return self

    def __exit__(self, *exc) -> None:
        self.close()
