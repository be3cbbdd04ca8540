"""Round 4 (issue 32, item 1), devices as they come: a rest reading of 0, readings that
fall under load, taxels that give nothing, and presses that find no contact.

Bad descriptions are refused with one line naming the key (exit status 2 on the CLI);
faults in a recording are found from its readings and said on stderr; a recording with
presses is never a silent ``0 contact rows``. The end-to-end case goes through the
CLI as a lab would: a TOML, frames as CSV, ``import``, ``locate``.
"""

import dataclasses
import re

import numpy as np
import pytest
from typer.testing import CliRunner

import tactsense as ts
from tactsense import flat_scenarios as fs
from tactsense.cli import app
from tactsense.estimate.contacts import signal_from_counts
from tactsense.sensor.common import SensorSpecError
from tactsense.sensor.registry import load_sensor, sensor_from_dict

runner = CliRunner()


def _said(result) -> str:
    return " ".join(result.output.split())


BAD_DESCRIPTIONS = [
    ('extends = "dome12"\n[transduction]\npolarity = "Falling"\n', "polarity = 'Falling'"),
    ('extends = "dome12"\n[transduction]\npolarity = "down"\n', "expected 'rising'"),
    ('extends = "pad16"\n[transduction]\npolarity = 1\n', "polarity = 1: expected a string"),
    ('extends = "pad16"\n[electronics]\nnominal_counts = -1\n', "must be 0 or more; got -1.0"),
    (
        'extends = "pad16"\n[electronics]\nnominal_counts = 4096\n',
        "does not fit in a 12-bit converter (0 to 4095)",
    ),
    (
        'extends = "pad16"\n[electronics]\nadc_bits = 8\nnominal_counts = 256\n',
        "does not fit in a 8-bit converter (0 to 255)",
    ),
    ('extends = "pad16"\n[electronics]\nnominal_counts = nan\n', "must be 0 or more"),
    ('extends = "dome12"\n[electronics]\nnominal_counts = 0\n', "capacitive chain's reading"),
    (
        'extends = "pad16"\n[transduction]\npolarity = "falling"\n[electronics]\n'
        "nominal_counts = 0\n",
        "a reading that rests at 0 cannot fall",
    ),
]


@pytest.mark.parametrize("text, names", BAD_DESCRIPTIONS, ids=[n for _, n in BAD_DESCRIPTIONS])
def test_a_bad_description_is_refused_naming_the_key(tmp_path, text, names):
    path = tmp_path / "bad.toml"
    path.write_text(text, encoding="utf-8")
    with pytest.raises(SensorSpecError, match=re.escape(names)):
        load_sensor(path)
    result = runner.invoke(app, ["sensor", "check", str(path)])
    assert result.exit_code == 2, result.output
    assert "Traceback" not in result.output and names in _said(result)


GOOD_DESCRIPTIONS = [
    ('extends = "pad16"\n[electronics]\nnominal_counts = 0\n', "0 counts of 4095", "rising"),
    (
        'extends = "dome12"\n[transduction]\npolarity = "falling"\n[electronics]\n'
        "adc_bits = 8\nnominal_counts = 245\n",
        "245 counts of 255",
        "falling",
    ),
    (
        'extends = "pad16"\n[transduction]\npolarity = "falling"\n[electronics]\n'
        "nominal_counts = 4000\n",
        "4000 counts of 4095",
        "falling",
    ),
]


@pytest.mark.parametrize("text, rest, polarity", GOOD_DESCRIPTIONS)
def test_a_zero_rest_or_falling_description_is_valid_and_round_trips(
    tmp_path, text, rest, polarity
):
    path = tmp_path / "good.toml"
    path.write_text(text, encoding="utf-8")
    spec = load_sensor(path)
    assert spec.transduction.polarity == polarity
    again = tmp_path / "again.toml"
    result = runner.invoke(app, ["sensor", "show", "--sensor", str(path), "--out", str(again)])
    assert result.exit_code == 0, result.output
    assert load_sensor(again) == spec  # TOML written and read back: the same sensor
    result = runner.invoke(app, ["sensor", "check", str(again)])
    assert result.exit_code == 0, result.output
    assert rest in _said(result) and f"reading {polarity} under load" in _said(result)


