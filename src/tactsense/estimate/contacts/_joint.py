"""A pad frame's contacts fitted jointly, each with its own size (issue 34 item 1).

The layer is linear: a frame under k round contacts is the sum of their responses
(:meth:`~tactsense.kinds.Kind.contact_model`). Seeded by the watershed's contacts and the
fixed-shape fit, the positions [mm], forces [N] and contact radii [mm] of all contacts of
a frame are fitted together by least squares over every taxel of the frame (the taxels'
noise is independent and equal: the maximum-likelihood fit under Gaussian noise).
"""

from __future__ import annotations

import math
import warnings

import numpy as np
from scipy.optimize import least_squares

from tactsense.estimate.contacts._joint_fisher import fisher_sd
from tactsense.estimate.contacts._joint_lm import NP, levenberg_marquardt, tables_of
from tactsense.estimate.contacts._joint_noise import contact_peak
from tactsense.estimate.contacts._joint_noise import data_noise_variance as _frames_noise
from tactsense.estimate.reading import signal_noise_variance

SEED_RADIUS_MM = 1.0
"""Contact radius the fit starts from [mm]."""

PRIOR_RADIUS_MM = 1.6
"""The prior's sphere: the scenarios' probe [mm]. Where a frame cannot tell a contact's
size (a few taxels read: a wider, stronger contact gives the same readings), the fit
takes the Hertz radius of this sphere at the contact's force."""

PRIOR_WIDTH = 0.7
"""Width of the prior on ln a [-] (spheres 1-10 mm at 10-500 g span ln a by 2.1)."""


def _bounds(model, frame, k):
    """Lower and upper bounds (5 k) of the fit's parameters."""
    px, py = model.pitch_mm
    rows, cols = frame.shape
    lo = np.tile([-2.0 * px, -2.0 * py, 0.0, 0.0, 0.0], k)
    hi = np.tile([(rows + 1) * px, (cols + 1) * py, np.inf, model.a_top_mm, 1.0], k)
    return lo, hi


def _start(model, x0, y0, f0, a0, w0, lo, hi):
    k = len(x0)
    w0 = np.full(k, 0.5) if w0 is None else w0
    p0 = np.column_stack(
        [x0, y0, np.maximum(f0, 1e-6), np.clip(a0, 0.0, model.a_top_mm), np.clip(w0, 0, 1)]
    )
    return np.clip(p0.ravel(), lo + 1e-9, hi - 1e-9)


MAX_ITERATIONS = 200
"""Most Levenberg-Marquardt steps per fit (a fit converges in 5-40)."""


def _fit_frame(model, frame, x0, y0, f0, a0, w0=None, sigma=None):
    """Least-squares (x, y [mm], force [N], a [mm], flat share w [-]) of k contacts on
    one frame (k, 5), and the residual sum of squares [-^2]. With ``sigma`` [-] (the
    noise's standard deviation) each ln a is drawn toward the prior's
    (:data:`PRIOR_RADIUS_MM`, :data:`PRIOR_WIDTH`): a maximum a posteriori fit, the
    prior weighing one noise's worth per width. Compiled Levenberg-Marquardt with the
    Jacobian in closed form (:mod:`._joint_lm`); :func:`_fit_frame_reference` is the
    same fit by SciPy with finite differences."""
    k = len(x0)
    lo, hi = _bounds(model, frame, k)
    p0 = _start(model, x0, y0, f0, a0, w0, lo, hi)
    prior = np.array(
        [0.0 if sigma is None else float(sigma), PRIOR_WIDTH, PRIOR_RADIUS_MM,
         model.modulus_star_pa]
    )  # fmt: skip
    with np.errstate(all="ignore"):
        p, rss, _ = levenberg_marquardt(
            p0, lo, np.minimum(hi, 1e300), np.ascontiguousarray(frame, float).ravel(),
            model.x_taxel, model.y_taxel, tables_of(model), not model.capacitive,
            float(model.scale), prior, MAX_ITERATIONS,
        )  # fmt: skip
    return p.reshape(k, NP), rss


