"""Contacts on the skin: probes, knife edges, rods, flat and soft objects.

Each contact is a small frozen dataclass in the user's units (mm, deg, N)
that knows how to break itself into *patches*: rectangles on the surface
with a force, a pressure profile along the finger and one around it, and a
tangential ratio beta. The array response (:mod:`array_response`) is a sum
over patches.

A Hertzian sphere pressed on the skin has pressure
``p0 sqrt(1 - r^2 / a^2)``; integrated across the finger this gives a
*parabolic* line load ``(3 F / 4 a) (1 - x^2 / a^2)`` along it, which is
why the probe uses parabolic profiles in both directions (the paper uses
"a parabola of the probe width, 3 mm" in section 5).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from tactsense._validation import TactsenseInputError, check_choice, check_positive
from tactsense.sensor import STANDARD_GRAVITY

PROFILES = ("point", "uniform", "parabolic", "elliptic")


def grams_force(grams):
    """Force of a mass of ``grams`` under standard gravity [N].

    The paper states loads in grams (a 50-g weight); ``grams_force(50)`` is
    0.490 N. Scalars give a float, arrays an array.
    """
    force = np.multiply(grams, 1e-3 * STANDARD_GRAVITY, dtype=float)
    return float(force) if np.ndim(force) == 0 else force


def newtons_to_grams(force_n) -> float | np.ndarray:
    """Mass in grams whose weight is ``force_n`` [g]."""
    return np.asarray(force_n, dtype=float) / (1e-3 * STANDARD_GRAVITY)


def profile_cdf(u, profile: str):
    """Cumulative share of a unit load on ``[-1, u]`` for a pressure profile.

    Parameters
    ----------
    u : array_like
        Position normalised by the half-width [-].
    profile : {"uniform", "parabolic", "elliptic"}
        Shape of the pressure across the contact: constant, ``1 - u^2``
        (Hertzian sphere, integrated across), ``sqrt(1 - u^2)`` (Hertzian
        cylinder, a large soft object).

    Returns
    -------
    ndarray
        Share of the load in [0, 1].
    """
    u = np.clip(np.asarray(u, dtype=float), -1.0, 1.0)
    if profile == "uniform":
        return 0.5 * (u + 1.0)
    if profile == "parabolic":
        return 0.75 * (u - u**3 / 3.0) + 0.5
    if profile == "elliptic":
        return (u * np.sqrt(1.0 - u * u) + np.arcsin(u)) / np.pi + 0.5
    raise TactsenseInputError(f"profile must be one of {PROFILES[1:]}; got {profile!r}")


@dataclass(frozen=True)
class Patches:
    """Rectangular load patches on the surface (arrays of equal length P)."""

    axial_mm: np.ndarray
    angle_deg: np.ndarray
    force_n: np.ndarray
    half_length_mm: np.ndarray
    half_width_mm: np.ndarray
    profile_axial: tuple[str, ...]
    profile_around: tuple[str, ...]
    beta: np.ndarray

    def __len__(self) -> int:
        return int(self.force_n.size)

    @staticmethod
    def concatenate(parts: list[Patches]) -> Patches:
        if not parts:
            return Patches(*(np.zeros(0),) * 5, (), (), np.zeros(0))
        return Patches(
            axial_mm=np.concatenate([p.axial_mm for p in parts]),
            angle_deg=np.concatenate([p.angle_deg for p in parts]),
            force_n=np.concatenate([p.force_n for p in parts]),
            half_length_mm=np.concatenate([p.half_length_mm for p in parts]),
            half_width_mm=np.concatenate([p.half_width_mm for p in parts]),
            profile_axial=sum((p.profile_axial for p in parts), ()),
            profile_around=sum((p.profile_around for p in parts), ()),
            beta=np.concatenate([p.beta for p in parts]),
        )


def _single(axial_mm, angle_deg, force_n, half_length, half_width, prof_ax, prof_ar, beta):
    return Patches(
        np.array([axial_mm], float),
        np.array([angle_deg], float),
        np.array([force_n], float),
        np.array([half_length], float),
        np.array([half_width], float),
        (prof_ax,),
        (prof_ar,),
        np.array([beta], float),
    )


class _ContactBase:
    """Shared checks and helpers of all contacts."""

    kind = "contact"

    def _check_common(self) -> None:
        check_positive(self.force_n, f"{self.kind} force_n", allow_zero=True)
        for name in ("axial_mm", "angle_deg", "alpha_deg"):
            value = getattr(self, name)
            if not math.isfinite(value):
                raise TactsenseInputError(f"{self.kind} {name} must be finite; got {value!r}")
        if abs(self.alpha_deg) >= 90.0:
            raise TactsenseInputError(
                f"{self.kind} alpha_deg = {self.alpha_deg} must lie in (-90, 90): "
                "the angle of the force from the surface normal"
            )

    @property
    def beta(self) -> float:
        """Tangential-to-normal ratio tan(alpha) along the finger [-]."""
        return math.tan(math.radians(self.alpha_deg))

    @property
    def normal_force_n(self) -> float:
        """Normal component of the force [N]."""
        return self.force_n * math.cos(math.radians(self.alpha_deg))

    def moved(self, d_axial_mm: float = 0.0, d_angle_deg: float = 0.0, force_scale: float = 1.0):
        """A copy moved on the surface and with the force scaled."""
        return dataclasses.replace(
            self,
            axial_mm=self.axial_mm + d_axial_mm,
            angle_deg=self.angle_deg + d_angle_deg,
            force_n=self.force_n * force_scale,
        )

    def to_dict(self) -> dict:
        """Plain dictionary of the contact's fields and kind (recording metadata)."""
        return {
            "kind": self.kind,
            **{name: getattr(self, name) for name in self.__dataclass_fields__},
        }