def test_a_description_written_before_polarity_existed_still_reads_as_rising():
    data = load_sensor("pad16").to_dict()
    del data["transduction"]["polarity"]  # a complete description of round 3
    spec = sensor_from_dict(data)
    assert spec == load_sensor("pad16")


def test_a_baseline_of_zeros_is_valid_for_a_resistive_pad():
    pad = load_sensor("pad16").replace(electronics__nominal_counts=0.0)
    frames = np.zeros((2, *pad.shape))
    frames[1, 7, 7] = 50.0
    signal, flags = signal_from_counts(frames, np.zeros(pad.shape), pad)
    assert flags.tolist() == [0, 0]  # not DEAD_TACTEL: 0 is the rest, not a fault
    assert signal[1, 7, 7] == pytest.approx(50.0 / pad.transduction.counts_per_strain)


@pytest.fixture(scope="module")
def zero_pad(tmp_path_factory):
    """A zero-at-rest 12-bit resistive pad (pad16 reading 0 untouched) and a press."""
    folder = tmp_path_factory.mktemp("round4_devices")
    toml = folder / "zero16.toml"
    toml.write_text(
        'extends = "pad16"\nname = "zero16"\ndescription = "FSR-like 16x16, 0 at rest"\n'
        '[transduction]\nkind = "resistive"\n[electronics]\nnominal_counts = 0\n',
        encoding="utf-8",
    )
    spec = load_sensor(toml)
    recording = ts.simulate(spec, fs.press(spec, x_mm=18.1, y_mm=20.7, repeats=2), rng=0)
    return folder, toml, spec, recording


def _locate(path, out, *extra):
    return runner.invoke(app, ["locate", str(path), "--out", str(out), "-q", *extra])


def test_end_to_end_a_zero_at_rest_pad_from_csv(zero_pad):
    """TOML -> CSV frames -> import -> locate: both presses found, no warning."""
    folder, toml, spec, recording = zero_pad
    frames = recording.frames.reshape(len(recording.frames), -1).astype(int)
    assert frames.min() == 0  # the untouched taxels really read 0
    csv = folder / "frames.csv"
    names = [f"r{r}c{c}" for r in range(spec.shape[0]) for c in range(spec.shape[1])]
    rows = [",".join(["time", *names])]
    rows += [
        f"{t:.6f}," + ",".join(map(str, f)) for t, f in zip(recording.time_s, frames, strict=True)
    ]
    csv.write_text("\n".join(rows) + "\n", encoding="utf-8")
    rec = folder / "imported.h5"
    result = runner.invoke(app, ["import", str(csv), "--sensor", str(toml), "--out", str(rec)])
    assert result.exit_code == 0, result.output
    out = folder / "contacts.csv"
    result = _locate(rec, out)
    assert result.exit_code == 0, result.output
    said = _said(result)
    # the one warning pad16 at rest 100 gives too (main, the same press: 75 frames
    # BELOW_BASELINE after the lifts, the release re-zero of an import without creep)
    assert said.count("warning") == said.count("frames read below the baseline"), said
    import pandas as pd

    table = pd.read_csv(out)
    births = table[table["event"] == "birth"]
    assert len(births) == 2  # two presses, one id each
    assert (table["x_mm"] - 18.1).abs().max() < 1.0 and (table["y_mm"] - 20.7).abs().max() < 1.0


def test_a_falling_sensor_described_as_rising_is_warned(tmp_path):
    dome = load_sensor("dome12")
    falling = dome.replace(
        name="fingertip", transduction__polarity="falling", electronics__nominal_counts=245.0,
        electronics__adc_bits=8,
    )  # fmt: skip
    recording = ts.simulate(falling, fs.press(falling, x_mm=0.0, y_mm=0.0, at_taxel=5), rng=0)
    wrong = dataclasses.replace(recording, sensor=falling.replace(transduction__polarity="rising"))
    for name, rec in (("right", recording), ("wrong", wrong)):
        ts.write_recording(tmp_path / f"{name}.h5", rec)
    for drift in ("2", "0"):  # following drift, the lift reads as a contact; fixed, none
        result = _locate(tmp_path / "wrong.h5", tmp_path / f"w{drift}.csv", "--drift-s", drift)
        assert result.exit_code == 0, result.output
        said = _said(result)
        assert "fell below the baseline" in said and "set polarity = 'falling'" in said, said
    result = _locate(tmp_path / "right.h5", tmp_path / "r.csv")
    assert result.exit_code == 0 and "polarity" not in _said(result), result.output


