"""Indenters on a flat surface: the pressure each puts on a pad (or a taxel's tangent plane).

Every indenter is a small frozen dataclass with its centre ``(x_mm, y_mm)`` on the
surface (the pad's axes, ``tactsense.sensor.pad``), its total normal force [N] and its
shape, and answers :meth:`pressure_pa` on a regular grid of points. The pressure is
averaged over each grid cell (sub-sampled) and scaled so that it sums to the force
exactly: a grid coarser than the contact still carries the right load.

Pressure laws:

* :class:`SphereProbe`: a rigid sphere pressed into the layer, Hertz's elliptical
  pressure ``p = p0 sqrt(1 - r^2/a^2)`` with the contact radius of a rigid sphere on an
  elastic half space, ``a = (3 F R / (4 E*))^(1/3)``, ``E* = E / (1 - nu^2)`` (Johnson,
  *Contact Mechanics*, 1985, eq. 4.22); the layer's thickness is ignored for ``a``.
* :class:`DiscProbe`: uniform pressure on a disc (a soft-tipped probe).
* :class:`FlatPunch`: a rigid flat-ended cylinder, ``p = F / (2 pi a sqrt(a^2 - r^2))``
  (Boussinesq's punch; Johnson 1985, eq. 3.35), its edge singularity cell-averaged.
* :class:`KnifeEdge`: a line load of a given length, angle and width (elliptical across
  the edge, as a 2-D Hertz contact).
* :class:`SquareStamp`: a rigid flat rectangular (by default square) stamp turned by an
  angle. Its exact pressure has no closed form; it is approximated by the product of
  two plane-strain flat-punch profiles (Sneddon; Johnson 1985, eq. 2.64),
  ``p = F / (pi^2 sqrt((a^2 - u^2) (b^2 - v^2)))`` over ``|u| < a``, ``|v| < b``: it
  carries the load exactly, is singular as ``1/sqrt`` along every edge (as the exact
  one is) and concentrates at the corners; each axis' singularity is band-averaged.
* :class:`CylinderProbe`: a rigid cylinder of a given radius and length lying on the
  surface: Hertz's line contact (Johnson 1985, eqs. 4.43-4.45), half-width
  ``b = sqrt(4 F R / (pi L E*))`` and ``p = (2 F / (pi b L)) sqrt(1 - u^2/b^2)`` across,
  uniform along its length (the ends' concentration left out).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field
from typing import Any, ClassVar

import numpy as np

from tactsense._validation import TactsenseInputError

_SUBSAMPLES = 5  # per grid cell and axis: cell-averages a 1-cell contact to about 1 %


def _finite_positive(name: str, value: float) -> None:
    if not (isinstance(value, int | float) and math.isfinite(value) and value > 0):
        raise TactsenseInputError(f"{name} must be a positive number; got {value!r}")


@dataclass(frozen=True)
class Indenter:
    """What every indenter has: where, how hard, and its pressure law."""

    x_mm: float
    y_mm: float
    force_n: float
    at_taxel: int | None = field(default=None, kw_only=True)
    """Point sets only: (x_mm, y_mm) are in this taxel's tangent plane, from its centre."""
    shear_x_n: float = field(default=0.0, kw_only=True)
    """Tangential force the indenter applies to the surface along +x [N] (0: a pure
    press). Only kinds that sense shear (``Kind.senses_shear``) read it."""
    shear_y_n: float = field(default=0.0, kw_only=True)
    """Tangential force the indenter applies to the surface along +y [N]."""
    friction: float = field(default=1.0, kw_only=True)
    """Coefficient of friction mu between indenter and skin [-]: the tangential traction
    is at most mu times the pressure (Cattaneo-Mindlin: slip spreads in from the contact's
    edge as the tangential force rises, and the whole contact slides at mu times the
    normal force)."""

    kind: ClassVar[str] = "indenter"

    def __post_init__(self) -> None:
        for name in ("x_mm", "y_mm", "force_n", "shear_x_n", "shear_y_n", "friction"):
            value = getattr(self, name)
            if not (isinstance(value, int | float) and math.isfinite(value)):
                raise TactsenseInputError(f"{name} must be a finite number; got {value!r}")
        if self.force_n < 0:
            raise TactsenseInputError(f"force_n must be >= 0 (a push); got {self.force_n!r}")
        if self.friction <= 0:
            raise TactsenseInputError(f"friction must be > 0; got {self.friction!r}")

    @property
    def shear_n(self) -> float:
        """Magnitude of the tangential force [N]."""
        return math.hypot(self.shear_x_n, self.shear_y_n)

    def _shape(self, dx, dy, modulus_star_pa, step_mm):  # pragma: no cover - every kind defines it
        raise NotImplementedError

    def _integral_mm2(self, modulus_star_pa):  # pragma: no cover - every kind defines it
        raise NotImplementedError

    def reach_mm(self, modulus_star_pa: float) -> float:  # pragma: no cover
        """Distance from the centre beyond which the pressure is zero [mm]."""
        raise NotImplementedError

    def pressure_pa(
        self, x_mm: np.ndarray, y_mm: np.ndarray, *, modulus_star_pa: float = 2.5e5 / 0.75
    ) -> np.ndarray:
        """Cell-averaged pressure on a regular grid, scaled to sum to ``force_n`` [Pa].

        Parameters
        ----------
        x_mm, y_mm : ndarray, shape (M,), (N,)
            Cell centres along x and y, evenly spaced [mm].
        modulus_star_pa : float
            Plane-strain modulus E / (1 - nu^2) of the layer, for contact sizes that
            depend on it [Pa].

        Returns
        -------
        ndarray, shape (M, N)
            Pressure [Pa], compression positive.
        """
        x_mm = np.asarray(x_mm, dtype=float)
        y_mm = np.asarray(y_mm, dtype=float)
        hx = float(x_mm[1] - x_mm[0]) if x_mm.size > 1 else 1.0
        hy = float(y_mm[1] - y_mm[0]) if y_mm.size > 1 else 1.0
        if self.force_n == 0:
            return np.zeros((x_mm.size, y_mm.size))
        offsets = (np.arange(_SUBSAMPLES) + 0.5) / _SUBSAMPLES - 0.5
        sub_x = (x_mm[:, None] + hx * offsets[None, :]).ravel() - self.x_mm
        sub_y = (y_mm[:, None] + hy * offsets[None, :]).ravel() - self.y_mm
        shape = self._shape(
            sub_x[:, None], sub_y[None, :], modulus_star_pa, min(hx, hy) / _SUBSAMPLES
        )
        cells = shape.reshape(x_mm.size, _SUBSAMPLES, y_mm.size, _SUBSAMPLES).mean(axis=(1, 3))
        reach = self.reach_mm(modulus_star_pa)
        inside = (
            x_mm[0] - hx / 2 <= self.x_mm - reach
            and self.x_mm + reach <= x_mm[-1] + hx / 2
            and y_mm[0] - hy / 2 <= self.y_mm - reach
            and self.y_mm + reach <= y_mm[-1] + hy / 2
        )
        # wholly on the grid: scale so the cells carry the force exactly; partly off it:
        # the shape's exact integral, so the part off the grid is missing, not moved
        total = (
            cells.sum() * hx * hy if inside else self._integral_mm2(modulus_star_pa)
        ) * 1e-6  # [shape units * m^2]
        if total <= 0:
            return np.zeros_like(cells)
        return cells * (self.force_n / total)

    def moved(self, dx_mm: float, dy_mm: float, force_scale: float = 1.0) -> Indenter:
        """The same indenter shifted by (dx, dy) [mm] with its force scaled [-]."""
        return dataclasses.replace(
            self,
            x_mm=self.x_mm + dx_mm,
            y_mm=self.y_mm + dy_mm,
            force_n=max(0.0, self.force_n * force_scale),
        )

    def to_dict(self) -> dict[str, Any]:
        """Plain description, ``kind`` first (JSON in recordings)."""
        data = dataclasses.asdict(self)
        if data["at_taxel"] is None:
            del data["at_taxel"]
        for name, default in (("shear_x_n", 0.0), ("shear_y_n", 0.0), ("friction", 1.0)):
            if data[name] == default:  # a pure press reads as before
                del data[name]
        return {"kind": self.kind, **data}


