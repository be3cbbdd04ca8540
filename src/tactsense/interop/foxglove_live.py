"""Frames and contacts served live to Foxglove over its WebSocket protocol (``foxglove-sdk``).

``tactsense live SOURCE --foxglove [HOST:]PORT`` and ``tactsense view SOURCE --foxglove
[HOST:]PORT`` start a Foxglove WebSocket server with the channels of the MCAP export
(:mod:`tactsense.interop.mcap`), byte for byte: the same topics (``/tactile_states``,
``/tactile_contacts``, ``/contact_states``), the same schemas (``tactile_msgs/msg/...`` in
the ``ros2msg`` encoding, the same definition texts) and the same CDR messages, built by
the MCAP writer's own encoder. A Foxglove user opens the app, connects to
``ws://HOST:PORT`` and sees the sensor as it arrives; a layout made on an exported MCAP
file works unchanged. The server binds 127.0.0.1 unless told otherwise.

Stamps (headers and log times) are each frame's arrival on the host's clock (Unix time
[ns]), as ``record --out X.mcap`` stamps them. Contacts are what the command estimates
(``live``'s locator, the view's): a finger's one contact, or every tracked contact of a
pad or a point set named ``<sensor>/<id>``, with the normal of the nearest taxel, as in
the export. A frame still in the baseline (no estimate yet) has an empty
``TactileContacts``.
"""

from __future__ import annotations

import io
import math

import numpy as np

from tactsense._validation import TactsenseInputError
from tactsense.interop.mcap import (
    CONTACT_LISTS_TOPIC,
    CONTACTS_TOPIC,
    STATES_TOPIC,
    McapTactileWriter,
)
from tactsense.interop.ros import (
    TACTILE_CONTACT,
    TACTILE_CONTACT_MSGDEF,
    TACTILE_CONTACTS,
    TACTILE_CONTACTS_MSGDEF,
    TACTILE_STATE,
    TACTILE_STATE_MSGDEF,
)
from tactsense.kinds import kind_of

DEFAULT_HOST = "127.0.0.1"
DEFAULT_PORT = 8765
"""Foxglove's usual port: the app's "Foxglove WebSocket" connection offers ws://localhost:8765."""

CHANNELS = (
    (STATES_TOPIC, TACTILE_STATE, TACTILE_STATE_MSGDEF),
    (CONTACTS_TOPIC, TACTILE_CONTACT, TACTILE_CONTACT_MSGDEF),
    (CONTACT_LISTS_TOPIC, TACTILE_CONTACTS, TACTILE_CONTACTS_MSGDEF),
)
"""Topic, schema name and ``ros2msg`` definition of each channel, as in the MCAP export."""

SCHEMA_ENCODING = "ros2msg"
MESSAGE_ENCODING = "cdr"


class FoxgloveAddressError(TactsenseInputError):
    """A ``--foxglove`` address that is not ``[HOST:]PORT``."""


def parse_address(text: str) -> tuple[str, int]:
    """``[HOST:]PORT`` as (host, port); the host 127.0.0.1 when none is given.

    ``PORT`` is 0-65535 (0: a free port); an IPv6 host goes in brackets
    (``[::1]:8765``).
    """
    text = str(text).strip()
    host, sep, port = text.rpartition(":")
    if not sep:
        host, port = DEFAULT_HOST, text
    elif host.startswith("[") and host.endswith("]"):
        host = host[1:-1]
    elif ":" in host:
        raise FoxgloveAddressError(
            f"--foxglove {text!r}: put an IPv6 address in brackets, e.g. [::1]:{DEFAULT_PORT}"
        )
    if not host or any(c.isspace() for c in host):
        raise FoxgloveAddressError(
            f"--foxglove {text!r}: expected [HOST:]PORT, e.g. {DEFAULT_PORT} or "
            f"127.0.0.1:{DEFAULT_PORT}"
        )
    if not port.isdigit() or not 0 <= int(port) <= 65535:
        raise FoxgloveAddressError(
            f"--foxglove {text!r}: the port must be a whole number 0-65535 (0: a free port), "
            f"e.g. {DEFAULT_PORT}"
        )
    return host, int(port)


