"""Calibration of any array from a lab's own data (pads and point sets): one import path
for :mod:`.calibration` (the :class:`ArrayCalibration` a file holds, applied by
``find_contacts``), :mod:`.lab_logs` (force, stage and weights logs),
:mod:`.weight_curve` (known weights to a force curve) and :mod:`.calibrate_array`
(building one)."""

from __future__ import annotations

from tactsense.estimate.contacts.calibrate_array import (
    LOG_RANK_LIMIT,
    LOG_SCALE_LIMIT,
    METHODS,
    calibrate_array,
    check_force_log,
    contact_totals,
    gains_from_press,
    gains_from_sweep,
    uniform_gains,
)
from tactsense.estimate.contacts.calibration import (
    FORMAT,
    ArrayCalibration,
    ArrayCalibrationError,
    load_calibration,
)
from tactsense.estimate.contacts.lab_logs import (
    LOAD_COLUMNS,
    STANDARD_GRAVITY,
    UNITLESS,
    WeightsLog,
    presses_from_log,
    read_force_log,
    read_stage_log,
    read_weights_log,
)
from tactsense.estimate.contacts.weight_curve import (
    MIN_PRESS_FRAMES,
    MONOTONE_RANK,
    PRESS_LEVEL,
    SAME_WEIGHT,
    SATURATION_SLOPE,
    SHORT_PRESS,
    SMOOTH_FRAMES,
    TOP_MARGIN,
    Presses,
    _plateau,  # noqa: F401  (its old path)
    force_curve,
    hysteresis,
    segment_presses,
    temperature_coefficient,
    weight_curve,
    weight_presses,
)

__all__ = [
    "FORMAT",
    "LOAD_COLUMNS",
    "LOG_RANK_LIMIT",
    "LOG_SCALE_LIMIT",
    "METHODS",
    "MIN_PRESS_FRAMES",
    "MONOTONE_RANK",
    "PRESS_LEVEL",
    "SAME_WEIGHT",
    "SATURATION_SLOPE",
    "SHORT_PRESS",
    "SMOOTH_FRAMES",
    "STANDARD_GRAVITY",
    "TOP_MARGIN",
    "UNITLESS",
    "ArrayCalibration",
    "ArrayCalibrationError",
    "Presses",
    "WeightsLog",
    "calibrate_array",
    "check_force_log",
    "contact_totals",
    "force_curve",
    "gains_from_press",
    "gains_from_sweep",
    "hysteresis",
    "load_calibration",
    "presses_from_log",
    "read_force_log",
    "read_stage_log",
    "read_weights_log",
    "segment_presses",
    "temperature_coefficient",
    "uniform_gains",
    "weight_curve",
    "weight_presses",
]
