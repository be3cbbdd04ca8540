"""What the estimators return, and the flags of their rows: the types the estimators
(:mod:`tactsense.estimate.finger`, :mod:`tactsense.estimate.contacts`) fill and the
writers (:mod:`tactsense.estimate.output`) write, importing nothing of either."""

from __future__ import annotations

from dataclasses import dataclass, field, fields
from enum import IntFlag
from typing import ClassVar

import numpy as np


class Flag(IntFlag):
    """Quality flags of an estimate; several may be set at once."""

    NONE = 0
    NO_CONTACT = 1
    """No tactel deflects more than the contact threshold: nothing is reported."""
    NAN_INPUT = 2
    """The frame held NaN or infinite readings; those tactels were ignored."""
    SATURATED = 4
    """A tactel read the converter's full scale: the load there is unknown."""
    DEAD_TACTEL = 8
    """A tactel read zero counts (open junction) or was marked dead; it was ignored."""
    NOT_CONVERGED = 16
    """Newton's method did not reach 0.01 tactel within its iteration limit."""
    EDGE = 32
    """The peak lies within half a tactel of an open edge of the array: biased inward."""
    TIP = 64
    """The peak lies toward the tip row, where the half-plane model does not hold."""
    MULTIPLE = 128
    """A second, separate contact was seen; the fields describe the largest one."""
    BELOW_BASELINE = 256
    """A taxel read below its baseline by more than the contact threshold where no
    tension beside a contact explains it (a resistive taxel, a frame without contact, or
    deeper than the frame's largest compression:
    :func:`~tactsense.estimate.contacts.baseline.below_baseline`): the baseline was taken under
    load, or has drifted (:class:`~tactsense.estimate.contacts.baseline.DriftBaseline`)."""
    NEGATIVE_FORCE = 512
    """A tactel is above the contact threshold but the deflections sum to zero or less:
    the skin reads as much tension as compression around the contact (as the solid 3-D
    skin can, whose tensile side lobes cancel its compression, ``docs/model.md``
    sections 3a-3b), so the sum is no measure of the load; the force is NaN."""
    BEYOND_CALIBRATION = 1024
    """The contact's total signal lies beyond the range its array calibration's weights
    covered (above the heaviest unsaturated weight): its force would be an extrapolation,
    so it is NaN (:mod:`~tactsense.estimate.contacts.array_calibration`)."""

    @classmethod
    def describe(cls, value: int) -> str:
        """Names of the flags set in ``value``, joined by '|' ('' for none)."""
        return "|".join(flag.name for flag in cls if flag and value & flag)


@dataclass
class Estimates:
    """Per-frame estimates; every field has the batch shape of the frames."""

    row: np.ndarray
    """Fractional row of the peak [tactel]; NaN without contact."""
    col: np.ndarray
    """Fractional column of the peak [tactel]."""
    axial_mm: np.ndarray
    """Surface position along the finger [mm]."""
    angle_deg: np.ndarray
    """Surface position around the finger [deg]."""
    peak_deflection: np.ndarray
    """Interpolated fractional deflection at the peak [-]."""
    force_n: np.ndarray
    """Total normal force from the integral of the deflection [N]; NaN in frames flagged
    SATURATED (a clipped reading makes the integral a lower bound only)."""
    skew: np.ndarray
    """Skew index along the finger (eq. 63) [-]."""
    iterations: np.ndarray
    """Newton steps."""
    converged: np.ndarray
    """Newton reached 0.01 tactel."""
    flags: np.ndarray
    """:class:`~tactsense.estimate.finger.deflection.Flag` bits."""

    UNITS: ClassVar[dict[str, str]] = {
        "row": "tactel",
        "col": "tactel",
        "axial_mm": "mm",
        "angle_deg": "deg",
        "peak_deflection": "1",
        "force_n": "N",
        "skew": "1",
        "iterations": "1",
        "converged": "bool",
        "flags": "names",
    }

    def __len__(self) -> int:
        return int(np.size(self.row))

    def _asdict_rows(self) -> list[dict]:
        """One dict per frame (flattened batch), for tests and quick looks."""
        names = [f.name for f in fields(self)]
        columns = {name: np.ravel(getattr(self, name)) for name in names}
        return [{name: columns[name][k] for name in names} for k in range(len(self))]


_INT_COLUMNS = ("frame", "contact", "id", "taxels", "flags")