def _fit_frame_reference(model, frame, x0, y0, f0, a0, w0=None, sigma=None):
    """Least-squares (x, y [mm], force [N], a [mm], flat share w [-]) of k contacts on
    one frame (k, 5), and the residual sum of squares [-^2]: :func:`_fit_frame` by SciPy's
    trust-region least squares with finite-difference Jacobians (the reference its
    compiled fit is checked and timed against). With ``sigma`` [-] (the
    noise's standard deviation) each ln a is drawn toward the prior's
    (:data:`PRIOR_RADIUS_MM`, :data:`PRIOR_WIDTH`): a maximum a posteriori fit, the
    prior weighing one noise's worth per width."""
    k = len(x0)
    px, py = model.pitch_mm
    lo, hi = _bounds(model, frame, k)
    p0 = _start(model, x0, y0, f0, a0, w0, lo, hi)
    target = frame.ravel()

    def residual(p):
        q = p.reshape(k, NP)
        misfit = model.signal(q[:, :2], q[:, 2], q[:, 3], q[:, 4]).ravel() - target
        if sigma is None:
            return misfit
        prior = _prior_radius(model, q[:, 2])
        pull = sigma * np.log(np.maximum(q[:, 3], 1e-3) / prior) / PRIOR_WIDTH
        return np.concatenate([misfit, pull])

    scale = np.tile([0.1 * px, 0.1 * py, max(float(np.max(f0)), 1e-3) * 0.05, 0.1, 0.1], k)
    with warnings.catch_warnings(), np.errstate(all="ignore"):
        warnings.simplefilter("ignore")
        out = least_squares(
            residual, p0, bounds=(lo, hi), x_scale=scale, method="trf",
            diff_step=1e-6, xtol=1e-10, ftol=1e-12, gtol=1e-12, max_nfev=200 * (k + 1),
        )  # fmt: skip
    q = out.x.reshape(k, NP)
    return q, float(np.sum(out.fun[: target.size] ** 2))


def _prior_radius(model, force):
    """Hertz radius [mm] of :data:`PRIOR_RADIUS_MM`'s sphere under ``force`` [N]."""
    f = np.maximum(force, 1e-4) * 1e-3
    a = (3.0 * f * PRIOR_RADIUS_MM / (4.0 * model.modulus_star_pa)) ** (1.0 / 3.0) * 1e3
    return np.minimum(a, PRIOR_RADIUS_MM)


SPLIT_MIN_PITCH = 0.3
"""Two contacts found by a split must lie at least this far apart [pitch] (closer, the
pair is one contact's shape fitted by two)."""

MODEL_ERROR = 2e-3
"""The model's own error against an exact solution of the layer, as a share of the
frame's largest signal [-] (the table: 1e-3 against the Hankel transform,
tests/_layer_truth.py), added to the noise's standard deviation when the criterion
weighs a fit's residual."""

MAX_POLISHED = 2
"""Most contacts of a frame :func:`_polish` re-seeds (its starts grow as k^2: pairs only)."""

SPLIT_MIN_SHARE = 0.1
"""Each of two contacts found by a split carries at least this share of their force."""


def _split_seed(q, c, moments, pitch, turn=0.0, half=None):
    """Seeds (k + 1, 4) with contact ``c`` replaced by two along its major axis: a pair
    d apart widens a contact's signal by (d/2)^2 along it, so the half separation is
    the square root of the major minus the minor second moment (at least 0.4 taxel).
    ``turn`` [rad] turns the axis, ``half`` [taxel] sets the half separation."""
    rr, cc, rc = moments
    lam = np.linalg.eigh(np.array([[rr, rc], [rc, cc]]))
    (minor, major), vectors = lam
    u = vectors[:, 1]
    if turn:
        cos, sin = math.cos(turn), math.sin(turn)
        u = np.array([cos * u[0] - sin * u[1], sin * u[0] + cos * u[1]])
    h = max(0.4, math.sqrt(max(major - minor, 0.0))) if half is None else half  # [taxel]
    step = np.array([u[0] * h * pitch[0], u[1] * h * pitch[1]])
    one, two = q[c].copy(), q[c].copy()
    one[:2] += step
    two[:2] -= step
    one[2] = two[2] = q[c, 2] / 2.0
    one[3] = two[3] = SEED_RADIUS_MM
    one[4] = two[4] = 0.5
    return np.vstack([np.delete(q, c, axis=0), one, two])


