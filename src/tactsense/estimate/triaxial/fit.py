"""Each contact of a three-axis frame: position, normal force and tangential force.

A frame's change from the rest readings (every taxel's three components [counts], each
taxel's through its 3x3 calibration matrix) is split into contacts: the taxels whose
change is larger than the threshold, in groups of neighbours (8-connected). Each group,
with the ring of taxels around it (less other groups' taxels), is fitted with the
kind's response (:mod:`.response`): for a position ``p`` the change is
``N R_n(p) + Q_x R_x(p) + Q_y R_y(p)``, linear in the loads, so the loads are a linear
least-squares solution at each node of the response grid and the position is the node
of least residual, refined by a simplex search over the response's cubic spline
between nodes (variable projection). The tangential force's magnitude and direction follow.

The normal force cannot come from a sum over the taxels: an incompressible layer
(nu = 0.5) bonded to a rigid base moves as much material up beside a contact as down
under it, and a magnet beside a press reads the opposite change of one under it; the
fit of the response to all three components uses both.
"""

from __future__ import annotations

import math

import numpy as np
from scipy import ndimage, optimize

from tactsense._validation import TactsenseInputError
from tactsense.estimate.reading import vector_threshold_counts
from tactsense.estimate.results import ContactTable, Flag
from tactsense.estimate.triaxial.response import response_table

_EIGHT = np.ones((3, 3), dtype=bool)


def vector_taxels(sensor) -> bool:
    """Whether ``sensor``'s taxels read several components (``frame_shape`` has a
    component axis): its contacts are this package's to estimate."""
    return int(getattr(sensor, "components", 1)) > 1


def default_threshold_counts(sensor) -> float:
    """Smallest change of a taxel's field that counts as contact [counts]
    (:func:`~tactsense.estimate.reading.vector_threshold_counts`)."""
    return vector_threshold_counts(sensor)


def check_vector_frames(frames, sensor) -> np.ndarray:
    """``frames`` as float, shape (N, rows, cols, components), or a one-line error."""
    frames = np.asarray(frames, dtype=float)
    shape = tuple(sensor.frame_shape)
    if frames.shape == shape:
        frames = frames[None]
    if frames.ndim != len(shape) + 1 or frames.shape[1:] != shape:
        raise TactsenseInputError(
            f"frames of {sensor.name!r} must have the shape (N, {', '.join(map(str, shape))}) "
            f"(rows, cols, components); got {frames.shape}"
        )
    return frames


