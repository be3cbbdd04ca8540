"""Old import path of :mod:`tactsense.estimate.finger.force` (the same module object)."""

import sys

from tactsense.estimate.finger import force as _module

sys.modules[__name__] = _module