SPLIT_TURNS_DEG = (0.0, 45.0, 90.0, -45.0)
"""Directions a split is tried in, from the contact's major axis [deg]: where the
moments do not show the pair's axis (a pair on the diagonal of a coarse grid reads
round), the fit starts from each (issue 34 item 2: every orientation)."""

SPLIT_HALVES = (None, 0.6, 0.9)
"""Half separations a split is tried at [taxel]; None: from the second moments."""


def _residual_seed(model, frame, q):
    """(c, seed): the contacts kept and one more at the taxel where the frame most
    exceeds the fit (its force: that excess over the response's peak per newton), ``c``
    the contact nearest to it (the seed lists it last but one, as a split does)."""
    fitted = model.signal(q[:, :2], q[:, 2], q[:, 3], q[:, 4])
    excess = np.asarray(frame, float) - fitted
    i, j = np.unravel_index(int(np.argmax(excess)), excess.shape)
    where = np.array([model.x_taxel[i], model.y_taxel[j]])
    radius = float(_prior_radius(model, np.array([max(float(q[:, 2].mean()), 1e-3)]))[0])
    peak = float(model.signal([where], [1.0], [radius]).max())
    new = np.array([*where, max(excess[i, j], 0.0) / max(peak, 1e-30), radius, 0.0])
    c = int(np.argmin(np.hypot(q[:, 0] - where[0], q[:, 1] - where[1])))
    return c, np.vstack([np.delete(q, c, axis=0), q[c], new])


def _split_seeds(q, c, moments, pitch):
    """Every seed :func:`_order` tries for a split of contact ``c``."""
    for turn in SPLIT_TURNS_DEG:
        for half in SPLIT_HALVES:
            yield _split_seed(q, c, moments, pitch, math.radians(turn), half)


def _order(model, frame, q, rss, moments, noise_var, max_contacts):
    """More contacts where a likelihood criterion asks for them: one more at the largest
    residual (:func:`_residual_seed`) or a contact split in two (:func:`_split_seeds`),
    the frame refitted jointly from each seed and the best kept when
    the Bayesian information criterion falls (:data:`NP` more parameters: ``rss /
    sigma^2`` must fall by more than ``NP ln n``). Returns the fitted contacts (k', NP),
    the index among the originals each came from, and the RSS."""
    n = frame.size
    parents = list(range(len(q)))
    while len(q) < max_contacts:
        if rss / noise_var < n + 3.0 * math.sqrt(2.0 * n):  # consistent with noise alone
            break
        best = None
        tries = [_residual_seed(model, frame, q)]
        tries += [
            (c, seed)
            for c in range(len(q))
            for seed in _split_seeds(q, c, moments[parents[c]], model.pitch_mm)
        ]
        for c, seed in tries:  # try each contact's splits, keep the best
            q2, rss2 = _fit_frame(model, frame, *seed.T, sigma=math.sqrt(noise_var))
            pair = q2[-2:]
            apart = np.hypot(*((pair[0, :2] - pair[1, :2]) / model.pitch_mm))
            share = pair[:, 2].min() / max(pair[:, 2].sum(), 1e-30)
            gain = (rss - rss2) / noise_var
            if apart < SPLIT_MIN_PITCH or share < SPLIT_MIN_SHARE:
                continue
            if gain > NP * math.log(n) and (best is None or rss2 < best[1]):
                order = [p for i, p in enumerate(parents) if i != c] + [parents[c]] * 2
                best = (q2, rss2, order)
        if best is None:
            break
        q, rss, parents = best
    if len(q) > len(moments):
        q, rss, parents = _prune(model, frame, q, rss, parents, noise_var)
    return q, np.asarray(parents), rss


WALD_Z = 2.0
"""Fewest standard errors the force of a contact at the box's bound must stand from
zero [-] (a Wald test at about 95 %) where the frame's Fisher matrix is regular."""


