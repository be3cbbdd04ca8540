"""Ctrl-C and compiled code.

A Ctrl-C (SIGINT) handled while a Numba-compiled function runs can crash the
interpreter or leave it in a broken state: Python raises KeyboardInterrupt at the next
Python code it runs, and inside a compiled call that is one of Numba's own helpers
(numba/numba#2324: "interrupting ... sometimes gives a segmentation fault"; observed
here as a segfault in ``locate`` on 300,000 frames, and as ``SystemError:
_numba_unpickle returned a result with an exception set``).

:func:`deferred_interrupts` swaps Python's SIGINT handler for one that only notes the
press, for the length of the compiled calls, and raises the KeyboardInterrupt after
them, in ordinary Python code. A real-time loop cannot pay for two swaps a frame: it
installs the gate once (:func:`gate_ready`) and sets and clears a flag around each
compiled call (``RealTimeLocator``); where the gate is installed,
:func:`deferred_interrupts` uses the same flag. (Blocking the signal with ``pthread_sigmask`` is not
enough: any other thread, e.g. a progress bar's, can receive it.) Callers keep each
block of compiled work short, so that Ctrl-C stays prompt.
"""

from __future__ import annotations

import signal
import threading

try:  # the C functions: ``signal.signal`` / ``getsignal`` wrap them in enum
    # conversions that cost about 3 us and 2 us a call (0.3 us and 15 ns without)
    from _signal import getsignal as _getsignal
    from _signal import signal as _setsignal
except ImportError:  # pragma: no cover - not CPython
    _getsignal = signal.getsignal
    _setsignal = signal.signal

_MAIN_THREAD = threading.main_thread().ident

# ---- the gate: one process-wide SIGINT handler, a flag per compiled call ---------
# Swapping the handler around every compiled call costs two ``signal.signal`` calls;
# a real-time loop (RealTimeLocator, 10 kHz) cannot afford that. The gate is installed
# once instead and stays: while ``_inside_compiled`` is set it only notes a press,
# otherwise it hands the signal to the handler that was in force before it. Entering
# and leaving compiled code is then a flag set and clear; a press noted meanwhile is
# delivered right after, in ordinary Python code (:func:`deliver`).

_inside_compiled = False
"""Set (by the main thread) while compiled code runs: the gate only notes a press."""
_pressed = False
"""A SIGINT arrived while ``_inside_compiled`` was set and is not delivered yet."""
_previous = signal.default_int_handler
"""The SIGINT handler in force when the gate was installed (the gate hands on to it)."""


def _hand_on(previous, number, frame) -> None:
    """Do what ``previous`` (a SIGINT handler or SIG_DFL / SIG_IGN) would have done."""
    if callable(previous):
        previous(number, frame)
    elif previous == signal.SIG_DFL or terminated:
        raise KeyboardInterrupt


def _gate(number, frame) -> None:
    """The process-wide SIGINT handler of :func:`gate_ready`."""
    global _pressed
    if _inside_compiled:
        _pressed = True
    else:
        _hand_on(_previous, number, frame)


def gate_ready() -> bool:
    """True when the caller may hold Ctrl-C back with the ``_inside_compiled`` flag.

    That is: the caller runs in the main thread and the gate is SIGINT's handler,
    installed now (over whatever handler is in force, which it then hands on to) if
    another handler replaced it or it never was. In other threads: False (the handler
    runs in the main thread anyway, as for :func:`deferred_interrupts`).
    """
    global _previous
    if threading.get_ident() != _MAIN_THREAD:
        return False
    current = _getsignal(signal.SIGINT)
    if current is not _gate:
        if current is None:  # installed from outside Python: leave it alone
            return False
        _previous = current
        _setsignal(signal.SIGINT, _gate)
    return True


def deliver() -> None:
    """Deliver a press noted while compiled code ran (call after clearing the flag)."""
    global _pressed
    if _pressed and not _inside_compiled:
        _pressed = False
        _hand_on(_previous, signal.SIGINT, None)


def remove_gate() -> None:
    """Put back the handler the gate hands on to, if the gate is SIGINT's handler."""
    if threading.get_ident() == _MAIN_THREAD and _getsignal(signal.SIGINT) is _gate:
        _setsignal(signal.SIGINT, _previous)


class _Hold:
    """The context manager behind :func:`deferred_interrupts` (a class: a generator-based
    one costs more than the compiled call it guards in a real-time loop)."""

    __slots__ = ("outer", "pressed", "previous")

    def __init__(self) -> None:
        self.pressed = False
        self.previous = None
        self.outer = None

    def _note(self, number, frame) -> None:
        self.pressed = True

    def __enter__(self) -> None:
        global _inside_compiled
        if threading.get_ident() != _MAIN_THREAD:
            return
        if _getsignal(signal.SIGINT) is _gate:  # the gate is in force: just the flag
            self.outer = _inside_compiled
            _inside_compiled = True
        else:
            self.previous = _setsignal(signal.SIGINT, self._note)

    def __exit__(self, *exc) -> None:
        global _inside_compiled
        outer, self.outer = self.outer, None
        if outer is not None:
            _inside_compiled = outer
            if not outer:
                deliver()
            return
        previous, self.previous = self.previous, None
        if previous is None:
            return
        _setsignal(signal.SIGINT, previous)
        if self.pressed:
            self.pressed = False
            _hand_on(previous, signal.SIGINT, None)


def deferred_interrupts() -> _Hold:
    """Hold a Ctrl-C back while the block runs; raise it when the block ends.

    Only the main thread can install signal handlers; elsewhere this does nothing (the
    handler runs in the main thread anyway). Where the gate (:func:`gate_ready`) is
    SIGINT's handler, the hold is its flag, not a swap of handlers.
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
    handler = _getsignal(signal.SIGINT)
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
