"""Recordings: frames of A/D counts with their time stamps, sensor and scenario, in HDF5.

Layout of a recording file (format ``tactsense-recording``, version 2)::

    /                    attrs: format, format_version, tactsense_version, created,
                                sensor_toml, scenario_json, flaws, scan_rate_hz,
                                source (recorded streams: the URL)
    /frames              (T, rows, cols) counts       attrs: units = "counts", axes
                         (T, rows, cols, components) for taxels of several components
                         (the sensor's frame_shape; a three-axis taxel's x, y, z last)
    /time                (T,) frame start time        attrs: units = "s"
    /sample_offset       (rows, cols) sample instant within a frame, attrs: units = "s"
    /gains               (rows, cols) per-tactel gain used by the simulator (optional)
    /truth/...           what was applied, for simulated recordings (optional)
    /sequence            (T,) uint16 sequence number on the wire (recorded streams, v2)
    /host_time           (T,) arrival on the host, Unix time [s] (recorded streams, v2)
    /device_time_us      (T,) int64 device clock as sent [us] (recorded streams, exact)
    /losses              (K,) int64 loss counters, attrs: kinds = comma list (v2)

Version 1 (no stream datasets) is still read. Every dataset tactsense writes is chunked
with HDF5's Fletcher-32 checksum filter, and :func:`write_recording` writes HDF5's v110
file format, whose superblock, object headers and indexes carry checksums too: damaged
bytes are an error on reading, not wrong numbers. Files written before (no checksums)
read as before.

A damaged HDF5 file can make libhdf5 loop for ever (a zeroed global-heap object header
does), holding the interpreter and ignoring Ctrl-C. So every opening of a recording
(:func:`read_recording`, :class:`RecordingReader`, and through them every command)
first has a child process walk the file's structure (:func:`check_structure`), killed
after :data:`CHECK_TIMEOUT_S`; a damaged file ends with ``RecordingError("<path> is
damaged: ...")`` within seconds, and Ctrl-C works throughout.

A recorded stream is written in HDF5's single-writer/multiple-reader (SWMR) mode and
flushed at least once a second: a recorder killed mid-way leaves a file that
:func:`read_recording` opens, holding every frame up to the last flush
(``Recording.closed_cleanly`` is then False). Plain ``h5py.File(path)`` refuses such a
file ("file is already open for write": the writer's flag is still set); open it with
``h5py.File(path, "r", swmr=True)``, or clear the flag once with ``h5clear -s path``
(Debian/Ubuntu package ``hdf5-tools``), after which any HDF5 reader opens it.

Axis -2 of ``frames`` runs along the finger (row 0 under the tip), axis -1
around it (``docs/nomenclature.md``); for taxels of several components the rows and
columns are axes 1 and 2 and the components axis 3 (``frames.attrs["axes"]`` says so,
from the kind's ``frame_axes``). Files written before the attribute followed the kind
read unchanged: the shape is checked against the sensor description, not the attribute.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from contextlib import contextmanager
from pathlib import Path

import h5py
import numpy as np

from tactsense._validation import TactsenseInputError
from tactsense.io._layout import (
    FORMAT,
    FORMAT_VERSION,
    Recording,
    RecordingError,
    write_recording,
)
from tactsense.io._writer import RecordingWriter
from tactsense.sensor import SensorSpec, SensorSpecError

__all__ = [
    "CHECK_TIMEOUT_S",
    "FORMAT",
    "FORMAT_VERSION",
    "Recording",
    "RecordingError",
    "RecordingReader",
    "RecordingWriter",
    "check_structure",
    "read_losses",
    "read_recording",
    "write_recording",
]


# The structure check, run in a child process so that a loop inside libhdf5 (a damaged
# B-tree or heap makes it cycle for ever, holding the GIL and ignoring Ctrl-C) can be cut
# off. It imports h5py alone, opens the file as the reader will, walks every object,
# reads every attribute, every small dataset and every chunked dataset's chunk index;
# exit status 3 and one line on standard output when libhdf5 raises.
_CHECK_CODE = r"""
import signal, sys
signal.signal(signal.SIGINT, signal.SIG_IGN)  # the parent decides; it kills us
if hasattr(signal, "alarm"):  # end even if the parent was killed: SIG_DFL acts inside C
    signal.signal(signal.SIGALRM, signal.SIG_DFL)
    signal.alarm(int(float(sys.argv[2])) + 5)
try:
    import h5py
except Exception:  # no check possible here: not a verdict on the file
    sys.exit(4)
SMALL = 4 << 20  # datasets stored in fewer bytes are read whole