def _drop_undetermined(model, frame, q, rss, parents, sigma):
    """While one of k >= 2 contacts sits at the box's bound (its position the search's
    limit, not a maximum of the likelihood) with a force within :data:`WALD_Z` of its
    standard error of zero (:func:`._joint_fisher.fisher_sd`), the one with the fewest
    goes, the others refitted jointly: a tail beyond the taxels that soaks up what the
    model leaves (issue 38's 18.5-N contact). Elsewhere (a Wald test drops real noisy
    pairs, its sigma carrying the model's error) or where the matrix is singular, the
    information criterion alone decides. First, a contact whose modelled signal is under
    the noise ``sigma`` [-] on every taxel goes (round 10's trial: a 0.1-mN contact where
    the taxels read 0, counted in a hand's wrench)."""
    prior = np.array([sigma, PRIOR_WIDTH, PRIOR_RADIUS_MM, model.modulus_star_pa])
    while len(q) > 1:
        peak = [contact_peak(model, c, signed=False) for c in q]
        if min(peak) < sigma:  # reads under the noise on every taxel: no contact (r10)
            c = int(np.argmin(peak))
            rest = np.delete(q, c, axis=0)
            q, rss = _fit_frame(model, frame, *rest.T, sigma=sigma)
            parents = [p for i, p in enumerate(parents) if i != c]
            continue
        lo, hi = _bounds(model, frame, 1)
        edge = 1e-6 * max(model.pitch_mm)
        outside = (np.abs(q[:, :2] - lo[:2]) < edge).any(1) | (
            np.abs(q[:, :2] - hi[:2]) < edge
        ).any(1)
        if not outside.any():
            break
        sd = fisher_sd(model, frame, q, prior)[:, 2]
        with np.errstate(all="ignore"):
            z = np.where(outside & np.isfinite(sd) & (sd > 0), q[:, 2] / sd, np.inf)
        c = int(np.argmin(z))
        if z[c] >= WALD_Z:
            break
        rest = np.delete(q, c, axis=0)
        q, rss = _fit_frame(model, frame, *rest.T, sigma=sigma)
        parents = [p for i, p in enumerate(parents) if i != c]
    return q, rss, parents


def _prune(model, frame, q, rss, parents, noise_var):
    """Backward elimination after splits: while a fit without one of the contacts (the
    others its seed, refitted jointly) explains the frame as well by the Bayesian
    information criterion (``rss / sigma^2`` grows by at most :data:`NP` ``ln n``),
    that contact goes (a split that only repaired a poor local minimum of the fewer
    contacts' fit)."""
    n = frame.size
    sigma = math.sqrt(noise_var)
    while len(q) > 1:
        best = None
        for c, seed in _fewer_seeds(model, q):
            q2, rss2 = _fit_frame(model, frame, *seed.T, sigma=sigma)
            if best is None or rss2 < best[1]:
                best = (q2, rss2, c)
        q2, rss2, c = best
        if (rss2 - rss) / noise_var > NP * math.log(n):
            break
        q, rss = q2, rss2
        parents = [p for i, p in enumerate(parents) if i != c]
    return q, rss, parents


POLISH_TURNS_DEG = (0.0, 45.0, 90.0, -45.0)
"""Directions a pair is re-seeded in by :func:`_polish`, from its own axis [deg]."""

POLISH_HALVES = (None, 0.4, 0.75, 1.0, 1.5)
"""Half separations a pair is re-seeded at by :func:`_polish` [taxel]; None: its own."""


def _pair_seeds(model, q, c, d):
    """Seeds with contacts ``c`` and ``d`` replaced by a pair about their force-weighted
    centre, sharing their summed force equally, in each of :data:`POLISH_TURNS_DEG` from
    their axis and at each of :data:`POLISH_HALVES`."""
    px, py = model.pitch_mm
    f = q[c, 2] + q[d, 2]
    w = q[c, 2] / f if f > 0 else 0.5
    centre = w * q[c, :2] + (1.0 - w) * q[d, :2]
    axis = (q[c, :2] - q[d, :2]) / np.array([px, py])  # [taxel]
    own = float(np.hypot(*axis)) / 2.0
    base = math.atan2(axis[1], axis[0]) if own > 0 else 0.0
    for turn in POLISH_TURNS_DEG:
        angle = base + math.radians(turn)
        for half in POLISH_HALVES:
            h = max(own if half is None else half, 0.2)
            step = np.array([math.cos(angle) * h * px, math.sin(angle) * h * py])
            seed = q.copy()
            seed[c, :2], seed[d, :2] = centre + step, centre - step
            seed[c, 2] = seed[d, 2] = f / 2.0
            seed[c, 3] = seed[d, 3] = max(q[c, 3], q[d, 3])
            yield seed


