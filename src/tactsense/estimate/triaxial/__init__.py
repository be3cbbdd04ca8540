"""Contacts on three-axis taxels: position, normal force, tangential force and its
direction, and slip (issue 35, item 4).

Each taxel reads a vector (the field components x, y, z of a magnetic skin, in counts).
The estimator works from the change of every component from the taxel's rest reading
(the baseline), mapped through the taxel's 3x3 calibration matrix
(:mod:`.calibration`); it fits the kind's own response to a normal and two tangential
loads (:mod:`.response`, asked of the kind, never of the simulator) to each contact's
taxels (:mod:`.fit`): a contact's position [mm], normal force [N] and tangential force
(x, y) [N]. :mod:`.slip` follows each tracked contact's tangential/normal ratio through
time for incipient slip (Cattaneo-Mindlin) and gross slip with its onset.
:mod:`.locate` runs a recording piece by piece (a file:
:func:`tactsense.batch.shear_contacts_file`); :mod:`.live` frame by frame.
"""

from tactsense.estimate.triaxial.calibration import (
    TriaxialCalibration,
    calibrate_triaxial,
    is_triaxial_calibration,
)
from tactsense.estimate.triaxial.fit import find_shear_contacts, vector_taxels
from tactsense.estimate.triaxial.live import LiveShearContacts
from tactsense.estimate.triaxial.response import ResponseTable, response_table
from tactsense.estimate.triaxial.slip import SLIP_STATES, SlipMonitor

__all__ = [
    "SLIP_STATES",
    "LiveShearContacts",
    "ResponseTable",
    "SlipMonitor",
    "TriaxialCalibration",
    "calibrate_triaxial",
    "find_shear_contacts",
    "is_triaxial_calibration",
    "response_table",
    "vector_taxels",
]
