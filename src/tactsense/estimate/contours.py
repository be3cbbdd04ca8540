"""Old import path of :mod:`tactsense.estimate.finger.contours` (the same module object)."""

import sys

from tactsense.estimate.finger import contours as _module

sys.modules[__name__] = _module
