"""Old import path of :mod:`tactsense.estimate.finger.model_fit` (the same module object)."""

import sys

from tactsense.estimate.finger import model_fit as _module

sys.modules[__name__] = _module
