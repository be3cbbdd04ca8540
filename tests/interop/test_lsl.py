"""The Lab Streaming Layer: tactsense's outlets read by pylsl's own inlet, and tactsense's
inlet recording an outlet, in one process (pylsl's wheel bundles liblsl)."""

import threading
import time
import uuid

import numpy as np
import pytest
from typer.testing import CliRunner

import tactsense as ts
from tactsense.cli import app
from tactsense.interop.lsl import CONTACT_CHANNELS, LslOutlets, LslReader, _pylsl
from tactsense.stream import LiveLocator
from tactsense.stream.reader import StreamError, StreamFrame

runner = CliRunner()


@pytest.fixture(scope="module")
def sweep(initial):
    return ts.simulate(initial, ts.probe_sweep(initial, along="axial", dwell_s=0.3), rng=9)


def _frames(rec):
    for k, counts in enumerate(rec.frames):
        yield StreamFrame(k, k, float(rec.time_s[k]), time.time(), time.perf_counter(), counts)


def _unique_sensor(rec):
    """The sensor under a name of its own: outlets of other tests never answer."""
    import dataclasses

    return dataclasses.replace(rec.sensor, name=f"lsltest{uuid.uuid4().hex[:8]}")


def test_outlets_are_read_by_pylsl_frame_by_frame(sweep):
    pylsl = _pylsl()
    sensor = _unique_sensor(sweep)
    identity = {"serial": f"twin-{uuid.uuid4().hex[:6]}", "device": "tactsense twin"}
    outlets = LslOutlets(sensor, identity, 7.0)
    try:
        (found,) = pylsl.resolve_byprop("source_id", f"tactsense:{identity['serial']}:frames", 1, 5)
        (found_c,) = pylsl.resolve_byprop(
            "source_id", f"tactsense:{identity['serial']}:contacts", 1, 5
        )
        inlet = pylsl.StreamInlet(found)
        inlet_c = pylsl.StreamInlet(found_c)
        info = inlet.info(timeout=5)
        assert info.name() == f"{sensor.name}-frames" and info.type() == "Tactile"
        assert info.channel_count() == 64 and info.nominal_srate() == 7.0
        channel = info.desc().child("channels").child("channel")
        labels = []
        while not channel.empty():
            labels.append(
                (channel.child_value("label"), int(channel.child_value("row")),
                 int(channel.child_value("col")), float(channel.child_value("axial_mm")),
                 float(channel.child_value("angle_deg")))
            )  # fmt: skip
            channel = channel.next_sibling()
        assert len(labels) == 64
        assert labels[13] == ("r1c5", 1, 5, pytest.approx(sensor.row_axial_mm[1], abs=1e-5),
                              pytest.approx(sensor.col_angle_deg[5]))  # fmt: skip
        toml = info.desc().child("tactsense").child_value("sensor_toml")
        assert ts.SensorSpec.from_toml_string(toml) == sensor
        contact_labels = []
        ch = inlet_c.info(timeout=5).desc().child("channels").child("channel")
        while not ch.empty():
            contact_labels.append(ch.child_value("label"))
            ch = ch.next_sibling()
        assert tuple(contact_labels) == CONTACT_CHANNELS
        inlet.open_stream(timeout=5)
        inlet_c.open_stream(timeout=5)
        time.sleep(0.3)
        locator = LiveLocator(sensor, baseline=ts.baseline_from(sweep.frames, 5))
        estimates = []
        for frame in _frames(sweep):
            estimate = locator(frame)
            estimates.append(estimate)
            outlets.push(frame, estimate)
        got, got_c = [], []
        deadline = time.time() + 10
        while (len(got) < len(sweep) or len(got_c) < len(sweep)) and time.time() < deadline:
            samples, _ = inlet.pull_chunk(timeout=0.2)
            got.extend(samples)
            samples, _ = inlet_c.pull_chunk(timeout=0.2)
            got_c.extend(samples)
        assert len(got) == len(sweep)
        np.testing.assert_array_equal(np.asarray(got).reshape(-1, 8, 8), sweep.frames)
        assert len(got_c) == len(sweep)
        expected = np.array([[e[name] for name in CONTACT_CHANNELS] for e in estimates], float)
        np.testing.assert_allclose(np.asarray(got_c), expected, rtol=1e-12, equal_nan=True)
    finally:
        outlets.close()


def test_record_from_an_lsl_outlet(tmp_path, sweep):
    sensor = _unique_sensor(sweep)
    outlets = LslOutlets(sensor, {"serial": uuid.uuid4().hex[:6]}, 70.0)
    stop = threading.Event()

    def push():
        time.sleep(1.0)  # the recorder resolves and opens the inlet first
        for frame in _frames(sweep):
            if stop.is_set():
                return
            outlets.push(frame, None)
            time.sleep(1 / 200)

    pusher = threading.Thread(target=push, daemon=True)
    pusher.start()
    out = tmp_path / "from_lsl.h5"
    try:
        result = runner.invoke(
            app,
            ["record", f"lsl:{sensor.name}-frames", "--frames", str(len(sweep)),
             "--out", str(out), "--duration", "30"],
        )  # fmt: skip
    finally:
        stop.set()
        pusher.join(5)
        outlets.close()
    assert result.exit_code == 0, result.output
    rec = ts.read_recording(out)
    assert rec.sensor.name == sensor.name  # from the outlet's own description
    np.testing.assert_array_equal(rec.frames, sweep.frames)
    assert rec.source == f"lsl:{sensor.name}-frames"


