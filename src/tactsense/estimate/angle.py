"""Old import path of :mod:`tactsense.estimate.finger.angle` (the same module object)."""

import sys

from tactsense.estimate.finger import angle as _module

sys.modules[__name__] = _module
