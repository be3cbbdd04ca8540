"""Old import path of :mod:`tactsense.estimate.finger.calibrate` (the same module object)."""

import sys

from tactsense.estimate.finger import calibrate as _module

sys.modules[__name__] = _module
