"""Sensor kinds: what differs between kinds of array, asked of one object per kind.

``kind_of(sensor)`` answers every question whose answer depends on the kind (see
:class:`Kind`); the built-in kinds are the paper's ``finger``, the flat ``pad`` and the
``points`` set, and other packages add theirs through the ``tactsense.kinds``
entry-point group (``docs/kinds.md``).
"""

from tactsense.kinds.base import Kind, KindNotSupported
from tactsense.kinds.registry import GROUP, kind_of, kinds

__all__ = ["GROUP", "Kind", "KindNotSupported", "kind_of", "kinds"]
