"""The joint fit's model order and local minima, noise-free (issue 34 items 1-2;
r9-padjoint2): frames from the Hankel-transform layer solution (tests/_layer_truth.py,
not the estimator's table), quantized to one A/D count.

* A wide contact at 500 g is one contact: before round 9 the order selection split a
  flat disc 3 pitches across on pad16 into four contacts and a 10-mm sphere on pad12x32
  into six (the single fit stalled in a poor local minimum that four contacts fit
  exactly; the backward elimination only deleted contacts, never merged them).
* A pair 1.5 pitches apart on pad4 is placed within twice its two-contact bound: before
  round 9 three placements of twenty were placed 1.4-2.8 mm off against bounds of
  0.020-0.028 mm (one contact drawn to the pair's middle).
* A pair 2 pitches apart on pad4 is two contacts: before round 10 the pair's fit from
  the watershed's seeds stalled at 245 times the noise's chi-square (a local minimum)
  and the order selection let a third contact in, which three contacts fit to 1.7
  (16 taxels, 15 parameters); the pair is now polished before the order is judged."""

import numpy as np
import pytest

from tactsense.estimate.contacts import find_contacts
from tactsense.estimate.contacts._joint_lm import residual_jacobian, tables_of
from tactsense.kinds import kind_of
from tactsense.physics._pad_model import hertz_radius_mm
from tactsense.sensor.registry import load_sensor
from tests._layer_truth import hankel_hertz_strain


def _quantized(spec, strain):
    t = spec.transduction
    if t.kind == "capacitive":
        step = 1.0 / spec.electronics.nominal_counts
        return np.round(t.strain_gain * strain / step) * step
    return np.round(np.maximum(strain, 0.0) * t.counts_per_strain) / t.counts_per_strain


@pytest.mark.parametrize(
    ("name", "shape", "radius_mm", "x", "y"),
    [
        ("pad16", "disc", 3.75, 21.082130987318692, 20.850126411007373),
        ("pad12x32", "sphere", 10.0, 12.466357917259298, 32.374125130521115),
    ],
)
def test_wide_heavy_contact_is_one(name, shape, radius_mm, x, y):
    """The placements of docs/contacts.md's item-1 table (scripts/padfit_numbers.py,
    seed 34) that split: one contact, force within 2 % and position within 0.05 pitch
    (measured +0.02 % / +0.05 %)."""
    spec = load_sensor(name)
    load = 4.9
    strain = hankel_hertz_strain(spec, x, y, load, radius_mm=radius_mm, shape=shape)
    fit = find_contacts(_quantized(spec, strain), spec, counts=False, method="joint")
    assert len(fit) == 1
    assert abs(fit.force_n[0] / load - 1.0) < 0.02
    pitch = spec.grid.row_pitch_mm
    assert np.hypot(fit.x_mm[0] - x, fit.y_mm[0] - y) < 0.05 * pitch


def _pair_bound(spec, truth, load):
    """RMS position bound per contact [mm] of two 1.6-mm spheres at ``truth`` (2, 2)
    [mm] under quantization's variance (one A/D step squared over 12): the Fisher matrix
    of both positions and forces from the model's closed-form Jacobian."""
    model = kind_of(spec).contact_model(spec)
    t = spec.transduction
    per = spec.electronics.nominal_counts if t.kind == "capacitive" else t.counts_per_strain
    a = float(hertz_radius_mm(load, 1.6, model.modulus_star_pa))
    p = np.array([*truth[0], load, a, 0.0, *truth[1], load, a, 0.0])
    n = model.x_taxel.size * model.y_taxel.size
    r, jac = np.empty(n + 2), np.empty((n + 2, 10))
    residual_jacobian(
        p, np.zeros(n), model.x_taxel, model.y_taxel, tables_of(model), not model.capacitive,
        float(model.scale), np.zeros(4), r, jac,
    )  # fmt: skip
    j = jac[:n][:, [0, 1, 2, 5, 6, 7]]
    c = np.diag(np.linalg.inv(j.T @ j * 12.0 * per**2))
    return float(np.sqrt((c[0] + c[1] + c[3] + c[4]) / 2.0))


@pytest.mark.parametrize(
    ("sep", "angle_deg", "cx", "cy"),
    [
        (1.5, 0.0, 9.552423723734611, 12.183061754454004),
        (1.5, 0.0, 9.17814646931398, 12.38148980495049),
        (1.5, 90.0, 7.910164455725866, 9.851986470168454),
        (2.0, 0.0, 8.497879215274335, 8.2356348953169),
    ],
)
@pytest.mark.parametrize("truth_from", ["hankel", "model"])
def test_pad4_pair_near_the_bound(sep, angle_deg, cx, cy, truth_from):
    """Two 50-g 1.6-mm spheres ``sep`` pitches apart on pad4, at the placements of
    docs/contacts.md's pair table (scripts/padfit_pairs.py) that fell in a local
    minimum before round 9 (1.5 pitches: placed 1.4-2.8 mm off, 55-120x the two-contact
    bound) or round 10 (2 pitches: three contacts found): two contacts, RMS position
    error within 4x the bound, on the Hankel solution's frames and on the estimator's
    own model's (quantized: what the algorithm reaches without the table's error).
    Measured at 1.5 pitches: 0.73x / 2.7x / 0.62x (Hankel) and 3.1x / 0.58x / 0.59x
    (model); at 2 pitches 1.4x (Hankel). A bound on the RMS over placements, not on one:
    quantization is a fixed error per placement, not a fresh draw; over the table's
    twenty placements per separation the RMS ratio is in docs/contacts.md (goal 2x)."""
    spec = load_sensor("pad4")
    load = 0.49
    th = np.radians(angle_deg)
    half = 0.5 * sep * spec.grid.row_pitch_mm * np.array([np.cos(th), np.sin(th)])
    centre = np.array([cx, cy])
    truth = np.array([centre + half, centre - half])
    if truth_from == "hankel":
        strain = sum(hankel_hertz_strain(spec, x, y, load) for x, y in truth)
        frame = _quantized(spec, strain)
    else:
        model = kind_of(spec).contact_model(spec)
        a = float(hertz_radius_mm(load, 1.6, model.modulus_star_pa))
        signal = model.signal(truth, [load, load], [a, a], signed=True)
        step = 1.0 / spec.electronics.nominal_counts
        frame = np.round(signal / step) * step
    fit = find_contacts(frame, spec, counts=False, method="joint")
    assert len(fit) == 2
    est = np.column_stack([fit.x_mm, fit.y_mm])
    d = np.hypot(*(truth[:, None, :] - est[None, :, :]).transpose(2, 0, 1))
    err = min(np.hypot(d[0, 0], d[1, 1]), np.hypot(d[0, 1], d[1, 0])) / np.sqrt(2)
    assert err < 4.0 * _pair_bound(spec, truth, load), err