def find_shear_contacts(
    frames,
    sensor,
    *,
    baseline,
    calibration=None,
    threshold_counts: float | None = None,
    max_contacts: int = 8,
    first_frame: int = 0,
    dead=None,
    radius_mm: float | None = None,
) -> ContactTable:
    """Every contact of every frame of a three-axis sensor.

    Parameters
    ----------
    frames : array_like, shape (N, rows, cols, 3) or (rows, cols, 3)
        Readings [counts].
    sensor : a three-axis sensor description (``frame_shape`` (rows, cols, 3))
    baseline : array_like, shape (rows, cols, 3)
        Every taxel's rest reading [counts].
    calibration : TriaxialCalibration, optional
        Its per-taxel 3x3 matrices map each taxel's change to the model's.
    threshold_counts : float, optional
        Smallest change of a taxel's field (length of the change of its three
        components) that counts as contact [counts]; :func:`default_threshold_counts`.
    max_contacts : int
        At most this many contacts per frame (the largest by normal force), 1-64.
    first_frame : int
        Added to the ``frame`` column.
    dead : array_like of bool, shape (rows, cols), optional
        Taxels to ignore.
    radius_mm : float, optional
        Radius of the indenter's sphere [mm]: the response fitted is the kind's for it
        (:func:`.response.response_table`); None: the kind's default probe.

    Returns
    -------
    ContactTable
        One row per contact per frame, with the extra columns ``shear_x_n``,
        ``shear_y_n`` (tangential force the contact applies to the skin along x and y
        [N]), ``shear_n`` (its magnitude [N]), ``shear_angle_deg`` (its direction from
        +x toward +y, in (-180, 180] [deg]), ``shear_ratio`` (tangential over normal
        force [-]) and ``residual`` (the fit's residual over the read noise [-]).
    """
    if not (isinstance(max_contacts, int | np.integer) and 1 <= max_contacts <= 64):
        raise TactsenseInputError(f"max_contacts must be an integer in 1-64; got {max_contacts!r}")
    frames = check_vector_frames(frames, sensor)
    base = np.asarray(baseline, dtype=float)
    if base.shape != tuple(sensor.frame_shape):
        raise TactsenseInputError(
            f"baseline must have the shape {tuple(sensor.frame_shape)}; got {base.shape}"
        )
    if threshold_counts is None:
        threshold_counts = default_threshold_counts(sensor)
    if not (math.isfinite(threshold_counts) and threshold_counts > 0):
        raise TactsenseInputError(f"threshold must be positive; got {threshold_counts!r}")
    rows, cols = sensor.shape
    full_scale = 2**sensor.electronics.adc_bits - 1
    table = response_table(sensor, radius_mm=radius_mm)
    bad = np.zeros((rows, cols), bool) if dead is None else np.asarray(dead, bool).copy()
    out: dict[str, list] = {name: [] for name in _COLUMNS}
    for f, frame in enumerate(frames):
        flags = 0
        finite = np.isfinite(frame).all(axis=-1)
        if not finite.all():
            flags |= int(Flag.NAN_INPUT)
        railed = ((frame <= 0) | (frame >= full_scale)).any(axis=-1) & finite
        ignored = bad | ~finite
        change = np.where(ignored[..., None], 0.0, np.nan_to_num(frame) - base)
        if calibration is not None:
            change = calibration.apply(change)
        size = np.linalg.norm(change, axis=-1)
        above = (size > threshold_counts) & ~ignored
        if not above.any():
            continue
        labels, n = ndimage.label(above, structure=_EIGHT)
        found = []
        for label in range(1, n + 1):
            own = labels == label
            window = ndimage.binary_dilation(own, structure=_EIGHT) & ~ignored
            window &= (labels == 0) | own
            fits = _fit_group(change, window, own, table, sensor, max_contacts > 1)
            for fit, mine in fits:
                found.append((fit, mine, railed))
        found.sort(key=lambda item: -item[0]["force_n"])
        for rank, (fit, own, railed_) in enumerate(found[:max_contacts]):
            _append(out, first_frame + f, rank, fit, own, size, railed_, flags, sensor)
    return _table(out, len(frames), sensor)


_COLUMNS = ("frame", "contact", "x_mm", "y_mm", "force_n", "shear_x_n", "shear_y_n",
            "residual", "peak", "taxels", "flags", "rr", "cc", "rc")  # fmt: skip


def _solve(a: np.ndarray, m: np.ndarray):
    """Loads (P, 3) and residual (P,) of ``m`` (k,) against responses ``a`` (P, 3, k)."""
    gram = np.einsum("pik,pjk->pij", a, a) + 1e-9 * np.eye(3)
    rhs = np.einsum("pik,k->pi", a, m)
    loads = np.linalg.solve(gram, rhs[..., None])[..., 0]
    residual = float(m @ m) - np.einsum("pi,pi->p", loads, rhs)
    return loads, residual


