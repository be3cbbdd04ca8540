"""Contacts on any array: several per frame, found, tracked and calibrated.

:func:`find_contacts` segments each frame into contacts (:mod:`.segment`) and places
them per kind of array (:mod:`.find`; a pad's force from its layer's response,
:mod:`.pad`; a point set's neighbour graph, :mod:`.points`); :mod:`.track` gives them
identities, :mod:`.baseline` follows the readings' drift, and :mod:`.array_calibration`
calibrates a pad or a point set. The rows are a :class:`ContactTable`
(:mod:`tactsense.estimate.results`).
"""

from tactsense.estimate.contacts.find import find_contacts
from tactsense.estimate.contacts.pad import (
    FIT_STEPS,
    MERGED_GAIN,
    MERGED_HALVES,
    MERGED_SPREAD,
    pad_contact_force,
    pad_fit,
    pad_force_kernel,
    pad_merged_force,
    point_reach,
    point_taxels,
)
from tactsense.estimate.contacts.points import points_force_kernel
from tactsense.estimate.contacts.segment import (
    BLOCK,
    METHODS,
    NOISE_DIP,
    PAIR_RIDGE,
    RING_RATIO,
    SADDLE_RATIO,
    WEAK_SHARE,
    dip_floor,
)
from tactsense.estimate.reading import (
    at_rail,
    default_threshold,
    reading_mode,
    signal_from_counts,
    signal_noise_variance,
    threshold_counts,
    unusable_baseline,
)
from tactsense.estimate.results import ContactTable

__all__ = [
    "BLOCK",
    "FIT_STEPS",
    "MERGED_GAIN",
    "MERGED_HALVES",
    "MERGED_SPREAD",
    "METHODS",
    "NOISE_DIP",
    "PAIR_RIDGE",
    "RING_RATIO",
    "SADDLE_RATIO",
    "WEAK_SHARE",
    "ContactTable",
    "at_rail",
    "default_threshold",
    "dip_floor",
    "find_contacts",
    "pad_contact_force",
    "pad_fit",
    "pad_force_kernel",
    "pad_merged_force",
    "point_reach",
    "point_taxels",
    "points_force_kernel",
    "reading_mode",
    "signal_from_counts",
    "signal_noise_variance",
    "threshold_counts",
    "unusable_baseline",
]
