"""From counts to the signal of every taxel (compiled)."""

from __future__ import annotations

import numpy as np

from tactsense._jit import jit
from tactsense.estimate.finger._fast import taxel_signal


@jit(nogil=True)
def prepare_signal(
    frames, baseline, unusable, full_scale, resistive, falling, per_count, nan_flag, sat_flag,
    dead_flag,
):  # fmt: skip
    """Signal of every taxel and the flags of each frame, in one pass.

    Compression positive whichever way the reading moves (``falling``):
    :func:`~tactsense.estimate.finger._fast.taxel_signal`. Unusable taxels (excluded, NaN, an
    open capacitive junction) read 0.
    """
    n, rows, cols = frames.shape
    signal = np.empty((n, rows, cols), np.float64)
    flags = np.zeros(n, np.int64)
    any_unusable = False
    for r in range(rows):
        for c in range(cols):
            if unusable[r, c]:
                any_unusable = True
    for f in range(n):
        flag = dead_flag if any_unusable else 0
        for r in range(rows):
            for c in range(cols):
                d, bits = taxel_signal(
                    float(frames[f, r, c]), baseline[r, c], unusable[r, c], full_scale,
                    resistive, falling, per_count, nan_flag, sat_flag, dead_flag,
                )  # fmt: skip
                flag |= bits
                signal[f, r, c] = d
        flags[f] = flag
    return signal, flags