def _sdk():
    try:
        import foxglove
    except ImportError:
        raise TactsenseInputError(
            'Foxglove live needs the foxglove extra: pip install "tactsense[foxglove]"'
        ) from None
    return foxglove


def check_available() -> None:
    """Raise a one-line :class:`TactsenseInputError` when ``foxglove-sdk`` (or the MCAP
    encoder the messages are built with) is missing."""
    from tactsense.interop.mcap import _writer_class

    _sdk()
    _writer_class()


class _Channels:
    """Stands in for the MCAP writer under :class:`McapTactileWriter`: each message its
    fast path makes goes to the Foxglove channel of its topic instead of into a file."""

    def __init__(self, channels: dict):
        self.channels = channels

    def add_message(self, *, channel_id, log_time, publish_time, sequence, data) -> None:
        self.channels[channel_id].log(data, log_time=int(log_time))


class _LiveEncoder(McapTactileWriter):
    """The MCAP writer's encoder, its messages sent to Foxglove channels (by topic).

    The MCAP writer underneath writes only its header and schema records into a small
    buffer, never a message: memory does not grow with the run."""

    def __init__(self, sensor, channels: dict, frame_id: str):
        super().__init__(io.BytesIO(), sensor, frame_id=frame_id, chunk_size=1024, fast=True)
        self._raw = _Channels(channels)

    def _channel(self, topic: str, schema) -> str:
        return topic


