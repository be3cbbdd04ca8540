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

    # ---- estimation (r5-estimate) ----------------------------------------------
    array_calibration: ClassVar[bool] = True
    """Whether the kind takes an array's calibration (``tactsense calibrate``: a probe
    on every taxel, a uniform press or known weights; per-taxel gains and a force curve);
    False: the paper's finger calibration (a probe swept along every column, section 3.1,
    with creep steps and a knife edge)."""
    response_fit: ClassVar[bool] = False
    """Whether the kind tabulates its layer's response on a grid
    (:meth:`contact_response` with a window ``half``), so that ``find_contacts`` can fit
    it: the ``fit`` method, the sub-taxel refinement of ``interpolate``, a contact's
    force as the response's amplitude, and the reach of two point loads (pads)."""

    def contact_response(
        self, spec: Any, *, half: int = 0, n_sub: int = 8, signed: bool = False
    ) -> np.ndarray:
        """The response an estimator fits: the signal of the taxels per newton of the
        scenarios' probe (a 1.6-mm sphere) [-/N], from the kind's own forward model.

        Parameters
        ----------
        spec : the sensor's description
        half : int
            Half width of the window of taxels [taxel] (grid kinds).
        n_sub : int
            Sub-taxel positions of the probe per taxel along each axis (grid kinds).
        signed : bool
            A resistive taxel's strain before it is clipped at zero (grid kinds), so
            that the responses to several loads add up.

        Returns
        -------
        ndarray
            On a grid kind (:attr:`response_fit`), shape ``(n_sub + 1, n_sub + 1,
            2 half + 1, 2 half + 1)``: ``[a, b, i, j]`` the taxel at offset ``(i - half,
            j - half)`` from the taxel nearest below the probe, for the probe ``(a, b) /
            n_sub`` taxels from that taxel. On a kind without a grid, shape ``(N, N)``:
            row ``i`` for the probe centred on taxel ``i`` (``half``, ``n_sub`` unused).
        """
        raise self.unsupported(spec, "a contact response")


def positions_of(spec: Any) -> np.ndarray:
    """Surface positions [mm] of every taxel, frame order, (N, 3)."""
    return np.asarray(spec.taxel_positions_mm(), dtype=float)