def check(name, obj):
    for key in obj.attrs:
        obj.attrs[key]
    if isinstance(obj, h5py.Dataset):
        obj.shape, obj.dtype
        if obj.chunks:
            try:
                obj.id.chunk_iter(lambda info: None)
            except (AttributeError, NotImplementedError):
                for index in range(obj.id.get_num_chunks()):
                    obj.id.get_chunk_info(index)
        if obj.id.get_storage_size() <= SMALL:
            obj[()]

try:
    try:
        h5 = h5py.File(sys.argv[1], "r")
    except OSError as error:
        if "already open for write" not in str(error):
            raise
        h5 = h5py.File(sys.argv[1], "r", swmr=True)
    with h5:
        check("/", h5)
        h5.visititems(check)
except Exception as error:
    print(" ".join(str(error).split()) or type(error).__name__, flush=True)
    sys.exit(3)
"""

CHECK_TIMEOUT_S = 10.0
"""Longest time the structure check of a file may take [s]; the environment variable
``TACTSENSE_CHECK_TIMEOUT_S`` overrides it (for very large files on slow disks)."""


def _check_timeout_s() -> float:
    """:data:`CHECK_TIMEOUT_S`, or ``TACTSENSE_CHECK_TIMEOUT_S`` if set [s]."""
    text = os.environ.get("TACTSENSE_CHECK_TIMEOUT_S", "").strip()
    if not text:
        return CHECK_TIMEOUT_S
    try:
        value = float(text)
    except ValueError:
        value = float("nan")
    if not 0 < value < 1e6:
        raise RecordingError(
            f"TACTSENSE_CHECK_TIMEOUT_S={text!r} is not a time in seconds; expected a "
            "positive number, e.g. 30"
        )
    return value


_verdicts: dict[tuple, str | None] = {}


def _one_line(error: BaseException | str) -> str:
    return " ".join(str(error).split())


def check_structure(path: str | Path, *, timeout_s: float | None = None) -> None:
    """Check that libhdf5 can walk a file's structure, in a child process with a timeout.

    A damaged HDF5 file can make libhdf5 loop for ever (it holds the interpreter and
    ignores Ctrl-C), or fail deep inside a read. Before a recording is trusted, a child
    process opens it, walks every object, reads every attribute and small dataset and
    walks every chunk index; it is killed after ``timeout_s``. The parent waits
    interruptibly (Ctrl-C works at any moment). The verdict is kept per (path, size,
    modification time), so a file is checked once per process.

    Parameters
    ----------
    path : path
        An existing regular file.
    timeout_s : float, optional
        Longest time the check may take [s]; default :data:`CHECK_TIMEOUT_S` (or the
        environment variable ``TACTSENSE_CHECK_TIMEOUT_S``).

    Raises
    ------
    RecordingError
        ``"<path> is damaged: ..."`` naming what libhdf5 found, or that the check did
        not finish in time.
    """
    path = Path(path)
    stat = path.stat()
    key = (str(path.resolve()), stat.st_size, stat.st_mtime_ns)
    if key not in _verdicts:
        _verdicts[key] = _run_check(path, _check_timeout_s() if timeout_s is None else timeout_s)
    if _verdicts[key] is not None:
        raise RecordingError(f"{path} is damaged: {_verdicts[key]}")


def _run_check(path: Path, timeout_s: float) -> str | None:
    """Run the child; None if the structure is sound, else what is wrong."""
    if not sys.executable:  # an embedded interpreter: nothing to run the check with
        return None
    process = subprocess.Popen(
        # the same interpreter and path as this process (h5py may come from PYTHONPATH)
        [sys.executable, "-c", _CHECK_CODE, str(path), f"{timeout_s:g}"],
        stdin=subprocess.DEVNULL,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,  # a Ctrl-C at the terminal reaches the parent alone
    )
    try:
        out, err = process.communicate(timeout=timeout_s)
    except subprocess.TimeoutExpired:
        return (
            f"libhdf5 did not finish reading its structure within {timeout_s:g} s "
            "(damaged metadata can make it loop for ever; if the file is sound but on a "
            "very slow disk, raise TACTSENSE_CHECK_TIMEOUT_S)"
        )
    finally:
        if process.poll() is None:  # timed out, or Ctrl-C in the parent
            process.kill()
            process.wait()
    if process.returncode in (0, 4):  # sound, or h5py not importable there: no verdict
        return None
    if process.returncode == 3 and out.strip():
        return _one_line(out.strip().splitlines()[-1])
    lines = (err or "").strip().splitlines()
    return f"the check of its structure ended with status {process.returncode}" + (
        f" ({_one_line(lines[-1])})" if lines else ""
    )


@contextmanager
def _damage(path: Path):
    """Turn an error libhdf5 raises while reading ``path`` into a :class:`RecordingError`."""
    try:
        yield
    except (OSError, RuntimeError, KeyError, ValueError) as error:
        if isinstance(error, RecordingError):
            raise
        raise RecordingError(f"{path} is damaged: {_one_line(error)}") from None


def _check_file(path: Path) -> None:
    """Refuse what is not a readable HDF5 file with one line naming it, then check it."""
    if not path.exists():
        raise RecordingError(f"recording {path} does not exist")
    if path.is_dir():
        raise RecordingError(
            f"{path} is a folder; expected a recording (an HDF5 file written by tactsense)"
        )
    if not path.is_file():
        raise RecordingError(f"{path} is not a regular file; expected a recording")
    if path.stat().st_size == 0:
        raise RecordingError(f"{path} is empty (0 bytes); expected a recording")
    try:
        with open(path, "rb"):
            pass
    except OSError as error:
        raise RecordingError(f"cannot read {path}: {error.strerror or error}") from None
    if not h5py.is_hdf5(path):
        raise RecordingError(
            f"{path} is not a readable HDF5 file (no HDF5 signature: another kind of "
            "file, or its start is damaged); expected a recording"
        )
    check_structure(path)


def _open_validated(path: str | Path):
    """Open a recording and check it: (h5 file, sensor, number of frames, closed cleanly).

    The file's structure is checked first in a child process (:func:`check_structure`),
    so a damaged file ends with a :class:`RecordingError` instead of a hang. The caller
    closes the file. Raises :class:`RecordingError` for everything
    :func:`read_recording` refuses.
    """
    path = Path(path)
    _check_file(path)
    closed_cleanly = True
    try:
        h5 = h5py.File(path, "r")
    except OSError as error:
        if "already open for write" not in str(error):
            raise RecordingError(
                f"{path} is not a readable HDF5 file ({_one_line(error)})"
            ) from None
        # a recorder still writing, or killed: SWMR readers see everything flushed
        closed_cleanly = False
        try:
            h5 = h5py.File(path, "r", swmr=True)
        except OSError as again:
            raise RecordingError(
                f"{path} is not a readable HDF5 file ({_one_line(again)})"
            ) from None
    try:
        with _damage(path):
            sensor, n = _validate(path, h5)
    except BaseException:
        h5.close()
        raise
    return h5, sensor, n, closed_cleanly


def _validate(path: Path, h5) -> tuple[SensorSpec, int]:
    """Check the open file is a recording this tactsense reads: (sensor, frames)."""
    if h5.attrs.get("format") != FORMAT:
        raise RecordingError(
            f"{path} is not a tactsense recording (format attribute "
            f"{h5.attrs.get('format')!r}, expected {FORMAT!r})"
        )
    try:
        version = int(h5.attrs.get("format_version", -1))
    except (TypeError, ValueError):
        raise RecordingError(
            f"{path}: format_version {h5.attrs.get('format_version')!r} is not a number"
        ) from None
    if version > FORMAT_VERSION:
        raise RecordingError(
            f"{path} has format version {version}; this tactsense reads up to "
            f"{FORMAT_VERSION}: upgrade tactsense"
        )
    for name in ("frames", "time", "sample_offset"):
        if name not in h5:
            raise RecordingError(f"{path} lacks the dataset /{name}")
    try:
        sensor = SensorSpec.from_toml_string(str(h5.attrs["sensor_toml"]))
    except (KeyError, SensorSpecError) as error:
        raise RecordingError(f"{path}: sensor description unreadable: {error}") from None
    for name in ("frames", "time", "sample_offset", "sequence", "host_time", "device_time_us"):
        if name in h5 and h5[name].dtype.kind not in "uif":
            raise RecordingError(
                f"{path}: /{name} holds {h5[name].dtype} values; expected numbers "
                "(counts or fractional deflections for /frames, seconds for times)"
            )
    per_frame = [
        h5[name].shape[0]
        for name in ("frames", "time", "sequence", "host_time", "device_time_us")
        if name in h5 and h5[name].ndim >= 1
    ]
    n = min(per_frame)  # a killed writer may have flushed one dataset further
    shape = h5["frames"].shape
    if len(shape) != 1 + len(sensor.frame_shape) or shape[1:] != sensor.frame_shape:
        raise RecordingError(
            f"{path}: /frames has shape {shape}; expected (T, "
            f"{', '.join(str(n) for n in sensor.frame_shape)}) for its sensor {sensor.name!r}"
        )
    return sensor, n


def _losses(h5) -> dict[str, int]:
    """The /losses counters by kind (empty if the recording has none)."""
    if "losses" not in h5:
        return {}
    kinds = str(h5["losses"].attrs.get("kinds", "")).split(",")
    return {k: int(v) for k, v in zip(kinds, h5["losses"][()], strict=False) if k}


def read_recording(path: str | Path) -> Recording:
    """Open and validate a recording written by :func:`write_recording`.

    Raises
    ------
    RecordingError
        If the file is missing, not HDF5, not a tactsense recording, lacks a
        dataset, or has shapes that disagree with its sensor.
    """
    path = Path(path)
    h5, sensor, n, closed_cleanly = _open_validated(path)
    with h5, _damage(path):
        frames = h5["frames"][:n]
        truth: dict = {}
        if "truth" in h5:
            group = h5["truth"]
            truth = {key: group[key][()] for key in group}
            truth.update({key: str(value) for key, value in group.attrs.items()})
        try:
            scenario = json.loads(str(h5.attrs.get("scenario_json", "{}")))
        except json.JSONDecodeError as error:
            raise RecordingError(f"{path}: scenario metadata is not valid JSON ({error})") from None
        flaws = tuple(f for f in str(h5.attrs.get("flaws", "")).split(",") if f)
        losses = _losses(h5)
        return Recording(
            frames=frames,
            time_s=h5["time"][:n],
            sample_offset_s=h5["sample_offset"][()],
            sensor=sensor,
            scenario=scenario,
            flaws=flaws,
            truth=truth,
            gains=h5["gains"][()] if "gains" in h5 else None,
            sequence=h5["sequence"][:n] if "sequence" in h5 else None,
            host_time_s=h5["host_time"][:n] if "host_time" in h5 else None,
            device_time_us=h5["device_time_us"][:n] if "device_time_us" in h5 else None,
            losses=losses,
            source=str(h5.attrs.get("source", "")),
            closed_cleanly=closed_cleanly,
        )


class RecordingReader:
    """A recording read in pieces, for recordings larger than memory.

    Validated as :func:`read_recording` validates, but nothing but the metadata is read
    until asked for. Use as a context manager.

    Examples
    --------
    >>> with RecordingReader("long.h5") as reader:  # doctest: +SKIP
    ...     for start, frames, time_s in reader.chunks():
    ...         ...
    """

    def __init__(self, path: str | Path):
        self.path = Path(path)
        self._h5, self.sensor, self.n_frames, self.closed_cleanly = _open_validated(self.path)

    def __enter__(self) -> RecordingReader:
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def close(self) -> None:
        self._h5.close()

    @property
    def chunk_frames(self) -> int:
        """Frames per piece: the HDF5 chunk length (a multiple of it near 65,536)."""
        chunks = self._h5["frames"].chunks
        if not chunks:
            return 65_536
        return max(chunks[0], (65_536 // chunks[0]) * chunks[0])

    def frames(self, start: int, stop: int) -> np.ndarray:
        """Frames ``start`` to ``stop`` (exclusive) [counts]."""
        with _damage(self.path):
            return self._h5["frames"][start : min(stop, self.n_frames)]

    def time_s(self, start: int, stop: int) -> np.ndarray:
        """Their times [s]."""
        with _damage(self.path):
            return self._h5["time"][start : min(stop, self.n_frames)]

    @property
    def has_host_time(self) -> bool:
        """Whether the recording holds each frame's arrival on the host's clock."""
        return "host_time" in self._h5

    def host_time_s(self, start: int, stop: int) -> np.ndarray:
        """Arrival of frames ``start`` to ``stop`` on the host, Unix time [s]."""
        with _damage(self.path):
            return self._h5["host_time"][start : min(stop, self.n_frames)]

    @property
    def losses(self) -> dict[str, int]:
        """Frames lost by kind, as the recorder counted them (empty if none recorded)."""
        with _damage(self.path):
            return _losses(self._h5)

    @property
    def attrs(self) -> dict:
        """The file's top-level attributes (sensor, scenario, flaws, source, ...)."""
        with _damage(self.path):
            return dict(self._h5.attrs)

    def chunks(self, chunk_frames: int | None = None):
        """Yield ``(start, frames, time_s)`` for consecutive pieces of the recording."""
        size = int(chunk_frames or self.chunk_frames)
        if size < 1:
            raise TactsenseInputError(f"chunk_frames must be at least 1; got {size}")
        for start in range(0, self.n_frames, size):
            yield start, self.frames(start, start + size), self.time_s(start, start + size)


def read_losses(path: str | Path) -> dict[str, int]:
    """A recording's loss counters alone, without reading its frames."""
    with RecordingReader(path) as reader:
        return reader.losses
