"""The damaged-file matrix (issue 21, items 2 and 3): every command that opens a
recording, given a damaged, truncated or foreign file, ends within a bound with exit
status 2 and one line naming the file, never a hang, a traceback or an output.

Each damage is placed by what lies at that spot in the file (found from its structure
or its bytes), not at a fixed offset, so the cases stay meaningful when the layout moves.
The commands run as subprocesses with a timeout: a hang fails the test instead of
hanging CI. Before the structure check, the ``heap`` cases (a zeroed global-heap object
header in front of the scenario attribute) ran at 100 % CPU inside libhdf5 until killed,
in old (HDF5 default format) and new (v110) files alike; ``time data`` read back as
silently wrong times before the Fletcher-32 checksums.
"""

import os
import signal
import subprocess
import sys
import time

import h5py
import numpy as np
import pytest

import tactsense as ts
from tactsense.io.recording import RecordingWriter

BOUND_S = 20.0  # longest a command may take on a damaged file [s]
# the structure check's own limit, short here so the hang cases are quick (default 10 s)
ENV = {**os.environ, "TACTSENSE_CHECK_TIMEOUT_S": "4"}
CLI = [sys.executable, "-m", "tactsense_launcher"]


def _old_style(path, rec):
    """A recording as tactsense wrote it before Fletcher-32: HDF5's default (earliest)
    format, contiguous datasets; users' files look like this."""
    with h5py.File(path, "w") as h5:
        h5.attrs["format"] = "tactsense-recording"
        h5.attrs["format_version"] = 2
        h5.attrs["sensor_toml"] = rec.sensor.to_toml_string()
        h5.attrs["scenario_json"] = __import__("json").dumps(rec.scenario)
        h5.attrs["flaws"] = ",".join(rec.flaws)
        h5.attrs["source"] = ""
        n = len(rec)
        h5.create_dataset("frames", data=rec.frames, compression="gzip", chunks=(n, 8, 8))
        h5["time"] = rec.time_s
        h5["sample_offset"] = rec.sample_offset_s


def _device(path, spec):
    """A recording as ``tactsense record`` writes it (SWMR, chunked stream datasets)."""
    rng = np.random.default_rng(0)
    with RecordingWriter(path, spec, np.zeros(spec.shape), source="loop://") as writer:
        for i in range(3000):
            writer.append(rng.integers(1900, 2100, spec.shape, dtype=np.uint16), i / 7, i, i)


@pytest.fixture(scope="module")
def sources(tmp_path_factory):
    folder = tmp_path_factory.mktemp("io_matrix")
    spec = ts.fearing1990_initial()
    rec = ts.simulate(spec, ts.probe_sweep(spec), rng=0)
    ts.write_recording(folder / "new.h5", rec)
    _old_style(folder / "old.h5", rec)
    _device(folder / "device.h5", spec)
    return folder


def _first_chunk(path, name):
    with h5py.File(path, "r") as h5:
        dataset = h5[name]
        if dataset.chunks:
            info = dataset.id.get_chunk_info(0)
            return info.byte_offset, info.size
        return dataset.id.get_offset(), dataset.id.get_storage_size()


def _zero(data: bytearray, start: int, stop: int) -> None:
    data[start:stop] = bytes(stop - start)