@dataclass
class ContactTable:
    """Contacts of a batch of frames, one row per contact per frame (long format).

    Every column is a 1-D array of the same length (the number of contacts found);
    rows are sorted by ``frame``, then by ``contact``.
    """

    frame: np.ndarray
    """Index of the frame in the batch (or recording) [-], int64."""
    contact: np.ndarray
    """Rank of the contact within its frame, 0 for the largest force [-], int32."""
    x_mm: np.ndarray
    """Position in the sensor frame [mm]."""
    y_mm: np.ndarray
    """[mm]"""
    z_mm: np.ndarray
    """[mm] (0 on a pad)."""
    row: np.ndarray
    """Fractional row of the peak [taxel] on grids (pads, fingers); NaN on point sets."""
    col: np.ndarray
    """Fractional column of the peak [taxel]; NaN on point sets."""
    force_n: np.ndarray
    """Normal force carried by the contact [N]; NaN when a taxel of it saturated or
    without a force calibration where one is needed."""
    peak: np.ndarray
    """Interpolated peak deflection (capacitive) or strain (resistive) [-]."""
    major_mm: np.ndarray
    """Extent: square root of the larger eigenvalue of the second moment of the
    contact's readings about its centre [mm] (a standard deviation, not a radius)."""
    minor_mm: np.ndarray
    """Extent along the other principal axis [mm]."""
    orientation_deg: np.ndarray
    """Angle of the major axis from the x axis, in (-90, 90] [deg]."""
    taxels: np.ndarray
    """Taxels in the contact's region [-], int32."""
    flags: np.ndarray
    """:class:`~tactsense.estimate.finger.deflection.Flag` bits of the contact, int64."""
    n_frames: int = 0
    """Frames the table covers (frames with no contact have no row)."""
    id: np.ndarray | None = None
    """Stable identity across frames (set by the tracker) [-], int64; None before."""
    vx_mm_s: np.ndarray | None = None
    """Velocity of the tracked contact [mm/s] (set by the tracker)."""
    vy_mm_s: np.ndarray | None = None
    """[mm/s]"""
    vz_mm_s: np.ndarray | None = None
    """[mm/s]"""
    slip: np.ndarray | None = None
    """True where the contact moves under a roughly constant force (tracker), bool."""
    area_mm2: np.ndarray | None = None
    """Area of the contact's taxels, each its cell of the grid (a pad's row pitch times
    column pitch; a finger's axial step times its arc) [mm^2]; NaN on point sets (set
    by :func:`find_contacts`; None in a table made otherwise)."""
    extra: dict = field(default_factory=dict)
    """Further per-row columns (name -> 1-D array), e.g. ``axial_mm`` on a finger."""

    UNITS: ClassVar[dict[str, str]] = {
        "frame": "1",
        "contact": "1",
        "id": "1",
        "x_mm": "mm",
        "y_mm": "mm",
        "z_mm": "mm",
        "row": "taxel",
        "col": "taxel",
        "force_n": "N",
        "peak": "1",
        "major_mm": "mm",
        "minor_mm": "mm",
        "orientation_deg": "deg",
        "taxels": "1",
        "area_mm2": "mm2",
        "flags": "bits",
        "vx_mm_s": "mm/s",
        "vy_mm_s": "mm/s",
        "vz_mm_s": "mm/s",
        "slip": "bool",
    }

    def __len__(self) -> int:
        return int(np.size(self.frame))

    def columns(self) -> dict[str, np.ndarray]:
        """Every column that is set, in a fixed order (``extra`` last)."""
        out = {}
        for f in fields(self):
            if f.name in ("n_frames", "extra"):
                continue
            value = getattr(self, f.name)
            if value is None and f.name == "area_mm2":  # a table made without it
                value = np.full(len(self.frame), np.nan)
            if value is not None:
                out[f.name] = np.asarray(value)
        out.update({k: np.asarray(v) for k, v in self.extra.items()})
        return out

    def per_frame_counts(self) -> np.ndarray:
        """Number of contacts in each of the ``n_frames`` frames [-]."""
        return np.bincount(np.asarray(self.frame, dtype=np.int64), minlength=self.n_frames)

    @classmethod
    def concatenate(cls, tables) -> ContactTable:
        """The tables of consecutive pieces as one: rows joined, ``n_frames`` summed
        (every piece's ``frame`` column is already numbered for the whole)."""
        tables = list(tables)
        if not tables:
            return cls.empty(0)
        kw = {}
        for f in fields(cls):
            if f.name in ("n_frames", "extra"):
                continue
            values = [getattr(t, f.name) for t in tables]
            kw[f.name] = None if any(v is None for v in values) else np.concatenate(values)
        extra = {
            key: np.concatenate([t.extra[key] for t in tables])
            for key in tables[0].extra
            if all(key in t.extra for t in tables)
        }
        return cls(**kw, n_frames=sum(t.n_frames for t in tables), extra=extra)

    @classmethod
    def empty(cls, n_frames: int = 0) -> ContactTable:
        """A table with no contact over ``n_frames`` frames."""
        kw = {}
        for f in fields(cls):
            if f.name in ("n_frames", "extra", "id", "vx_mm_s", "vy_mm_s", "vz_mm_s", "slip"):
                continue
            dtype = np.int64 if f.name in _INT_COLUMNS else float
            kw[f.name] = np.zeros(0, dtype=dtype)
        return cls(**kw, n_frames=n_frames)
