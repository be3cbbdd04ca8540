"""Standard errors of a joint fit's contacts (issue 34 item 2): each contact's x, y
[mm] and force [N] with its error from the Fisher matrix at the fit, so that a contact
the frame does not determine (beyond the pad's edge, where a farther contact with more
force reads alike) is not reported as a confident number."""

from __future__ import annotations

import math

import numpy as np

from tactsense.estimate.contacts._joint import (
    MODEL_ERROR,
    PRIOR_RADIUS_MM,
    PRIOR_WIDTH,
    data_noise_variance,
)
from tactsense.estimate.contacts._joint_fisher import fisher_sd
from tactsense.estimate.reading import signal_noise_variance


def _fisher_sd(model, frame, q, sigma):
    """:func:`~._joint_fisher.fisher_sd` under the fit's prior with noise ``sigma`` [-]."""
    prior = np.array([sigma, PRIOR_WIDTH, PRIOR_RADIUS_MM, model.modulus_star_pa])
    return fisher_sd(model, frame, q, prior)


def standard_errors(signal, frame_index, row, col, force, radius, flat, sensor, model):
    """Standard errors (n, 3) of each contact's x, y [mm] and force [N] of a joint fit
    (:func:`fit_sizes`' rows: frame ``frame_index``, ``row``, ``col`` [taxel], ``force``
    [N], ``radius`` [mm], ``flat`` [-]), from the Fisher matrix at the fit
    (:func:`_fisher_sd`), under the noise the order selection weighs (the described or
    the frames' own, whichever is larger, plus :data:`MODEL_ERROR`); NaN where it is
    singular or the contact has no fit. A contact the taxels barely reach (beyond the
    pad's edge, where a farther contact with more force reads alike) carries a large
    error instead of passing as a confident number."""
    n = len(row)
    out = np.full((n, 3), np.nan)
    px, py = model.pitch_mm
    frames = np.asarray(frame_index)
    q_all = np.column_stack([np.asarray(row) * px, np.asarray(col) * py, force, radius, flat])
    fitted = []
    for f in np.unique(frames):
        idx = np.flatnonzero((frames == f) & np.all(np.isfinite(q_all), axis=1))
        if len(idx):
            fitted.append((idx, np.asarray(signal[int(f)], float), q_all[idx]))
    if not fitted:
        return out
    noise_var = max(
        signal_noise_variance(sensor),
        data_noise_variance(model, [(frame, q) for _, frame, q in fitted]),
    )
    for idx, frame, q in fitted:
        sigma = math.sqrt(noise_var) + MODEL_ERROR * float(np.abs(frame).max())
        with np.errstate(all="ignore"):
            out[idx] = _fisher_sd(model, frame, q, sigma)
    return out
