"""Old import path of :mod:`tactsense.estimate.contacts.array_calibration` (the same module)."""

import sys

from tactsense.estimate.contacts import array_calibration as _module

sys.modules[__name__] = _module
