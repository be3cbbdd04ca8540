"""The shared layer truth (tactsense.analysis.layer_truth) against independent
evaluations: the simulator's closed-form transfer functions (a different representation:
Papkovich-Neuber potentials in closed form, not Love's function solved numerically),
the Boussinesq/Love closed form on the half space, scipy quadrature of the load spectra,
and the FFT grid of the simulator on a pad."""

import numpy as np
import pytest
from scipy import integrate, special

from tactsense._validation import TactsenseInputError
from tactsense.analysis import layer_truth
from tactsense.physics.indenters import FlatPunch, SphereProbe
from tactsense.physics.layer import transfer_functions
from tactsense.physics.pad_response import pad_strain
from tactsense.sensor.registry import load_sensor


@pytest.mark.parametrize("nu", [0.0, 0.3, 0.45, 0.5])
@pytest.mark.parametrize("zf", [0.0, 0.4, 0.75, 1.0])
def test_love_solve_matches_the_closed_form_transfer(nu, zf):
    # two representations of one boundary-value problem; 1e-8 is the 4x4 solve's
    # rounding at the smallest kh (a nearly singular basis)
    h = 2e-3
    k = np.geomspace(1e-3, 300, 200) / h
    w, eps = layer_truth.love_transfer(k, zf * h, h, nu)
    tf = transfer_functions(k, zf * h, h, nu)
    assert np.allclose(w, tf["W_P"].real, rtol=1e-8, atol=1e-8 * h)
    assert np.allclose(eps, tf["dW_P"].real, rtol=1e-8, atol=1e-10)


@pytest.mark.parametrize("nu", [0.3, 0.5])
def test_half_space_disc_matches_boussinesq_love(nu):
    # eps_zz on the axis under a uniform disc (Timoshenko & Goodier, section 138)
    E, a, p = 2.5e5, 1e-3, 2e3
    for z in (0.25 * a, a, 2 * a):
        R = np.hypot(a, z)
        s_zz = -p * (1 - z**3 / R**3)
        s_rr = -p / 2 * ((1 + 2 * nu) - 2 * (1 + nu) * z / R + z**3 / R**3)
        expected = (s_zz - 2 * nu * s_rr) / E
        _, eps = layer_truth.disc_field(0.0, z, np.inf, nu, a, p, E)
        assert eps == pytest.approx(expected, rel=2e-4)


@pytest.mark.parametrize("shape", ["sphere", "disc", "punch"])
def test_spectra_match_quadrature_of_the_profiles(shape):
    a, force = 1.3e-3, 0.7
    profiles = {
        "sphere": lambda r: 3 * force / (2 * np.pi * a**2) * np.sqrt(1 - (r / a) ** 2),
        "disc": lambda r: force / (np.pi * a**2),
        "punch": lambda r: force / (2 * np.pi * a * np.sqrt(a**2 - r**2)),
    }
    for q in (1e-4, 0.5, 2.0, 7.3):
        k = q / a
        ref = integrate.quad(
            lambda r, k=k: profiles[shape](r) * special.j0(k * r) * 2 * np.pi * r, 0, a, limit=200
        )[0]
        assert layer_truth.pressure_spectrum(q, force, shape) == pytest.approx(ref, rel=1e-6)


@pytest.mark.parametrize("name", ["pad4", "pad16", "pad12x32"])
def test_pad_truth_agrees_with_the_fft_grid(name):
    # two independent solutions of one pad; the FFT grid's step (0.5 mm against a Hertz
    # disc of about 1.2 mm, a punch's 1/sqrt edge cell-averaged) limits the agreement:
    # measured 0.6 / 1.4 / 1.8 % of the peak for the sphere on pad4 / pad16 / pad12x32,
    # 0.4 / 2.1 / 3.9 % for the punch; bounds just above the worst of each
    spec = load_sensor(name)
    x, y = 1.37 * spec.grid.row_pitch_mm, 2.21 * spec.grid.col_pitch_mm
    for probe, shape, radius in (
        (SphereProbe(x, y, 0.49, radius_mm=1.6), "sphere", 1.6),
        (FlatPunch(x, y, 0.49, radius_mm=2.0), "punch", 2.0),
    ):
        fft = pad_strain(spec, [probe])
        truth = layer_truth.taxel_strain(spec, x, y, 0.49, radius, shape=shape)
        bound = 0.02 if shape == "sphere" else 0.045
        assert np.max(np.abs(fft - truth)) < bound * np.max(np.abs(truth)), shape


def test_superposition_and_a_changed_layer():
    spec = load_sensor("pad16")
    one = layer_truth.taxel_strain(spec, 10.0, 12.0, 0.3)
    two = layer_truth.taxel_strain(spec, 20.0, 12.0, 0.3)
    both = layer_truth.taxel_strain(spec, [10.0, 20.0], [12.0, 12.0], 0.3)
    assert np.allclose(both, one + two, atol=1e-12)
    thick = layer_truth.TrueLayer(2.3, 1.725, 2.5e5, 0.5)
    other = layer_truth.taxel_strain(spec, 10.0, 12.0, 0.3, layer=thick)
    assert not np.allclose(other, one, rtol=0.01)


def test_bad_shape_is_a_one_line_error():
    with pytest.raises(TactsenseInputError, match="shape"):
        layer_truth.taxel_strain(load_sensor("pad4"), 1.0, 1.0, 0.5, shape="cube")
    with pytest.raises(TactsenseInputError, match="k > 0"):
        layer_truth.love_transfer([0.0], 0.0, 1e-3, 0.3)
