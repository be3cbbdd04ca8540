"""The digital twin as a device: frames of the forward model, encoded as firmware would
send them, served on a pseudo-terminal or a TCP port, with faults injected on request.

The device idles until the host sends START, answers IDENTIFY with its identity (the
sensor description among it) at any time, and on STOP, or when its frames run out, sends
END with the last sequence number and the number of frames sent.
"""

from __future__ import annotations

import os
import select
import socket
import threading
import time
import tty
from collections.abc import Iterator
from dataclasses import asdict, dataclass, fields

import numpy as np

from tactsense._validation import TactsenseInputError
from tactsense._version import __version__
from tactsense.io.recording import Recording
from tactsense.sensor import SensorSpec
from tactsense.stream.protocol import (
    FRAME_V2,
    ControlPacket,
    Kind,
    PacketSplitter,
    ProtocolError,
    decode_packet,
    encode_control,
    encode_end,
    encode_frame,
)

FORMAT_BOOT_S = 0.25
"""In another wire format, the device streams this long after a host connects [s] (as a
board that resets when its port opens; pyserial discards what arrived while it opened)."""


@dataclass(frozen=True)
class FaultRates:
    """Probability per frame of each fault the emulated line injects (0 to 1)."""

    garbage: float = 0.0
    """A burst of 1-32 random bytes before the frame (line noise)."""
    bitflip: float = 0.0
    """One bit of the encoded frame inverted."""
    drop: float = 0.0
    """The frame is not sent (its sequence number is used)."""
    truncate: float = 0.0
    """The frame is cut short and delimited."""
    stall: float = 0.0
    """The device pauses ``stall_s`` before the frame."""
    stall_s: float = 0.5
    """Length of a stall [s]."""

    def __post_init__(self) -> None:
        for spec in fields(self):
            value = getattr(self, spec.name)
            if spec.name == "stall_s":
                if not (np.isfinite(value) and 0 <= value <= 60):
                    raise TactsenseInputError(f"stall_s must lie in [0, 60] s; got {value!r}")
            elif not (np.isfinite(value) and 0 <= value <= 1):
                raise TactsenseInputError(
                    f"fault rate {spec.name} must lie in [0, 1] per frame; got {value!r}"
                )


@dataclass
class FaultLog:
    """What the emulator did: frames sent and faults injected, by kind."""

    frames: int = 0
    """Frames the device generated, dropped ones included (= sequence numbers used)."""
    delivered_intact: int = 0
    """Frames sent without any damage."""
    garbage: int = 0
    bitflip: int = 0
    drop: int = 0
    truncate: int = 0
    stall: int = 0

    def as_dict(self) -> dict:
        return asdict(self)


def _host_on_pty(master: int) -> bool:
    """Whether a host holds the slave side of a pseudo-terminal open (the master reports
    a hang-up while nobody does)."""
    poll = select.poll()
    poll.register(master, select.POLLIN)
    return not any(event & select.POLLHUP for _, event in poll.poll(0))


