"""The hand's estimator's tables: the long table of contacts and the wrench table
(:mod:`tactsense.estimate.robot`)."""

from __future__ import annotations

import numpy as np

CONTACT_COLUMNS = (
    "time_s", "frame", "patch", "link", "contact", "x_mm", "y_mm", "z_mm",
    "x_link_mm", "y_link_mm", "z_link_mm", "nx_link", "ny_link", "nz_link",
    "x_base_mm", "y_base_mm", "z_base_mm", "nx_base", "ny_base", "nz_base",
    "force_n", "fx_link_n", "fy_link_n", "fz_link_n", "fx_base_n", "fy_base_n", "fz_base_n",
    "row", "col", "peak", "taxels", "flags",
)  # fmt: skip
"""Columns of the long table of contacts: the time and hand frame, the patch, its link,
the contact's rank in its patch's frame (0: the largest summed signal); its point in the
sensor's frame (``x_mm``...; a pad's ``row``/``col`` [taxel]), in the link's frame and in
the base frame [mm] with the unit outward normal there; its normal force [N] and force
vector (``-force_n * normal``) in both frames [N]; interpolated peak signal [-], taxels
and flags (:class:`~tactsense.estimate.results.Flag`)."""

JOINT_COLUMNS = (*CONTACT_COLUMNS, "contact_radius_mm", "flat_share")
"""Columns of the long table with ``method="joint"``: :data:`CONTACT_COLUMNS` and the
joint fit's contact radius [mm] and flat share [-] (the share of the force pressed as a
uniform pressure over the disc, the rest as a Hertzian sphere's: ``find_contacts``'s
extras of the same names, docs/contacts.md); NaN on point-set patches,
which keep their own estimator."""

HAND_METHODS = ("interpolate", "joint")
"""How the hand's estimator finds a pad patch's contacts (:class:`HandLocator`)."""

WRENCH_COLUMNS = (
    "time_s", "frame", "link", "what", "contacts", "force_x_n", "force_y_n", "force_z_n",
    "torque_x_n_mm", "torque_y_n_mm", "torque_z_n_mm",
)  # fmt: skip
"""Columns of the wrench table: per hand frame one row per link holding patches
(``what = "link"``: in the link's frame, torque about the link's origin) and one for the
grasp (``what = "total"``, ``link`` the base link: in the base frame about its origin);
``contacts`` the contacts held; force [N], torque [N mm]."""


class RobotContacts:
    """The long table of contacts and the wrench table of some hand frames (columns as
    :data:`CONTACT_COLUMNS` and :data:`WRENCH_COLUMNS`, NumPy arrays), built when first
    asked for (a live loop that reads only :attr:`total` does not pay for them).

    Attributes
    ----------
    n_frames : int
        Hand frames covered.
    total : ndarray (n_frames, 6) or None
        The grasp's total wrench per hand frame, in the base frame about its origin:
        force [N], torque [N mm].
    n_contacts : int
        Contact rows.
    """

    def __init__(self, contacts=None, wrenches=None, n_frames: int = 0, warnings=None, *,
                 build=None, total=None, n_contacts: int | None = None):  # fmt: skip
        self._contacts = contacts
        self._wrenches = wrenches
        self._build = build
        self.n_frames = int(n_frames)
        self.warnings: list[str] = list(warnings or [])
        self.total = total
        self.n_contacts = len(contacts["frame"]) if n_contacts is None else int(n_contacts)

    def _materialize(self) -> None:
        if self._build is not None:
            self._contacts, self._wrenches = self._build()
            self._build = None

    @property
    def contacts(self) -> dict[str, np.ndarray]:
        self._materialize()
        return self._contacts

    @property
    def wrenches(self) -> dict[str, np.ndarray]:
        self._materialize()
        return self._wrenches

    def contacts_table(self):
        """The contacts as a :class:`pyarrow.Table`."""
        return _arrow(self.contacts)

    def wrenches_table(self):
        """The wrenches as a :class:`pyarrow.Table`."""
        return _arrow(self.wrenches)

    @classmethod
    def concatenate(cls, parts) -> RobotContacts:
        parts = list(parts)
        join = lambda what: {  # noqa: E731
            key: np.concatenate([getattr(p, what)[key] for p in parts])
            for key in getattr(parts[0], what)
        }
        totals = [p.total for p in parts]
        total = np.concatenate(totals) if all(t is not None for t in totals) else None
        return cls(join("contacts"), join("wrenches"), sum(p.n_frames for p in parts),
                   total=total)  # fmt: skip


def _arrow(columns):
    """A pyarrow table with a fixed type per column (names as strings), whatever the
    rows: the blocks of one run share one schema."""
    import pyarrow as pa

    arrays = {}
    for key, value in columns.items():
        kind = pa.string() if value.dtype == object else pa.from_numpy_dtype(value.dtype)
        arrays[key] = pa.array(value, type=kind)
    return pa.table(arrays)
