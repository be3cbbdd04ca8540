"""Ctrl-C and compiled code.

A Ctrl-C (SIGINT) handled while a Numba-compiled function runs can crash the
interpreter or leave it in a broken state: Python raises KeyboardInterrupt at the next
Python code it runs, and inside a compiled call that is one of Numba's own helpers
(numba/numba#2324: "interrupting ... sometimes gives a segmentation fault"; observed
here as a segfault in ``locate`` on 300,000 frames, and as ``SystemError:
_numba_unpickle returned a result with an exception set``).

:func:`deferred_interrupts` swaps Python's SIGINT handler for one that only notes the
press, for the length of the compiled calls, and raises the KeyboardInterrupt after
them, in ordinary Python code. (Blocking the signal with ``pthread_sigmask`` is not
enough: any other thread, e.g. a progress bar's, can receive it.) Callers keep each
block of compiled work short, so that Ctrl-C stays prompt.
"""

from __future__ import annotations

import signal
import threading
from contextlib import contextmanager


@contextmanager
def deferred_interrupts():
    """Hold a Ctrl-C back while the block runs; raise it when the block ends.

    Only the main thread can install signal handlers; elsewhere this does nothing (the
    handler runs in the main thread anyway).
    """
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    pressed: list[int] = []
    previous = signal.signal(signal.SIGINT, lambda number, frame: pressed.append(number))
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)
    if pressed:
        if callable(previous):
            previous(signal.SIGINT, None)
        elif previous == signal.SIG_DFL:
            raise KeyboardInterrupt
