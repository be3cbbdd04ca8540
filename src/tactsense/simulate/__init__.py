"""The simulator: a scenario of contacts over time in, a recording of A/D frames out.

A :class:`Scenario` is a sequence of :class:`Step` s, each a set of contacts
held for a duration (an empty set: nothing touches). :func:`simulate` runs
it through the forward model:

contacts -> elastic deflection (the sensor's kind: ``Kind.elastic_batch``) ->
per-tactel gain -> viscoelastic memory -> stiffening -> capacitance and voltage
(eqs. 1-2) -> read noise -> A/D counts, each tactel sampled at its own instant of
the row/column scan.

The scan clock (``rows * cols`` samples per frame) is the simulation's time
step: the load is held constant over each sample interval, so step
boundaries are resolved to one sample (2.2 ms at 7 Hz on an 8x8 array).

The package's modules: :mod:`~tactsense.simulate.scenario` (what a scenario is),
:mod:`~tactsense.simulate.scenarios` (the paper's scenarios for the finger; a pad's and
a point set's are in :mod:`tactsense.flat_scenarios`), :mod:`~tactsense.simulate.run`
(the time loop) and :mod:`~tactsense.simulate.write` (to a file as frames are made).
"""

from tactsense.simulate.contact_frames import ContactBatch, ContactBatchError, frames_from_contacts
from tactsense.simulate.run import simulate
from tactsense.simulate.scenario import Scenario, Step
from tactsense.simulate.scenarios import (
    calibration_sweep,
    default_col,
    default_row,
    force_steps,
    knife_edge_sweep,
    load_series,
    probe_sweep,
    repeated_load,
    static,
)
from tactsense.simulate.write import simulate_to_file

__all__ = [
    "ContactBatch",
    "ContactBatchError",
    "Scenario",
    "Step",
    "calibration_sweep",
    "default_col",
    "default_row",
    "force_steps",
    "frames_from_contacts",
    "knife_edge_sweep",
    "load_series",
    "probe_sweep",
    "repeated_load",
    "simulate",
    "simulate_to_file",
    "static",
]
