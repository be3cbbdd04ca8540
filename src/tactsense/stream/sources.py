"""Sources by name: one table from a format's name to its module (``docs/devices.md``).

A source is a pyserial URL (the tactsense protocol), or ``FORMAT[,KEY=VALUE...]:URL``
for a device that speaks another wire format, e.g. ``text:/dev/ttyACM0``,
``marker,start=AA55,width=16:socket://127.0.0.1:5000``, ``justfloat:/dev/ttyUSB0``.

>>> from tactsense.stream.sources import open_source            # doctest: +SKIP
>>> with open_source("text:/dev/ttyACM0", sensor=load_sensor("pad16")) as stream:
...     for frame in stream.frames(max_frames=100):
...         ...
"""

from __future__ import annotations

import re

from tactsense.sensor import SensorSpec
from tactsense.stream.framed import (
    FormatError,
    FormatReader,
    WireFormat,
    parse_components,
    parse_options,
)
from tactsense.stream.justfloat import JustFloat
from tactsense.stream.marker import MarkerFrames
from tactsense.stream.protocol import MAX_COMPONENTS
from tactsense.stream.reader import StreamReader
from tactsense.stream.textlines import TextLines

FORMATS: dict[str, type[WireFormat]] = {
    "text": TextLines,
    "marker": MarkerFrames,
    "justfloat": JustFloat,
}
"""Every wire format besides tactsense's own, by the name a source or --format gives."""


def parse_format(spec: str) -> WireFormat:
    """A format from ``NAME[,KEY=VALUE...]`` (``marker,start=AA55,width=16``)."""
    name, _, rest = spec.strip().partition(",")
    name = name.strip().lower()
    if name not in FORMATS:
        raise FormatError(
            f"unknown wire format {name!r}; expected one of {', '.join(FORMATS)} "
            "(with options, e.g. marker,start=AA55,width=16)"
        )
    cls = FORMATS[name]
    return cls(**parse_options(name, rest, cls.options))


_LINE = re.compile(r"[A-Za-z][\w+.-]*://|/|\.|COM\d|[A-Za-z]:\\", re.IGNORECASE)
"""How a line begins: a URL, a path, a Windows port."""


_FORMAT_NAME = re.compile(r"([A-Za-z][\w-]+)(,[^:]*)?:")
"""A word (two letters or more: not a Windows drive) and options, before a colon."""


def _check_unknown_format(source: str) -> None:
    """Raise for ``NAME:LINE`` whose NAME is no format (``csvline:/dev/ttyACM0``): the
    line is a URL or a path, so the word before it can only be meant as a format."""
    match = _FORMAT_NAME.match(source)
    if match and _LINE.match(source, match.end()):
        raise FormatError(
            f"{source}: unknown wire format {match.group(1)!r}; the formats are "
            f"{', '.join(FORMATS)} (e.g. text:/dev/ttyACM0), or a plain pyserial URL or "
            "device path for the tactsense protocol"
        )


def split_source(source: str) -> tuple[WireFormat | None, str]:
    """The format a source names (None: the tactsense protocol) and the line's URL.

    The line starts after the first ``:`` that a URL or a path follows, so an option
    may hold a colon: ``text,prefix=F::/dev/ttyACM0`` is the prefix ``F:``.
    """
    name = source.partition(",")[0].partition(":")[0].strip().lower()
    if source[len(name) : len(name) + 3] == "://":
        return None, source
    if name not in FORMATS:
        _check_unknown_format(source)
        return None, source
    at = source.find(":")
    while at >= 0:
        if _LINE.match(source, at + 1):
            return parse_format(source[:at]), source[at + 1 :]
        at = source.find(":", at + 1)
    raise FormatError(
        f"{source}: no line after the format; expected e.g. {name}:/dev/ttyUSB0 or "
        f"{name}:socket://127.0.0.1:5000"
    )


def open_source(
    source: str,
    *,
    sensor: SensorSpec | None = None,
    timeout_s: float | None = None,
    start: bool = True,
):
    """A reader of any source: :class:`~tactsense.stream.StreamReader` for a URL,
    :class:`~tactsense.stream.framed.FormatReader` for ``FORMAT:URL``."""
    wire_format, url = split_source(source)
    if wire_format is None:
        return StreamReader(url, sensor=sensor, timeout_s=timeout_s, start=start)
    return FormatReader(url, wire_format, sensor=sensor, timeout_s=timeout_s, start=start)


def with_components(source: str, components: int | None) -> str:
    """The source with its format's ``components=N`` set (``--components N`` of the live
    commands): unchanged for None.

    Raises :class:`FormatError` for N outside 1..4, for a source of the tactsense
    protocol (its frames say their components: ``docs/protocol.md``, version 2), and for
    an N that disagrees with a ``components=`` already in the source.
    """
    if components is None:
        return source
    wire_format, url = split_source(source)
    if wire_format is None:
        raise FormatError(
            f"--components applies to text, marker and justfloat sources (e.g. "
            f"text:/dev/ttyACM0); {source} speaks the tactsense protocol, whose frames say "
            "their components (docs/protocol.md, version 2)"
        )
    return f"{_set_components(wire_format, components).spec()}:{url}"


def format_with_components(spec: str | None, components: int | None) -> str | None:
    """A format's name and options (``emulate --format``) with ``components=N`` set."""
    if components is None:
        return spec
    if spec is None:
        raise FormatError(
            "--components applies to another wire format (--format text, marker or "
            "justfloat); the tactsense protocol's frames say their components"
        )
    return _set_components(parse_format(spec), components).spec()


def _set_components(wire_format: WireFormat, components: int) -> WireFormat:
    try:
        count = parse_components(wire_format.name, components)
    except FormatError:
        raise FormatError(
            f"--components {components}: expected a whole number of values per taxel from "
            f"1 to {MAX_COMPONENTS} (3 for a three-axis taxel)"
        ) from None
    if wire_format.components not in (None, count):
        raise FormatError(
            f"--components {count} disagrees with the source's components="
            f"{wire_format.components}; give one of them"
        )
    wire_format.components = count
    return wire_format
