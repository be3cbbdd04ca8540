"""Old import path of :mod:`tactsense.estimate.finger.locate` (the same module object)."""

import sys

from tactsense.estimate.finger import locate as _module

sys.modules[__name__] = _module
