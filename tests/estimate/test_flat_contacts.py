"""Flat and large contacts are one contact: a square stamp, a punch and a cylinder
through the twin with 20 % gain spread and 2 % of full scale noise, found and tracked
as one; two probes stay two; the area column through every writer."""

import dataclasses

import h5py
import numpy as np
import pandas as pd
import pytest

from tactsense.estimate.contacts import find_contacts
from tactsense.estimate.contacts.track import ContactTracker
from tactsense.estimate.output import ContactsWriter
from tactsense.physics.indenters import CylinderProbe, SphereProbe, SquareStamp
from tactsense.sensor.registry import load_sensor
from tactsense.simulate import Scenario, Step, simulate

FLAWS = ("gain_spread", "jitter", "noise", "quantization", "nonlinearity")


def _noisy(name: str, seed: int = 0):
    """The preset with 20 % gain spread and read noise of 2 % of its full scale."""
    spec = load_sensor(name)
    full_scale = 2**spec.electronics.adc_bits - 1
    flaws = dataclasses.replace(
        spec.flaws, gain_spread_sd=0.2, read_noise_counts=0.02 * full_scale, gain_seed=seed
    )
    return dataclasses.replace(spec, flaws=flaws)


def _presses(spec, tools, rng_seed=1):
    steps = [Step((), 0.2, "baseline")]
    for tool in tools:
        steps += [Step((tool,), 0.3, "press"), Step((), 0.2, "lifted")]
    rec = simulate(spec, Scenario(tuple(steps)), flaws=FLAWS, rng=rng_seed)
    step = rec.truth["frame_step"]
    press = np.where(step % 2 == 1, (step - 1) // 2, -1)
    baseline = rec.frames[step == 0].mean(axis=0)
    return rec.frames, press, baseline


@pytest.mark.parametrize("seed", [0, 1])
def test_a_square_stamp_is_one_contact_with_one_id(seed):
    """A rigid 7.5-mm (3-pitch) square stamp of 6 N on pad16, turned 0, 30 and 60 deg:
    the layer reads its rim (its corners highest); every pressed frame holds exactly one
    contact, each press one id, its centre within 1.75 mm (0.7 pitch) of the stamp's:
    the rim is sampled by a 2.5-mm grid, whose taxels a stamp placed off the grid's
    symmetry reads unevenly (up to half a pitch), and the gains move it some more.
    With the saddle rule alone (ring 0) the same frames are two contacts or more."""
    spec = _noisy("pad16", seed)
    centres = [(18.0, 19.5), (19.5, 18.0), (18.75, 18.75)]
    tools = [SquareStamp(x, y, 6.0, side_mm=7.5, angle_deg=a)
             for (x, y), a in zip(centres, (0.0, 30.0, 60.0), strict=True)]  # fmt: skip
    frames, press, baseline = _presses(spec, tools)
    table = find_contacts(frames, spec, baseline=baseline)
    tracked, _ = ContactTracker(spec.scan_period_s).update(table)
    counts = table.per_frame_counts()
    assert np.all(counts[press >= 0] == 1)
    for k, (x, y) in enumerate(centres):
        rows = np.isin(tracked.frame, np.flatnonzero(press == k))
        assert len(np.unique(tracked.id[rows])) == 1
        assert np.all(np.hypot(tracked.x_mm[rows] - x, tracked.y_mm[rows] - y) < 1.75)
    before = find_contacts(frames, spec, baseline=baseline, ring=0.0).per_frame_counts()
    assert np.mean(before[press >= 0] == 1) < 0.5


def test_a_rectangular_stamp_reports_its_orientation_and_area():
    """A 12.5 x 5 mm stamp at 30 deg on pad16 (noise and gains as above): one contact,
    its major axis at 30 deg within 10 deg (the rim's second moments on a 2.5-mm grid;
    the gains tilt it by a few degrees), longer than across; its area the count of its
    taxels times 6.25 mm^2."""
    spec = _noisy("pad16", 2)
    tool = SquareStamp(18.75, 18.75, 8.0, side_mm=12.5, width_mm=5.0, angle_deg=30.0)
    frames, press, baseline = _presses(spec, [tool])
    table = find_contacts(frames[press == 0], spec, baseline=baseline)
    assert np.all(table.per_frame_counts() == 1)
    angle = np.median(table.orientation_deg)
    assert abs(angle - 30.0) < 10.0
    assert np.all(table.major_mm > table.minor_mm)
    np.testing.assert_array_equal(table.area_mm2, table.taxels * 2.5 * 2.5)


def test_a_cylinder_across_the_pad_is_one_contact():
    """A 5-mm-radius cylinder 15 mm (6 pitches) long on pad16 with 5 N along x: the layer
    reads its two ends highest; one contact in at least 98 % of the pressed frames (the
    goal of issue 32), elongated along x (orientation within 15 deg of 0)."""
    spec = _noisy("pad16", 0)
    tools = [CylinderProbe(18.75, 18.75 + dy, 5.0, length_mm=15.0) for dy in (-1.0, 0.0, 1.2)]
    frames, press, baseline = _presses(spec, tools)
    table = find_contacts(frames, spec, baseline=baseline)
    counts = table.per_frame_counts()
    assert np.mean(counts[press >= 0] == 1) >= 0.98
    pressed = np.isin(table.frame, np.flatnonzero(press >= 0))
    assert np.median(np.abs(table.orientation_deg[pressed])) < 15.0


@pytest.mark.parametrize("apart_pitch", [2.0, 3.0])
def test_two_probes_stay_two_under_the_same_noise(apart_pitch):
    """Two 1.6-mm spheres of 2 N each (a peak about half the A/D range, like the stamps)
    2 and 3 pitches apart on the noisy pad16, the pair centred on a taxel: two contacts
    in every pressed frame (the ridge groups need three maxima or a hole, and two probes
    make two maxima and no hole)."""
    spec = _noisy("pad16", 1)
    d = apart_pitch * 2.5 / 2
    pair = (SphereProbe(17.5, 17.5 - d, 2.0), SphereProbe(17.5, 17.5 + d, 2.0))
    steps = (Step((), 0.2, "baseline"), Step(pair, 0.3, "press"))
    rec = simulate(spec, Scenario(steps), flaws=FLAWS, rng=3)
    pressed = rec.truth["frame_step"] == 1
    baseline = rec.frames[~pressed].mean(axis=0)
    counts = find_contacts(rec.frames[pressed], spec, baseline=baseline).per_frame_counts()
    assert np.all(counts == 2)


def test_the_default_threshold_follows_the_described_noise():
    """With 82 counts of read noise (2 % of 12 bits) the old 10-count threshold finds
    contacts in untouched frames; the default (5 sigma of the noise) does not (the chance
    of a taxel above 5 sigma is 3e-7: none in 256 x 100 readings)."""
    spec = _noisy("pad16", 0)
    rec = simulate(spec, Scenario((Step((), 1.0, "untouched"),)), flaws=FLAWS, rng=5)
    baseline = rec.frames.mean(axis=0)
    assert len(find_contacts(rec.frames, spec, baseline=baseline)) == 0
    old = find_contacts(rec.frames, spec, baseline=baseline, threshold=10 / 20000)
    assert len(old) > 100


@pytest.mark.parametrize("suffix", [".csv", ".parquet", ".h5"])
def test_area_goes_through_every_writer(tmp_path, suffix):
    """``area_mm2`` in the long table as written, read back with each format's reader,
    equal to the table's (the same column in CSV, Parquet and HDF5)."""
    spec = load_sensor("pad16")
    frame = np.zeros(spec.shape)
    frame[4:7, 4:7] = 0.01
    frame[11, 11] = 0.02
    table = find_contacts(frame[None], spec, counts=False)
    tracked, events = ContactTracker(spec.scan_period_s).update(table)
    path = tmp_path / f"c{suffix}"
    with ContactsWriter(path) as writer:
        writer.write_contacts(np.zeros(len(tracked)), tracked, events)
    if suffix == ".csv":
        read = pd.read_csv(path)["area_mm2"].to_numpy()
    elif suffix == ".parquet":
        read = pd.read_parquet(path)["area_mm2"].to_numpy()
    else:
        with h5py.File(path) as f:
            group = next(iter(f.values())) if "area_mm2" not in f else f
            read = np.asarray(group["area_mm2"])
    np.testing.assert_allclose(read, tracked.area_mm2)
    assert sorted(read) == [6.25, 9 * 6.25]


def test_a_point_set_has_no_area():
    spec = load_sensor("dome12")
    signal = np.zeros((1, *spec.shape))
    signal[0, 0, 0] = 0.02
    table = find_contacts(signal, spec, counts=False)
    assert len(table) == 1 and np.isnan(table.area_mm2[0])