RELOCATE_STEP = 0.5
"""Spacing of the positions :func:`_relocate_seeds` tries for a contact [pitch]."""

RELOCATE_BEST = 2
"""Positions :func:`_relocate_seeds` keeps per contact (the largest gains, a pitch apart)."""


def _relocate_seeds(model, frame, q, c):
    """Seeds with contact ``c`` moved to where it best explains what the others leave:
    its unit response (own radius and flat share) every :data:`RELOCATE_STEP` pitch
    over the box, its force the least-squares amplitude, the :data:`RELOCATE_BEST`
    largest gains a pitch apart kept: a global search for one contact of a linear
    layer (a matched filter). It escapes a contact beyond the edge slid along the ridge
    where a farther contact with more force reads alike (issue 34 item 2)."""
    px, py = model.pitch_mm
    lo, hi = _bounds(model, frame, 1)
    o = np.delete(q, c, axis=0)
    rest = np.asarray(frame, float) - model.signal(o[:, :2], o[:, 2], o[:, 3], o[:, 4], signed=True)
    xs = np.arange(lo[0], hi[0] + 1e-9, RELOCATE_STEP * px)
    ys = np.arange(lo[1], hi[1] + 1e-9, RELOCATE_STEP * py)
    found = []
    for x in xs:
        for y in ys:
            r = model.signal([[x, y]], [1.0], [q[c, 3]], [q[c, 4]], signed=True)
            rr = float(np.sum(r * r))
            if rr <= 0.0:
                continue
            f = float(np.sum(r * rest)) / rr
            if f > 0.0:
                found.append((f * f * rr, x, y, f))
    kept = []
    for _, x, y, f in sorted(found, reverse=True):
        if len(kept) < RELOCATE_BEST and all(
            np.hypot((x - u) / px, (y - v) / py) >= 1 for u, v, _ in kept
        ):
            kept.append((x, y, f))
    for x, y, f in kept:
        seed = q.copy()
        seed[c, :3] = x, y, f
        yield seed


def _polish(model, frame, q, rss, sigma):
    """The frame's k >= 2 contacts refitted from other starts, the lowest residual kept
    (same k, same order): each pair re-seeded about its centre (:func:`_pair_seeds`).
    A pair fitted jointly has local minima (one contact drawn to the pair's middle, the
    other to a tail: on pad4 a resolved pair 1.5 pitches apart placed 1-3 mm off where
    the two-contact bound is 0.02-0.03 mm, issue 34 item 2); a few starts reach the
    global one."""
    for _ in range(2):
        best = (q, rss)
        for c in range(len(q)):
            for d in range(c + 1, len(q)):
                for seed in _pair_seeds(model, q, c, d):
                    q2, rss2 = _fit_frame(model, frame, *seed.T, sigma=sigma)
                    if rss2 < best[1]:
                        best = (q2, rss2)
            for seed in _relocate_seeds(model, frame, q, c):
                q2, rss2 = _fit_frame(model, frame, *seed.T, sigma=sigma)
                if rss2 < best[1]:
                    best = (q2, rss2)
        if best[1] >= rss * (1.0 - 1e-6):
            break
        q, rss = best
    return q, rss