@dataclass(frozen=True)
class SphereProbe(Indenter):
    """A rigid sphere of ``radius_mm`` pressed with ``force_n``: Hertz pressure."""

    radius_mm: float = 1.6
    kind: ClassVar[str] = "sphere"

    def __post_init__(self) -> None:
        super().__post_init__()
        _finite_positive("radius_mm", self.radius_mm)

    def contact_radius_mm(self, modulus_star_pa: float) -> float:
        """Hertz contact radius a = (3 F R / (4 E*))^(1/3) [mm]."""
        radius_m = self.radius_mm * 1e-3
        return 1e3 * (3.0 * self.force_n * radius_m / (4.0 * modulus_star_pa)) ** (1.0 / 3.0)

    def reach_mm(self, modulus_star_pa):
        return min(self.contact_radius_mm(modulus_star_pa), self.radius_mm)

    def _integral_mm2(self, modulus_star_pa):
        return 2.0 * math.pi * self.reach_mm(modulus_star_pa) ** 2 / 3.0

    def _shape(self, dx, dy, modulus_star_pa, step_mm):
        a = self.reach_mm(modulus_star_pa)
        rho2 = (dx**2 + dy**2) / a**2
        return np.sqrt(np.clip(1.0 - rho2, 0.0, None))


@dataclass(frozen=True)
class DiscProbe(Indenter):
    """Uniform pressure on a disc of ``radius_mm``."""

    radius_mm: float = 1.5
    kind: ClassVar[str] = "disc"

    def __post_init__(self) -> None:
        super().__post_init__()
        _finite_positive("radius_mm", self.radius_mm)

    def reach_mm(self, modulus_star_pa):
        return self.radius_mm

    def _integral_mm2(self, modulus_star_pa):
        return math.pi * self.radius_mm**2

    def _shape(self, dx, dy, modulus_star_pa, step_mm):
        return (dx**2 + dy**2 <= self.radius_mm**2).astype(float)


