"""A taxel point set: any array given as surface positions, outward normals and areas.

For fingertip modules, glove patches and other irregular arrays (the URDF ``<taxel>``
list of the ROS tactile toolbox describes exactly this). Each taxel lies under the same
elastic layer, taken as locally flat around it: the twin loads each taxel through the
flat layer model in its own tangent plane. Frames of a point set have shape
``(1, N)``: one row, one column per taxel, in the order given.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import ClassVar

import numpy as np

from tactsense.sensor.checks import (
    check_electronics,
    check_flaws,
    check_layer,
    check_transduction,
)
from tactsense.sensor.common import (
    Electronics,
    Flaws,
    Layer,
    SensorSpecError,
    SpecBase,
    Transduction,
    capacitance_f,
)


@dataclass(frozen=True)
class Taxels:
    """Where the taxels are: one entry per taxel, in frame order."""

    positions_mm: tuple[tuple[float, ...], ...] = ((0.0, 0.0, 0.0),)
    """Point on the free surface above each taxel, ``[x, y, z]`` [mm]."""
    normals: tuple[tuple[float, ...], ...] = ((0.0, 0.0, 1.0),)
    """Outward surface normal at each taxel, ``[nx, ny, nz]`` (scaled to unit length) [-]."""
    area_mm2: tuple[float, ...] = (4.0,)
    """Effective (electrode) area of each taxel [mm^2]."""


@dataclass(frozen=True)
class PointsSpec(SpecBase):
    """Complete description of a taxel point set (TOML ``kind = "points"``)."""

    name: str = "points"
    description: str = ""
    taxels: Taxels = field(default_factory=Taxels)
    layer: Layer = field(default_factory=Layer)
    transduction: Transduction = field(default_factory=Transduction)
    electronics: Electronics = field(default_factory=Electronics)
    flaws: Flaws = field(default_factory=Flaws)

    kind: ClassVar[str] = "points"
    SECTIONS: ClassVar[dict[str, type]] = {
        "taxels": Taxels,
        "layer": Layer,
        "transduction": Transduction,
        "electronics": Electronics,
        "flaws": Flaws,
    }

    def problems(self) -> list[str]:
        """Every problem with this description, as readable sentences (none: valid)."""
        return _validate(self)

    @property
    def shape(self) -> tuple[int, int]:
        """Shape ``(1, N)`` of a frame [-]."""
        return (1, len(self.taxels.positions_mm))

    def summary(self) -> list[tuple[str, str]]:
        """Derived quantities worth printing, as (label, value with unit) rows."""
        positions = self.taxel_positions_mm()
        low, high = positions.min(axis=0), positions.max(axis=0)
        gaps = np.linalg.norm(positions[:, None] - positions[None, :], axis=-1)
        np.fill_diagonal(gaps, np.inf)
        nearest = gaps.min(axis=1) if len(positions) > 1 else np.array([np.nan])
        return [
            ("kind", "points"),
            ("taxels", f"{len(positions)} (frame shape {self.shape})"),
            (
                "bounding box",
                " x ".join(f"{h - lo:.3g}" for lo, h in zip(low, high, strict=True)) + " mm",
            ),
            ("nearest-neighbour distance", f"{nearest.min():.3g} to {nearest.max():.3g} mm"),
            ("electrode area", f"{self.areas_mm2.min():.3g} to {self.areas_mm2.max():.3g} mm^2"),
            (
                "layer",
                f"{self.layer.thickness_mm:g} mm, sensing depth {self.layer.sensing_depth_mm:g} mm",
            ),
            (
                "transduction",
                f"{self.transduction.kind}, reading {self.transduction.polarity} under load",
            ),
            (
                "rest reading",
                f"{self.electronics.nominal_counts:g} counts of {2**self.electronics.adc_bits - 1}",
            ),
        ]

    def taxel_positions_mm(self) -> np.ndarray:
        """Surface point of every taxel, shape (N, 3) [mm]."""
        return np.asarray(self.taxels.positions_mm, dtype=float).reshape(-1, 3)

    def taxel_normals(self) -> np.ndarray:
        """Unit outward normal of every taxel, shape (N, 3) [-]."""
        normals = np.asarray(self.taxels.normals, dtype=float).reshape(-1, 3)
        return normals / np.linalg.norm(normals, axis=1, keepdims=True)

    @property
    def areas_mm2(self) -> np.ndarray:
        """Electrode area of every taxel, shape (N,) [mm^2]."""
        return np.asarray(self.taxels.area_mm2, dtype=float)

    @property
    def junction_capacitance_f(self) -> np.ndarray:
        """Undeflected capacitance of each capacitive taxel, eq. 2 of the paper, (1, N) [F]."""
        return capacitance_f(self.transduction, self.areas_mm2)[np.newaxis, :]


def taxels_from_json(path: str | Path) -> Taxels:
    """Taxels from a JSON list of ``{"xyz": [x, y, z], "normal": [...], "area": a}`` [mm].

    The list order is the frame order. ``area`` is in mm^2.
    """
    path = Path(path)
    try:
        entries = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError) as error:
        raise SensorSpecError(f"cannot read taxel list {path}: {error}") from None
    except json.JSONDecodeError as error:
        raise SensorSpecError(f"{path} is not JSON: {error}") from None
    if not isinstance(entries, list) or not entries:
        raise SensorSpecError(f"{path}: expected a non-empty JSON list of taxels")
    positions, normals, areas = [], [], []
    for index, entry in enumerate(entries):
        try:
            positions.append(tuple(float(v) for v in entry["xyz"]))
            normals.append(tuple(float(v) for v in entry["normal"]))
            areas.append(float(entry["area"]))
        except (KeyError, TypeError, ValueError):
            raise SensorSpecError(
                f"{path}: taxel {index} must be {{'xyz': [x, y, z], 'normal': [nx, ny, nz], "
                f"'area': a}} in mm and mm^2; got {entry!r}"
            ) from None
    return Taxels(positions_mm=tuple(positions), normals=tuple(normals), area_mm2=tuple(areas))


def _validate(spec: PointsSpec) -> list[str]:
    problems: list[str] = []
    t = spec.taxels
    n = len(t.positions_mm)
    if n == 0:
        problems.append("[taxels] positions_mm is empty; give at least one taxel")
    if len(t.normals) != n or len(t.area_mm2) != n:
        problems.append(
            f"[taxels] {n} positions, {len(t.normals)} normals and {len(t.area_mm2)} areas: "
            "give one of each per taxel"
        )
    for key, rows in (("positions_mm", t.positions_mm), ("normals", t.normals)):
        for index, row in enumerate(rows):
            if len(row) != 3 or not all(math.isfinite(v) for v in row):
                problems.append(f"[taxels] {key}[{index}] = {list(row)!r}: expected 3 numbers")
                break
    for index, normal in enumerate(t.normals):
        if len(normal) == 3 and math.hypot(*normal) < 1e-9:
            problems.append(f"[taxels] normals[{index}] is zero; expected a direction")
            break
    for index, area in enumerate(t.area_mm2):
        if not (math.isfinite(area) and 0 < area <= 1e4):
            problems.append(
                f"[taxels] area_mm2[{index}] = {area!r} must be positive and at most "
                "1e4 mm^2 (a 10-cm square)"
            )
            break
    if n > 65_536:
        problems.append(f"[taxels] {n} taxels: at most 65,536 are supported")
    if not problems and n > 1:
        points = np.asarray(t.positions_mm, dtype=float)
        order = np.lexsort(points.T[::-1])
        same = np.all(np.diff(points[order], axis=0) == 0, axis=1)
        if same.any():
            first = int(np.argmax(same))
            k, other = sorted((int(order[first + 1]), int(order[first])))
            problems.append(
                f"[taxels] positions_mm[{other}] = {points[other].tolist()} repeats another "
                f"taxel's position (taxel {k}'s); every taxel needs its own point"
            )
    check_layer(spec.layer, problems)
    check_transduction(spec.transduction, problems)
    check_electronics(spec.electronics, problems, spec.transduction)
    if not problems:
        check_flaws(spec.flaws, spec.shape, problems)
    return problems