def _fewer_seeds(model, q):
    """Seeds with one contact fewer, each ``(c, seed)`` (``c`` the contact whose row
    goes): each contact deleted (the others kept), and each pair merged into one at
    their force-weighted centre with their summed force and a radius reaching over
    both (kept in the first's place). A wide contact split into several by a poor local
    minimum of the single fit (a flat disc 3 pitches across at 500 g fitted exactly by
    four: issue 34 item 1) is merged back by the second kind; deleting one of them
    never leads there."""
    k = len(q)
    for c in range(k):
        yield c, np.delete(q, c, axis=0)
    for c in range(k):
        for d in range(c + 1, k):
            f = q[c, 2] + q[d, 2]
            w = q[c, 2] / f if f > 0 else 0.5
            merged = q[c].copy()
            merged[:2] = w * q[c, :2] + (1.0 - w) * q[d, :2]
            merged[2] = f
            reach = np.hypot(*(q[c, :2] - q[d, :2])) / 2.0 + max(q[c, 3], q[d, 3])
            merged[3] = min(reach, model.a_top_mm)
            merged[4] = w * q[c, 4] + (1.0 - w) * q[d, 4]
            seed = q.copy()
            seed[c] = merged
            yield d, np.delete(seed, d, axis=0)


def joint_fit(signal, seg, row, col, force, sensor, model, noise_var=None, max_contacts=0):
    """Each contact's row, column [taxel], force [N], contact radius [mm] and flat share
    [-], fitted
    jointly with the other contacts of its frame, starting from ``row``, ``col``
    [taxel] and ``force`` [N] (the fixed-shape fit). Contacts whose seed force is not
    finite keep their seed.

    With ``noise_var`` [-^2] and ``max_contacts`` > 0, a frame may hold more contacts
    than the watershed found (:func:`_order`): returns also ``added``, a list of
    ``(parent index, row, col, force, radius)`` for each contact added (it shares its
    parent's region), and ``dropped``, the indices of the originals whose contacts the
    pruning removed all of (:func:`_prune`)."""
    n = len(seg["frame"])
    row, col, force = (np.array(v, float, copy=True) for v in (row, col, force))
    radius = np.full(n, np.nan)
    flat = np.full(n, np.nan)
    added, dropped = [], []
    if n == 0:
        return row, col, force, radius, flat, added, dropped
    px, py = model.pitch_mm
    frames = np.asarray(seg["frame"])
    order = np.argsort(frames, kind="stable")
    bounds = np.flatnonzero(np.diff(frames[order])) + 1
    described = math.sqrt(signal_noise_variance(sensor))
    fitted = []  # first pass: each frame's contacts from the seeds, the noise described
    for group in np.split(order, bounds):
        good = group[np.isfinite(force[group]) & np.isfinite(row[group])]
        if len(good) == 0:
            continue
        frame = np.asarray(signal[int(frames[good[0]])], float)
        q, rss = None, np.inf
        for a0 in _seed_radii(model, seg, good):  # the best of a few starting sizes
            q2, rss2 = _fit_frame(
                model, frame, row[good] * px, col[good] * py,
                force[good], a0, sigma=described,
            )  # fmt: skip
            if rss2 < rss:
                q, rss = q2, rss2
        fitted.append((good, frame, q, rss))
    if noise_var is not None:  # the frames' own noise where it exceeds the described
        seen = data_noise_variance(model, [(frame, q) for _, frame, q, _ in fitted])
        noise_var = max(noise_var, seen)
    for good, frame, q, rss in fitted:
        parents = np.arange(len(good))
        if noise_var is not None and max_contacts > 1:
            sigma = math.sqrt(noise_var) + MODEL_ERROR * float(np.abs(frame).max())
            if len(good) > 1:  # a watershed region on noise alone: no contact there
                q, rss, kept = _prune(model, frame, q, rss, list(parents), sigma**2)
                parents = np.asarray(kept)
            polished = None
            if 1 < len(q) <= MAX_POLISHED:  # the order is judged against k's best fit
                q, rss = _polish(model, frame, q, rss, sigma)
                polished = rss
            if max_contacts > len(q):
                moments = [(seg["rr"][i], seg["cc"][i], seg["rc"][i]) for i in good]
                q, local, rss = _order(
                    model, frame, q, rss, [moments[p] for p in parents], sigma**2, max_contacts
                )
                parents = parents[local]
            if 1 < len(q) <= MAX_POLISHED and rss != polished:
                q, rss = _polish(model, frame, q, rss, sigma)
            if len(q) > 1:
                q, rss, kept = _drop_undetermined(model, frame, q, rss, list(parents), sigma)
                parents = np.asarray(kept)
        seen = set()
        for j, p in enumerate(parents):
            i = good[p]
            values = (q[j, 0] / px, q[j, 1] / py, q[j, 2], q[j, 3], q[j, 4])
            if p in seen:
                added.append((i, *values))
                continue
            seen.add(p)
            row[i], col[i], force[i], radius[i], flat[i] = values
        for p in set(range(len(good))) - seen:  # an original pruned away: its row goes
            dropped.append(good[p])
    return row, col, force, radius, flat, added, dropped