def _damage(path, kind) -> bytes:
    """The bytes of ``path`` with one kind of damage."""
    data = bytearray(path.read_bytes())
    if kind == "superblock":  # keep the signature, zero the rest of the superblock
        _zero(data, 8, 48)
    elif kind == "heap":  # the global-heap object header in front of the scenario text
        at = data.find(b'{"')
        assert at > 16
        _zero(data, at - 16, at)
    elif kind == "object header":  # the /frames dataset's header
        with h5py.File(path, "r") as h5:
            at = h5py.h5o.get_info(h5["frames"].id).addr
        _zero(data, at, at + 64)
    elif kind == "chunk index":  # the first chunk index (v1 B-tree or v2 structures)
        hits = [data.find(tag) for tag in (b"TREE", b"BTHD", b"EAHD", b"FAHD")]
        at = min(h for h in hits if h > 0)
        _zero(data, at, at + 64)
    elif kind in ("frames data", "time data"):
        offset, size = _first_chunk(path, kind.split()[0])
        _zero(data, offset + size // 4, offset + size // 2)
    elif kind == "bytes 3000-6000":  # the case, whatever lies there
        _zero(data, 3000, 6000)
    elif kind == "truncated half":
        data = data[: len(data) // 2]
    elif kind == "truncated 3000":
        data = data[:3000]
    elif kind == "random block":  # 2 KB of noise after the superblock
        data[512:2560] = np.random.default_rng(1).integers(0, 256, 2048, np.uint8).tobytes()
    else:
        raise ValueError(kind)
    return bytes(data)


DAMAGES = [
    "superblock",
    "heap",
    "object header",
    "chunk index",
    "frames data",
    "time data",
    "truncated half",
    "truncated 3000",
    "random block",
    "bytes 3000-6000",
]
# (damage, source) pairs: every damage on the files tactsense writes now; the old
# layout and the recorder's layout for the damages that hung or read wrong numbers
CASES = (
    [(d, "new.h5") for d in DAMAGES]
    + [(d, "old.h5") for d in ("heap", "chunk index", "object header", "bytes 3000-6000")]
    + [(d, "device.h5") for d in ("heap", "chunk index", "time data", "truncated half")]
)


def _run(args, timeout=BOUND_S):
    start = time.monotonic()
    try:
        result = subprocess.run(
            [*CLI, *args], capture_output=True, text=True, timeout=timeout, env=ENV
        )
    except subprocess.TimeoutExpired:
        pytest.fail(f"{' '.join(args)} did not end within {timeout} s (hang)")
    return result, time.monotonic() - start


def _check_one_line(result, name, *phrases):
    err = result.stderr.strip()
    assert result.returncode == 2, (result.returncode, err, result.stdout)
    assert "Traceback" not in err and "HDF5-DIAG" not in err, err
    assert len(err.splitlines()) == 1, err
    assert err.startswith("error:") and name in err, err
    assert any(p in err for p in phrases), err


def _leftover_checkers(path) -> list[int]:
    """Processes still running with ``path`` on their command line."""
    found = []
    for pid in filter(str.isdigit, os.listdir("/proc")):
        try:
            with open(f"/proc/{pid}/cmdline", "rb") as handle:
                if str(path).encode() in handle.read():
                    found.append(int(pid))
        except OSError:
            pass
    return found


@pytest.mark.parametrize("kind, source", CASES, ids=[f"{s}-{k}" for k, s in CASES])
def test_info_on_damaged_files(sources, tmp_path, kind, source):
    bad = tmp_path / f"bad_{source}"
    bad.write_bytes(_damage(sources / source, kind))
    result, _ = _run(["info", str(bad)])
    _check_one_line(result, bad.name, "is damaged", "not a readable HDF5 file")
    assert not _leftover_checkers(bad)


COMMANDS = {
    "locate": "locate {rec} --out {out}.csv",
    "view": "view {rec} --port 0",
    "export": "export {rec} --format mcap --out {out}.mcap",
    "calibrate": "calibrate {rec} --partial --out {out}.json",
    "emulate": "emulate --recording {rec} --port 0",
    "batch": "batch {rec} --out {out}",
}


@pytest.mark.parametrize("kind", ["heap", "frames data"])
@pytest.mark.parametrize("command", list(COMMANDS))
def test_every_command_refuses_a_damaged_recording(sources, tmp_path, command, kind):
    bad = tmp_path / "bad.h5"
    bad.write_bytes(_damage(sources / "new.h5", kind))
    out = tmp_path / "out"
    # batch starts a Dask cluster, which retries a failed task on another worker
    bound = 3 * BOUND_S if command == "batch" else BOUND_S
    result, _ = _run(COMMANDS[command].format(rec=bad, out=out).split(), timeout=bound)
    if command == "batch":  # batch goes on past a bad recording and reports it
        # (Dask's worker log prints the task's traceback: batch's own matter, not checked)
        assert result.returncode != 0, result.stderr
        summary = (out / "summary.csv").read_text()
        assert "bad.h5 is damaged" in summary, summary
        assert not list(out.glob("bad*"))
    else:
        _check_one_line(result, "bad.h5", "is damaged")
        assert not [p for p in tmp_path.iterdir() if p.name.startswith(("out", ".out"))]


def _folder(path):
    path.mkdir()


FOREIGN = {
    "a folder": (_folder, "is a folder"),
    "an empty file": (lambda p: p.write_bytes(b""), "is empty"),
    "a text file": (lambda p: p.write_text("frame,counts\n1,2\n"), "not a readable HDF5 file"),
    "random bytes": (
        lambda p: p.write_bytes(np.random.default_rng(2).integers(0, 256, 5000, np.uint8)),
        "not a readable HDF5 file",
    ),
}


@pytest.mark.parametrize("command", ["info", "locate"])
@pytest.mark.parametrize("what", list(FOREIGN))
def test_foreign_inputs_get_one_line(tmp_path, what, command):
    make, phrase = FOREIGN[what]
    path = tmp_path / "input.h5"
    make(path)
    args = ["info", str(path)] if command == "info" else ["locate", str(path), "--out", "o.csv"]
    result, _ = _run(args)
    _check_one_line(result, "input.h5", phrase)


def test_ctrl_c_during_a_hanging_check(sources, tmp_path):
    """Ctrl-C ends the command at once though libhdf5 loops in the checker."""
    bad = tmp_path / "hangs.h5"
    bad.write_bytes(_damage(sources / "new.h5", "heap"))
    env = {**ENV, "TACTSENSE_CHECK_TIMEOUT_S": "120"}
    process = subprocess.Popen(
        [*CLI, "info", str(bad)], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env
    )
    try:
        deadline = time.monotonic() + 30
        while len(_leftover_checkers(bad)) < 2:  # the command and its checker
            assert time.monotonic() < deadline and process.poll() is None, "no checker"
            time.sleep(0.1)
        time.sleep(1.0)  # the checker is now looping inside libhdf5
        sent = time.monotonic()
        process.send_signal(signal.SIGINT)
        _, err = process.communicate(timeout=10)
        assert time.monotonic() - sent < 5
    finally:
        if process.poll() is None:  # it ignored Ctrl-C: do not leave it spinning
            process.kill()
            process.communicate()
    assert process.returncode == 1 and "interrupted" in err and "Traceback" not in err, err
    time.sleep(0.2)
    assert not _leftover_checkers(bad)  # the checker was killed with it
