"""Old import path of :mod:`tactsense.estimate.finger.realtime` (the same module object)."""

import sys

from tactsense.estimate.finger import realtime as _module

sys.modules[__name__] = _module