class FoxgloveLive:
    """A Foxglove WebSocket server with the MCAP export's channels; :meth:`push` sends
    one frame and its estimate (the interface of :class:`tactsense.interop.lsl.LslOutlets`).

    Parameters
    ----------
    sensor : SensorSpec, PadSpec or PointsSpec, optional
        The sensor of the frames; None binds the server now and takes the sensor later
        (:meth:`attach`), as ``live`` and ``view`` do before they open their source.
    host : str
        Address to bind; 127.0.0.1 (this machine only) by default.
    port : int
        TCP port, 0-65535 (0: a free port; :attr:`port` says which).
    frame_id : str
        The ``frame_id`` of every header, as the export's ``--frame-id``.
    name : str, optional
        The server's name shown by Foxglove (default ``tactsense <sensor>``).

    Raises
    ------
    TactsenseInputError
        Without ``foxglove-sdk``, or when the address cannot be bound (in use, not this
        machine's).
    """

    def __init__(
        self,
        sensor=None,
        *,
        host: str = DEFAULT_HOST,
        port: int = DEFAULT_PORT,
        frame_id: str = "finger",
        name: str | None = None,
    ):
        from tactsense.estimate import Flag

        foxglove = _sdk()
        self._no_contact = int(Flag.NO_CONTACT)
        self.sensor = None
        self.host = host
        self._frame_id = frame_id
        self._context = foxglove.Context()
        self.channels = {
            topic: foxglove.Channel(
                topic,
                schema=foxglove.Schema(
                    name=schema, encoding=SCHEMA_ENCODING, data=definition.encode()
                ),
                message_encoding=MESSAGE_ENCODING,
                context=self._context,
            )
            for topic, schema, definition in CHANNELS
        }
        try:
            self._server = foxglove.start_server(
                name=name or ("tactsense" if sensor is None else f"tactsense {sensor.name}"),
                host=host,
                port=int(port),
                context=self._context,
            )
        except Exception as error:  # the SDK raises RuntimeError with the OS's reason
            self._close_channels()
            raise TactsenseInputError(f"cannot serve Foxglove on {host}:{port}: {error}") from None
        self.port = int(self._server.port)
        self.frames = 0
        self.contacts = 0
        if sensor is not None:
            self.attach(sensor)

    def attach(self, sensor) -> None:
        """Say which sensor the frames come from (a server bound before its source was
        opened: ``sensor`` None at construction); before the first :meth:`push`."""
        self.sensor = sensor
        self._multi = kind_of(sensor).multi_contact
        if self._multi:
            self._positions = np.asarray(sensor.taxel_positions_mm(), dtype=float)
            self._normals = np.asarray(sensor.taxel_normals(), dtype=float)
        self._encoder = _LiveEncoder(sensor, self.channels, self._frame_id)

    @property
    def url(self) -> str:
        """``ws://HOST:PORT``, what Foxglove's "Open connection" asks for."""
        host = f"[{self.host}]" if ":" in self.host else self.host
        return f"ws://{host}:{self.port}"

    def push(self, frame, estimate: dict | None) -> None:
        """Send one frame (``TactileState``) and its contacts (``TactileContact`` each,
        and their ``TactileContacts``), stamped with the frame's arrival on the host.

        Parameters
        ----------
        frame : StreamFrame
            Its ``counts`` [counts] and ``host_time_s`` [s, Unix time].
        estimate : dict or None
            What ``live``'s locator returned for it (None while the baseline is taken).
        """
        t = float(frame.host_time_s)
        writer = self._encoder
        writer.frame(frame.counts, t, sequence=int(frame.sequence))
        if estimate is None:
            writer.contacts_at([t], np.zeros(0, int), np.zeros((0, 3)), np.zeros((0, 3)), [])
            self.frames += 1  # counted once every message of the frame is sent
            return
        if not self._multi:
            force = estimate.get("force_n")
            touching = (
                not int(estimate.get("flags", 0)) & self._no_contact
                and force is not None
                and math.isfinite(force)
            )
            axial, angle = (_number(estimate.get(k)) for k in ("axial_mm", "angle_deg"))
            writer.contacts_of([t], [axial], [angle], [force if touching else 0.0], [touching])
            self.frames += 1
            self.contacts += int(touching)
            return
        kept = [c for c in estimate.get("contacts", []) if _located(c)]
        xyz = np.array([[c["x_mm"], c["y_mm"], c["z_mm"]] for c in kept], dtype=float)
        xyz = xyz.reshape(-1, 3)
        nearest = (
            np.argmin(((xyz[:, None, :] - self._positions[None, :, :]) ** 2).sum(axis=-1), axis=1)
            if len(xyz)
            else np.zeros(0, int)
        )
        names = [f"{self.sensor.name}/{c['id']}" for c in kept]
        force = np.array([c["force_n"] for c in kept], dtype=float)
        from tactsense.interop.components import contact_shear  # r8-triinterop

        writer.contacts_at(
            [t], np.zeros(len(kept), int), xyz * 1e-3, self._normals[nearest], force, names,
            shear_n=contact_shear(kept),
        )  # fmt: skip
        self.frames += 1
        self.contacts += len(kept)

    def _close_channels(self) -> None:
        for channel in self.channels.values():
            channel.close()

    def close(self) -> None:
        """Stop the server (clients see the connection close) and close the channels."""
        server, self._server = getattr(self, "_server", None), None
        if server is not None:
            server.stop()
        self._close_channels()

    def __enter__(self):
        return self

    def __exit__(self, *exc) -> None:
        self.close()


def _number(value) -> float:
    """A JSON-ready estimate's number (None for not-a-number) as a float."""
    return float("nan") if value is None else float(value)


def _located(contact: dict) -> bool:
    """A contact with a position and a force (as the export keeps them)."""
    values = [contact.get(k) for k in ("x_mm", "y_mm", "z_mm", "force_n")]
    return all(v is not None and math.isfinite(float(v)) for v in values)


class PublishingLocator:
    """A locator that also pushes every frame and its estimate to ``sink``
    (:class:`FoxgloveLive`); everything else is the wrapped locator's.

    ``tactsense view --foxglove`` wraps its feed's locator so: the page and Foxglove
    show the same frames and the same estimates.
    """

    def __init__(self, locator, sink):
        self._locator = locator
        self._sink = sink

    def __call__(self, frame):
        estimate = self._locator(frame)
        self._sink.push(frame, estimate)
        return estimate

    def __getattr__(self, name: str):
        return getattr(self._locator, name)
