"""Contacts in the robot's frame: every patch of a skin at once, wrenches per link.

:class:`HandLocator` takes hand frames (every taxel of the skin in one vector, patches in
skin order) and, in one compiled call per block of frames (:mod:`._robot_kernel`),
finds every patch's contacts exactly as the single-array estimator does
(:func:`~tactsense.estimate.contacts.find_contacts`, method ``interpolate``, a fixed
baseline), places each in its link's frame (the patch's ``origin``) and in the base frame
(the links' poses for the joint state: URDF forward kinematics), gives it a force vector
(the normal force along the taxel's normal, pressing inward: ``-force_n * normal``; the
kinds estimate no tangential force today) and sums per link the wrench about the link's
origin (force [N], torque [N mm], in the link's frame), as the ROS tactile toolbox's
merger does, and the grasp's total in the base frame about the base origin.

With ``method="joint"`` each pad patch's contacts are instead
``find_contacts(..., method="joint")``'s (every contact of a frame fitted jointly with
its size: position, force, contact radius and flat share; the patch's new frames of a
block in one call), run before the compiled call and handed to it, which places them
and sums the wrenches exactly as for ``interpolate``; point-set patches keep their
estimator (the neighbour graph's peak: they have no size-aware fit).

:func:`locate_robot_recording` runs it over a robot recording (each patch at its own
rate: a hand frame at each frame of the fastest stream, each patch contributing its
latest frame; its contacts written once per frame of its own, at that frame's time, its
wrench held until its next frame). :func:`locate_robot_reference` is the
straightforward per-patch loop the fast path is checked against. Joint states:
:mod:`._robot_joints`.
"""

from __future__ import annotations

import math
from collections.abc import Mapping

import numpy as np

from tactsense._signals import deferred_interrupts
from tactsense._validation import TactsenseInputError
from tactsense.estimate import _robot_kernel as K
from tactsense.estimate._robot_joints import JointStates
from tactsense.estimate._robot_params import (
    _pad_parameters,
    _points_parameters,
    locate_robot_reference,
)
from tactsense.estimate._robot_tables import (
    CONTACT_COLUMNS,
    HAND_METHODS,
    JOINT_COLUMNS,
    WRENCH_COLUMNS,
    RobotContacts,
)
from tactsense.estimate.results import Flag
from tactsense.kinds import kind_of
from tactsense.robot import RobotSkin

OFF_TAXELS = 0.5
"""With ``method="joint"``: a pad contact whose fitted centre lies more than this many
pitches beyond the patch's outer taxels has no force (NaN): beyond the edge the frame
trades the contact's distance for its force (docs/contacts.md, "Two contacts fitted
jointly": a contact 4 mm beyond the last taxel fitted with 2.0 N for 0.49 N; on the docs'
grasp a 33-kN contact two pitches off the palm, docs/robot.md)."""