class Emulator:
    """The twin playing the device.

    Parameters
    ----------
    sensor : SensorSpec
    frames : ndarray, shape (T, rows, cols) or (T, rows, cols, components)
        The readings the device sends, in order [counts] (e.g. ``simulate(...).frames``):
        ``(T, *sensor.frame_shape)``. Taxels of several components go out as version-2
        FRAMEs (``docs/protocol.md``).
    speed : float
        Frames go out at ``speed`` times the sensor's scan rate; 0 sends as fast as the
        line takes them.
    faults : FaultRates, optional
    repeat : bool
        Start over when the frames run out (sequence and device clock run on).
    rng : int or Generator, optional
        Seed of the fault draws.
    serial_number : str
        Reported by IDENT; a stream consumer uses it to recognise the device.
    wire_format : WireFormat, optional
        Speak another wire format (``tactsense.stream.sources.FORMATS``,
        ``docs/devices.md``) instead of tactsense's: the device then streams as soon as
        a host connects, ignores what the host sends, and closes the line when its
        frames run out. :attr:`frames` holds the frames as the format carries them.
    """

    def __init__(
        self,
        sensor: SensorSpec,
        frames,
        *,
        speed: float = 1.0,
        faults: FaultRates | None = None,
        repeat: bool = False,
        rng=None,
        serial_number: str = "twin-0001",
        wire_format=None,
    ):
        frames = np.asarray(frames)
        frame_shape = tuple(sensor.frame_shape)
        if (
            frames.ndim != 1 + len(frame_shape)
            or frames.shape[1:] != frame_shape
            or (frames.shape[0] == 0)
        ):
            raise TactsenseInputError(
                f"frames have shape {frames.shape}; expected (T > 0, "
                f"{', '.join(map(str, frame_shape))}) for sensor {sensor.name!r}"
            )
        if not (np.isfinite(speed) and speed >= 0):
            raise TactsenseInputError(f"speed must be a finite number >= 0; got {speed!r}")
        self.sensor = sensor
        self.frames = np.clip(np.nan_to_num(frames), 0, 65535).astype(np.uint16)
        self.format = wire_format
        if wire_format is not None:
            wire_format.check_shape(sensor.shape)
            wire_format.check_components(sensor)
            self.frames = wire_format.prepare(self.frames, sensor.electronics.adc_bits)
        self.speed = float(speed)
        self.faults = faults or FaultRates()
        self.repeat = repeat
        self.serial_number = serial_number
        self.log = FaultLog()
        self._rng = np.random.default_rng(rng)
        self._next = 0
        self._start = 0
        self._stop = threading.Event()
        self._lock = threading.Lock()

    @classmethod
    def from_recording(cls, recording: Recording, **options) -> Emulator:
        """An emulator that sends the frames of a recording.

        A simulation with creep on (``viscoelastic``) knows its creep: the description it
        sends says so (``creep_known = true``), so a client compensates it as ``locate``
        does the recording; a measured recording's description is sent as it is.
        """
        sensor = recording.sensor
        flaws = getattr(sensor, "flaws", None)
        if (
            flaws is not None
            and not recording.source
            and "viscoelastic" in recording.flaws
            and not flaws.creep_known
        ):
            sensor = sensor.replace(flaws__creep_known=True)
        return cls(sensor, recording.frames, **options)

    @property
    def scan_period_s(self) -> float:
        return self.sensor.scan_period_s

    @property
    def frame_rate_hz(self) -> float:
        """Frames per second on the line (0: as fast as it takes them)."""
        return self.sensor.electronics.scan_rate_hz * self.speed

    def identity(self) -> dict:
        """The IDENT body: who the device is and what it measures. A sensor of several
        components per taxel speaks version 2 and says how many (``components``)."""
        components = int(self.sensor.components)
        identity = {
            "device": "tactsense twin",
            "firmware": __version__,
            "serial": self.serial_number,
            "protocol": 1 if components == 1 else FRAME_V2,
            "rows": self.sensor.shape[0],
            "cols": self.sensor.shape[1],
        }
        if components > 1:
            identity["components"] = components
        identity["frame_rate_hz"] = self.frame_rate_hz
        identity["sensor_toml"] = self.sensor.to_toml_string()
        return identity

    # ---- frames on the wire ------------------------------------------------------

    @property
    def exhausted(self) -> bool:
        return not self.repeat and self._next - self._start >= len(self.frames)

    def rewind(self) -> None:
        """Start the frames over at the next frame; sequence and device clock run on."""
        self._start = self._next

    def next_packet(self) -> tuple[bytes, float]:
        """The next frame's bytes on the wire (faults applied) and the stall before it [s].

        Raises StopIteration when the frames are exhausted (and ``repeat`` is off).
        """
        if self.exhausted:
            raise StopIteration
        k = self._next
        self._next += 1
        counts = self.frames[(k - self._start) % len(self.frames)]
        if self.format is None:
            wire = encode_frame(k, round(k * self.scan_period_s * 1e6), counts)
        else:
            wire = self.format.encode(counts)
        rates, rng, log = self.faults, self._rng, self.log
        log.frames += 1
        stall = 0.0
        if rates.stall and rng.random() < rates.stall:
            log.stall += 1
            stall = rates.stall_s
        if rates.drop and rng.random() < rates.drop:
            log.drop += 1
            return b"", stall
        damaged = False
        if rates.bitflip and rng.random() < rates.bitflip:
            log.bitflip += 1
            damaged = True
            data = bytearray(wire)
            data[int(rng.integers(len(wire) - (self.format is None)))] ^= 1 << int(rng.integers(8))
            wire = bytes(data)
        if rates.truncate and rng.random() < rates.truncate:
            log.truncate += 1
            damaged = True
            if self.format is None:
                wire = wire[: int(rng.integers(1, len(wire) - 2))] + b"\x00"
            else:
                wire = self.format.truncate(wire, rng)
        if rates.garbage and rng.random() < rates.garbage:
            log.garbage += 1
            noise = rng.integers(0, 256, int(rng.integers(1, 33)), dtype=np.uint8).tobytes()
            if self.format is not None:  # noise that makes no false delimiter: exact counts
                noise = noise.translate(None, self.format.noise_excluded) or b"\xff"
            damaged |= self.format is not None or not noise.endswith(b"\x00")
            wire = noise + wire
        log.delivered_intact += not damaged
        return wire, stall

    def packets(self, count: int | None = None) -> Iterator[bytes]:
        """The bytes of the next ``count`` frames (all, by default), faults applied, no
        pacing: for replay over ``loop://`` and for benchmarks."""
        produced = 0
        while (count is None or produced < count) and not self.exhausted:
            wire, _ = self.next_packet()
            produced += 1
            if wire:
                yield wire

    def end_packet(self) -> bytes:
        return encode_end(max(self._next - 1, 0), self._next)

    # ---- the device loop ---------------------------------------------------------

    def stop(self) -> None:
        """Ask a running :meth:`serve_fd`, :meth:`serve_tcp` or :meth:`serve_pty` to return."""
        self._stop.set()

    def serve_fd(self, read, write, fileno: int) -> None:
        """Run the device on a byte channel until the host goes away or :meth:`stop`.

        Parameters
        ----------
        read : callable() -> bytes
            Reads what the host sent (empty: the host went away).
        write : callable(bytes)
            Sends bytes to the host.
        fileno : int
            File descriptor to wait on for the host's commands.
        """
        if self.format is not None:
            self._serve_format(read, write, fileno)
            return
        splitter = PacketSplitter()
        streaming = False
        period = self.scan_period_s / self.speed if self.speed > 0 else 0.0
        due = time.perf_counter()
        while not self._stop.is_set():
            now = time.perf_counter()
            if streaming:
                wait = max(due - now, 0.0)
            else:
                wait = 0.1
            ready, _, _ = select.select([fileno], [], [], wait)
            if ready:
                try:
                    data = read()
                except OSError:
                    return
                if not data:
                    return
                for raw in splitter.feed(data):
                    try:
                        packet = decode_packet(raw)
                    except ProtocolError:
                        continue
                    if not isinstance(packet, ControlPacket):
                        continue
                    if packet.kind == Kind.IDENTIFY:
                        write(encode_control(Kind.IDENT, self.identity()))
                    elif packet.kind == Kind.START:
                        if not streaming:
                            self.rewind()  # each host's run starts at the first frame
                        streaming, due = True, time.perf_counter()
                        if self.exhausted:
                            write(self.end_packet())
                            streaming = False
                    elif packet.kind == Kind.STOP:
                        if streaming:
                            write(self.end_packet())
                        streaming = False
                continue
            if not streaming:
                continue
            due += self._send_burst(write, period) + period
            if self.exhausted:
                write(self.end_packet())
                streaming = False

    def _send_burst(self, write, period: float) -> float:
        """Send the next frame (64 at once when unpaced), pausing at injected stalls;
        returns the seconds stalled, by which the next frame is due later."""
        chunks = []
        stalled = 0.0
        for _ in range(1 if period > 0 else 64):
            if self.exhausted:
                break
            wire, stall = self.next_packet()
            if stall:
                if chunks:
                    write(b"".join(chunks))
                    chunks = []
                time.sleep(stall)
                stalled += stall
            chunks.append(wire)
        if chunks:
            write(b"".join(chunks))
        return stalled

    def _serve_format(self, read, write, fileno: int) -> None:
        """Stream in :attr:`format` from the first frame until the frames run out (then
        return: the line closes) or the host goes away; what the host sends is ignored."""
        self.rewind()
        if self._stop.wait(FORMAT_BOOT_S):
            return
        write(self.format.preamble())
        period = self.scan_period_s / self.speed if self.speed > 0 else 0.0
        due = time.perf_counter()
        while not self._stop.is_set() and not self.exhausted:
            ready, _, _ = select.select([fileno], [], [], max(due - time.perf_counter(), 0.0))
            if ready:
                try:
                    if not read():
                        return
                except OSError:
                    return
                continue
            due += self._send_burst(write, period) + period

    def serve_tcp(self, port: int = 0, host: str = "127.0.0.1", *, ready=None) -> None:
        """Serve hosts one after another on a TCP port until :meth:`stop`.

        ``ready(port)`` is called once listening (with the port chosen when ``port`` is 0).
        """
        with socket.create_server((host, port)) as server:
            server.settimeout(0.1)
            if ready is not None:
                ready(server.getsockname()[1])
            while not self._stop.is_set():
                try:
                    conn, _ = server.accept()
                except TimeoutError:
                    continue
                with conn:
                    conn.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
                    conn.setblocking(True)
                    try:
                        self.serve_fd(lambda c=conn: c.recv(1 << 16), conn.sendall, conn.fileno())
                    except (BrokenPipeError, ConnectionResetError):
                        pass

    def open_pty(self) -> tuple[int, int | None, str]:
        """A new pseudo-terminal in raw mode: (master fd, slave fd, slave path).

        In another wire format the slave is closed at once (None): the device then sees
        a host open the line (the master's hang-up clears) and starts to stream
        :data:`FORMAT_BOOT_S` later, as on a TCP port. The protocol's device keeps it
        open (it waits for START; a read of the master never fails).
        """
        master, slave = os.openpty()
        tty.setraw(slave)
        path = os.ttyname(slave)
        if self.format is not None:
            os.close(slave)
            return master, None, path
        return master, slave, path

    def serve_pty(self, master: int) -> None:
        """Serve on the master side of a pseudo-terminal until :meth:`stop`."""

        def write(data: bytes) -> None:
            view = memoryview(data)
            while view and not self._stop.is_set():
                _, ready, _ = select.select([], [master], [], 0.1)
                if ready:
                    view = view[os.write(master, view) :]

        while not self._stop.is_set():
            if self.format is not None and self.exhausted:
                self._stop.wait(0.1)  # a pty never closes: the device is done
                continue
            if self.format is not None and not _host_on_pty(master):
                self._stop.wait(0.01)  # streams only once a host opened the line
                continue
            self.serve_fd(lambda: os.read(master, 1 << 16), write, master)
            time.sleep(0.05)  # the host closed the line; wait for the next one

    def start_tcp(self, port: int = 0) -> tuple[threading.Thread, int]:
        """Serve TCP on 127.0.0.1 in a background thread; returns it and the port."""
        chosen: list[int] = []
        listening = threading.Event()

        def ready(p: int) -> None:
            chosen.append(p)
            listening.set()

        thread = threading.Thread(target=self.serve_tcp, args=(port,), kwargs={"ready": ready})
        thread.daemon = True
        thread.start()
        if not listening.wait(5.0):
            raise TactsenseInputError(f"the emulator could not listen on port {port}")
        return thread, chosen[0]

    def start_pty(self) -> tuple[threading.Thread, str]:
        """Serve on a new pseudo-terminal in a background thread; returns it and its path."""
        master, slave, path = self.open_pty()

        def run() -> None:
            try:
                self.serve_pty(master)
            finally:
                os.close(master)
                if slave is not None:
                    os.close(slave)

        thread = threading.Thread(target=run, daemon=True)
        thread.start()
        return thread, path
