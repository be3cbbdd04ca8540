"""The inverse: from frames to contacts. Never imports the simulator."""

from tactsense.estimate.angle import angle_from_skew, even_odd, inverse_filter, skew_index
from tactsense.estimate.calibrate import Calibration, CalibrationError, calibrate_sweep
from tactsense.estimate.deflection import Flag, baseline_from, deflection_from_counts
from tactsense.estimate.force import force_per_deflection, total_force
from tactsense.estimate.interpolate import kernel, reconstruct_row, surface
from tactsense.estimate.localize import locate_contacts, newton_peak
from tactsense.estimate.locate import Estimates, locate, write_estimates_csv

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
