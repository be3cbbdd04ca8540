"""tactsense: the capacitive tactile finger of Fearing (IJRR 1990), modelled and interpreted.

The forward model (a digital twin of the finger) lives in
:mod:`tactsense.physics` and :mod:`tactsense.simulate`; sensors are
described by :class:`tactsense.SensorSpec`; recordings are HDF5 files read
and written by :mod:`tactsense.io`.
"""

from tactsense._version import __version__
from tactsense.estimate import Estimates, Flag, baseline_from, locate
from tactsense.io.recording import Recording, read_recording, write_recording
from tactsense.physics.array_response import tactel_deflection
from tactsense.physics.contact import (
    FlatContact,
    LineContact,
    Probe,
    grams_force,
    knife_edge,
    newtons_to_grams,
    rod,
    soft_object,
)
from tactsense.sensor import (
    SensorSpec,
    SensorSpecError,
    fearing1990_improved,
    fearing1990_initial,
    load_sensor,
    preset,
)
from tactsense.simulate import (
    Scenario,
    Step,
    calibration_sweep,
    force_steps,
    knife_edge_sweep,
    load_series,
    probe_sweep,
    repeated_load,
    simulate,
    simulate_to_file,
    static,
)

__all__ = [
    "Estimates",
    "Flag",
    "FlatContact",
    "LineContact",
    "Probe",
    "Recording",
    "Scenario",
    "SensorSpec",
    "SensorSpecError",
    "Step",
    "__version__",
    "baseline_from",
    "calibration_sweep",
    "fearing1990_improved",
    "fearing1990_initial",
    "force_steps",
    "grams_force",
    "knife_edge",
    "knife_edge_sweep",
    "load_sensor",
    "load_series",
    "locate",
    "newtons_to_grams",
    "preset",
    "probe_sweep",
    "read_recording",
    "repeated_load",
    "rod",
    "simulate",
    "simulate_to_file",
    "soft_object",
    "static",
    "tactel_deflection",
    "write_recording",
]
