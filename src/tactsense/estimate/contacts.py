"""Several contacts per frame, on any array: the long table every multi-contact tool shares.

A :class:`ContactTable` holds one row per contact per frame (a "long" table): the
segmentation (:func:`find_contacts`) fills the geometric columns, the tracker
(:mod:`tactsense.estimate.track`) the identity and motion columns. Frames without any
contact have no row; ``n_frames`` says how many frames the table covers, so that empty
frames are known.

Positions are in the sensor's own frame [mm] for every kind of array: a pad's taxel
``(r, c)`` sits at ``x = r * row_pitch_mm``, ``y = c * col_pitch_mm``, ``z = 0``; a point
set's and a finger's positions are points of the surface (``taxel_positions_mm``).
"""

from __future__ import annotations

from dataclasses import dataclass, field, fields
from typing import ClassVar

import numpy as np

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
    """:class:`~tactsense.estimate.deflection.Flag` bits of the contact, int64."""
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
            if value is not None:
                out[f.name] = np.asarray(value)
        out.update({k: np.asarray(v) for k, v in self.extra.items()})
        return out

    def per_frame_counts(self) -> np.ndarray:
        """Number of contacts in each of the ``n_frames`` frames [-]."""
        return np.bincount(np.asarray(self.frame, dtype=np.int64), minlength=self.n_frames)

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