def test_no_such_outlet_is_a_clear_error():
    with pytest.raises(StreamError, match="no Lab Streaming Layer outlet named"):
        LslReader(f"nothing-{uuid.uuid4().hex}", timeout_s=0.5)


@pytest.mark.parametrize("kind", ["initial", "pad4", "dome12"])
def test_stream_metadata_follows_the_xdf_meta_data_conventions(kind):
    """channels/channel/{label,unit,type,location/X,Y,Z [mm]}, acquisition/{manufacturer,
    model}, a type on the contacts stream and its channels: read back through pylsl's XML
    (StreamInfo.as_xml, the text LabRecorder writes into an XDF stream header)."""
    import xml.etree.ElementTree as ET

    from tactsense.interop.lsl import contacts_info, frames_info

    sensor = ts.preset(kind)
    identity = {"serial": "s-1", "device": "tactsense twin", "manufacturer": "lab"}
    root = ET.fromstring(frames_info(sensor, identity, 7.0).as_xml())
    assert root.findtext("type") == "Tactile"
    assert root.findtext("desc/acquisition/manufacturer") == "lab"
    assert root.findtext("desc/acquisition/model") == "tactsense twin"
    channels = root.findall("desc/channels/channel")
    assert len(channels) == sensor.n_taxels
    positions = np.array(
        [[float(ch.findtext(f"location/{axis}")) for axis in "XYZ"] for ch in channels]
    )
    # the sensor's taxel positions in frame order, to the 6 significant digits written
    np.testing.assert_allclose(positions, sensor.taxel_positions_mm(), rtol=1e-5, atol=1e-9)
    for ch in channels:
        assert ch.findtext("unit") == "counts" and ch.findtext("type") == "Tactile"
        assert ch.findtext("label") == f"r{ch.findtext('row')}c{ch.findtext('col')}"
    # tactsense's own reader still finds the sensor
    assert root.findtext("desc/tactsense/sensor_toml")

    contacts = ET.fromstring(contacts_info(sensor, identity, 7.0).as_xml())
    assert contacts.findtext("type") == "TactileContact"
    assert contacts.findtext("desc/acquisition/model") == "tactsense twin"
    rows = [(c.findtext("label"), c.findtext("unit"), c.findtext("type"))
            for c in contacts.findall("desc/channels/channel")]  # fmt: skip
    # the finger's one contact; a pad's or point set's fixed slots of tracked contacts
    from tactsense.interop.lsl import SLOT_CHANNELS, SLOTS

    expected = CONTACT_CHANNELS if sensor.kind == "finger" else SLOT_CHANNELS
    assert [r[0] for r in rows] == list(expected)
    assert all(unit and kind for _, unit, kind in rows)
    assert dict((r[0], r[1]) for r in rows)["force_n"] == "N"
    if sensor.kind != "finger":
        units = dict((r[0], r[1]) for r in rows)
        assert units[f"c{SLOTS - 1}_y_mm"] == "mm" and units["c0_force_n"] == "N"
        assert contacts.findtext("desc/tactsense/slots") == str(SLOTS)


def test_a_pad_contacts_outlet_carries_the_slots():
    """A pad's tracked contacts on pylsl's own inlet: per frame the count, total force,
    flags and latency, then each contact's id, position and force in its slot, NaN in the
    slots left over."""
    from tactsense import flat_scenarios as fs
    from tactsense.interop.lsl import SLOT_CHANNELS, SLOTS
    from tactsense.stream.live import LiveContacts

    pylsl = _pylsl()
    pad = ts.preset("pad16")
    rec = ts.simulate(pad, fs.two_probes(pad), rng=0)
    sensor = _unique_sensor(rec)
    identity = {"serial": f"pad-{uuid.uuid4().hex[:6]}"}
    outlets = LslOutlets(sensor, identity, 100.0)
    try:
        (found,) = pylsl.resolve_byprop(
            "source_id", f"tactsense:{identity['serial']}:contacts", 1, 5
        )
        inlet = pylsl.StreamInlet(found)
        inlet.open_stream(timeout=5)
        time.sleep(0.3)
        locator = LiveContacts(sensor)
        estimates = []
        for frame in _frames(rec):
            estimate = locator(frame)
            outlets.push(frame, estimate)
            if estimate is not None:
                estimates.append(estimate)
        got = []
        deadline = time.time() + 10
        while len(got) < len(estimates) and time.time() < deadline:
            samples, _ = inlet.pull_chunk(timeout=0.2)
            got.extend(samples)
        got = np.asarray(got)
        assert got.shape == (len(estimates), len(SLOT_CHANNELS))
        column = {name: k for k, name in enumerate(SLOT_CHANNELS)}
        for sample, estimate in zip(got, estimates, strict=True):
            assert sample[column["n_contacts"]] == estimate["n_contacts"]
            for k in range(SLOTS):
                if k < estimate["n_contacts"]:
                    c = estimate["contacts"][k]
                    assert sample[column[f"c{k}_id"]] == c["id"]
                    assert sample[column[f"c{k}_y_mm"]] == pytest.approx(c["y_mm"])
                else:
                    assert np.isnan(sample[column[f"c{k}_id"]])
        assert got[:, column["n_contacts"]].max() == 2
    finally:
        outlets.close()