def _fit_group(change, window, own, table, sensor, pairs: bool = True) -> list:
    """The contacts on the group ``own``: one, or two where a pair explains its taxels
    much better (:data:`PAIR_GAIN`), each as (fit dict, its taxels)."""
    pick = np.repeat(window.ravel(), 3)
    m = change.reshape(-1)[pick]
    rows_, cols_ = np.nonzero(own)
    n_sub_x = (len(table.x_mm) - 1) / sensor.shape[0]
    n_sub_y = (len(table.y_mm) - 1) / sensor.shape[1]
    # nodes within a pitch of the group's taxels
    i0 = max(0, int((rows_.min() - 0.5) * n_sub_x))
    i1 = min(len(table.x_mm), math.ceil((rows_.max() + 1.5) * n_sub_x) + 1)
    j0 = max(0, int((cols_.min() - 0.5) * n_sub_y))
    j1 = min(len(table.y_mm), math.ceil((cols_.max() + 1.5) * n_sub_y) + 1)
    a = table.values[i0:i1, j0:j1][..., pick]
    nodes = (table.x_mm[i0:i1], table.y_mm[j0:j1])
    one = _fit_one(m, a, nodes, table, pick)
    if one is None:
        return []
    noise = max(float(getattr(sensor.flaws, "read_noise_counts", 0.0) or 0.0), 1.0)
    fits = [one]
    if pairs and own.sum() >= 3 and _rms(one[1], m) > PAIR_MIN * noise:
        pair = _fit_pair(m, a, nodes, table, pick, one, sensor)
        if pair is not None and pair[1] < one[1] / PAIR_GAIN:
            fits = [(pair[0][0], pair[1]), (pair[0][1], pair[1])]
    out = []
    positions = np.array([f[0][:2] for f in fits])
    r, c = np.nonzero(own)
    xy = np.column_stack([r * sensor.grid.row_pitch_mm, c * sensor.grid.col_pitch_mm])
    nearest = np.argmin(((xy[:, None] - positions[None]) ** 2).sum(-1), axis=1)
    for k, ((x, y, load), res) in enumerate(fits):
        mine = np.zeros_like(own)
        mine[r[nearest == k], c[nearest == k]] = True
        if not mine.any():
            continue
        fit = {"x_mm": float(x), "y_mm": float(y), "force_n": float(load[0]),
               "shear_x_n": float(load[1]), "shear_y_n": float(load[2]),
               "residual": _rms(res, m) / noise}  # fmt: skip
        out.append((fit, mine))
    return out


PAIR_MIN = 4.0
"""A group whose one-contact fit leaves more than this many read noises (rms) is tried
as a pair of contacts [-]."""

PAIR_GAIN = 4.0
"""A pair replaces the one contact where it divides the residual (sum of squares) by
more than this [-]."""


PAIR_SEPARATION = 0.9
"""Two contacts closer than this many pitches are one (a single contact's misfit, the
field's curvature under a magnet, is not taken for a second) [-]."""


def _rms(res: float, m: np.ndarray) -> float:
    return math.sqrt(max(float(res), 0.0) / max(len(m), 1))


def _fit_one(m, a, nodes, table, pick):
    """((x, y, loads), residual) of one contact, or None."""
    shape = a.shape[:2]
    loads, residual = _solve(a.reshape(-1, 3, a.shape[-1]), m)
    residual = np.where(loads[:, 0] > 0, residual, np.inf).reshape(shape)
    if not np.isfinite(residual).any():
        return None
    bi, bj = np.unravel_index(int(np.argmin(residual)), shape)
    x0, y0 = nodes[0][bi], nodes[1][bj]
    hx, hy = table.step_mm

    def solved(p):
        loads_, res_ = _solve(table.at(p[0], p[1], pick)[None], m)
        return loads_[0], float(res_[0])

    best = optimize.minimize(
        lambda p: solved(p)[1], np.array([x0, y0]), method="Nelder-Mead",
        options={"initial_simplex": [[x0, y0], [x0 + 0.5 * hx, y0], [x0, y0 + 0.5 * hy]],
                 "xatol": 1e-3, "fatol": 1e-6 * max(float(m @ m), 1e-12), "maxiter": 200},
    )  # fmt: skip
    load, res = solved(best.x)
    if load[0] <= 0 or res > residual[bi, bj]:
        return (x0, y0, loads.reshape(*shape, 3)[bi, bj]), float(residual[bi, bj])
    return (float(best.x[0]), float(best.x[1]), load), res


