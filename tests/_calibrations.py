"""Calibrations built by hand for tests that need one with a known creep model."""

import numpy as np

from tactsense.estimate.finger import calibrate as cal


def creep_calibration(spec, baseline, creep=(0.5, 0.05, 0.3, 10.0)) -> cal.Calibration:
    """Unit gains, nothing excluded, the given baseline and creep model
    (delayed fraction, its time constant [s], creep fraction, its time constant [s])."""
    return cal.Calibration(
        sensor_toml=spec.to_toml_string(),
        gains=np.ones(spec.shape),
        baseline=baseline,
        dead=np.zeros(spec.shape, bool),
        weak=np.zeros(spec.shape, bool),
        noisy=np.zeros(spec.shape, bool),
        threshold_g=np.ones(spec.shape),
        viscoelastic=cal.Viscoelastic(*creep),
    )
