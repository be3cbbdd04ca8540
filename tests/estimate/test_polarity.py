"""Devices as they come (issue 32, item 1): a resistive pad that reads 0 at rest and a
capacitive point set whose readings fall under load, simulated by the twin and located
by ``locate``'s pipeline (:class:`tactsense.batch.iter_contacts`).

Round trips, with their tolerances:

* the zero-at-rest pad (pad16 with ``nominal_counts = 0``) against pad16 itself (rest
  100): the rest reading only offsets the counts, so the same press gives the same
  contacts; the one difference is the read noise below 0, clipped at a rest of 0 (0.3
  counts against a threshold of 10). Positions within 0.01 mm, forces within 0.5 %
  (measured: 6e-5 mm and 3e-5 relative). Against the truth, every loaded frame has
  exactly one contact within 1 mm (0.4 pitch) of the press: the twin's default flaws
  (gain spread 35 %, position jitter) put pad16's own estimate up to 0.56 mm (x) and
  0.61 mm (y) off here;
* the falling point set (dome12 reading ``2 V_o - V``) against the rising dome12: the
  falling signal is the exact inverse of the falling chain, so only the noise, which is
  not mirrored, differs: positions within 0.05 mm and the median force within 1 %
  (measured: 0 mm, 0.1 %);
* the same point set as an iCub-like 8-bit fingertip resting at 245: a contact in every
  loaded frame, the median distance to the pressed taxel under 0.5 mm (measured 0.11)
  and the median force within 5 % of the 12-bit rising one (measured 2 %): its 8-bit
  quantization (1 count of 245, against 1 of 2000) moves the peak between neighbours.
"""

import numpy as np
import pytest

import tactsense as ts
from tactsense import flat_scenarios as fs
from tactsense.batch import iter_contacts
from tactsense.estimate.contacts import default_threshold, signal_from_counts
from tactsense.estimate.finger.deflection import Flag
from tactsense.io.recording import RecordingReader
from tactsense.physics.transduction import deflection_to_counts
from tactsense.sensor.registry import load_sensor


def _contacts(folder, spec, scenario):
    path = folder / f"{spec.name}.h5"
    ts.write_recording(path, ts.simulate(spec, scenario, rng=0))
    with RecordingReader(path) as reader:
        pieces = list(iter_contacts(reader))
    tables = [table for _, _, _, table, _ in pieces]
    columns = ("frame", "x_mm", "y_mm", "z_mm", "force_n")
    return {c: np.concatenate([getattr(t, c) for t in tables]) for c in columns}


def test_a_zero_at_rest_pad_locates_as_the_same_pad_at_rest_100(tmp_path):
    pad = load_sensor("pad16")
    zero = pad.replace(electronics__nominal_counts=0.0, name="zero16")
    x, y = 18.1, 20.7
    found = {}
    for spec in (pad, zero):
        found[spec.name] = _contacts(tmp_path, spec, fs.press(spec, x_mm=x, y_mm=y))
    a, b = found["pad16"], found["zero16"]
    loaded = np.arange(20, 70)  # settle 0.2 s, then 0.5 s pressed, at 100 Hz
    for table in (a, b):
        inside = np.isin(table["frame"], loaded)
        assert np.array_equal(np.sort(table["frame"][inside]), loaded)  # one each
        assert np.abs(table["x_mm"][inside] - x).max() < 1.0
        assert np.abs(table["y_mm"][inside] - y).max() < 1.0
    assert np.array_equal(a["frame"], b["frame"])
    assert np.abs(a["x_mm"] - b["x_mm"]).max() < 0.01
    assert np.abs(a["y_mm"] - b["y_mm"]).max() < 0.01
    assert np.allclose(a["force_n"], b["force_n"], rtol=0.005)


@pytest.fixture(scope="module")
def domes(tmp_path_factory):
    folder = tmp_path_factory.mktemp("domes")
    dome = load_sensor("dome12")
    out = {}
    for name, polarity, nominal, bits in (
        ("rising", "rising", 2000.0, 12),
        ("falling", "falling", 2000.0, 12),
        ("icub_like", "falling", 245.0, 8),
    ):
        spec = dome.replace(
            name=name,
            transduction__polarity=polarity,
            electronics__nominal_counts=nominal,
            electronics__adc_bits=bits,
        )
        scenario = fs.press(spec, x_mm=0.0, y_mm=0.0, at_taxel=5)
        out[name] = (spec, _contacts(folder, spec, scenario))
    return out


