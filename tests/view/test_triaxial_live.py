"""``live`` on a three-axis pad (issue 35 item 5): the estimator its frames get, and the
shear and slip of every contact in its JSON lines and CSV rows.

The device is stood in for by a reader that yields the frames of a simulated recording
(``mag4x4``, a sphere pressed at the pad's centre, then pushed tangentially along +y):
the wire's three-component frames are another part's (``docs/protocol.md``); what is
tested here is what ``live`` does with them.
"""

import csv
import io
import json
import math
import threading

import numpy as np
import pytest

from tactsense.cli._live_outputs import (
    LIVE_CONTACT_COLUMNS,
    SHEAR_COLUMNS,
    LiveFormat,
    write_estimates,
)
from tactsense.cli._live_sources import _locator_for
from tactsense.physics.indenters import SphereProbe
from tactsense.sensor import preset
from tactsense.simulate import Scenario, Step, simulate
from tactsense.stream.reader import StreamFrame


class _Stats:
    def summary(self, used=None):
        return ""


class _Reader:
    """What ``write_estimates`` asks of a device: its sensor and its frames."""

    def __init__(self, rec):
        self.sensor, self.rec, self.stats = rec.sensor, rec, _Stats()

    def frames(self, max_frames=None, duration_s=None):
        for k, counts in enumerate(self.rec.frames):
            t = float(self.rec.time_s[k])
            yield StreamFrame(k, k, t, t, 0.0, counts)


@pytest.fixture(scope="module")
def pushed():
    spec = preset("mag4x4")
    probe = SphereProbe(7.05, 7.05, force_n=0.5, radius_mm=5.0)
    sheared = SphereProbe(7.05, 7.05, force_n=0.5, radius_mm=5.0, shear_y_n=0.15,
                          friction=1.0)  # fmt: skip
    scenario = Scenario((Step((), 0.1), Step((probe,), 0.1), Step((sheared,), 0.2)))
    return simulate(spec, scenario, rng=0, flaws=())


def _run(rec, output_format):
    spec = rec.sensor
    locator = _locator_for(spec, None, 5, None, keep_deflection=False,
                           contact_options={"max_contacts": 8})  # fmt: skip
    out = io.StringIO()
    write_estimates(
        out, _Reader(rec), locator, output_format=output_format, multi=True, frames=None,
        duration=None, rezero=threading.Event(), outlets=None, latencies=[], used=[0],
    )  # fmt: skip
    return out.getvalue()


def test_live_jsonl_gives_each_contacts_shear_and_direction(pushed):
    lines = [json.loads(line) for line in _run(pushed, LiveFormat.jsonl).splitlines()]
    assert len(lines) == len(pushed.frames) - 5  # the first five: the baseline
    last = lines[-1]
    assert last["n_contacts"] >= 1
    contact = max(last["contacts"], key=lambda c: c["force_n"])
    # pushed along +y: the estimated direction is within the goal (5 deg) of 90
    assert contact["shear_n"] > 0
    assert abs(contact["shear_angle_deg"] - 90.0) < 5.0
    assert contact["slip_state"] in ("stick", "partial", "gross")


def test_live_csv_has_the_shear_columns(pushed):
    rows = list(csv.DictReader(io.StringIO(_run(pushed, LiveFormat.csv))))
    assert tuple(rows[0]) == (*LIVE_CONTACT_COLUMNS, *SHEAR_COLUMNS)
    touched = [r for r in rows if r["n_contacts"] != "0"]
    assert touched
    last = touched[-1]
    x, y = float(last["shear_x_n"]), float(last["shear_y_n"])
    assert math.isclose(float(last["shear_n"]), math.hypot(x, y), rel_tol=1e-6)
    assert last["slip_state"] in ("stick", "partial", "gross")
    assert np.isfinite(float(last["shear_angle_deg"]))


@pytest.mark.parametrize(
    "threshold, options, said",
    # (--threshold is taken, as locate takes it: tests/estimate/test_triaxial_fixb8.py)
    [(None, {"method": "joint"}, "--method 'joint' applies to scalar pads")],
)  # fmt: skip
def test_live_refuses_a_scalar_pads_options_on_a_three_axis_pad(threshold, options, said):
    from tactsense._validation import TactsenseInputError

    with pytest.raises(TactsenseInputError, match=said) as error:
        _locator_for(preset("mag4x4"), None, 5, threshold, keep_deflection=False,
                     contact_options=options)  # fmt: skip
    assert "\n" not in str(error.value)


def test_live_jsonl_is_strict_json(pushed):
    # no NaN token anywhere, the contacts' fields included (a stick ratio not yet known)
    def refuse(token):
        raise AssertionError(f"{token} in live's JSON")

    for line in _run(pushed, LiveFormat.jsonl).splitlines():
        json.loads(line, parse_constant=refuse)
