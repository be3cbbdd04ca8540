"""The ``tactsense`` script's entry point, outside the package on purpose.

Importing :mod:`tactsense` (NumPy, SciPy, Numba, h5py) takes about a second; a Ctrl-C
in that second would otherwise print a Python traceback. This module imports nothing
heavy itself, so it can hold that interrupt until the imports are done and then end as
every command does: one line, exit status 1.
"""

import sys


def _interrupted() -> None:
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
    pressed = []
    previous = signal.signal(signal.SIGINT, lambda *_: pressed.append(True))
    try:
        from tactsense.cli.app import main as run
    finally:
        signal.signal(signal.SIGINT, previous)
    if pressed:
        _interrupted()
    try:
        run()
    except KeyboardInterrupt:
        _interrupted()
    except SystemExit as done:
        if done.code == 130:  # typer's code for a Ctrl-C outside the command's own guard
            _interrupted()
        # the command is over and its output complete: a Ctrl-C now changes nothing
        signal.signal(signal.SIGINT, signal.SIG_IGN)
        raise


if __name__ == "__main__":
    main()
