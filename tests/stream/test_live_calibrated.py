"""``live --calibration`` on a finger runs the compiled per-frame path
(RealTimeLocator.from_deflection) and gives what batch ``locate`` gives with the same
calibration, frame for frame."""

import time

import numpy as np

import tactsense as ts
from tactsense.estimate.finger import calibrate as cal
from tactsense.stream import LiveLocator
from tactsense.stream.reader import StreamFrame


def test_live_calibrated_equals_batch_locate():
    spec = ts.fearing1990_initial()
    sweep = ts.simulate(spec, ts.calibration_sweep(spec), rng=1)
    calibration = cal.calibrate_sweep(sweep.frames, spec)
    rec = ts.simulate(spec, ts.probe_sweep(spec), rng=2)
    batch = ts.locate(rec.frames, spec, calibration=calibration)
    live = LiveLocator(spec, calibration=calibration)
    rows = []
    for k, counts in enumerate(rec.frames):
        frame = StreamFrame(k, k, float(rec.time_s[k]), time.time(), time.perf_counter(), counts)
        rows.append(live(frame))
    for name in ("axial_mm", "angle_deg", "force_n", "skew", "peak_deflection"):
        got = np.array([r[name] for r in rows], dtype=float)
        np.testing.assert_allclose(got, getattr(batch, name), rtol=1e-9, atol=1e-12,
                                   equal_nan=True, err_msg=name)  # fmt: skip
    np.testing.assert_array_equal([r["flags"] for r in rows], batch.flags)
    assert np.isfinite([r["force_n"] for r in rows]).sum() > 50
