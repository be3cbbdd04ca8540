"""Round 4 (issue 32, item 3), flat and large contacts: bad input for the new indenters,
the new ``ring`` option and ``--angle-deg`` on a press; and the user's report (a
3 x 3-taxel square stamp, 8 presses) from ``simulate`` to contacts and ids.

Each case failed before the change: the indenters and ``ring`` did not exist (an
``unknown indenter`` error, a ``TypeError``), ``--angle-deg`` did not apply to a press,
and the stamp was two contacts or more in most frames with several ids a press.
"""

import math

import numpy as np
import pytest
from typer.testing import CliRunner

import tactsense as ts
from tactsense._validation import TactsenseInputError
from tactsense.cli import app
from tactsense.estimate.contacts import find_contacts
from tactsense.estimate.contacts.track import ContactTracker
from tactsense.flat_scenarios import make_indenter, press
from tactsense.physics.indenters import CylinderProbe, SquareStamp
from tactsense.sensor.registry import load_sensor

runner = CliRunner()


@pytest.mark.parametrize("ring", [-0.1, 1.0, 2, math.nan, True, "0.1", None])
def test_ring_out_of_range_is_refused(ring):
    spec = load_sensor("pad16")
    with pytest.raises(TactsenseInputError, match=r"ring must be in \[0, 1\)"):
        find_contacts(np.zeros((1, *spec.shape)), spec, counts=False, ring=ring)


@pytest.mark.parametrize(
    "make, message",
    [
        (lambda: SquareStamp(0, 0, 1.0, side_mm=-2.0), "side_mm must be a positive number"),
        (lambda: SquareStamp(0, 0, 1.0, width_mm=0.0), "width_mm must be a positive number"),
        (lambda: SquareStamp(0, 0, 1.0, angle_deg=math.nan), "angle_deg must be a finite"),
        (lambda: SquareStamp(0, 0, -1.0), "force_n must be >= 0"),
        (lambda: CylinderProbe(0, 0, 1.0, length_mm=math.inf), "length_mm must be a positive"),
        (lambda: CylinderProbe(0, 0, 1.0, radius_mm=0.0), "radius_mm must be a positive"),
        (lambda: CylinderProbe(math.nan, 0, 1.0), "x_mm must be a finite number"),
        (lambda: make_indenter("sphere", 0, 0, 1.0, 1.6, angle_deg=30.0), "a sphere has no axis"),
        (lambda: make_indenter("punch", 0, 0, 1.0, 3.0, angle_deg=-5.0), "a punch has no axis"),
        (lambda: press(load_sensor("pad16"), indenter="square", size_mm=0.0),
         "side_mm must be a positive number"),
        (lambda: press(load_sensor("pad16"), indenter="cylinder", angle_deg=math.inf),
         "angle_deg must be a finite"),
    ],
)  # fmt: skip
def test_bad_flat_indenters_are_refused(make, message):
    with pytest.raises(TactsenseInputError, match=message):
        make()


@pytest.mark.parametrize(
    "line, message",
    [
        ("--indenter sphere --angle-deg 30", "a sphere has no axis"),
        ("--indenter disc --angle-deg 10", "a disc has no axis"),
        ("--indenter square --size-mm 0", "--size-mm"),
        ("--indenter cylinder --angle-deg 400", "--angle-deg"),
        ("--indenter square --scenario two-probes", "--indenter does not apply"),
    ],
)
def test_bad_press_options_exit_2_with_one_line(tmp_path, line, message):
    out = tmp_path / "x.h5"
    result = runner.invoke(app, ["simulate", "--sensor", "pad16", *line.split(), "--out", str(out)])
    assert result.exit_code == 2, result.output
    assert message in " ".join(result.output.split())
    assert "Traceback" not in result.output
    assert not out.exists()


def _noisy_pad(tmp_path):
    """The user's array as a description: pad16 with 20 % gain spread and 82 counts (2 %
    of 12 bits) of read noise."""
    path = tmp_path / "noisy16.toml"
    path.write_text(
        'kind = "pad"\nextends = "pad16"\nname = "noisy16"\n\n[flaws]\n'
        "gain_spread_sd = 0.2\nread_noise_counts = 82.0\ncreep_known = true\n",
        encoding="utf-8",
    )
    return path


def test_a_square_stamp_pressed_eight_times_is_eight_contacts_with_eight_ids(tmp_path):
    """The report: a flat square stamp covering about 3 x 3 taxels (7.5 mm on pad16's
    2.5-mm pitch), pressed 8 times, came out as two contacts in 22 % of its frames and
    19 ids. Simulated through the CLI from the array's description (every flaw of the
    twin), found against the untouched frames' median and tracked: one contact in every
    pressed frame, and 8 ids, one a press. (``locate`` takes the same frames through its
    creep compensation and lift re-zero, which are not yet noise-aware, see
    docs/contacts.md.)"""
    sensor = _noisy_pad(tmp_path)
    rec = tmp_path / "stamp.h5"
    made = runner.invoke(
        app,
        ["simulate", "--sensor", str(sensor), "--indenter", "square", "--size-mm", "7.5",
         "--force-g", "600", "--angle-deg", "20", "--repeats", "8", "--dwell-s", "0.4",
         "--lift-s", "0.6", "--seed", "4", "--out", str(rec)],
    )  # fmt: skip
    assert made.exit_code == 0, made.output
    recording = ts.read_recording(rec)
    step = recording.truth["frame_step"]
    baseline = np.median(recording.frames[step == 0].astype(float), axis=0)
    table = find_contacts(recording.frames, recording.sensor, baseline=baseline)
    tracked, _ = ContactTracker(recording.sensor.scan_period_s).update(table)
    pressed = np.flatnonzero(step % 2 == 1)
    assert np.all(table.per_frame_counts()[pressed] == 1)
    ids = [np.unique(tracked.id[np.isin(tracked.frame, np.flatnonzero(step == 2 * k + 1))])
           for k in range(8)]  # fmt: skip
    assert [len(i) for i in ids] == [1] * 8
    assert len(np.unique(np.concatenate(ids))) == 8
