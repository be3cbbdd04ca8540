"""Old import path of :mod:`tactsense.estimate.contacts.track` (the same module object)."""

import sys

from tactsense.estimate.contacts import track as _module

sys.modules[__name__] = _module
