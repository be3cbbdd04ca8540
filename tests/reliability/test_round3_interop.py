"""Issue 31 (round three), interop: nothing lost between tactsense and the lab's other
tools. Each case failed before its fix."""

from collections import defaultdict

import pandas as pd
import pytest
from typer.testing import CliRunner

import tactsense as ts
from tactsense.cli import app
from tactsense.flat_scenarios import two_probes

runner = CliRunner()


@pytest.fixture(scope="module")
def recordings(tmp_path_factory):
    """A pad and a point set, each pressed by two probes at once; and a finger."""
    folder = tmp_path_factory.mktemp("round3_interop")
    paths = {}
    for name in ("pad16", "dome12"):
        sensor = ts.preset(name)
        paths[name] = folder / f"{name}.h5"
        ts.write_recording(paths[name], ts.simulate(sensor, two_probes(sensor), rng=2))
    finger = ts.fearing1990_initial()
    paths["finger"] = folder / "finger.h5"
    ts.write_recording(paths["finger"], ts.simulate(finger, ts.probe_sweep(finger), rng=0))
    return paths


# --- item 4: every contact of a frame keeps its own name in MCAP -------------------------


@pytest.mark.parametrize("kind", ["pad16", "dome12"])
def test_mcap_contacts_of_one_frame_have_distinct_names(tmp_path, recordings, kind):
    """Upstream's TactileContact.name is the "unique name of the contact" and RViz's
    contact display keeps one contact per (frame_id, name): two contacts of one frame
    named alike show as one. Each is ``<sensor>/<tracked id>`` (locate's long table
    gives the ids), and each frame's contacts also come as one TactileContacts list
    (upstream's merger's message), an empty one for a frame without a contact; decoded
    with mcap-ros2-support's own decoder."""
    from mcap.reader import make_reader
    from mcap_ros2.decoder import DecoderFactory

    rec = recordings[kind]
    out = tmp_path / "x.mcap"
    assert runner.invoke(app, ["export", str(rec), "--out", str(out)]).exit_code == 0
    by_stamp, lists, frames = defaultdict(list), [], 0
    with open(out, "rb") as stream:
        reader = make_reader(stream, decoder_factories=[DecoderFactory()])
        for schema, channel, message, decoded in reader.iter_decoded_messages():
            if channel.topic == "/tactile_contacts":
                by_stamp[message.log_time].append(decoded.name)
            elif channel.topic == "/contact_states":
                assert schema.name == "tactile_msgs/msg/TactileContacts"
                lists.append((message.log_time, [c.name for c in decoded.contacts]))
            else:
                frames += 1
    several = [names for names in by_stamp.values() if len(names) > 1]
    assert len(several) > 10  # two probes at once in many frames
    assert all(len(set(names)) == len(names) for names in several)
    # the names are the tracked ids of locate's long table, frame by frame
    table_path = tmp_path / "c.csv"
    assert runner.invoke(app, ["locate", str(rec), "--out", str(table_path)]).exit_code == 0
    table = pd.read_csv(table_path)
    sensor = ts.read_recording(rec).sensor.name
    expected = defaultdict(list)
    for time_s, i in zip(table["time_s"], table["id"], strict=True):
        expected[round(time_s * 1e9)].append(f"{sensor}/{i}")
    assert dict(by_stamp) == dict(expected)
    # one list per frame, holding that frame's contacts
    assert len(lists) == frames
    assert {t: names for t, names in lists if names} == dict(by_stamp)