def data_noise_variance(model, fitted) -> float:
    """The noise's variance [-^2] the frames themselves show
    (:func:`._joint_noise.data_noise_variance`, refitting with :func:`_fit_frame`)."""
    return _frames_noise(model, fitted, _fit_frame)


def _seed_radii(model, seg, good):
    """Starting contact radii [mm] of a frame's first fit: :data:`SEED_RADIUS_MM`, each
    region's extent (the root of its largest second moment, in mm), and half the table's
    top. A resistive taxel in tension reads rest, so a fit started too narrow sees no
    slope toward a wider contact whose readings it misses: it must start near it."""
    px = max(model.pitch_mm)
    extent = np.sqrt(np.maximum(np.maximum(seg["rr"][good], seg["cc"][good]), 0.0)) * px
    top = np.full(len(good), 0.5 * model.a_top_mm)
    one = np.full(len(good), SEED_RADIUS_MM)
    return [one, np.clip(extent, 0.1, model.a_top_mm), top]


def information(rss, noise_var, n_taxels, n_params):
    """Bayesian information criterion of a fit [-]: ``rss / sigma^2 + p ln n``."""
    return rss / noise_var + n_params * math.log(n_taxels)


def fit_sizes(signal, seg, row, col, force, sensor, model, max_contacts):
    """:func:`joint_fit` with model-order selection under the sensor's noise
    (:func:`~tactsense.estimate.reading.signal_noise_variance`): the segmentation's rows
    ``seg`` extended by the contacts added (each a copy of its parent's row, numbered
    after the frame's others), sorted by frame and contact, and each row's row, column
    [taxel], force [N], contact radius [mm] and flat share [-]."""
    noise_var = signal_noise_variance(sensor)
    row, col, force, radius, flat, added, dropped = joint_fit(
        signal, seg, row, col, force, sensor, model, noise_var, max_contacts
    )
    if not added and not dropped:
        return seg, row, col, force, radius, flat
    parent = np.array([a[0] for a in added], np.int64)
    seg = {key: np.concatenate([value, value[parent]]) for key, value in seg.items()}
    seg["contact"] = seg["contact"].copy()
    n_old = len(row)
    for j, p in enumerate(parent):  # numbered after the frame's others
        same = seg["frame"] == seg["frame"][p]
        seg["contact"][n_old + j] = seg["contact"][same].max() + 1
    extra = np.array([a[1:] for a in added], float).reshape(len(added), 5)
    row, col = np.concatenate([row, extra[:, 0]]), np.concatenate([col, extra[:, 1]])
    force, radius = np.concatenate([force, extra[:, 2]]), np.concatenate([radius, extra[:, 3]])
    flat = np.concatenate([flat, extra[:, 4]])
    keep = np.ones(len(row), bool)
    keep[np.asarray(dropped, np.int64)] = False
    order = np.flatnonzero(keep)[np.lexsort((seg["contact"][keep], seg["frame"][keep]))]
    seg = {key: value[order] for key, value in seg.items()}
    if dropped:  # numbered 0, 1, ... in each frame again
        frames = seg["frame"]
        first = np.r_[0, np.flatnonzero(np.diff(frames)) + 1]
        starts = np.repeat(first, np.diff(np.r_[first, len(frames)]))
        seg["contact"] = np.arange(len(frames)) - starts
    return seg, row[order], col[order], force[order], radius[order], flat[order]