@dataclass(frozen=True)
class Probe(_ContactBase):
    """Hemispherical probe (the paper's 3.2-mm diameter, 7.8 mm^2 probe).

    Parameters
    ----------
    axial_mm, angle_deg : float
        Centre of the contact on the surface [mm], [deg].
    force_n : float
        Total force [N]; see :func:`grams_force`.
    contact_diameter_mm : float
        Diameter of the pressed contact circle [mm]; the paper models the
        probe pressure as a parabola 3 mm wide.
    alpha_deg : float
        Angle of the force from the normal, tangential part along the finger [deg].
    """

    axial_mm: float
    angle_deg: float
    force_n: float
    contact_diameter_mm: float = 3.0
    alpha_deg: float = 0.0
    kind = "probe"

    def __post_init__(self) -> None:
        self._check_common()
        check_positive(self.contact_diameter_mm, "probe contact_diameter_mm", allow_zero=True)

    def patches(self) -> Patches:
        half = self.contact_diameter_mm / 2.0
        profile = "parabolic" if half > 0 else "point"
        return _single(
            self.axial_mm,
            self.angle_deg,
            self.normal_force_n,
            half,
            half,
            profile,
            profile,
            self.beta,
        )


@dataclass(frozen=True)
class FlatContact(_ContactBase):
    """A flat or large soft object pressing a rectangle of the skin (Fig. 26).

    Parameters
    ----------
    length_mm : float
        Contact length along the finger [mm].
    width_mm : float
        Contact width around the finger, measured on the surface [mm].
    profile : {"uniform", "parabolic", "elliptic"}
        Pressure profile in both directions; "elliptic" is the Hertzian
        pressure of a large soft cylinder, "uniform" a flat punch.
    """

    axial_mm: float
    angle_deg: float
    force_n: float
    length_mm: float = 10.0
    width_mm: float = 5.0
    profile: str = "elliptic"
    alpha_deg: float = 0.0
    kind = "flat"

    def __post_init__(self) -> None:
        self._check_common()
        check_positive(self.length_mm, "flat length_mm")
        check_positive(self.width_mm, "flat width_mm")
        check_choice(self.profile, "flat profile", PROFILES[1:])

    def patches(self) -> Patches:
        return _single(
            self.axial_mm,
            self.angle_deg,
            self.normal_force_n,
            self.length_mm / 2,
            self.width_mm / 2,
            self.profile,
            self.profile,
            self.beta,
        )


