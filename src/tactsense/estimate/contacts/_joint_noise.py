"""The noise a pad's frames show (issue 34 items 1-2): what the joint fit's order
selection weighs where the description's read noise is below what the pad reads."""

from __future__ import annotations

import numpy as np

from tactsense.estimate.contacts._joint_lm import NP

QUIET_SHARE = 0.02
"""A taxel is quiet where the fitted contacts' signal is below this share of their
largest [-]: what it reads there is noise (and rounding)."""

MIN_QUIET = 32
"""Fewest quiet readings on the noise's side that :func:`data_noise_variance` judges the
noise from [-] (fewer: the described noise stands)."""

HALF_NORMAL_MEDIAN = 0.6744897501960817
"""Median of |n| for n ~ N(0, 1) [-]."""

STRONG = 10.0
"""A capacitive frame's contact whose modelled peak exceeds this many of the first
pass's noise standard deviations is signal, never noise [-] (r10: a second contact of
a pair, counted as noise by the first pass, hid itself)."""


def _residuals(model, frame, q, fit_frame):
    """|frame - the contacts q refitted| (n,) [-], the contacts refitted (k, NP)."""
    q, _ = fit_frame(model, frame, *q.T)
    m = model.signal(q[:, :2], q[:, 2], q[:, 3], q[:, 4], signed=True)
    return np.abs(frame - m).ravel(), q


def contact_peak(model, c, signed=True) -> float:
    """The largest |signal| [-] one contact c (NP,) gives a taxel (``signed=False``: as a
    resistive taxel reads it, tension at rest)."""
    m = model.signal(c[None, :2], c[None, 2], c[None, 3], c[None, 4], signed=signed)
    return float(np.abs(m).max())


def _pair_residual(model, frame, one, alone, q, fit_frame):
    """The residual (n,) [-] against the strongest contact ``one`` (1, NP) and the next
    strongest of ``q`` (or, with none, a second one seeded where the frame most exceeds
    the first), refitted together, where that pair leaves a tenth of ``alone``'s
    squares or less and its weaker contact peaks above :data:`STRONG` standard
    deviations of what the pair leaves (a second contact, not a fit of noise: five more
    parameters take about 5 / (n - 5) of a noise's squares); else ``alone``; and the
    count of contacts fitted."""
    n = frame.size
    if len(q) > 1:
        seed = q[np.argsort(q[:, 2])[-2]]
    else:
        r = frame - model.signal(one[:, :2], one[:, 2], one[:, 3], one[:, 4], signed=True)
        i = int(np.argmax(np.abs(r.ravel())))
        x, y = np.meshgrid(model.x_taxel, model.y_taxel, indexing="ij")
        seed = one[0].copy()
        seed[:2] = x.ravel()[i], y.ravel()[i]
        seed[2] = one[0, 2] * abs(r.ravel()[i]) / max(contact_peak(model, one[0]), 1e-300)
    both, pair = _residuals(model, frame, np.vstack([one[0], seed]), fit_frame)
    left = float(np.sum(both**2))
    sd = np.sqrt(left / max(n - 2 * NP, 1))
    weaker = min(contact_peak(model, c) for c in pair)
    if left < 0.1 * float(np.sum(alone**2)) and weaker > STRONG * sd:
        return both, 2
    return alone, 1


def _scale(values, n, k) -> float:
    """The variance [-^2] from residual magnitudes ``values`` of frames of ``n``
    readings with ``k`` (mean) contacts fitted: the median over the half-normal's,
    times n / (n - 5 k) (the fit's parameters took their share of the residual)."""
    return float((np.median(values) / HALF_NORMAL_MEDIAN) ** 2 * n / max(n - NP * k, 1))


def data_noise_variance(model, fitted, fit_frame) -> float:
    """The noise's variance [-^2] the frames themselves show, 0 where they cannot tell
    (fewer than :data:`MIN_QUIET` readings to judge from), from ``fitted``: each frame
    (rows, cols) [-] with its contacts (k, NP); ``fit_frame`` the joint fit's
    (:func:`._joint._fit_frame`). A robust scale, pooled over the frames: a few
    unmodelled readings (a contact's tail, a region fitted on noise) move a quantile
    little.

    * Signed readings (capacitive): the residual of each frame against its strongest
      contact alone (refitted), or against it and a second contact where that pair
      explains the frame (:func:`_pair_residual`: round 10's trial found a recording of
      pairs on ``pad4`` resolved none of them when its frames were read together, the
      second contact counted as noise); the median of its magnitude over the
      half-normal's (0.674 sigma), times n / (n - 5 k) (the fit's parameters took their
      share of the residual). Not every contact is refitted: those fitted on noise
      regions would absorb noise (their modelled tension reaches every taxel of a
      capacitive pad, leaving no quiet one). Where the frames give at least
      :data:`MIN_QUIET` differences between successive frames, the smaller of that and
      what those differences show (their median magnitude over the half-normal's, over
      sqrt 2): a contact held still changes nothing from frame to frame, its noise does,
      so a pair the fit did not part (at 1.5 pitches on ``pad4``) is not taken for
      noise; contacts that move or frames of unrelated presses change more, and the
      residual's figure stands.
    * A resistive taxel's noise at rest is clipped at zero (the converter's rail: it
      reads max(n, 0)): over the quiet taxels (the contacts' signal below
      :data:`QUIET_SHARE` of its largest), the median of the readings above zero over
      the half-normal's median (0.674 sigma).

    Why: the described read noise (``read_noise_counts``) may be far below what the pad
    reads (a preset's 0.3 counts against 1-2 % of full scale on real arrays, 41-82
    counts); weighed with it, every noise blob passes the information criterion as a
    contact."""
    frames = [(np.asarray(frame, float), np.asarray(q, float)) for frame, q in fitted]
    if not model.capacitive:
        values = []
        for v, q in frames:
            m = model.signal(q[:, :2], q[:, 2], q[:, 3], q[:, 4], signed=True)
            quiet = np.abs(m) <= QUIET_SHARE * max(float(np.abs(m).max()), 1e-300)
            values.append(v[quiet & (v > 0)])
        v = np.concatenate(values) if values else np.zeros(0)
        if v.size < MIN_QUIET:
            return 0.0
        return float((np.median(v) / HALF_NORMAL_MEDIAN) ** 2)
    n = model.x_taxel.size * model.y_taxel.size
    if n * len(frames) < MIN_QUIET:
        return 0.0
    values, counts = [], []
    for v, q in frames:
        alone, one = _residuals(model, v, q[[int(np.argmax(q[:, 2]))]], fit_frame)
        r, k = _pair_residual(model, v, one, alone, q, fit_frame) if n > 2 * NP else (alone, 1)
        values.append(r)
        counts.append(k)
    variance = _scale(np.concatenate(values), n, float(np.mean(counts)))
    if len(frames) * n >= MIN_QUIET + n:  # what changes from one frame to the next
        steps = np.diff(np.stack([v for v, _ in frames]), axis=0).ravel()
        variance = min(variance, float((np.median(np.abs(steps)) / HALF_NORMAL_MEDIAN) ** 2 / 2))
    return variance
