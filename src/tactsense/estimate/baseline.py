"""Old import path of :mod:`tactsense.estimate.contacts.baseline` (the same module object)."""

import sys

from tactsense.estimate.contacts import baseline as _module

sys.modules[__name__] = _module
