"""Bad input to ``tactsense view`` for pads and point sets: exit status 2, one message
naming what was wrong, no traceback (the style of ``test_bad_input.py``)."""

import numpy as np
import pytest
from typer.testing import CliRunner

import tactsense as ts
from tactsense.cli import app
from tactsense.io.recording import Recording, write_recording

from .._calibrations import creep_calibration
from .test_bad_input import _check

runner = CliRunner()


@pytest.fixture(scope="module")
def workspace(tmp_path_factory):
    folder = tmp_path_factory.mktemp("padview")
    for name in ("pad16", "dome12"):
        spec = ts.preset(name)
        frames = np.full((10, *spec.shape), spec.electronics.nominal_counts, dtype=np.uint16)
        rec = Recording(
            frames=frames,
            time_s=np.arange(10) * spec.scan_period_s,
            sample_offset_s=np.zeros(spec.shape),
            sensor=spec,
        )
        write_recording(folder / f"{name}.h5", rec)
    finger = ts.fearing1990_initial()
    creep_calibration(finger, np.full(finger.shape, 2000.0)).save(folder / "finger_cal.json")
    return folder


BAD = [
    # (command line, what the message must say)
    (
        "view DIR/pad16.h5 --calibration DIR/finger_cal.json",
        "a finger's calibration does not apply to 'pad16', a pad",
    ),
    (
        "view DIR/dome12.h5 --calibration DIR/finger_cal.json",
        "does not apply to 'dome12', a point set",
    ),
    ("view DIR/pad16.h5 --sensor pad16", "--sensor applies to a device"),
]


@pytest.mark.parametrize("line, names", BAD, ids=[line for line, _ in BAD])
def test_view_refuses_bad_input_for_pads_and_point_sets(workspace, line, names):
    result = runner.invoke(app, line.replace("DIR", str(workspace)).split())
    _check(result, names)