class HandLocator:
    """Contacts and wrenches of a whole skin, one compiled call per block of hand frames.

    Parameters
    ----------
    skin : RobotSkin
        Its patches must be pads or point sets (the kinds whose contacts are many).
    baselines : mapping of patch name -> array_like (rows, cols)
        Each patch's untouched readings [counts] (a fixed baseline).
    threshold : float or mapping of patch name -> float, optional
        Smallest signal that counts as contact [-]; default each sensor's
        (:func:`~tactsense.estimate.contacts.default_threshold`).
    max_contacts : int
        At most this many contacts per patch and frame (1-64), the largest kept.
    method : {"interpolate", "joint"}
        How a pad patch's contacts are found: ``"interpolate"`` (the default: the paper's
        interpolation and a 1.6-mm probe's amplitude as force, compiled with the rest)
        or ``"joint"`` (the size-aware joint fit of
        :func:`~tactsense.estimate.contacts.find_contacts`: a broad contact's force
        right where ``interpolate`` reads it low; tens of ms to about a second per
        touched pad frame). Point-set patches keep their own estimator either way.
    """

    def __init__(
        self,
        skin: RobotSkin,
        baselines: Mapping[str, np.ndarray],
        *,
        threshold: float | Mapping[str, float] | None = None,
        max_contacts: int = 8,
        method: str = "interpolate",
    ):
        from tactsense.estimate.contacts import default_threshold
        from tactsense.estimate.contacts.pad import MERGED_GAIN, MERGED_HALVES, MERGED_SPREAD
        from tactsense.estimate.contacts.segment import PAIR_RIDGE
        from tactsense.estimate.finger.localize import MAX_ITERATIONS, TOLERANCE
        from tactsense.estimate.reading import reading_mode, unusable_baseline

        if not (isinstance(max_contacts, int) and 1 <= max_contacts <= 64):
            raise TactsenseInputError(
                f"max_contacts must be an integer in 1-64; got {max_contacts!r}"
            )
        if method not in HAND_METHODS:
            raise TactsenseInputError(
                f"method {method!r}: the hand's estimator takes one of "
                f"{', '.join(HAND_METHODS)} ('fit' and 'cop' work on a patch's own stream)"
            )
        self.method = method
        self.skin = skin
        self.patch_names = tuple(p.name for p in skin.patches)
        self.links = tuple(skin._order())
        self.joint_names = skin.movable_joints
        self._joint_column = {name: j for j, name in enumerate(self.joint_names)}
        movable = {j.name: j for j in skin.joints}
        self._lower = np.array([movable[name].lower - 1e-9 for name in self.joint_names])
        self._upper = np.array([movable[name].upper + 1e-9 for name in self.joint_names])
        link_index = {name: i for i, name in enumerate(self.links)}
        by_child = {j.child: j for j in skin.joints}
        n_links = len(self.links)
        self._parent = np.full(n_links, -1, np.int64)
        self._jtype = np.zeros(n_links, np.int64)
        self._origin = np.tile(np.eye(4), (n_links, 1, 1))
        self._axis = np.zeros((n_links, 3))
        self._column = np.full(n_links, -1, np.int64)
        for i, name in enumerate(self.links):
            joint = by_child.get(name)
            if joint is None:
                continue
            self._parent[i] = link_index[joint.parent]
            self._origin[i] = joint.origin.matrix()
            self._axis[i] = joint.axis
            self._jtype[i] = {"fixed": 0, "prismatic": 2}.get(joint.type, 1)
            if joint.type != "fixed":
                self._column[i] = self.joint_names.index(joint.name)
        n_patches = len(skin.patches)
        sizes = [p.n_taxels for p in skin.patches]
        self._offset = np.concatenate([[0], np.cumsum(sizes)[:-1]]).astype(np.int64)
        self.n_taxels = int(sum(sizes))
        self._mode = np.zeros(n_patches, np.int64)
        self._rows = np.array([p.sensor.shape[0] for p in skin.patches], np.int64)
        self._cols = np.array([p.sensor.shape[1] for p in skin.patches], np.int64)
        self._link = np.array([link_index[p.link] for p in skin.patches], np.int64)
        self._kernel_of = np.zeros(n_patches, np.int64)
        self._thresholds = np.zeros(n_patches)
        self._param = np.zeros((n_patches, K.N_PARAM))
        self._pose = np.array([p.origin.matrix() for p in skin.patches]).reshape(-1, 4, 4)
        self._baseline = np.zeros(self.n_taxels)
        self._unusable = np.zeros(self.n_taxels, np.bool_)
        self._normals = np.zeros((self.n_taxels, 3))
        self._positions = np.zeros((self.n_taxels, 3))
        graph_offset = np.zeros(n_patches, np.int64)
        nb_offsets, nb_lists, kernels, pt_offset = [], [], [], np.zeros(n_patches, np.int64)
        pad_kernels: dict = {}
        kernel_list: list = []
        graph_start, kernel_start = 0, 0
        for p, patch in enumerate(skin.patches):
            sensor = patch.sensor
            kind = kind_of(sensor)
            off, size = self._offset[p], sizes[p]
            if isinstance(threshold, Mapping):
                value = threshold.get(patch.name)
            else:
                value = threshold
            value = default_threshold(sensor) if value is None else value
            if not (isinstance(value, float | int) and math.isfinite(value) and value > 0):
                raise TactsenseInputError(
                    f"threshold for patch {patch.name!r} must be a positive number; got {value!r}"
                )
            if kind.image_grid and kind.multi_contact and kind.response_fit:
                if kind.periodic(sensor):
                    raise TactsenseInputError(f"patch {patch.name!r}: a periodic grid is not a pad")
                param, tables = _pad_parameters(sensor, float(value))
                key = id(tables[0])
                if key not in pad_kernels:
                    pad_kernels[key] = len(kernel_list)
                    kernel_list.append(tables)
                self._kernel_of[p] = pad_kernels[key]
                if method == "joint":
                    self._mode[p] = K.MODE_GIVEN
            elif not kind.image_grid and kind.multi_contact:
                self._mode[p] = K.MODE_POINTS
                param, positions, neighbours, kernel = _points_parameters(sensor, float(value))
                self._positions[off : off + size] = positions
                starts = np.cumsum([0] + [len(n) for n in neighbours]) + sum(map(len, nb_lists))
                graph_offset[p] = graph_start
                nb_offsets.append(starts)
                nb_lists.extend(neighbours)
                graph_start += size + 1
                pt_offset[p] = kernel_start
                kernels.append(kernel.ravel())
                kernel_start += size * size
            else:
                raise TactsenseInputError(
                    f"patch {patch.name!r} is a {kind.label}: the hand's estimator places the "
                    "contacts of pads and point sets; locate this patch's stream on its own"
                )
            self._thresholds[p] = float(value)
            resistive, falling, per_count = reading_mode(sensor)
            param[K.P_FULL_SCALE] = float(2**sensor.electronics.adc_bits - 1)
            param[K.P_RESISTIVE] = float(resistive)
            param[K.P_FALLING] = float(falling)
            param[K.P_PER_COUNT] = per_count
            self._param[p] = param
            self._normals[off : off + size] = np.asarray(sensor.taxel_normals(), float)
            if patch.name not in baselines:
                raise TactsenseInputError(f"no baseline for patch {patch.name!r}")
            base = np.asarray(baselines[patch.name], float)
            if base.shape != tuple(sensor.shape):
                raise TactsenseInputError(
                    f"baseline of patch {patch.name!r} has shape {base.shape}; expected "
                    f"{tuple(sensor.shape)}"
                )
            bad = unusable_baseline(base, sensor)
            self._unusable[off : off + size] = bad.ravel()
            self._baseline[off : off + size] = np.where(bad, 1.0, base).ravel()
        self._graph_offset = graph_offset
        self._nb_offset = (
            np.concatenate(nb_offsets).astype(np.int64) if nb_offsets else np.zeros(1, np.int64)
        )
        self._neighbours = (
            np.concatenate(nb_lists).astype(np.int64) if nb_lists else np.zeros(1, np.int64)
        )
        self._pt_kernel = np.concatenate(kernels) if kernels else np.zeros(1)
        self._pt_offset = pt_offset
        if not kernel_list:  # no pad: tables of the right type, never read
            from tactsense.sensor import preset

            kernel_list.append(_pad_parameters(preset("pad16"), 0.01)[1])
        self._k_amp = np.ascontiguousarray(np.stack([t[0] for t in kernel_list]))
        self._amp_step = float(kernel_list[0][1])
        self._k_sig = np.ascontiguousarray(np.stack([t[2] for t in kernel_list]))
        self._sig_step = float(kernel_list[0][3])
        self._k_max = np.ascontiguousarray(np.stack([t[4] for t in kernel_list]))
        self._halves = np.asarray(MERGED_HALVES, float)
        self._settings = (max_contacts, TOLERANCE, MAX_ITERATIONS, PAIR_RIDGE, MERGED_GAIN,
                          MERGED_SPREAD)  # fmt: skip
        self._flag_bits = np.array(
            [Flag.NAN_INPUT, Flag.SATURATED, Flag.DEAD_TACTEL, Flag.NOT_CONVERGED, Flag.EDGE],
            np.int64,
        )
        self.max_contacts = max_contacts
        self._link_has_patch = np.isin(np.arange(n_links), self._link)
        self.reset()
        self.locate(np.tile(self._baseline, (1, 1)))  # compile (or load) now
        self.reset()

    def reset(self) -> None:
        """Forget the held wrenches and the last frames (a jump in time)."""
        self._held = np.zeros((len(self.patch_names), 6))
        self._held_count = np.zeros(len(self.patch_names), np.int64)
        self._last = self._baseline.copy()
        self._patch_index = {name: p for p, name in enumerate(self.patch_names)}

    def update(self, patches: Mapping[str, np.ndarray], joints=None, *, time_s=None):
        """Live: the contacts of the patches in ``patches`` (name -> (rows, cols) counts,
        e.g. one device's frame), every other patch's wrench held; one compiled call.
        Returns a :class:`RobotContacts` of one hand frame (the wrenches of every link)."""
        fresh = np.zeros((1, len(self.patch_names)), np.bool_)
        for name, frame in patches.items():
            p = self._patch_index.get(name)
            if p is None:
                raise TactsenseInputError(f"{self.skin.name!r} has no patch {name!r}")
            size = int(self._rows[p] * self._cols[p])
            self._last[self._offset[p] : self._offset[p] + size] = np.ravel(frame)
            fresh[0, p] = True
        return self.locate(
            self._last[np.newaxis], joints, fresh=fresh,
            time_s=None if time_s is None else np.array([time_s], float),
        )  # fmt: skip

    def pack(self, frames: Mapping[str, np.ndarray]) -> np.ndarray:
        """Hand frames (n, T) [counts] from each patch's frames (n, rows, cols)."""
        first = np.asarray(frames[self.patch_names[0]])
        n = first.size // int(self._rows[0] * self._cols[0])
        out = np.empty((n, self.n_taxels))
        for p, name in enumerate(self.patch_names):
            size = int(self._rows[p] * self._cols[p])
            out[:, self._offset[p] : self._offset[p] + size] = np.asarray(frames[name]).reshape(
                n, size
            )
        return out

    def joint_array(self, joints, n: int) -> np.ndarray:
        """Joint positions (n, J) [rad or m] from a mapping (a fixed pose), an array, or
        None (every joint at 0); a mapping is checked against the skin."""
        if joints is None:
            return np.zeros((n, len(self.joint_names)))
        if isinstance(joints, Mapping):
            known = self._joint_column
            try:
                row = np.zeros(len(self.joint_names))
                for name, value in joints.items():
                    row[known[name]] = value
                ok = bool(np.all((row >= self._lower) & (row <= self._upper)))
            except (KeyError, TypeError, ValueError):
                ok = False
            if not ok:
                self.skin.link_poses(joints)  # raises what is wrong (names, values, limits)
            return np.broadcast_to(row, (n, len(row)))
        joints = np.asarray(joints, float).reshape(n, len(self.joint_names))
        return joints

    def locate(
        self, counts, joints=None, *, fresh=None, time_s=None, patch_time_s=None,
        first_frame: int = 0,
    ):  # fmt: skip
        """Contacts and wrenches of hand frames.

        Parameters
        ----------
        counts : array_like, shape (n, T) or (T,)
            Hand frames [counts] (:meth:`pack`).
        joints : mapping, array (n, J) or None
            The joint state (:meth:`joint_array`; columns in :attr:`joint_names`).
        fresh : array of bool (n, P), optional
            Which patches hold a new frame (default all).
        time_s : array (n,), optional
            Time of each hand frame [s] (default the frame index).
        patch_time_s : array (n, P), optional
            Time of each patch's frame in each hand frame [s] (a contact row's
            ``time_s``; default the hand frame's).
        """
        counts = np.asarray(counts)
        if counts.ndim == 1:
            counts = counts[np.newaxis]
        if counts.ndim != 2 or counts.shape[1] != self.n_taxels:
            raise TactsenseInputError(
                f"hand frames have shape {counts.shape}; expected (n, {self.n_taxels})"
            )
        if counts.dtype not in (np.float64,):
            counts = counts.astype(np.float64)
        n = len(counts)
        q = np.ascontiguousarray(self.joint_array(joints, n))
        n_patches = len(self.patch_names)
        fresh = np.ones((n, n_patches), np.bool_) if fresh is None else np.asarray(fresh, bool)
        capacity = max(16, int(fresh.sum()) * self.max_contacts)
        out_i = np.empty((capacity, K.N_INT), np.int64)
        out_f = np.empty((capacity, K.N_FLOAT))
        n_links = len(self.links)
        wrench_link = np.empty((n, n_links, 6))
        wrench_total = np.empty((n, 6))
        contacts_link = np.empty((n, n_links), np.int64)
        given = self._joint_contacts(counts, fresh)
        with deferred_interrupts():
            m = K.hand_block(
                np.ascontiguousarray(counts), fresh, q, self._parent, self._jtype, self._origin,
                self._axis, self._column, self._mode, self._offset, self._rows, self._cols,
                self._link, self._kernel_of, self._param, self._pose, self._graph_offset,
                self._baseline, self._unusable, self._normals, self._positions, self._neighbours,
                self._nb_offset, self._pt_kernel, self._pt_offset, self._k_amp, self._amp_step,
                self._k_sig, self._sig_step, self._k_max, self._halves, *self._settings,
                self._flag_bits, self._held, self._held_count, out_i, out_f, wrench_link,
                wrench_total, contacts_link, *given,
            )  # fmt: skip
        time_s = np.arange(first_frame, first_frame + n, dtype=float) if time_s is None else time_s
        time_s = np.asarray(time_s, float)
        frame, patch = out_i[:m, K.I_FRAME], out_i[:m, K.I_PATCH]
        row_time = time_s[frame] if patch_time_s is None else np.asarray(patch_time_s)[frame, patch]
        return RobotContacts(
            n_frames=n, total=wrench_total, n_contacts=m,
            build=lambda: self._tables(out_i[:m], out_f[:m], wrench_link, wrench_total,
                                       contacts_link, time_s, row_time, first_frame),
        )  # fmt: skip

    def _joint_contacts(self, counts, fresh) -> tuple:
        """The joint fit's contacts of every :data:`~._robot_kernel.MODE_GIVEN` patch's
        new frames (one :func:`find_contacts` call per patch and block), in the slots
        :func:`~._robot_kernel.hand_block` reads (``given_*``).

        A contact the fit places off the patch's taxels (its centre more than half a
        pitch beyond the outer rows or columns; flagged ``EDGE``) keeps its row with a NaN
        force, which adds nothing to a wrench (as a saturated contact's): the taxels see
        only its flank, where the fit trades distance for force (:data:`OFF_TAXELS`)."""
        k = self.max_contacts
        joint = np.flatnonzero(self._mode == K.MODE_GIVEN)
        start = np.zeros(len(self.patch_names), np.int64)
        slots = 0
        for p in joint:
            start[p] = slots
            slots += int(fresh[:, p].sum())
        count = np.zeros(max(slots, 1), np.int64)
        rc = np.zeros((max(slots, 1), k, 2))
        value = np.zeros((max(slots, 1), k))
        force = np.zeros((max(slots, 1), k))
        taxels = np.zeros((max(slots, 1), k), np.int64)
        flags = np.zeros((max(slots, 1), k), np.int64)
        size = np.full((max(slots, 1), k, 2), np.nan)
        if slots == 0:
            return start, count, rc, value, force, taxels, flags, size
        from tactsense.estimate.contacts import find_contacts

        for p in joint:
            new = np.flatnonzero(fresh[:, p])
            if len(new) == 0:
                continue
            sensor = self.skin.patches[p].sensor
            off, taxels_p = self._offset[p], int(self._rows[p] * self._cols[p])
            shape = tuple(sensor.shape)
            table = find_contacts(
                counts[new, off : off + taxels_p].reshape(len(new), *shape), sensor,
                baseline=self._baseline[off : off + taxels_p].reshape(shape),
                dead=self._unusable[off : off + taxels_p].reshape(shape),
                threshold=float(self._thresholds[p]), max_contacts=k, method="joint",
            )  # fmt: skip
            slot = start[p] + table.frame
            rank = table.contact
            rows, cols = shape
            off = (table.row < -OFF_TAXELS) | (table.row > rows - 1 + OFF_TAXELS)
            off |= (table.col < -OFF_TAXELS) | (table.col > cols - 1 + OFF_TAXELS)
            table.force_n[off] = np.nan  # off the taxels: listed, adds nothing (OFF_TAXELS)
            count[start[p] : start[p] + len(new)] = np.bincount(table.frame, minlength=len(new))
            rc[slot, rank, 0], rc[slot, rank, 1] = table.row, table.col
            value[slot, rank], force[slot, rank] = table.peak, table.force_n
            taxels[slot, rank], flags[slot, rank] = table.taxels, table.flags
            size[slot, rank, 0] = table.extra["contact_radius_mm"]
            size[slot, rank, 1] = table.extra["flat_share"]
        return start, count, rc, value, force, taxels, flags, size

    def _tables(
        self, out_i, out_f, wrench_link, wrench_total, contacts_link, time_s, row_time, first
    ):
        frame = out_i[:, K.I_FRAME]
        force = out_f[:, K.F_FORCE]
        contacts = {
            "time_s": row_time,
            "frame": frame + first,
            "patch": np.asarray(self.patch_names, dtype=object)[out_i[:, K.I_PATCH]],
            "link": np.asarray(self.links, dtype=object)[out_i[:, K.I_LINK]],
            "contact": out_i[:, K.I_RANK],
        }
        for name, column in (
            ("x_mm", K.F_XS), ("y_mm", K.F_YS), ("z_mm", K.F_ZS), ("x_link_mm", K.F_XL),
            ("y_link_mm", K.F_YL), ("z_link_mm", K.F_ZL), ("nx_link", K.F_NXL),
            ("ny_link", K.F_NYL), ("nz_link", K.F_NZL), ("x_base_mm", K.F_XB),
            ("y_base_mm", K.F_YB), ("z_base_mm", K.F_ZB), ("nx_base", K.F_NXB),
            ("ny_base", K.F_NYB), ("nz_base", K.F_NZB),
        ):  # fmt: skip
            contacts[name] = out_f[:, column].copy()
        contacts["force_n"] = force.copy()
        for frame_name, column in (("link", K.F_NXL), ("base", K.F_NXB)):
            for a, axis in enumerate("xyz"):
                contacts[f"f{axis}_{frame_name}_n"] = -force * out_f[:, column + a]
        contacts["row"] = out_f[:, K.F_ROW].copy()
        contacts["col"] = out_f[:, K.F_COL].copy()
        contacts["peak"] = out_f[:, K.F_PEAK].copy()
        contacts["taxels"] = out_i[:, K.I_TAXELS].copy()
        contacts["flags"] = out_i[:, K.I_FLAGS].copy()
        if self.method == "joint":  # the joint fit's size (NaN on point sets)
            contacts["contact_radius_mm"] = out_f[:, K.F_RADIUS].copy()
            contacts["flat_share"] = out_f[:, K.F_FLAT].copy()
        n = len(time_s)
        links = np.flatnonzero(self._link_has_patch)
        per = len(links) + 1
        w = np.empty((n, per, 6))
        w[:, :-1] = wrench_link[:, links]
        w[:, -1] = wrench_total
        held = np.empty((n, per), np.int64)
        held[:, :-1] = contacts_link[:, links]
        held[:, -1] = contacts_link.sum(axis=1)
        names = np.asarray([self.links[i] for i in links] + [self.skin.base_link], dtype=object)
        what = np.asarray(["link"] * len(links) + ["total"], dtype=object)
        wrenches = {
            "time_s": np.repeat(time_s, per),
            "frame": np.repeat(np.arange(first, first + n), per),
            "link": np.tile(names, n),
            "what": np.tile(what, n),
            "contacts": held.ravel(),
        }
        for c, name in enumerate(("force_x_n", "force_y_n", "force_z_n", "torque_x_n_mm",
                                  "torque_y_n_mm", "torque_z_n_mm")):  # fmt: skip
            wrenches[name] = w[:, :, c].ravel()
        return contacts, wrenches


