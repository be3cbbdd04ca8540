"""Compiled passes of :mod:`tactsense.estimate.contacts` (Numba): from counts to the signal
of every taxel, segmentation of a grid frame into contacts, and each contact's position,
moments and force.

One loop over the frames of a block, each frame kept in cache; no temporary arrays per
frame (the work arrays are made once per block). The NumPy reference of the same
mathematics is in :mod:`tactsense.estimate.contacts` (``_segment_reference``); the test
suite holds the two to rounding.
"""

from tactsense.estimate.contacts._fast.fit import amplitude_fit, fit_into, merged_force
from tactsense.estimate.contacts._fast.segment import segment_into
from tactsense.estimate.contacts._fast.signal import prepare_signal
from tactsense.estimate.contacts._fast.track import hungarian, track_into
from tactsense.estimate.contacts._fast.window import HALF_WINDOW

__all__ = [
    "HALF_WINDOW",
    "amplitude_fit",
    "fit_into",
    "hungarian",
    "merged_force",
    "prepare_signal",
    "segment_into",
    "track_into",
]
