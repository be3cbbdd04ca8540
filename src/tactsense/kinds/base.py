"""The one protocol a sensor kind answers.

Everything that differs between kinds of array is asked of the kind's :class:`Kind`
object: commands, writers, estimators and views hold a sensor, ask ``kind_of(sensor)``
and call it; none of them compares a kind's name. A kind lives in one module: its
description (a :class:`~tactsense.sensor.common.SpecBase` dataclass, which may live in
:mod:`tactsense.sensor`) and a :class:`Kind` subclass, registered through the
``tactsense.kinds`` entry-point group (see ``docs/kinds.md``).

Methods come in groups: what the kind *is* (names, presets), its *geometry* (positions,
neighbours, coordinates), its *forward model* (loads to taxel signals), its *estimation*
(the response a fit uses, defaults) and its *forms* for other tools (URDF, LSL, the
view). A method a kind cannot answer raises :class:`KindNotSupported`, a one-line error
naming the sensor and what it lacks, never a traceback.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from types import MappingProxyType
from typing import Any, ClassVar

import numpy as np

from tactsense._validation import TactsenseInputError


class KindNotSupported(TactsenseInputError):
    """What was asked has no meaning, or no model yet, for this kind of sensor."""


class Kind:
    """What one kind of sensor answers. Subclass it, set the class attributes, override
    what differs from the defaults, and register one instance (``docs/kinds.md``)."""

    # ---- what the kind is ------------------------------------------------------
    name: ClassVar[str]
    """The kind's name in TOML (``kind = "pad"``); equal to ``spec_class.kind``."""
    spec_class: ClassVar[type]
    """The frozen dataclass that describes one sensor of this kind."""
    label: ClassVar[str] = ""
    """The kind in words for a message (``"point set"``); default: its name."""
    plural: ClassVar[str] = ""
    """The plural in words (``"point sets"``); default: the label and an ``s``."""
    presets: ClassVar[Mapping[str, Callable[[], Any]]] = MappingProxyType({})
    """Built-in sensors of this kind by short name."""

    # ---- geometry --------------------------------------------------------------
    position_names: ClassVar[tuple[str, str]] = ("x_mm", "y_mm")
    """The two surface coordinates a contact's position is given in (column names)."""
    position_units: ClassVar[tuple[str, str]] = ("mm", "mm")
    """Their units."""
    image_grid: ClassVar[bool] = True
    """Whether a frame's (rows, cols) form a picture of the surface (a grid of taxels)."""
    multi_contact: ClassVar[bool] = True
    """Whether contacts are found and tracked per frame (many); False for a kind whose
    estimator reports the one contact of each frame (the paper's finger)."""

    def __init__(self) -> None:
        if not getattr(self, "label", ""):
            type(self).label = self.name
        if not getattr(self, "plural", ""):
            type(self).plural = self.label + "s"

    def describes(self, spec: Any) -> bool:
        """Whether ``spec`` is a sensor of this kind."""
        return isinstance(spec, self.spec_class)

    def periodic(self, spec: Any) -> bool:
        """Whether the columns wrap around (the last column neighbours the first)."""
        return False

    def jitter(self, spec: Any, first_mm: float, second_mm: float) -> tuple[float, float]:
        """A positioning error given in mm on the surface, in this kind's coordinates."""
        return first_mm, second_mm

    def unsupported(self, spec: Any, what: str) -> KindNotSupported:
        """The error to raise when ``what`` does not apply to ``spec``."""
        return KindNotSupported(f"{what} does not apply to {spec.name!r}, a {self.label}")

    def __repr__(self) -> str:
        return f"<{type(self).__name__} {self.name!r}>"

    # ---- forms for other tools: LSL, URDF (r5-interop) -------------------------
    def lsl_taxel_fields(self, spec: Any) -> dict[str, np.ndarray]:
        """Extra metadata of each channel of the LSL frames outlet, beside its label,
        unit, type, location [mm], row and column: field name (units in the name, e.g.
        ``axial_mm``) -> one number per taxel in frame order (row-major), shape (N,).
        Default: none."""
        return {}

    def urdf_array(self, spec: Any) -> dict | None:
        """The sensor as the ROS tactile toolbox's flat ``<array>``: ``rows``, ``cols``,
        ``size_mm`` (x, y) [mm] of a taxel and ``spacing_mm`` (x, y) [mm] between taxels
        (row (row, col) at (row * spacing x, col * spacing y)); None (the default) to be
        written as a ``<taxel>`` list at the taxels' real positions and normals."""
        return None

    def urdf_taxels(self, spec: Any) -> list[tuple[float, float]]:
        """The ``<box>`` (x, y) [mm] of each taxel of a ``<taxel>`` list, frame order (x
        along the tangent the URDF writer picks: +x, the finger's axis, where it can).
        Default: a square of each taxel's area (``spec.areas_mm2``)."""
        areas = getattr(spec, "areas_mm2", None)
        if areas is None:
            raise self.unsupported(spec, "a URDF <taxel> list (no taxel areas)")
        return [(float(np.sqrt(a)), float(np.sqrt(a))) for a in areas]

    def urdf_note(self, spec: Any) -> str | None:
        """A comment written before the ``<taxel>`` list (what the list cannot say);
        default none."""
        return None

    def from_urdf_array(self, array: Any, base: Any, *, path: Any, preset: str) -> Any:
        """A sensor of this kind from a URDF ``<array>`` (a
        :class:`~tactsense.kinds.urdf.TactileArray`), the rest from ``base`` (the preset
        named ``preset``); a :class:`~tactsense.kinds.urdf.UrdfError` naming ``path`` if it
        does not fit. None (the default): this kind is not read from an ``<array>``."""
        return None

    def from_urdf_taxels(self, taxels: Any, base: Any, *, path: Any) -> Any:
        """A sensor of this kind from a URDF ``<taxel>`` list (a
        :class:`~tactsense.kinds.urdf.TactileTaxels`), the rest from ``base``; a
        :class:`~tactsense.kinds.urdf.UrdfError` naming ``path`` if it does not fit. None
        (the default): this kind is not read from a ``<taxel>`` list."""
        return None


def positions_of(spec: Any) -> np.ndarray:
    """Surface positions [mm] of every taxel, frame order, (N, 3)."""
    return np.asarray(spec.taxel_positions_mm(), dtype=float)