@dataclass(frozen=True)
class FlatPunch(Indenter):
    """A rigid flat-ended cylinder of ``radius_mm``: Boussinesq's punch pressure."""

    radius_mm: float = 3.0
    kind: ClassVar[str] = "punch"

    def __post_init__(self) -> None:
        super().__post_init__()
        _finite_positive("radius_mm", self.radius_mm)

    def reach_mm(self, modulus_star_pa):
        return self.radius_mm

    def _integral_mm2(self, modulus_star_pa):
        return 2.0 * math.pi * self.radius_mm

    def _shape(self, dx, dy, modulus_star_pa, step_mm):
        # 1 / sqrt(a^2 - r^2) averaged over a radial band of one sub-sample (its integral
        # is arcsin(r / a)): bounded at the edge, where point samples would blow up
        a = self.radius_mm
        r = np.hypot(dx, dy)
        half = 0.5 * step_mm
        low = np.clip((r - half) / a, -1.0, 1.0)
        high = np.clip((r + half) / a, -1.0, 1.0)
        return (np.arcsin(high) - np.arcsin(low)) / (2.0 * half)


@dataclass(frozen=True)
class KnifeEdge(Indenter):
    """A line load: ``length_mm`` long at ``angle_deg`` from the x axis, ``width_mm`` wide."""

    length_mm: float = 10.0
    angle_deg: float = 0.0
    width_mm: float = 0.5
    kind: ClassVar[str] = "knife"

    def __post_init__(self) -> None:
        super().__post_init__()
        _finite_positive("length_mm", self.length_mm)
        _finite_positive("width_mm", self.width_mm)
        if not math.isfinite(self.angle_deg):
            raise TactsenseInputError(f"angle_deg must be finite; got {self.angle_deg!r}")

    def reach_mm(self, modulus_star_pa):
        return math.hypot(self.length_mm / 2.0, self.width_mm / 2.0)

    def _integral_mm2(self, modulus_star_pa):
        return math.pi / 4.0 * self.width_mm * self.length_mm

    def _shape(self, dx, dy, modulus_star_pa, step_mm):
        angle = math.radians(self.angle_deg)
        along = dx * math.cos(angle) + dy * math.sin(angle)
        across = -dx * math.sin(angle) + dy * math.cos(angle)
        half = self.width_mm / 2.0
        profile = np.sqrt(np.clip(1.0 - (across / half) ** 2, 0.0, None))
        return profile * (np.abs(along) <= self.length_mm / 2.0)


