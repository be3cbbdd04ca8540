"""The kind of the sensor an estimator is given (:mod:`tactsense.kinds`)."""

from __future__ import annotations

from typing import Any

from tactsense.kinds import Kind, KindNotSupported, kind_of


def kind_or_none(sensor: Any) -> Kind | None:
    """The registered kind of a sensor description; None for anything that is none (no
    ``kind`` of a registered name: a name alone, another object), for the caller's own
    message."""
    name = getattr(sensor, "kind", None)
    if not isinstance(name, str):
        return None
    try:
        return kind_of(name)
    except KindNotSupported:
        return None
