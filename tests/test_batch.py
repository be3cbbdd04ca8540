"""Recordings in pieces (tactsense.batch): the same numbers as one call on the whole
recording, in every output format, with the creep state carried across pieces."""

import numpy as np
import pyarrow.csv as pa_csv
import pyarrow.parquet as pq
import pytest

import tactsense as ts
from tactsense._validation import TactsenseInputError
from tactsense.batch import EstimatesWriter, iter_locate, locate_file
from tactsense.estimate.finger import calibrate as cal
from tactsense.io.recording import RecordingReader
from tests._calibrations import creep_calibration

FIELDS = ["row", "col", "axial_mm", "angle_deg", "peak_deflection", "force_n", "skew"]


@pytest.fixture(scope="module")
def recording(tmp_path_factory):
    spec = ts.fearing1990_initial()
    path = tmp_path_factory.mktemp("batch") / "rec.h5"
    ts.write_recording(path, ts.simulate(spec, ts.repeated_load(spec, repeats=30), rng=4))
    return path, ts.read_recording(path)


@pytest.mark.parametrize("chunk", [1, 7, 1000, 100_000])
def test_pieces_give_the_whole_recordings_numbers(recording, chunk):
    path, rec = recording
    whole = ts.locate(rec.frames, rec.sensor, baseline=ts.baseline_from(rec.frames, 5))
    with RecordingReader(path) as reader:
        pieces = list(iter_locate(reader, chunk_frames=chunk))
    assert [start for start, _, _ in pieces] == list(range(0, len(rec.frames), chunk))
    for name in [*FIELDS, "flags", "iterations"]:
        joined = np.concatenate([getattr(e, name) for _, _, e in pieces])
        np.testing.assert_array_equal(joined, getattr(whole, name), err_msg=name)
    np.testing.assert_array_equal(np.concatenate([t for _, t, _ in pieces]), rec.time_s)


def test_creep_compensation_carries_across_pieces(recording, tmp_path):
    """The causal creep filter has memory: pieces must continue it, not restart it."""
    path, rec = recording
    spec = rec.sensor
    calibration = creep_calibration(spec, ts.baseline_from(rec.frames, 5))
    whole = ts.locate(rec.frames, spec, calibration=calibration, frame_period_s=spec.scan_period_s)
    with RecordingReader(path) as reader:
        pieces = list(iter_locate(reader, calibration=calibration, chunk_frames=50))
    joined = np.concatenate([e.force_n for _, _, e in pieces])
    np.testing.assert_allclose(joined, whole.force_n, rtol=1e-12, equal_nan=True)
    # and without the carried state the numbers would differ (the test can fail)
    restarted = np.concatenate(
        [
            ts.locate(
                rec.frames[k : k + 50],
                spec,
                calibration=calibration,
                frame_period_s=spec.scan_period_s,
            ).force_n
            for k in range(0, len(rec.frames), 50)
        ]
    )
    assert not np.allclose(restarted, whole.force_n, equal_nan=True)


@pytest.mark.parametrize("suffix", [".csv", ".parquet", ".h5"])
def test_every_format_reads_back_at_full_precision(recording, tmp_path, suffix):
    import h5py

    path, rec = recording
    whole = ts.locate(rec.frames, rec.sensor, baseline=ts.baseline_from(rec.frames, 5))
    out = tmp_path / f"est{suffix}"
    summary = locate_file(path, out, chunk_frames=64)
    assert summary["frames"] == len(rec.frames)
    assert summary["contacts"] == int(np.isfinite(whole.row).sum())
    if suffix == ".csv":
        table = pa_csv.read_csv(out)
        force, time_s = table["force_n"].to_numpy(), table["time_s"].to_numpy()
        np.testing.assert_array_equal(table["flags"].to_numpy(), whole.flags)
        flags = table["flag_names"].to_pylist()
        assert flags[0] == ts.estimate.Flag.describe(int(whole.flags[0]))
    elif suffix == ".parquet":
        table = pq.read_table(out)
        force, time_s = table["force_n"].to_numpy(), table["time_s"].to_numpy()
        np.testing.assert_array_equal(table["flags"].to_numpy(), whole.flags)
    else:
        with h5py.File(out) as h5:
            force, time_s = h5["force_n"][()], h5["time_s"][()]
            assert h5["force_n"].attrs["units"] == "N"
    np.testing.assert_array_equal(force, whole.force_n)  # bit for bit: full precision
    np.testing.assert_array_equal(time_s, rec.time_s)


def test_empty_recording_gives_an_empty_file(tmp_path):
    import dataclasses

    spec = ts.fearing1990_initial()
    rec = ts.simulate(spec, ts.repeated_load(spec, repeats=1), rng=0)
    empty = dataclasses.replace(rec, frames=rec.frames[:0], time_s=rec.time_s[:0], truth={})
    ts.write_recording(tmp_path / "e.h5", empty)
    with pytest.raises(TactsenseInputError, match="need 5 untouched"):
        locate_file(tmp_path / "e.h5", tmp_path / "e.parquet")


def test_unknown_extension_is_refused(tmp_path):
    with pytest.raises(TactsenseInputError, match=r"\.csv, \.parquet or \.h5"):
        EstimatesWriter(tmp_path / "x.txt")


def test_workers_give_the_same_numbers(recording):
    _, rec = recording
    frames = np.tile(rec.frames, (60, 1, 1))  # several blocks of the compiled passes
    base = ts.baseline_from(rec.frames, 5)
    one = ts.locate(frames, rec.sensor, baseline=base)
    two = ts.locate(frames, rec.sensor, baseline=base, workers=2)
    for name in [*FIELDS, "flags"]:
        np.testing.assert_array_equal(getattr(two, name), getattr(one, name), err_msg=name)


def test_calibration_from_pieces_equals_the_whole_sweep():
    spec = ts.fearing1990_initial()
    sweep = ts.simulate(spec, ts.calibration_sweep(spec, increment=1.2), rng=1)
    whole = cal.calibrate_sweep(sweep.frames, spec)
    # pieces of 3 frames: the 5 baseline frames span two pieces
    pieces = cal.calibrate_sweep(
        (sweep.frames[k : k + 3] for k in range(0, len(sweep.frames), 3)), spec
    )
    for name in ("gains", "baseline", "dead", "weak", "noisy", "threshold_g"):
        np.testing.assert_array_equal(getattr(pieces, name), getattr(whole, name), err_msg=name)


def test_creep_memories_carry_linearly():
    """Memories after a range = A^L (memories before) + (the range's own, from zero): the
    identity that lets split ranges start where the whole recording is."""
    from tactsense.estimate.creep import CreepCompensator

    model = cal.Viscoelastic(0.5, 0.05, 0.3, 10.0)
    y = np.random.default_rng(0).random((700, 2, 3))
    whole = CreepCompensator(model, 1 / 7, (2, 3))
    first = CreepCompensator(model, 1 / 7, (2, 3))
    second = CreepCompensator(model, 1 / 7, (2, 3))
    for k, frame in enumerate(y):
        whole(frame)
        (first if k < 300 else second)(frame)
    carried = second.carry(first.state, 400) + second.state
    np.testing.assert_allclose(carried, whole.state, rtol=1e-12, atol=1e-15)
    assert not np.allclose(second.state, whole.state)  # the carry matters
    # and a compensator started from the carried memories continues the whole one
    resumed = CreepCompensator(model, 1 / 7, (2, 3))
    resumed.state = first.state
    for frame in y[300:]:
        resumed(frame)
    np.testing.assert_allclose(resumed.state, whole.state, rtol=1e-12, atol=1e-15)
