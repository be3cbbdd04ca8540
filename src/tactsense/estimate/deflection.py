"""Old import path of :mod:`tactsense.estimate.finger.deflection` (the same module object)."""

import sys

from tactsense.estimate.finger import deflection as _module

sys.modules[__name__] = _module
