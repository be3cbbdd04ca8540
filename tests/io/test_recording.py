import h5py
import numpy as np
import pytest

import tactsense as ts
from tactsense.io.recording import RecordingError


@pytest.fixture(scope="module")
def recording(initial):
    scene = ts.probe_sweep(initial, along="around", row=3, start=-30, stop=30, increment=10)
    return ts.simulate(initial, scene, rng=0)


def test_round_trip(recording, tmp_path):
    path = ts.write_recording(tmp_path / "r.h5", recording)
    back = ts.read_recording(path)
    np.testing.assert_array_equal(back.frames, recording.frames)
    np.testing.assert_array_equal(back.time_s, recording.time_s)
    assert back.sensor == recording.sensor
    assert back.scenario == recording.scenario
    assert back.flaws == recording.flaws
    np.testing.assert_array_equal(back.truth["frame_step"], recording.truth["frame_step"])
    with h5py.File(path) as h5:
        assert h5["frames"].attrs["units"] == "counts" and h5["time"].attrs["units"] == "s"


def test_never_overwrites(recording, tmp_path):
    path = tmp_path / "r.h5"
    path.write_bytes(b"precious")
    with pytest.raises(FileExistsError, match="--force"):
        ts.write_recording(path, recording)
    assert path.read_bytes() == b"precious"
    ts.write_recording(path, recording, overwrite=True)
    assert ts.read_recording(path).frames.shape == recording.frames.shape


def test_not_hdf5(tmp_path):
    path = tmp_path / "junk.h5"
    path.write_text("not an hdf5 file")
    with pytest.raises(RecordingError, match="not a readable HDF5 file"):
        ts.read_recording(path)


def test_missing_file(tmp_path):
    with pytest.raises(RecordingError, match="does not exist"):
        ts.read_recording(tmp_path / "absent.h5")


def test_foreign_hdf5(tmp_path):
    path = tmp_path / "other.h5"
    with h5py.File(path, "w") as h5:
        h5["data"] = np.zeros(3)
    with pytest.raises(RecordingError, match="not a tactsense recording"):
        ts.read_recording(path)


@pytest.mark.parametrize("damage", ["drop_time", "bad_shape", "bad_sensor"])
def test_damaged_recordings(recording, tmp_path, damage):
    path = ts.write_recording(tmp_path / "r.h5", recording)
    with h5py.File(path, "a") as h5:
        if damage == "drop_time":
            del h5["time"]
        elif damage == "bad_shape":
            del h5["frames"]
            h5["frames"] = np.zeros((4, 7, 8))
        else:
            h5.attrs["sensor_toml"] = "[array]\nwired_rows = 99\n"
    message = {
        "drop_time": "lacks the dataset /time",
        "bad_shape": "expected \\(T, 8, 8\\)",
        "bad_sensor": "sensor description unreadable",
    }[damage]
    with pytest.raises(RecordingError, match=message):
        ts.read_recording(path)


def test_missing_folder(recording, tmp_path):
    with pytest.raises(RecordingError, match="does not exist"):
        ts.write_recording(tmp_path / "nope" / "r.h5", recording)


def _recorded(path, spec, n=2500):
    from tactsense.io.recording import RecordingWriter

    with RecordingWriter(path, spec, np.zeros(spec.shape), source="loop://") as writer:
        for i in range(n):
            writer.append(np.full(spec.shape, 2000 + i % 7, np.uint16), i / 7, i, i)


def _dataset_names(h5) -> list[str]:
    names: list[str] = []
    h5.visititems(lambda name, obj: names.append(name) if isinstance(obj, h5py.Dataset) else None)
    return names


def test_every_dataset_written_carries_a_checksum(recording, tmp_path):
    path = ts.write_recording(tmp_path / "r.h5", recording)
    _recorded(tmp_path / "d.h5", recording.sensor)
    for name in (path, tmp_path / "d.h5"):
        with h5py.File(name) as h5:
            datasets = [h5[key] for key in _dataset_names(h5)]
            assert len(datasets) >= 4
            assert all(d.fletcher32 for d in datasets), [d.name for d in datasets]


@pytest.mark.parametrize("name", ["time", "frames", "truth/frame_step"])
def test_damaged_data_is_an_error_not_numbers(recording, tmp_path, name):
    """Zeroed bytes inside a dataset's data: without a checksum /time (stored raw) read
    back as zeros, silently; with Fletcher-32 the read fails, naming the file."""
    path = ts.write_recording(tmp_path / "r.h5", recording)
    with h5py.File(path) as h5:
        info = h5[name].id.get_chunk_info(0)
    data = bytearray(path.read_bytes())
    middle = info.byte_offset + info.size // 2
    data[middle : middle + 16] = bytes(16)
    path.write_bytes(data)
    with pytest.raises(RecordingError, match=r"r\.h5 is damaged: .*"):
        ts.read_recording(path)


def test_structure_is_checked_once_per_file_version(recording, tmp_path, monkeypatch):
    import os

    from tactsense.io import recording as module

    calls = []
    real = module._run_check
    monkeypatch.setattr(module, "_run_check", lambda *a: calls.append(a) or real(*a))
    path = ts.write_recording(tmp_path / "r.h5", recording)
    ts.read_recording(path)
    with module.RecordingReader(path):
        pass
    assert len(calls) == 1
    os.utime(path, ns=(0, 10**9))  # a changed file is checked again
    ts.read_recording(path)
    assert len(calls) == 2


