"""Old import path of :mod:`tactsense.estimate.finger.interpolate` (the same module object)."""

import sys

from tactsense.estimate.finger import interpolate as _module

sys.modules[__name__] = _module