def _punch_band(u, half_width, half_step):
    """Mean of ``1 / sqrt(1 - (u / a)^2)`` over ``[u - h, u + h]`` (its integral is
    ``a arcsin(u / a)``): the plane-strain punch profile, bounded at the edge [-]."""
    low = np.clip((u - half_step) / half_width, -1.0, 1.0)
    high = np.clip((u + half_step) / half_width, -1.0, 1.0)
    return half_width * (np.arcsin(high) - np.arcsin(low)) / (2.0 * half_step)


def _ellipse_band(u, half_width, half_step):
    """Mean of ``sqrt(1 - (u / b)^2)`` over ``[u - h, u + h]`` (Hertz's profile; its
    integral is ``b (t sqrt(1 - t^2) + arcsin t) / 2``, ``t = u / b``): exact however
    narrow the contact against the step [-]."""

    def primitive(t):
        t = np.clip(t, -1.0, 1.0)
        return 0.5 * (t * np.sqrt(1.0 - t * t) + np.arcsin(t))

    return (
        half_width
        * (primitive((u + half_step) / half_width) - primitive((u - half_step) / half_width))
        / (2.0 * half_step)
    )


def _local_axes(dx, dy, angle_deg):
    angle = math.radians(angle_deg)
    along = dx * math.cos(angle) + dy * math.sin(angle)
    across = -dx * math.sin(angle) + dy * math.cos(angle)
    return along, across


def _finite_angle(value) -> None:
    if not (isinstance(value, int | float) and math.isfinite(value)):
        raise TactsenseInputError(f"angle_deg must be a finite angle [deg]; got {value!r}")


@dataclass(frozen=True)
class SquareStamp(Indenter):
    """A rigid flat stamp ``side_mm`` long (along ``angle_deg`` from the x axis) and
    ``width_mm`` wide (None: square), pressed flat with ``force_n``.

    Pressure: the product of two plane-strain flat-punch profiles (module docstring),
    ``F / (pi^2 sqrt((a^2 - u^2) (b^2 - v^2)))`` with ``a = side / 2``, ``b = width / 2``.
    """

    side_mm: float = 5.0
    width_mm: float | None = None
    angle_deg: float = 0.0
    kind: ClassVar[str] = "square"

    def __post_init__(self) -> None:
        super().__post_init__()
        _finite_positive("side_mm", self.side_mm)
        if self.width_mm is not None:
            _finite_positive("width_mm", self.width_mm)
        _finite_angle(self.angle_deg)

    @property
    def half_sides_mm(self) -> tuple[float, float]:
        """Half the side along and across the stamp's axis [mm]."""
        width = self.side_mm if self.width_mm is None else self.width_mm
        return 0.5 * self.side_mm, 0.5 * width

    def area_mm2(self) -> float:
        """The stamp's face [mm^2]."""
        a, b = self.half_sides_mm
        return 4.0 * a * b

    def reach_mm(self, modulus_star_pa):
        return math.hypot(*self.half_sides_mm)

    def _integral_mm2(self, modulus_star_pa):
        # each axis' profile 1/sqrt(1 - (u/a)^2) integrates to pi a
        a, b = self.half_sides_mm
        return math.pi**2 * a * b

    def _shape(self, dx, dy, modulus_star_pa, step_mm):
        a, b = self.half_sides_mm
        along, across = _local_axes(dx, dy, self.angle_deg)
        half = 0.5 * step_mm
        return _punch_band(along, a, half) * _punch_band(across, b, half)


