"""What round 10's new-user trial found in the joint fit (issue 34), each checked where
it failed: a pair recording read in chunks, standard errors from one taxel, a contact
under the noise, a point set given a pad's method, the units of the joint fit's
columns."""

import json

import h5py
import numpy as np
import pyarrow.parquet as pq
import pytest

from tactsense._validation import TactsenseInputError
from tactsense.estimate.contacts import find_contacts
from tactsense.estimate.contacts._joint import MODEL_ERROR, _drop_undetermined
from tactsense.estimate.contacts._joint_errors import _fisher_sd
from tactsense.estimate.output import ContactsWriter
from tactsense.estimate.reading import signal_noise_variance
from tactsense.io import read_recording
from tactsense.kinds import kind_of
from tactsense.physics._pad_model import hertz_radius_mm
from tactsense.sensor.registry import load_sensor


def _pair_frames(spec, n, sep_mm):
    """n identical pad frames [-] of two 50-g 1.6-mm spheres ``sep_mm`` apart across the
    pad's middle, from the estimator's own model, quantized to one A/D step."""
    model = kind_of(spec).contact_model(spec)
    a = float(hertz_radius_mm(0.49, 1.6, model.modulus_star_pa))
    c = 0.5 * spec.grid.rows * spec.grid.row_pitch_mm
    where = [[c - 0.5 * sep_mm, 8.7], [c + 0.5 * sep_mm, 8.7]]
    frame = model.signal(where, [0.49, 0.49], [a, a])
    step = 1.0 / spec.electronics.nominal_counts
    return np.repeat((np.round(frame / step) * step)[None], n, axis=0), np.array(where)


@pytest.fixture(scope="module")
def pair_recording(tmp_path_factory):
    """The trial's recording: pad4, the two-probes scenario 7.5 mm (1.5 pitches) apart,
    quantization the only flaw (the simulator's frames, not the estimator's model)."""
    from typer.testing import CliRunner

    from tactsense.cli import app

    path = tmp_path_factory.mktemp("pair") / "pair.h5"
    line = ["simulate", "--sensor", "pad4", "--scenario", "two-probes", "--dwell-s", "0.1",
            "--flaws", "quantization", "--separation-mm", "7.5", "--out", str(path)]  # fmt: skip
    result = CliRunner().invoke(app, line)
    assert result.exit_code == 0, result.output
    return read_recording(path)


def test_a_pair_recording_reads_the_same_in_chunks_and_alone(pair_recording):
    """Frames read together give what each frame gives alone: two contacts in each
    pressed frame. Before: the frames' pooled noise counted the second contact as noise
    (60 times the described) and every frame read one contact at the midpoint with 0.85
    N (the trial's `--chunk-frames` finding); now the noise is also judged from what
    changes between successive frames, and a contact held still does not."""
    rec = pair_recording
    base = rec.frames[:5].astype(float).mean(axis=0)
    pressed = find_contacts(rec.frames, rec.sensor, baseline=base, method="interpolate")
    frames = np.unique(pressed.frame)
    assert len(frames) >= 5  # the premise: a held pair
    together = find_contacts(rec.frames[frames], rec.sensor, baseline=base, method="joint")
    assert np.bincount(together.frame, minlength=len(frames)).tolist() == [2] * len(frames)
    for k in (0, len(frames) // 2):
        alone = find_contacts(rec.frames[frames[k]], rec.sensor, baseline=base, method="joint")
        mine = together.frame == k
        np.testing.assert_allclose(np.sort(together.force_n[mine]), np.sort(alone.force_n),
                                   rtol=1e-3)  # fmt: skip


def test_standard_errors_are_nan_where_one_taxel_reads():
    """pad12x32 (resistive, 2-mm layer): a light small contact centred on a taxel
    compresses that taxel alone; one reading (and the size's prior) cannot determine
    x, y and force: NaN. This clean frame is singular by the condition number as well
    (the test passes on round 9's rule too); the trial's frame (every flaw on) was near
    singular, cond < 1e14, and gave errors of 11 m: the rule now counts the readings
    first (``_joint_fisher.fisher_sd``), which this test holds to."""
    spec = load_sensor("pad12x32")
    model = kind_of(spec).contact_model(spec)
    x, y = float(model.x_taxel[5]), float(model.y_taxel[9])
    a = float(hertz_radius_mm(0.098, 1.0, model.modulus_star_pa))
    frame = model.signal([[x, y]], [0.098], [a])
    assert np.sum(frame > 0) == 1  # the premise: one taxel reads
    sigma = np.sqrt(signal_noise_variance(spec)) + MODEL_ERROR * float(frame.max())
    sd = _fisher_sd(model, frame, np.array([[x, y, 0.098, a, 0.0]]), sigma)
    assert np.all(np.isnan(sd))


def test_a_contact_under_the_noise_goes():
    """A real contact and a 0.1-mN one whose modelled signal is under the noise on every
    taxel (the trial's phantom at a hand's pad, where the taxels read 0): the second
    goes and the first keeps its force within 1e-6 N (it alone explains the frame)."""
    spec = load_sensor("pad16")
    model = kind_of(spec).contact_model(spec)
    a = float(hertz_radius_mm(0.98, 1.6, model.modulus_star_pa))
    frame = model.signal([[20.1, 20.3]], [0.98], [a])
    q = np.array([[20.1, 20.3, 0.98, a, 0.0], [36.0, 3.0, 1e-4, 0.08, 0.0]])
    sigma = np.sqrt(signal_noise_variance(spec)) + MODEL_ERROR * float(frame.max())
    kept, _, parents = _drop_undetermined(model, frame, q, 0.0, [0, 1], sigma)
    assert parents == [0]
    assert abs(kept[0, 2] - 0.98) < 1e-6


@pytest.mark.parametrize("method", ["fit", "joint"])
def test_a_point_set_refuses_a_pads_method(method):
    """The pads' methods need a grid and a layer's response: a point set says so in one
    line, as the finger does (it used to return positions at 0, 0 without a word)."""
    spec = load_sensor("dome12")
    with pytest.raises(TactsenseInputError, match=f"method '{method}' works on pads"):
        find_contacts(np.zeros(spec.shape), spec, counts=False, method=method)


@pytest.mark.parametrize("suffix", [".parquet", ".h5"])
def test_the_joint_fits_columns_carry_their_units(tmp_path, suffix):
    """Parquet's `units` metadata is JSON and names the joint fit's extras; HDF5's
    columns carry them: mm for positions, sizes and their errors, N for the force's,
    1 for the flat share."""
    spec = load_sensor("pad4")
    frames, _ = _pair_frames(spec, 2, 10.0)
    table = find_contacts(frames, spec, counts=False, method="joint")
    path = tmp_path / f"c{suffix}"
    writer = ContactsWriter(path)
    writer.write_contacts(0.01 * table.frame, table)
    writer.close()
    want = {"x_sd_mm": "mm", "y_sd_mm": "mm", "force_sd_n": "N",
            "contact_radius_mm": "mm", "flat_share": "1"}  # fmt: skip
    if suffix == ".parquet":
        units = json.loads(pq.read_schema(path).metadata[b"units"])
    else:
        units = {}

        def note(name, obj):  # visititems stops at a callback's first value: none here
            if isinstance(obj, h5py.Dataset):
                units[name.split("/")[-1]] = obj.attrs.get("units")

        with h5py.File(path) as f:
            f.visititems(note)
    assert {k: units.get(k) for k in want} == want
