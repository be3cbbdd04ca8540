"""An unquantized recording's fractional counts go out to CSV and come back: ``import``
refuses only values the converter's range cannot hold (the bad-input matrix checks those)."""

import numpy as np
from typer.testing import CliRunner

import tactsense as ts
from tactsense import flat_scenarios as fs
from tactsense.cli import app
from tactsense.io.recording import read_recording


def test_fractional_counts_round_trip_through_csv(tmp_path):
    spec = ts.preset("mag4x4")
    recording = ts.simulate(spec, fs.press(spec), flaws="none", rng=0)
    assert recording.frames.dtype == np.float64
    assert not np.all(recording.frames == np.rint(recording.frames))  # fractions present
    source = tmp_path / "float.h5"
    ts.write_recording(source, recording)
    runner = CliRunner()
    out_csv, back = tmp_path / "float.csv", tmp_path / "back.h5"
    done = runner.invoke(app, ["export", str(source), "--format", "csv", "-o", str(out_csv)])
    assert done.exit_code == 0, done.output
    done = runner.invoke(app, ["import", str(out_csv), "--sensor", "mag4x4", "-o", str(back)])
    assert done.exit_code == 0, done.output
    # CSV keeps 17 significant digits: the frames come back to the last bit
    np.testing.assert_array_equal(read_recording(back).frames, recording.frames)
