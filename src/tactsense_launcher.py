"""The ``tactsense`` script's entry point, outside the package on purpose.

Importing :mod:`tactsense` (NumPy, SciPy, Numba, h5py) takes about a second; a Ctrl-C
in that second would otherwise print a Python traceback. This module imports nothing
heavy itself, so it can hold that interrupt until the imports are done and then end as
every command does: one line, exit status 1.

SIGTERM takes the same path as Ctrl-C (:func:`tactsense._signals.install_sigterm`):
outputs are closed or removed as on Ctrl-C; a command that ends on it reports exit
status 143 (128 + SIGTERM), as a shell does for a process SIGTERM ended.
"""

import sys


def _terminated() -> bool:
    signals = sys.modules.get("tactsense._signals")
    return bool(signals is not None and signals.terminated)


def _interrupted(terminated: bool = False) -> None:
    if terminated or _terminated():
        sys.stderr.write("error: stopped by SIGTERM; no output was left half-written\n")
        sys.exit(143)
    sys.stderr.write("error: interrupted; no output was left half-written\n")
    sys.exit(1)


def _unraisable(info) -> None:
    # a Ctrl-C that lands in a finalizer (a weakref callback during garbage collection)
    # is "ignored" by Python with a traceback; deliver it to the main thread instead
    # (re-raising here would only be "ignored" again, so a helper thread re-sends it a
    # moment later, once the finalizer has returned)
    if info.exc_type is not None and issubclass(info.exc_type, KeyboardInterrupt):
        import _thread
        import threading

        threading.Timer(0.05, _thread.interrupt_main).start()
        return
    sys.__unraisablehook__(info)


def main() -> None:
    import signal

    sys.unraisablehook = _unraisable
    # a Ctrl-C during the imports is noted, not raised inside some module's import
    pressed, terms = [], []
    previous = signal.signal(signal.SIGINT, lambda *_: pressed.append(True))
    signal.signal(signal.SIGTERM, lambda *_: terms.append(True))
    try:
        from tactsense._signals import install_sigterm
        from tactsense.cli.app import main as run
    finally:
        signal.signal(signal.SIGINT, previous)
    install_sigterm()
    if pressed or terms:
        _interrupted(bool(terms))
    try:
        run()
    except KeyboardInterrupt:
        _interrupted()
    except SystemExit as done:
        if done.code == 130:  # typer's code for a Ctrl-C outside the command's own guard
            _interrupted()
        # the command is over and its output complete: a Ctrl-C now changes nothing
        signal.signal(signal.SIGINT, signal.SIG_IGN)
        signal.signal(signal.SIGTERM, signal.SIG_IGN)
        if _terminated() and done.code in (0, None):
            sys.exit(143)  # stopped cleanly, but by SIGTERM: say so to the caller
        raise


if __name__ == "__main__":
    main()