def _fit_pair(m, a, nodes, table, pick, one, sensor):
    """(((x, y, loads), (x, y, loads)), residual) of two contacts, or None: the second
    placed where it best explains what the first leaves, then both moved together."""
    (x1, y1, load1), _ = one
    rest = m - load1 @ table.at(x1, y1, pick)
    second = _fit_one(rest, a, nodes, table, pick)
    if second is None:
        return None
    (x2, y2, _), _ = second

    def solved(p):
        both = np.concatenate([table.at(p[0], p[1], pick), table.at(p[2], p[3], pick)])
        gram = both @ both.T + 1e-9 * np.eye(6)
        rhs = both @ m
        loads = np.linalg.solve(gram, rhs)
        return loads, float(m @ m - loads @ rhs)

    start = np.array([x1, y1, x2, y2])
    best = optimize.minimize(lambda p: solved(p)[1], start, method="Nelder-Mead",
                             options={"xatol": 1e-3, "maxiter": 600})  # fmt: skip
    loads, res = solved(best.x)
    separation = math.hypot(best.x[0] - best.x[2], best.x[1] - best.x[3])
    if (
        loads[0] <= 0
        or loads[3] <= 0
        or separation < PAIR_SEPARATION * min(sensor.grid.row_pitch_mm, sensor.grid.col_pitch_mm)
    ):
        return None  # fmt: skip
    x = best.x
    return ((x[0], x[1], loads[:3]), (x[2], x[3], loads[3:])), res


def _append(out, frame, rank, fit, own, size, railed, flags, sensor) -> None:
    rows, cols = sensor.shape
    px, py = sensor.grid.row_pitch_mm, sensor.grid.col_pitch_mm
    weight = np.where(own, size, 0.0)
    total = weight.sum()
    r, c = np.indices(own.shape)
    mr, mc = (weight * r).sum() / total, (weight * c).sum() / total
    out["rr"].append((weight * (r - mr) ** 2).sum() / total)
    out["cc"].append((weight * (c - mc) ** 2).sum() / total)
    out["rc"].append((weight * (r - mr) * (c - mc)).sum() / total)
    for name in ("x_mm", "y_mm", "force_n", "shear_x_n", "shear_y_n", "residual"):
        out[name].append(fit[name])
    row, col = fit["x_mm"] / px, fit["y_mm"] / py
    flag = flags
    if row < 0.5 or row > rows - 1.5 or col < 0.5 or col > cols - 1.5:
        flag |= int(Flag.EDGE)
    if (railed & own).any():
        flag |= int(Flag.SATURATED)
    out["frame"].append(frame)
    out["contact"].append(rank)
    out["peak"].append(float(size[own].max()) / (2**sensor.electronics.adc_bits - 1))
    out["taxels"].append(int(own.sum()))
    out["flags"].append(flag)


def _table(out: dict, n_frames: int, sensor) -> ContactTable:
    from tactsense.estimate.contacts.segment import _extent

    px, py = sensor.grid.row_pitch_mm, sensor.grid.col_pitch_mm
    n = len(out["frame"])
    col = {k: np.asarray(v, dtype=np.int64 if k in ("frame", "contact", "taxels", "flags")
                         else float) for k, v in out.items()}  # fmt: skip
    qx, qy, normal = col["shear_x_n"], col["shear_y_n"], col["force_n"]
    shear = np.hypot(qx, qy)
    with np.errstate(invalid="ignore", divide="ignore"):
        ratio = np.where(normal > 0, shear / normal, np.nan)
    angle = np.degrees(np.arctan2(qy, qx))
    major, minor, orientation = _extent(col["rr"], col["cc"], col["rc"], px, py)
    return ContactTable(
        frame=col["frame"], contact=col["contact"].astype(np.int32), x_mm=col["x_mm"],
        y_mm=col["y_mm"], z_mm=np.zeros(n), row=col["x_mm"] / px, col=col["y_mm"] / py,
        force_n=normal, peak=col["peak"], major_mm=major, minor_mm=minor,
        orientation_deg=orientation, taxels=col["taxels"].astype(np.int32),
        area_mm2=col["taxels"] * px * py, flags=col["flags"], n_frames=n_frames,
        extra={"shear_x_n": qx, "shear_y_n": qy, "shear_n": shear, "shear_angle_deg": angle,
               "shear_ratio": ratio, "residual": col["residual"]},
    )  # fmt: skip
