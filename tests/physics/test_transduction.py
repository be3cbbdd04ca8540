import numpy as np
import pytest

from tactsense.physics import transduction as tr
from tactsense.sensor import VACUUM_PERMITTIVITY


def test_eq2_parallel_plate(initial):
    d0, area = 0.5e-3, 2.5e-3 * 5.1e-3
    for delta in (0.0, 0.05, 0.3):
        want = 4 * VACUUM_PERMITTIVITY * area / (d0 - delta * d0)
        assert tr.junction_capacitance(initial, delta) == pytest.approx(want, rel=1e-12)
    with pytest.raises(ValueError, match="plates would touch"):
        tr.junction_capacitance(initial, 1.0)


def test_eq1_approximation_holds_for_the_preset(initial):
    # C_L >> C_S and w R_L C_L >> 1: |V_S| ~ (C_S / C_L) V_d, low by C_S / C_L ~ 0.9 %
    c = initial.junction_capacitance_f
    approx = c / 100e-12 * 10.0
    assert tr.divider_voltage(initial, c) == pytest.approx(approx, rel=1.2e-2)


def test_nominal_reading_is_2000_counts(initial):
    assert tr.deflection_to_counts(initial, 0.0) == 2000


@pytest.mark.parametrize("delta", [0.001, 0.06, 0.2])
def test_eq4_recovers_the_deflection(initial, delta):
    v = tr.deflection_to_voltage(initial, delta)
    v0 = tr.deflection_to_voltage(initial, 0.0)
    # eq. 4 is exact for C_S << C_L; the preset's C_S/C_L ~ 1 % leaves a relative error ~1 %
    assert tr.fractional_deflection(v, v0) == pytest.approx(delta, rel=0.02)


def test_seven_bits_for_six_percent(initial):
    # section 3: 6 % deflection at V_o = 2000 units gives seven bits of signal
    change = tr.deflection_to_counts(initial, 0.06, quantize=False) - 2000
    # eq. 4, (V_S - V_o) / V_S = 0.06, solved by hand: V_S = V_o / 0.94, 127.7 units; the
    # preset's C_S / C_L of about 1 % (the test above) moves it by at most 2 %
    assert change == pytest.approx(2000 * 0.06 / 0.94, rel=0.02)


def test_quantization_and_saturation(initial):
    ideal = tr.deflection_to_counts(initial, 0.0123, quantize=False)
    assert tr.deflection_to_counts(initial, 0.0123) == np.rint(ideal)
    assert tr.voltage_to_counts(initial, 100.0) == 4095
    assert tr.voltage_to_counts(initial, -1.0) == 0


def test_dead_reading_gives_nan_not_a_number(initial):
    assert np.isnan(tr.fractional_deflection(0.0, 2000.0))


def test_scan_instants(initial):
    offsets = tr.sample_offsets(initial)
    assert offsets.shape == (8, 8)
    assert offsets[0, 0] == 0 and offsets.max() < initial.scan_period_s
    assert np.unique(offsets).size == 64
    assert offsets[0, 1] > offsets[0, 0] and offsets[1, 0] > offsets[0, 7]
