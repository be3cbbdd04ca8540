"""Old import path of :mod:`tactsense.estimate.contacts._fast` (the same module object)."""

import sys

from tactsense.estimate.contacts import _fast as _module

sys.modules[__name__] = _module
