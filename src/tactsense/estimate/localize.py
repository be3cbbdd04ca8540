"""Old import path of :mod:`tactsense.estimate.finger.localize` (the same module object)."""

import sys

from tactsense.estimate.finger import localize as _module

sys.modules[__name__] = _module
