"""Ctrl-C and RealTimeLocator: the process-wide SIGINT gate (tactsense._signals) holds a
press back while a frame's compiled call runs and delivers it right after, in Python: a
KeyboardInterrupt under the default handler, the call of any handler installed before."""

import os
import signal
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

import tactsense
from tactsense import _signals

SRC = str(Path(tactsense.__file__).resolve().parents[1])

LOOP = """
import os, signal, sys, threading, time
import numpy as np
import tactsense as ts
from tactsense import _signals
from tactsense.estimate.finger.realtime import RealTimeLocator

spec = ts.fearing1990_initial()
frames = ts.simulate(spec, ts.probe_sweep(spec), rng=0).frames
{before}
locator = RealTimeLocator(spec, ts.baseline_from(frames, 5))
assert signal.getsignal(signal.SIGINT) is _signals._gate
threading.Timer(0.2, os.kill, (os.getpid(), signal.SIGINT)).start()
calls = 0
deadline = time.monotonic() + 30
try:
    while time.monotonic() < deadline {until}:
        contact = locator(frames[calls % len(frames)])
        calls += 1
except KeyboardInterrupt:
    print("KeyboardInterrupt after", calls, "frames")
else:
    print("loop ended after", calls, "frames")
assert calls > 100, calls
assert np.isfinite(locator(frames[77]).row)  # the locator still works afterwards
_signals.remove_gate()
print("restored", signal.getsignal(signal.SIGINT) is {restored})
"""


def _run(before: str = "", until: str = "", restored: str = "signal.default_int_handler"):
    code = LOOP.format(before=textwrap.dedent(before), until=until, restored=restored)
    env = {**os.environ, "PYTHONPATH": SRC + os.pathsep + os.environ.get("PYTHONPATH", "")}
    return subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, timeout=120, env=env
    )


def test_sigint_during_a_realtime_loop_raises_keyboard_interrupt_cleanly():
    result = _run()
    assert result.returncode == 0, result.stderr
    assert "KeyboardInterrupt after" in result.stdout, result.stdout + result.stderr
    assert "restored True" in result.stdout
    assert "Fatal" not in result.stderr and "SystemError" not in result.stderr


def test_sigint_during_a_realtime_loop_goes_to_the_handler_installed_before():
    before = """
    pressed = []
    def on_sigint(number, frame):
        assert threading.current_thread() is threading.main_thread()
        pressed.append(number)
    signal.signal(signal.SIGINT, on_sigint)
    """
    result = _run(before, until="and not pressed", restored="on_sigint")
    assert result.returncode == 0, result.stderr
    assert "loop ended after" in result.stdout, result.stdout + result.stderr
    assert "restored True" in result.stdout


def test_sigint_ignored_before_stays_ignored():
    before = "signal.signal(signal.SIGINT, signal.SIG_IGN)"
    result = _run(before, until="and calls < 200_000", restored="signal.SIG_IGN")
    assert result.returncode == 0, result.stderr
    assert "loop ended after" in result.stdout, result.stdout + result.stderr
    assert "restored True" in result.stdout


@pytest.fixture
def gate():
    """The gate installed over a recording handler in this (main) thread; put back after."""
    previous = signal.getsignal(signal.SIGINT)
    pressed = []
    signal.signal(signal.SIGINT, lambda number, frame: pressed.append(number))
    assert _signals.gate_ready()
    yield pressed
    _signals.remove_gate()
    signal.signal(signal.SIGINT, previous)


def test_gate_notes_a_press_inside_compiled_code_and_delivers_it_after(gate):
    _signals._inside_compiled = True
    try:
        _signals._gate(signal.SIGINT, None)  # as the signal module would call it
        assert gate == [] and _signals._pressed
    finally:
        _signals._inside_compiled = False
    _signals.deliver()
    assert gate == [signal.SIGINT] and not _signals._pressed
    _signals._gate(signal.SIGINT, None)  # outside compiled code: handed on at once
    assert gate == [signal.SIGINT, signal.SIGINT]


def test_deferred_interrupts_uses_the_gate_flag_and_nests(gate):
    with _signals.deferred_interrupts():
        assert _signals._inside_compiled
        assert signal.getsignal(signal.SIGINT) is _signals._gate  # no swap
        with _signals.deferred_interrupts():
            _signals._gate(signal.SIGINT, None)
        assert _signals._inside_compiled and gate == []  # the outer hold still holds
    assert not _signals._inside_compiled and gate == [signal.SIGINT]


def test_gate_is_reinstalled_over_a_handler_that_replaced_it(gate):
    later = []
    signal.signal(signal.SIGINT, lambda number, frame: later.append(number))
    assert _signals.gate_ready()
    assert signal.getsignal(signal.SIGINT) is _signals._gate
    _signals._gate(signal.SIGINT, None)
    assert later == [signal.SIGINT] and gate == []
