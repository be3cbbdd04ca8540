"""The C library calls nothing outside itself (firmware/tactsense.h promises no library
calls beyond <stddef.h> and <stdint.h>, so that it links with -nostdlib), at every
optimisation level and with or without -ffreestanding; firmware/Makefile builds and checks
it; the host-side example (firmware/examples/host_device) streams to tactsense's own
reader and recorder.

GCC recognises loops that count a string's length or fill or copy memory and replaces
them with calls of strlen, memset or memcpy from -O2 on, unless told -ffreestanding or
-fno-builtin; the library's code is written so that it needs neither. Skipped only where
no C compiler exists and CI is unset; with CI set, a missing compiler fails."""

from __future__ import annotations

import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from tactsense.io.recording import read_recording
from tactsense.stream import StreamReader

from .test_c_encoder import LIBRARY_ONLY, STRICT, _compiler

ROOT = Path(__file__).resolve().parents[2]
FIRMWARE = ROOT / "firmware"
EXAMPLE = FIRMWARE / "examples" / "host_device" / "host_device.c"
CLI = [sys.executable, "-m", "tactsense_launcher"]
LEVELS = ["-O0", "-O1", "-O2", "-O3", "-Os"]


def _nm() -> str:
    path = shutil.which("nm")
    if path is None:
        pytest.skip("no nm (binutils) on PATH")
    return path


def _undefined(obj: Path) -> list[str]:
    done = subprocess.run([_nm(), "-u", str(obj)], capture_output=True, text=True, check=True)
    return done.stdout.split()[1::2]  # lines "U name"


@pytest.mark.parametrize("crc", ["", "-DTS_CRC_BYTE_TABLE"], ids=["crc-nibble", "crc-byte"])
@pytest.mark.parametrize("freestanding", [False, True], ids=["hosted", "freestanding"])
@pytest.mark.parametrize("level", LEVELS)
def test_the_object_has_no_undefined_symbols(tmp_path, level, freestanding, crc):
    cc = _compiler()
    obj = tmp_path / "tactsense.o"
    flags = [*STRICT, *LIBRARY_ONLY, level, *([crc] if crc else [])]
    if freestanding:
        flags += ["-ffreestanding", "-fno-builtin"]
    command = [cc, *flags, "-c", str(FIRMWARE / "tactsense.c"), "-o", str(obj)]
    done = subprocess.run(command, capture_output=True, text=True, check=False)
    assert done.returncode == 0, f"{' '.join(command)}\n{done.stderr}"
    assert _undefined(obj) == [], " ".join(command)


def test_the_makefile_builds_and_checks_the_library(tmp_path):
    make = shutil.which("make")
    if make is None:
        pytest.skip("no make on PATH")
    cc = _compiler()
    for level in LEVELS:
        build = tmp_path / level.lstrip("-")
        done = subprocess.run(
            [make, "-C", str(FIRMWARE), f"CC={cc}", f"OPT={level}", f"BUILD={build}", "check"],
            capture_output=True,
            text=True,
            check=False,
        )
        assert done.returncode == 0, done.stdout + done.stderr
        assert "no undefined symbols" in done.stdout
        assert _undefined(build / "tactsense.o") == []


@pytest.fixture
def host_device(tmp_path):
    """The host-side example, built as firmware/Makefile builds it, listening on a free
    port of 127.0.0.1 and sending END after 40 frames; yields its socket:// URL."""
    cc = _compiler()
    exe = tmp_path / "host_device"
    command = [cc, *STRICT, "-O2", f"-I{FIRMWARE}", str(EXAMPLE), str(FIRMWARE / "tactsense.c")]
    done = subprocess.run([*command, "-o", str(exe)], capture_output=True, text=True, check=False)
    assert done.returncode == 0, f"{' '.join(command)}\n{done.stderr}"
    process = subprocess.Popen([str(exe), "0", "40"], stdout=subprocess.PIPE, text=True)
    try:
        line = process.stdout.readline().strip()
        assert line.startswith("listening on 127.0.0.1:"), line
        yield "socket://" + line.rpartition(" ")[2]
    finally:
        process.kill()
        process.wait(10)


def _expected(n: int) -> np.ndarray:
    """What host_device.c documents: 500 counts at rest, tactel k mod 64 (row-major)
    at 800 in the k-th frame since START."""
    frames = np.full((n, 64), 500)
    frames[np.arange(n), np.arange(n) % 64] = 800
    return frames.reshape(n, 8, 8)


def test_host_example_streams_to_the_stream_reader(host_device):
    with StreamReader(host_device, timeout_s=5.0) as stream:
        sensor, identity = stream.sensor, stream.identity
        received = list(stream.frames())
        stats, sent, ended = stream.stats, stream.frames_sent, stream.ended
    assert sensor.name == "host_device" and sensor.shape == (8, 8)
    assert identity["device"] == "host_device"
    assert identity["frame_rate_hz"] == sensor.electronics.scan_rate_hz == 100.0
    assert ended and sent == len(received) == 40
    assert stats.frames == 40 and stats.lost == 0
    assert stats.bad_check == stats.truncated == stats.garbage == stats.duplicates == 0
    np.testing.assert_array_equal(np.stack([f.counts for f in received]), _expected(40))
    # the device clock is the nominal scan clock: 10 ms per scan
    assert [round(f.device_time_s * 1e6) for f in received] == [10_000 * k for k in range(40)]


def test_host_example_is_recorded_by_tactsense_record(host_device, tmp_path):
    out = tmp_path / "run.h5"
    subprocess.run(
        [*CLI, "record", host_device, "--out", str(out), "--quiet"],
        check=True,
        capture_output=True,
        timeout=60,
    )
    recording = read_recording(out)
    np.testing.assert_array_equal(recording.frames, _expected(40))
    assert recording.closed_cleanly and recording.source == host_device
    assert sum(recording.losses.values()) == 0
