"""`emulate` takes simulate's shear options (trial 8, defect 3; r8-fixc8)."""

import numpy as np
from typer.testing import CliRunner

from tactsense._validation import TactsenseInputError
from tactsense.cli import app
from tactsense.io.recording import read_recording

runner = CliRunner()
SHEAR = ["--sensor", "mag4x4", "--scenario", "shear", "--shear-ratio", "0.5",
         "--shear-angle-deg", "90", "--friction", "0.8", "--ramp-s", "0.2"]  # fmt: skip


def test_emulate_plays_the_shear_simulate_makes(tmp_path, monkeypatch):
    """The emulated device sends the frames `simulate` writes with the same options: a
    push along +y (90 deg) at Q/P 0.5, not the 0-deg, 0.3 default."""
    from tactsense.stream import Emulator

    played = {}

    def capture(source, **_):
        played["source"] = source
        raise TactsenseInputError("captured")  # stop before serving

    monkeypatch.setattr(Emulator, "from_recording", staticmethod(capture))
    result = runner.invoke(app, ["emulate", *SHEAR, "--port", "0"])
    assert "captured" in result.output, result.output
    out = tmp_path / "fixc8_shear.h5"
    assert runner.invoke(app, ["simulate", *SHEAR, "-o", str(out)]).exit_code == 0
    simulated, emulated = read_recording(out), played["source"]
    np.testing.assert_array_equal(emulated.frames, simulated.frames)
    shear_y = np.asarray(emulated.truth["step_shear_y_n"])
    shear_x = np.asarray(emulated.truth["step_shear_x_n"])
    force = np.asarray(emulated.truth["step_force_n"])
    held = shear_y.argmax()
    np.testing.assert_allclose(shear_y[held] / force[held], 0.5, rtol=1e-9)
    assert np.abs(shear_x).max() < 1e-9 * shear_y.max()


def test_emulate_checks_the_shear_options_as_simulate_does(tmp_path):
    """Both commands refuse the same bad values with the same message (one check)."""
    out = str(tmp_path / "fixc8_never.h5")
    for extra, names in (
        (["--shear-ratio", "0.9"], "shear_ratio 0.9 is at or above the friction 0.8"),
        (["--ramp-s", "0.001"], "--ramp-s 0.001 s is shorter than one scan period"),
    ):
        for tail in (["emulate", *SHEAR, *extra, "--port", "0"],
                     ["simulate", *SHEAR, *extra, "-o", out]):  # fmt: skip
            result = runner.invoke(app, tail)
            message = " ".join(result.output.split())
            assert result.exit_code == 2 and names in message, message
