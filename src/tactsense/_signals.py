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


class _Hold:
    """The context manager behind :func:`deferred_interrupts` (a class: a generator-based
    one costs more than the compiled call it guards in a real-time loop)."""

    __slots__ = ("pressed", "previous")

    def __init__(self) -> None:
        self.pressed = False
        self.previous = None

    def _note(self, number, frame) -> None:
        self.pressed = True

    def __enter__(self) -> None:
        if threading.current_thread() is threading.main_thread():
            self.previous = signal.signal(signal.SIGINT, self._note)

    def __exit__(self, *exc) -> None:
        previous, self.previous = self.previous, None
        if previous is None:
            return
        signal.signal(signal.SIGINT, previous)
        if self.pressed:
            self.pressed = False
            if callable(previous):
                previous(signal.SIGINT, None)
            elif previous == signal.SIG_DFL or terminated:
                raise KeyboardInterrupt


def deferred_interrupts() -> _Hold:
    """Hold a Ctrl-C back while the block runs; raise it when the block ends.

    Only the main thread can install signal handlers; elsewhere this does nothing (the
    handler runs in the main thread anyway).
    """
    return _Hold()


# ---- SIGTERM ---------------------------------------------------------------------
# A script or a service manager stops a program with SIGTERM, whose default action ends
# the process on the spot: a recording is then left "not closed by its writer" and an
# output half-written. tactsense takes SIGTERM the way it takes Ctrl-C: the handler does
# what the SIGINT handler in force does (raise KeyboardInterrupt, or note it while
# compiled code runs), so every command's Ctrl-C path (close the file, remove a partial
# output, say what was kept) serves both.

terminated = False
"""True once a SIGTERM has arrived."""


def _on_sigterm(number, frame) -> None:
    global terminated
    terminated = True
    handler = signal.getsignal(signal.SIGINT)
    if callable(handler):
        handler(signal.SIGINT, frame)
    else:  # SIG_DFL, or SIG_IGN as a background job of a script inherits it
        raise KeyboardInterrupt


def install_sigterm() -> None:
    """Route SIGTERM to the current SIGINT handler (the main thread only)."""
    if threading.current_thread() is threading.main_thread():
        signal.signal(signal.SIGTERM, _on_sigterm)


def stopped_by() -> str:
    """What stopped the command: ``"SIGTERM"`` or ``"Ctrl-C"``, for its last message."""
    return "SIGTERM" if terminated else "Ctrl-C"