@dataclass(frozen=True)
class CylinderProbe(Indenter):
    """A rigid cylinder of ``radius_mm`` and ``length_mm`` lying on the surface along
    ``angle_deg`` from the x axis, pressed with ``force_n``: Hertz's line contact."""

    length_mm: float = 10.0
    radius_mm: float = 5.0
    angle_deg: float = 0.0
    kind: ClassVar[str] = "cylinder"

    def __post_init__(self) -> None:
        super().__post_init__()
        _finite_positive("length_mm", self.length_mm)
        _finite_positive("radius_mm", self.radius_mm)
        _finite_angle(self.angle_deg)

    def half_width_mm(self, modulus_star_pa: float) -> float:
        """Hertz's half-width of the line contact, ``b = sqrt(4 F R / (pi L E*))`` [mm]
        (Johnson 1985, eq. 4.43, load per unit length ``F / L``), at most the radius."""
        per_length = self.force_n / (self.length_mm * 1e-3)  # [N/m]
        b = math.sqrt(4.0 * per_length * self.radius_mm * 1e-3 / (math.pi * modulus_star_pa))
        return min(1e3 * b, self.radius_mm)

    def reach_mm(self, modulus_star_pa):
        return math.hypot(0.5 * self.length_mm, self.half_width_mm(modulus_star_pa))

    def _integral_mm2(self, modulus_star_pa):
        return 0.5 * math.pi * self.half_width_mm(modulus_star_pa) * self.length_mm

    def _shape(self, dx, dy, modulus_star_pa, step_mm):
        b = self.half_width_mm(modulus_star_pa)
        if b <= 0:
            return np.zeros(np.broadcast(dx, dy).shape)
        along, across = _local_axes(dx, dy, self.angle_deg)
        half = 0.5 * step_mm
        inside = np.clip(
            (np.minimum(along + half, 0.5 * self.length_mm)
             - np.maximum(along - half, -0.5 * self.length_mm)) / step_mm,
            0.0, 1.0,
        )  # fmt: skip
        return _ellipse_band(across, b, half) * inside


INDENTERS: dict[str, type] = {
    cls.kind: cls
    for cls in (SphereProbe, DiscProbe, FlatPunch, KnifeEdge, SquareStamp, CylinderProbe)
}


def indenter_from_dict(data: dict[str, Any]) -> Indenter:
    """An indenter from :meth:`Indenter.to_dict` output."""
    data = dict(data)
    kind = data.pop("kind", None)
    if kind not in INDENTERS:
        raise TactsenseInputError(
            f"unknown indenter kind {kind!r}; expected one of {', '.join(INDENTERS)}"
        )
    return INDENTERS[kind](**data)


def pressure_map(indenters, x_mm, y_mm, *, modulus_star_pa: float) -> np.ndarray:
    """Sum of the pressures of several indenters on one grid (superposition) [Pa]."""
    total = np.zeros((np.size(x_mm), np.size(y_mm)))
    for indenter in indenters:
        total += indenter.pressure_pa(x_mm, y_mm, modulus_star_pa=modulus_star_pa)
    return total
