"""Three-axis frames on Foxglove live (issue 35 item 3): ``FoxgloveLive`` sends each
frame as the MCAP export's ``TactileState`` (a channel per component), checked by the
node client a Foxglove user's tools run (``@foxglove/ws-protocol`` and Foxglove's ROS 2
decoder, tests/interop/foxglove_node/). The server binds 127.0.0.1."""

from __future__ import annotations

import base64
import time

import numpy as np
import pytest
from typer.testing import CliRunner

import tactsense as ts
from tactsense.cli import app

pytest.importorskip("foxglove")
pytest.importorskip("mcap_ros2")

from tactsense.interop.foxglove_live import FoxgloveLive
from tactsense.interop.mcap import export_mcap

from .test_foxglove_live import (  # noqa: F401  (node_client: the fixture)
    OFFSET_S,
    client_output,
    mcap_messages,
    node_client,
    plain,
    push_recording,
    start_client,
)

TOPIC = "/tactile_states"


def test_three_axis_live_equals_the_mcap_export(tmp_path, node_client):  # noqa: F811
    path = tmp_path / "press.h5"
    runner = CliRunner()
    result = runner.invoke(
        app, ["simulate", "--sensor", "mag4x4", "--scenario", "press", "-o", str(path)]
    )
    assert result.exit_code == 0, result.output
    rec = ts.read_recording(path)
    export = tmp_path / "press.mcap"
    export_mcap(path, export, start_time_s=OFFSET_S)
    expected = mcap_messages(export)[TOPIC]
    assert len(expected) == len(rec)
    with FoxgloveLive(rec.sensor, port=0, frame_id="finger") as server:
        client = start_client(node_client, server.url, {TOPIC: len(rec)})
        deadline = time.monotonic() + 30
        while not server.channels[TOPIC].has_sinks():
            assert client.poll() is None and time.monotonic() < deadline
            time.sleep(0.05)
        push_recording(server, rec.sensor, rec, lambda frame: None)
        lines = client_output(client)
    got = [line for line in lines if line["op"] == "message" and line["topic"] == TOPIC]
    assert len(got) == len(rec)
    for k, (line, (_, _, message, decoded)) in enumerate(zip(got, expected, strict=True)):
        assert int(line["timestamp"]) == message.log_time
        assert base64.b64decode(line["data"]) == message.data
        assert line["decoded"] == plain(decoded)  # Foxglove's decoder reads what mcap's does
        sensors = line["decoded"]["sensors"]
        assert [s["name"] for s in sensors] == ["mag4x4/x", "mag4x4/y", "mag4x4/z"]
        values = np.stack([np.asarray(s["values"]) for s in sensors], axis=-1)
        np.testing.assert_array_equal(values.reshape(4, 4, 3), rec.frames[k])
