"""Old import path of :mod:`tactsense.estimate.finger._fast` (the same module object)."""

import sys

from tactsense.estimate.finger import _fast as _module

sys.modules[__name__] = _module
