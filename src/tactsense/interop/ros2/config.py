"""Where the DDS traffic goes: Cyclone DDS configuration for tactsense's participants.

A DDS participant's default discovery sends multicast to every host on the network.
tactsense's participant takes its configuration from ``--ros2-config``, else from
``CYCLONEDDS_URI`` (as any ROS 2 node with Cyclone DDS on the machine does), else
speaks on the loopback interface only, with multicast off and 127.0.0.1 as its only
peer (:data:`LOOPBACK_XML`): a ROS 2 node on the same machine with the same kind of
configuration (``CYCLONEDDS_URI=file://`` :func:`loopback_config`'s file) sees the
topics, and nothing leaves the machine.
"""

from __future__ import annotations

import os
import xml.etree.ElementTree as ET
from pathlib import Path

from tactsense._validation import TactsenseInputError

LOOPBACK_XML = """\
<?xml version="1.0" encoding="UTF-8"?>
<!-- tactsense: DDS on the loopback interface only, multicast off, peer 127.0.0.1 -->
<CycloneDDS xmlns="https://cdds.io/config">
  <Domain Id="any">
    <General>
      <Interfaces>
        <NetworkInterface address="127.0.0.1" multicast="false"/>
      </Interfaces>
      <AllowMulticast>false</AllowMulticast>
      <DontRoute>true</DontRoute>
    </General>
    <Discovery>
      <ParticipantIndex>auto</ParticipantIndex>
      <MaxAutoParticipantIndex>50</MaxAutoParticipantIndex>
      <Peers>
        <Peer address="127.0.0.1"/>
      </Peers>
    </Discovery>
  </Domain>
</CycloneDDS>
"""
"""Cyclone DDS on 127.0.0.1 alone: unicast discovery to the participant ports of that
address (up to 50 participants on the machine), no multicast."""

CONFIG_ENV = "CYCLONEDDS_URI"


class Ros2ConfigError(TactsenseInputError):
    """A DDS configuration that cannot be used (unreadable, not Cyclone DDS XML)."""


def loopback_config(folder: str | Path | None = None) -> Path:
    """Write :data:`LOOPBACK_XML` to ``folder`` (default: the user's cache folder) and
    return its path, for ``CYCLONEDDS_URI=file://PATH`` of another program on the machine."""
    import tempfile

    folder = Path(folder) if folder is not None else Path.home() / ".cache" / "tactsense"
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / "cyclonedds-loopback.xml"
    if not path.exists() or path.read_text() != LOOPBACK_XML:
        with tempfile.NamedTemporaryFile("w", dir=folder, delete=False, suffix=".tmp") as out:
            out.write(LOOPBACK_XML)
        os.replace(out.name, path)
    return path


def _text(config: str, origin: str = "--ros2-config ") -> str:
    """The XML of a configuration given as XML, as ``file://PATH`` or as a path
    (``origin``: how an error names where it came from)."""
    stripped = config.strip()
    if stripped.startswith("<"):
        return stripped
    path = Path(stripped.removeprefix("file://"))
    try:
        return path.read_text()
    except OSError as error:
        raise Ros2ConfigError(
            f"{origin}{config}: cannot read it ({error.strerror or error})"
        ) from None
    except UnicodeDecodeError:
        raise Ros2ConfigError(
            f"{origin}{config}: not a text file (a Cyclone DDS XML configuration)"
        ) from None


def is_loopback_only(config: str) -> bool:
    """True when a Cyclone DDS configuration (XML, ``file://PATH`` or a path) keeps a
    participant on 127.0.0.1 with multicast off: every network interface named is the
    loopback address (or ``lo``), ``AllowMulticast`` is false and every peer is 127.0.0.1
    or localhost."""
    root = _parse(config)

    def local(tag: str):
        return [e for e in root.iter() if e.tag.rpartition("}")[2] == tag]

    interfaces = local("NetworkInterface")
    if not interfaces or any(
        e.get("address") not in ("127.0.0.1", None) or e.get("name") not in ("lo", None)
        for e in interfaces
    ):
        return False
    multicast = local("AllowMulticast")
    if not multicast or any((e.text or "").strip().lower() != "false" for e in multicast):
        return False
    peers = local("Peer")
    return all(
        (e.get("address") or e.get("Address") or "").split(":")[0] in ("127.0.0.1", "localhost")
        for e in peers
    )


def _parse(config: str, origin: str = "--ros2-config"):
    try:
        root = ET.fromstring(_text(config, origin + " "))
    except ET.ParseError as error:
        where = "" if config.lstrip().startswith("<") else f" {config}"
        raise Ros2ConfigError(f"{origin}{where}: not XML ({error})") from None
    if root.tag.rpartition("}")[2] != "CycloneDDS":
        raise Ros2ConfigError(
            f"{origin}{'' if config.lstrip().startswith('<') else ' ' + config}: a Cyclone DDS "
            "configuration has the root element <CycloneDDS>; "
            f"this one has <{root.tag.rpartition('}')[2]}>"
        )
    return root


def _check_environment(uri: str) -> None:
    """Check each file a ``CYCLONEDDS_URI`` names (``file://PATH`` or a path; several
    separated by commas, as Cyclone DDS reads them) as ``--ros2-config`` is checked:
    readable, XML, root ``<CycloneDDS>``. XML given in the variable itself (starting
    with ``<``) is left to Cyclone DDS."""
    if uri.startswith("<"):
        return
    for item in (part.strip() for part in uri.split(",")):
        if item and not item.startswith("<"):
            _parse(item, CONFIG_ENV)


def resolve_config(config: str | Path | None) -> tuple[str, str]:
    """The configuration a participant starts with, and where it came from.

    ``config`` (XML, ``file://PATH`` or a path; checked to be Cyclone DDS XML) first;
    else the environment's ``CYCLONEDDS_URI`` (as a ROS 2 node on this machine would use
    it; each file it names checked as ``config`` is, then passed to Cyclone DDS as it
    stands); else tactsense's loopback-only
    :data:`LOOPBACK_XML`, never Cyclone DDS's own default (multicast on every interface).

    Returns
    -------
    (str, str)
        The configuration (XML or a URI Cyclone DDS reads) and its source: ``option``,
        ``CYCLONEDDS_URI`` or ``loopback``.
    """
    if config is not None:
        _parse(str(config))
        text = _text(str(config))
        return text, "option"
    environment = os.environ.get(CONFIG_ENV, "").strip()
    if environment:
        _check_environment(environment)
        return environment, CONFIG_ENV
    return LOOPBACK_XML, "loopback"