LOADED = np.arange(10, 35)
"""Frames under load in :func:`fs.press` at 50 Hz: settle 0.2 s, press 0.5 s."""


def _loaded(table):
    inside = np.isin(table["frame"], LOADED)
    return {key: value[inside] for key, value in table.items()}


def test_a_falling_point_set_locates_as_the_rising_one(domes):
    _, rising = domes["rising"]
    _, falling = domes["falling"]
    a, b = _loaded(rising), _loaded(falling)
    assert np.array_equal(a["frame"], LOADED) and np.array_equal(b["frame"], LOADED)
    for key in ("x_mm", "y_mm", "z_mm"):
        assert np.abs(a[key] - b[key]).max() < 0.05
    assert abs(np.median(b["force_n"]) / np.median(a["force_n"]) - 1.0) < 0.01


def test_an_8_bit_falling_fingertip_resting_at_245_finds_its_press(domes):
    spec, table = domes["icub_like"]
    _, rising = domes["rising"]
    b = _loaded(table)
    assert np.array_equal(b["frame"], LOADED)
    taxel = spec.taxel_positions_mm()[5]
    distance = np.sqrt((b["x_mm"] - taxel[0]) ** 2 + (b["y_mm"] - taxel[1]) ** 2
                       + (b["z_mm"] - taxel[2]) ** 2)  # fmt: skip
    assert np.median(distance) < 0.5
    force = np.median(_loaded(rising)["force_n"])
    assert abs(np.median(b["force_n"]) / force - 1.0) < 0.05


@pytest.mark.parametrize("deflection", [0.0, 0.01, 0.1, 0.3])
def test_the_falling_signal_inverts_the_falling_chain(deflection):
    """The twin's falling chain (eqs. 1-2, mirrored) read back by the estimator gives the
    deflection it was made from (unquantized: to rounding)."""
    spec = load_sensor("dome12").replace(transduction__polarity="falling")
    counts = deflection_to_counts(spec, np.full(spec.shape, deflection), quantize=False)
    assert np.all(counts <= spec.electronics.nominal_counts)
    rest = np.full(spec.shape, spec.electronics.nominal_counts)
    signal, flags = signal_from_counts(counts, rest, spec)
    rising = load_sensor("dome12")
    expected, _ = signal_from_counts(
        deflection_to_counts(rising, np.full(spec.shape, deflection), quantize=False), rest, rising
    )
    assert np.allclose(signal, expected, atol=1e-12) and flags[0] == 0


def test_saturation_is_the_rail_the_reading_moves_toward():
    pad = load_sensor("pad16")
    falling = pad.replace(transduction__polarity="falling", electronics__nominal_counts=3000.0)
    frames = np.full((2, *pad.shape), 3000.0)
    frames[1, 4, 4] = 0.0  # a falling cell pressed to the bottom of the converter
    _, flags = signal_from_counts(frames, frames[0], falling)
    assert flags[1] & Flag.SATURATED and not flags[0] & Flag.SATURATED
    frames[1, 4, 4] = 4095.0  # the top: a falling reading moving the wrong way
    _, flags = signal_from_counts(frames, frames[0], falling)
    assert not flags[1] & Flag.SATURATED


def test_the_default_threshold_is_in_counts_whatever_the_rest_and_the_bits():
    pad = load_sensor("pad16")
    per_count = 1.0 / pad.transduction.counts_per_strain
    assert default_threshold(pad.replace(electronics__nominal_counts=0.0)) == pytest.approx(
        10 * per_count
    )
    eight = pad.replace(electronics__adc_bits=8, electronics__nominal_counts=0.0)
    assert default_threshold(eight) == pytest.approx(3 * per_count)  # 10: 3.9 % of 8 bits
    icub = load_sensor("dome12").replace(
        transduction__polarity="falling", electronics__nominal_counts=245.0,
        electronics__adc_bits=8,
    )  # fmt: skip
    assert default_threshold(icub) == pytest.approx(3 / 248)  # 3 counts from 245
    for name in ("pad4", "dome12", "initial"):  # the presets keep 0.005
        assert default_threshold(load_sensor(name)) == 0.005


def test_a_baseline_of_zeros_on_a_capacitive_pad_is_an_open_junction():
    pad = load_sensor("pad4")
    frames = np.full((1, *pad.shape), 2000.0)
    baseline = np.full(pad.shape, 2000.0)
    baseline[1, 1] = 0.0
    signal, flags = signal_from_counts(frames, baseline, pad)
    assert flags[0] & Flag.DEAD_TACTEL and signal[0, 1, 1] == 0.0