def hand_frame_grid(streams_time_s: Mapping[str, np.ndarray], patch_names) -> tuple:
    """Hand frames of streams at their own rates: at each frame of the fastest stream
    (the most frames; ties: the first in skin order), each patch's latest frame at or
    before it. Returns ``(time_s (n,), index (n, P) frame of each patch or -1, fresh (n, P))``."""
    present = [name for name in patch_names if name in streams_time_s]
    if not present:
        raise TactsenseInputError("the recording holds no stream of the skin's patches")
    lead = max(present, key=lambda name: len(streams_time_s[name]))
    times = np.asarray(streams_time_s[lead], float)
    index = np.full((len(times), len(patch_names)), -1, np.int64)
    for p, name in enumerate(patch_names):
        if name in streams_time_s:
            own = np.asarray(streams_time_s[name], float)
            index[:, p] = np.searchsorted(own, times, side="right") - 1
    fresh = index >= 0
    fresh[1:] &= index[1:] != index[:-1]
    return times, index, fresh


__all__ = [
    "CONTACT_COLUMNS",
    "HAND_METHODS",
    "JOINT_COLUMNS",
    "OFF_TAXELS",
    "WRENCH_COLUMNS",
    "HandLocator",
    "JointStates",
    "RobotContacts",
    "hand_frame_grid",
    "locate_robot_reference",
]