def test_presses_under_a_threshold_too_high_are_warned(zero_pad, tmp_path):
    _, _, _, recording = zero_pad
    path = tmp_path / "zero.h5"
    ts.write_recording(path, recording)
    result = _locate(path, tmp_path / "out.csv", "--threshold", "0.9")
    assert result.exit_code == 0, result.output
    said = _said(result)
    assert "0 contact rows" in said
    assert "warning: no contact found, yet the readings moved" in said, said
    assert "lower --threshold" in said


def test_an_untouched_recording_gets_no_warning(tmp_path):
    pad = load_sensor("pad16").replace(electronics__nominal_counts=0.0)
    recording = ts.simulate(pad, fs.press(pad, force_n=1e-9, dwell_s=0.3), rng=0)
    path = tmp_path / "still.h5"
    ts.write_recording(path, recording)
    result = _locate(path, tmp_path / "out.csv")
    assert result.exit_code == 0 and "warning" not in _said(result), result.output


def test_dead_stuck_and_unreadable_taxels_are_found_and_named(zero_pad, tmp_path):
    recording = zero_pad[3]
    frames = recording.frames.astype(float)
    frames[:, 2, 3] = 17.0  # dead: one value throughout, while the others carry noise
    frames[:, 5, 5] = 4095.0  # stuck at full scale: it can read no load
    frames[:, 9, 1] = np.nan  # no reading at all
    faulty = dataclasses.replace(recording, frames=frames)
    path = tmp_path / "faulty.h5"
    ts.write_recording(path, faulty)
    out = tmp_path / "out.csv"
    result = _locate(path, out)
    assert result.exit_code == 0, result.output
    said = _said(result)
    assert re.search(r"never changed over the recording .*: \(2, 3\)", said), said
    assert re.search(r"stuck \(every reading at full scale \(4095\).*: \(5, 5\)", said), said
    assert "no finite reading (ignored, flag DEAD_TACTEL): (9, 1)" in said
    import pandas as pd

    table = pd.read_csv(out)
    assert len(table) > 0 and table["flag_names"].str.contains("DEAD_TACTEL").all()
    assert not table["flag_names"].str.contains("SATURATED").any()  # the stuck one left out


def test_the_examples_in_docs_sensors_md_are_valid_and_print_what_it_says(tmp_path):
    """docs/sensors.md's two descriptions load, and ``sensor check`` prints the lines the
    doc quotes for the first."""
    from pathlib import Path

    doc = (Path(__file__).parents[2] / "docs" / "sensors.md").read_text(encoding="utf-8")
    blocks = re.findall(r"```toml\n(.*?)```", doc, re.S)
    ours = [b for b in blocks if 'name = "zero16"' in b or 'name = "fingertip"' in b]
    assert len(ours) == 2
    for k, text in enumerate(ours):
        path = tmp_path / f"example{k}.toml"
        path.write_text(text, encoding="utf-8")
        result = runner.invoke(app, ["sensor", "check", str(path)])
        assert result.exit_code == 0, result.output
        rows = dict(load_sensor(path).summary())
        if "zero16" in text:
            flat = " ".join(doc.split())
            assert f"`transduction: {rows['transduction']}`" in flat
            assert f"`rest reading: {rows['rest reading']}`" in flat
        else:
            assert rows["transduction"] == "capacitive, reading falling under load"


def test_the_finger_s_per_frame_locate_warns_of_presses_it_does_not_find(tmp_path):
    finger = ts.fearing1990_initial()
    path = tmp_path / "finger.h5"
    ts.write_recording(path, ts.simulate(finger, ts.probe_sweep(finger), rng=0))
    result = _locate(path, tmp_path / "est.csv", "--threshold", "0.9")
    assert result.exit_code == 0, result.output
    said = _said(result)
    assert "0 with a contact" in said
    assert "warning: no contact found, yet the readings moved" in said, said
    result = _locate(path, tmp_path / "est2.csv")  # found: nothing to say
    assert result.exit_code == 0 and "warning" not in _said(result), result.output
