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
