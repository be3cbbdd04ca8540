"""The inverse: from frames to contacts. Never imports the simulator.

Two jobs: the paper's finger pipeline (:mod:`tactsense.estimate.finger`) and contacts on
any array (:mod:`tactsense.estimate.contacts`); their result types and flags are
:mod:`tactsense.estimate.results`, the writers :mod:`tactsense.estimate.output`. The
finger's modules are ``tactsense.estimate.finger.<name>`` (``deflection``, ``force``,
``angle``, ``interpolate``, ``localize``, ``locate``, ``realtime``, ``model_fit``,
``contours``, ``calibrate``), the arrays' ``tactsense.estimate.contacts.<name>``
(``find``, ``track``, ``baseline``, ``array_calibration``, ...); the names below are the
public API and keep their paths.
"""

from tactsense.estimate.finger.angle import angle_from_skew, even_odd, inverse_filter, skew_index
from tactsense.estimate.finger.calibrate import Calibration, CalibrationError, calibrate_sweep
from tactsense.estimate.finger.deflection import baseline_from, deflection_from_counts
from tactsense.estimate.finger.force import force_per_deflection, total_force
from tactsense.estimate.finger.interpolate import kernel, reconstruct_row, surface
from tactsense.estimate.finger.localize import locate_contacts, newton_peak
from tactsense.estimate.finger.locate import locate, write_estimates_csv
from tactsense.estimate.results import Estimates, Flag

__all__ = [
    "Calibration",
    "CalibrationError",
    "Estimates",
    "Flag",
    "angle_from_skew",
    "baseline_from",
    "calibrate_sweep",
    "deflection_from_counts",
    "even_odd",
    "force_per_deflection",
    "inverse_filter",
    "kernel",
    "locate",
    "locate_contacts",
    "newton_peak",
    "reconstruct_row",
    "skew_index",
    "surface",
    "total_force",
    "write_estimates_csv",
]
