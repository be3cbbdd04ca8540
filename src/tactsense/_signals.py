"""Ctrl-C and compiled code.

A SIGINT that arrives while a Numba-compiled function runs can crash the interpreter
(numba/numba#2324: "interrupting ... sometimes gives a segmentation fault"; observed
here in ``locate`` on 300,000 frames). :func:`deferred_interrupts` blocks SIGINT in the
calling thread for the length of a compiled call; a Ctrl-C pressed meanwhile stays
pending and is delivered, as an ordinary KeyboardInterrupt, when the call returns.
Callers keep each call short (chunks of frames) so that Ctrl-C stays prompt.
"""

from __future__ import annotations

import signal
import threading
from contextlib import contextmanager

_BLOCKABLE = hasattr(signal, "pthread_sigmask")


@contextmanager
def deferred_interrupts():
    """Hold SIGINT back while the block runs (main thread, POSIX); elsewhere a no-op."""
    if not _BLOCKABLE or threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, previous)
