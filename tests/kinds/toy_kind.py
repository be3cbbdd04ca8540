"""A toy sensor kind in one file: a flat patch of taxels on a hexagonal lattice.

``rings`` rings of taxels around a centre taxel (1 + 3 rings (rings + 1) taxels: 19 for
two rings), ``pitch_mm`` apart, on a flat elastic layer. Its description is its own
dataclass (TOML ``kind = "hexpatch"`` with a ``[lattice]`` section instead of a list of
taxels); everything else is the point set's: the taxels are points with normals and
areas, so the kind reuses the points machinery (forward model, contacts, forms).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from itertools import pairwise
from types import MappingProxyType
from typing import ClassVar

from tactsense.kinds.points import PointsKind
from tactsense.sensor.common import Electronics, Flaws, Layer, Transduction
from tactsense.sensor.points import PointsSpec, Taxels


@dataclass(frozen=True)
class Lattice:
    """Where the taxels are: a hexagon of rings around a centre taxel."""

    rings: int = 2
    """Rings around the centre taxel [-] (0: one taxel)."""
    pitch_mm: float = 3.0
    """Distance between neighbouring taxels [mm]."""
    area_mm2: float = 4.0
    """Electrode area of each taxel [mm^2]."""


def hexagon(lattice: Lattice) -> Taxels:
    """The taxels of a lattice: centre first, then ring by ring, on the plane z = 0."""
    points = [(0.0, 0.0, 0.0)]
    corners = [(math.cos(math.pi / 3 * k), math.sin(math.pi / 3 * k)) for k in range(7)]
    for ring in range(1, lattice.rings + 1):
        for (x0, y0), (x1, y1) in pairwise(corners):
            for step in range(ring):
                u = step / ring
                x = ring * lattice.pitch_mm * (x0 + u * (x1 - x0))
                y = ring * lattice.pitch_mm * (y0 + u * (y1 - y0))
                points.append((round(x, 9) + 0.0, round(y, 9) + 0.0, 0.0))
    n = len(points)
    return Taxels(
        positions_mm=tuple(points),
        normals=((0.0, 0.0, 1.0),) * n,
        area_mm2=(float(lattice.area_mm2),) * n,
    )


@dataclass(frozen=True)
class HexPatchSpec(PointsSpec):
    """A hexagonal patch (TOML ``kind = "hexpatch"``): a point set whose taxels are
    given by a ``[lattice]`` instead of listed one by one."""

    name: str = "hexpatch"
    lattice: Lattice = field(default_factory=Lattice)

    kind: ClassVar[str] = "hexpatch"
    SECTIONS: ClassVar[dict[str, type]] = {
        "lattice": Lattice,
        "layer": Layer,
        "transduction": Transduction,
        "electronics": Electronics,
        "flaws": Flaws,
    }

    def __post_init__(self) -> None:
        if not self.lattice_problems():  # the taxels follow from a valid lattice
            object.__setattr__(self, "taxels", hexagon(self.lattice))
        super().__post_init__()  # every problem at once, as one SensorSpecError

    def lattice_problems(self) -> list[str]:
        """What is wrong with the ``[lattice]`` section, one sentence each."""
        lattice, found = self.lattice, []
        if not (isinstance(lattice.rings, int) and 0 <= lattice.rings <= 20):
            found.append(f"[lattice] rings = {lattice.rings!r}: expected an integer from 0 to 20")
        for key in ("pitch_mm", "area_mm2"):
            value = getattr(lattice, key)
            if not (isinstance(value, float | int) and math.isfinite(value) and value > 0):
                found.append(f"[lattice] {key} = {value!r}: expected a positive number")
        return found

    def problems(self) -> list[str]:
        """Every problem of the description (``SpecBase`` raises them as one error): the
        lattice's, else the point set's (layer, transduction, electronics, flaws)."""
        return self.lattice_problems() or super().problems()

    def summary(self) -> list[tuple[str, str]]:
        rows = super().summary()
        return [("kind", self.kind), *rows[1:]]


def hex19() -> HexPatchSpec:
    """19 taxels 3 mm apart under dome12's layer and electronics."""
    from tactsense.sensor.registry import preset

    dome = preset("dome12")
    return HexPatchSpec(
        name="hex19",
        description="19 taxels on a hexagonal lattice, 3 mm pitch (the kind suite's toy)",
        lattice=Lattice(rings=2, pitch_mm=3.0, area_mm2=4.0),
        layer=dome.layer,
        transduction=dome.transduction,
        electronics=dome.electronics,
        flaws=dome.flaws,
    )


class HexPatchKind(PointsKind):
    """The kind: a point set in all but its name, description and presets."""

    name = "hexpatch"
    spec_class = HexPatchSpec
    label = "hexagonal patch"
    plural = "hexagonal patches"
    presets = MappingProxyType({"hex19": hex19})


KIND = HexPatchKind()
"""What the entry point names: ``hexpatch = "toy_kind:KIND"`` in ``tactsense.kinds``."""