def test_files_written_before_the_checksums_still_read(recording, tmp_path):
    """Version-1 and version-2 files as earlier tactsense wrote them: HDF5's default
    format, contiguous datasets, no Fletcher-32."""
    for version in (1, 2):
        path = tmp_path / f"v{version}.h5"
        with h5py.File(path, "w") as h5:
            h5.attrs["format"] = "tactsense-recording"
            h5.attrs["format_version"] = version
            h5.attrs["sensor_toml"] = recording.sensor.to_toml_string()
            h5.attrs["scenario_json"] = '{"description": "old"}'
            h5.attrs["flaws"] = "noise"
            h5.create_dataset("frames", data=recording.frames, compression="gzip")
            h5["time"] = recording.time_s
            h5["sample_offset"] = recording.sample_offset_s
            if version == 2:
                h5["sequence"] = np.arange(len(recording), dtype=np.uint16)
        back = ts.read_recording(path)
        np.testing.assert_array_equal(back.frames, recording.frames)
        np.testing.assert_array_equal(back.time_s, recording.time_s)
        assert back.flaws == ("noise",)


def test_a_killed_recording_opens_in_plain_h5py_in_swmr_mode(initial, tmp_path):
    """What the module docstring and docs/recordings.md say of a recorder killed
    outright: plain ``h5py.File(path)`` refuses it (the writer's flag is still set),
    ``h5py.File(path, "r", swmr=True)`` reads every flushed frame, and tactsense reads
    it without help."""
    import subprocess
    import sys

    path = tmp_path / "killed.h5"
    code = (
        "import os, numpy as np, tactsense as ts\n"
        "from tactsense.io.recording import RecordingWriter\n"
        "spec = ts.fearing1990_initial()\n"
        f"w = RecordingWriter({str(path)!r}, spec, np.zeros(spec.shape), source='x')\n"
        "for i in range(1500):\n"
        "    w.append(np.full(spec.shape, i % 4096, np.uint16), i / 7, i, i)\n"
        "w.flush()\n"
        "for i in range(1500, 1600):\n"
        "    w.append(np.full(spec.shape, i % 4096, np.uint16), i / 7, i, i)\n"
        "os.kill(os.getpid(), 9)\n"
    )
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, timeout=120)
    assert result.returncode == -9, result.stderr
    with pytest.raises(OSError, match="already open for write"):
        h5py.File(path, "r")
    with h5py.File(path, "r", swmr=True) as h5:
        assert h5["frames"].shape[0] == h5["time"].shape[0] == 1500
        np.testing.assert_array_equal(h5["frames"][:, 0, 0], np.arange(1500) % 4096)
    back = ts.read_recording(path)
    assert len(back) == 1500 and not back.closed_cleanly


@pytest.mark.parametrize(
    "make, message",
    [
        (lambda p: p.mkdir(), "is a folder; expected a recording"),
        (lambda p: p.write_bytes(b""), "is empty \\(0 bytes\\)"),
    ],
    ids=["folder", "empty"],
)
def test_folder_and_empty_file_get_one_clean_line(tmp_path, make, message):
    path = tmp_path / "x.h5"
    make(path)
    with pytest.raises(RecordingError, match=message) as error:
        ts.read_recording(path)
    assert "\n" not in str(error.value) and "x.h5" in str(error.value)


def _info(path) -> str:
    from typer.testing import CliRunner

    from tactsense.cli import app

    result = CliRunner().invoke(app, ["info", str(path)], env={"COLUMNS": "400"})
    assert result.exit_code == 0, result.output
    return " ".join(result.output.split())


def test_info_calls_a_device_recordings_flaws_unknown(recording, tmp_path):
    _recorded(tmp_path / "d.h5", recording.sensor)
    assert "flaws │ unknown (a device)" in _info(tmp_path / "d.h5")
    ts.write_recording(tmp_path / "s.h5", recording)  # a simulation lists its own
    assert f"flaws │ {', '.join(recording.flaws)}" in _info(tmp_path / "s.h5")


def test_info_streams_in_blocks(recording, tmp_path, monkeypatch):
    """info never reads the whole recording, and its figures over many small blocks are
    those of the whole array (NaN frames in different blocks, extremes in others)."""
    import dataclasses

    from tactsense.cli import model
    from tactsense.io import recording as module

    frames = recording.frames.astype(float)
    frames[[3, 10, 11, 30]] = np.nan
    frames[20, 2, 2], frames[25, 5, 5] = -7.5, 9999.25
    path = ts.write_recording(tmp_path / "f.h5", dataclasses.replace(recording, frames=frames))

    def whole(*_):
        raise AssertionError("info read the whole recording")

    monkeypatch.setattr(model, "read_recording", whole, raising=False)
    monkeypatch.setattr(module.RecordingReader, "chunk_frames", property(lambda self: 7))
    finite = frames[np.isfinite(frames)]
    text = _info(path)
    assert f"counts │ {finite.min():g} .. {finite.max():g} (4 frames hold NaN" in text
    assert f"frames │ {len(frames)} x 8 x 8" in text


@pytest.mark.parametrize("value", ["abc", "0", "-3", "nan"])
def test_a_bad_check_timeout_is_one_line(recording, tmp_path, monkeypatch, value):
    path = ts.write_recording(tmp_path / "r.h5", recording)
    monkeypatch.setenv("TACTSENSE_CHECK_TIMEOUT_S", value)
    with pytest.raises(RecordingError, match=r"TACTSENSE_CHECK_TIMEOUT_S=.*expected a positive"):
        ts.read_recording(path)