@dataclass(frozen=True)
class LineContact(_ContactBase):
    """A straight edge or rod pressing a line on the skin.

    Parameters
    ----------
    length_mm : float
        Length of the contact line [mm].
    orientation_deg : float
        Angle between the line and the finger axis [deg]: 90 is a knife
        edge across the finger (a line load in the sense of section 4.1),
        45 the rod of Fig. 22.
    width_mm : float
        Width of the contact strip [mm].
    segment_mm : float
        Length of the uniform segments the line is split into [mm].
    """

    axial_mm: float
    angle_deg: float
    force_n: float
    length_mm: float = 10.0
    orientation_deg: float = 90.0
    width_mm: float = 0.3
    alpha_deg: float = 0.0
    segment_mm: float = 0.5
    kind = "line"

    def __post_init__(self) -> None:
        self._check_common()
        check_positive(self.length_mm, "line length_mm")
        check_positive(self.width_mm, "line width_mm")
        check_positive(self.segment_mm, "line segment_mm")

    def patches(self, radius_mm: float = 12.7) -> Patches:
        """Split the line into segments; ``radius_mm`` turns arc length into angle."""
        n = max(1, math.ceil(self.length_mm / self.segment_mm))
        seg = self.length_mm / n
        centre = (np.arange(n) + 0.5) * seg - self.length_mm / 2.0
        theta = math.radians(self.orientation_deg)
        along, around = centre * math.cos(theta), centre * math.sin(theta)
        half_length = seg / 2 * abs(math.cos(theta)) + self.width_mm / 2 * abs(math.sin(theta))
        half_width = seg / 2 * abs(math.sin(theta)) + self.width_mm / 2 * abs(math.cos(theta))
        return Patches(
            axial_mm=self.axial_mm + along,
            angle_deg=self.angle_deg + np.rad2deg(around / radius_mm),
            force_n=np.full(n, self.normal_force_n / n),
            half_length_mm=np.full(n, half_length),
            half_width_mm=np.full(n, half_width),
            profile_axial=("uniform",) * n,
            profile_around=("uniform",) * n,
            beta=np.full(n, self.beta),
        )


def knife_edge(
    axial_mm: float,
    angle_deg: float,
    force_n: float,
    *,
    length_mm: float = 10.0,
    alpha_deg: float = 0.0,
) -> LineContact:
    """A knife edge across the finger: the line load of section 4.1 and Fig. 28."""
    return LineContact(
        axial_mm,
        angle_deg,
        force_n,
        length_mm=length_mm,
        orientation_deg=90.0,
        width_mm=0.2,
        alpha_deg=alpha_deg,
    )


def rod(
    axial_mm: float,
    angle_deg: float,
    force_n: float,
    *,
    orientation_deg: float = 45.0,
    length_mm: float = 30.0,
    width_mm: float = 2.0,
) -> LineContact:
    """A rod lying on the cylinder at ``orientation_deg`` to its axis (Fig. 22)."""
    return LineContact(
        axial_mm,
        angle_deg,
        force_n,
        length_mm=length_mm,
        orientation_deg=orientation_deg,
        width_mm=width_mm,
    )


def soft_object(
    axial_mm: float,
    angle_deg: float,
    force_n: float,
    *,
    length_mm: float,
    width_mm: float | None = None,
) -> FlatContact:
    """A large soft object (another finger, Figs. 21 and 26): Hertzian elliptic pressure."""
    return FlatContact(
        axial_mm,
        angle_deg,
        force_n,
        length_mm=length_mm,
        width_mm=length_mm if width_mm is None else width_mm,
        profile="elliptic",
    )


CONTACT_TYPES = {"probe": Probe, "flat": FlatContact, "line": LineContact}


def contact_from_dict(data: dict):
    """Rebuild a contact from :meth:`to_dict` output (recording metadata)."""
    from tactsense.physics.indenters import INDENTERS, indenter_from_dict

    data = dict(data)
    if data.get("kind") in INDENTERS:  # a pad's or a point set's indenter
        return indenter_from_dict(data)
    kind = data.pop("kind", None)
    if kind not in CONTACT_TYPES:
        raise TactsenseInputError(
            f"unknown contact kind {kind!r}; expected one of "
            f"{', '.join([*CONTACT_TYPES, *INDENTERS])}"
        )
    return CONTACT_TYPES[kind](**data)


def contacts_to_patches(contacts, radius_mm: float) -> Patches:
    """All patches of a sequence of contacts."""
    parts = []
    for contact in contacts:
        if isinstance(contact, LineContact):
            parts.append(contact.patches(radius_mm))
        elif isinstance(contact, Probe | FlatContact):
            parts.append(contact.patches())
        else:
            raise TactsenseInputError(
                f"expected Probe, FlatContact or LineContact; got {type(contact).__name__}"
            )
    return Patches.concatenate(parts)
