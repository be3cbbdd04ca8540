"""Which kinds exist: the built-in ones and those other packages register.

A package adds a kind with an entry point in the ``tactsense.kinds`` group whose object
is a :class:`~tactsense.kinds.base.Kind` instance (``docs/kinds.md``)::

    [project.entry-points."tactsense.kinds"]
    ring = "my_lab.ring_kind:KIND"
"""

from __future__ import annotations

from functools import cache
from importlib.metadata import entry_points
from typing import Any

from tactsense.kinds.base import Kind, KindNotSupported

GROUP = "tactsense.kinds"
"""The entry-point group kinds register in."""


@cache
def kinds() -> dict[str, Kind]:
    """Every registered kind by name: the built-ins first, then the entry points."""
    from tactsense.kinds import finger, pad, points

    found: dict[str, Kind] = {k.name: k for k in (finger.KIND, pad.KIND, points.KIND)}
    for ep in entry_points(group=GROUP):
        if ep.name in found:
            continue
        try:
            kind = ep.load()
        except Exception as err:  # a broken plug-in must not stop the built-ins
            raise KindNotSupported(
                f"the sensor kind {ep.name!r} registered by {ep.value!r} failed to load: {err}"
            ) from err
        if isinstance(kind, type):
            kind = kind()
        if not isinstance(kind, Kind):
            raise KindNotSupported(
                f"the entry point {ep.name!r} = {ep.value!r} in group {GROUP!r} is a "
                f"{type(kind).__name__}; expected a tactsense.kinds.Kind instance"
            )
        found[kind.name] = kind
    return found


def kind_of(spec: Any) -> Kind:
    """The kind of a sensor description (or of a kind's name)."""
    name = spec if isinstance(spec, str) else getattr(spec, "kind", None)
    every = kinds()
    if name in every:
        return every[name]
    raise KindNotSupported(
        f"no sensor kind named {name!r} is registered; known: {', '.join(every)}"
    )
