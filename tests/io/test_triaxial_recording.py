"""Recordings of three-axis taxels (issue 35, item 3): frames ``(T, rows, cols, 3)`` in
HDF5, written whole and streamed, the frames' ``axes`` attribute from the kind, files
written before read unchanged, and ``info`` on them."""

import dataclasses

import h5py
import numpy as np
import pytest
from typer.testing import CliRunner

import tactsense as ts
from tactsense.cli import app
from tactsense.io.recording import Recording, RecordingError, RecordingWriter, read_recording
from tactsense.kinds import kind_of
from tactsense.physics.transduction import sample_offsets
from tactsense.sensor import load_sensor

MAG = load_sensor("mag4x4")


def _recording(n: int = 40, seed: int = 0) -> Recording:
    rng = np.random.default_rng(seed)
    frames = (32768 + rng.integers(-4000, 4000, (n, *MAG.frame_shape))).astype(np.uint16)
    return Recording(frames, np.arange(n) * MAG.scan_period_s, sample_offsets(MAG), MAG)


def test_three_axis_frames_round_trip_with_their_axes(tmp_path):
    recording = _recording()
    path = ts.write_recording(tmp_path / "m.h5", recording)
    back = read_recording(path)
    assert back.frames.shape == (40, 4, 4, 3) and back.sensor == MAG
    np.testing.assert_array_equal(back.frames, recording.frames)
    with h5py.File(path) as h5:
        assert h5["frames"].attrs["axes"] == kind_of(MAG).frame_axes
        assert h5["frames"].attrs["axes"].endswith("component (x, y, z)")
        assert h5["frames"].chunks[1:] == (4, 4, 3)


def test_the_streaming_writer_takes_three_axis_frames(tmp_path):
    recording = _recording(25, seed=1)
    with RecordingWriter(tmp_path / "s.h5", MAG, sample_offsets(MAG), source="x") as writer:
        for k, frame in enumerate(recording.frames):
            writer.append(frame, k * MAG.scan_period_s, k, 1e9 + k, device_time_us=k * 10_000)
    back = read_recording(tmp_path / "s.h5")
    np.testing.assert_array_equal(back.frames, recording.frames)
    np.testing.assert_array_equal(back.device_time_us, np.arange(25) * 10_000)
    with h5py.File(tmp_path / "s.h5") as h5:
        assert h5["frames"].attrs["axes"] == kind_of(MAG).frame_axes


def test_the_streaming_writer_refuses_a_frame_without_its_components(tmp_path):
    with RecordingWriter(tmp_path / "s.h5", MAG, sample_offsets(MAG)) as writer:
        with pytest.raises(RecordingError, match=r"shape \(4, 4\) .* frames are \(4, 4, 3\)"):
            writer.append(np.zeros((4, 4), np.uint16), 0.0, 0, 0.0)


@pytest.mark.parametrize("preset", ["fearing1990_initial", "pad16"])
def test_scalar_recordings_keep_their_kinds_axes(tmp_path, preset):
    spec = load_sensor(preset)
    frames = np.zeros((3, *spec.shape), np.uint16)
    recording = Recording(frames, np.arange(3) * spec.scan_period_s, sample_offsets(spec), spec)
    path = ts.write_recording(tmp_path / "r.h5", recording)
    with h5py.File(path) as h5:
        assert h5["frames"].attrs["axes"] == kind_of(spec).frame_axes
        assert h5["frames"].shape == (3, *spec.shape)
    if preset == "fearing1990_initial":  # the finger's string, as written since round 1
        assert kind_of(spec).frame_axes == "time, row (along the finger, 0 = tip), col (around)"


def test_a_file_written_before_the_axes_followed_the_kind_reads_unchanged(tmp_path):
    """As earlier tactsense wrote any recording: the finger's axes string on every file,
    HDF5's default format, no checksums. The shape is read from the sensor, not the
    attribute."""
    recording = _recording(12, seed=2)
    path = tmp_path / "old.h5"
    with h5py.File(path, "w") as h5:
        h5.attrs["format"] = "tactsense-recording"
        h5.attrs["format_version"] = 2
        h5.attrs["sensor_toml"] = MAG.to_toml_string()
        h5.attrs["scenario_json"] = '{"description": "old"}'
        h5.attrs["flaws"] = ""
        frames = h5.create_dataset("frames", data=recording.frames)
        frames.attrs["axes"] = "time, row (along the finger, 0 = tip), col (around)"
        h5["time"] = recording.time_s
        h5["sample_offset"] = recording.sample_offset_s
    np.testing.assert_array_equal(read_recording(path).frames, recording.frames)


def test_frames_without_the_sensors_components_are_a_clear_error(tmp_path):
    path = tmp_path / "flat.h5"
    with h5py.File(path, "w") as h5:
        h5.attrs["format"] = "tactsense-recording"
        h5.attrs["format_version"] = 2
        h5.attrs["sensor_toml"] = MAG.to_toml_string()
        h5.attrs["scenario_json"] = "{}"
        h5.attrs["flaws"] = ""
        h5["frames"] = np.zeros((5, 4, 4), np.uint16)
        h5["time"] = np.arange(5.0)
        h5["sample_offset"] = np.zeros((4, 4))
    with pytest.raises(RecordingError, match=r"expected \(T, 4, 4, 3\)"):
        read_recording(path)


def _info(path) -> str:
    result = CliRunner().invoke(app, ["info", str(path)], env={"COLUMNS": "400"})
    assert result.exit_code == 0, result.output
    return " ".join(result.output.split())


def test_info_shows_the_components_and_each_ones_range(tmp_path):
    recording = _recording(30, seed=3)
    frames = recording.frames.astype(float)
    frames[[4, 9], 1, 2, 0] = np.nan  # two frames with a NaN x component
    frames[7, 0, 0, 2] = 70_000.5  # a z reading outside the others
    path = ts.write_recording(tmp_path / "m.h5", dataclasses.replace(recording, frames=frames))
    text = _info(path)
    assert "frames │ 30 x 4 x 4 x 3 counts" in text
    assert "components │ 3 per taxel (x, y, z), the last axis" in text
    assert "(2 frames hold NaN or infinite readings)" in text
    # each component's range, against numpy over the component axis
    expected = ", ".join(
        f"{name} {np.nanmin(frames[..., k]):g} .. {np.nanmax(frames[..., k]):g}"
        for k, name in enumerate("xyz")
    )
    assert f"counts by component │ {expected}" in text
    assert "70000.5" in expected


def test_info_of_a_scalar_recording_has_no_component_rows(tmp_path):
    spec = load_sensor("pad16")
    frames = np.full((3, *spec.shape), 100, np.uint16)
    recording = Recording(frames, np.arange(3) * spec.scan_period_s, sample_offsets(spec), spec)
    text = _info(ts.write_recording(tmp_path / "p.h5", recording))
    assert "frames │ 3 x 16 x 16 counts" in text
    assert "components" not in text


def test_the_info_rows_in_docs_recordings_md_are_what_info_prints(tmp_path):
    import re
    from pathlib import Path

    text = (Path(__file__).resolve().parents[2] / "docs" / "recordings.md").read_text()
    block = re.search(r"<!-- info-triaxial -->\s*```text\n(.*?)```", text, re.S).group(1)
    printed = _info(ts.write_recording(tmp_path / "doc.h5", _recording()))
    for line in block.strip().splitlines():
        assert " ".join(line.split()) in printed, line
