"""Bad input to ``tactsense import`` and ``export --format lerobot``: exit status 2, one
line naming what was wrong and what was expected, no traceback, nothing at the output."""

import json

import pytest
from typer.testing import CliRunner

import tactsense as ts
from tactsense.cli import app

runner = CliRunner()


@pytest.fixture(scope="module")
def workspace(tmp_path_factory):
    folder = tmp_path_factory.mktemp("data_matrix")
    spec = ts.fearing1990_initial()
    rec = ts.simulate(spec, ts.probe_sweep(spec), rng=0)
    ts.write_recording(folder / "rec.h5", rec)
    (folder / "a_dir").mkdir()
    (folder / "notes.txt").write_text("hello")
    (folder / "junk.mcap").write_bytes(b"\x89MCAP0\r\n" + b"\x00" * 40)
    (folder / "junk.xdf").write_bytes(b"XDF:" + b"\xff" * 30)
    (folder / "text.xdf").write_text("not an xdf file")
    header = "time," + ",".join(f"v{k}" for k in range(64))
    row = "0.0," + ",".join(["2000"] * 64)
    (folder / "good.csv").write_text(f"{header}\n{row}\n")
    (folder / "short.csv").write_text("time,a,b\n0,1,2\n")
    (folder / "nan.csv").write_text(f"{header}\n{row}\n" + row.replace("2000", "x", 1) + "\n")
    (folder / "ragged.csv").write_text(f"{header}\n{row}\n0.1,5\n")
    (folder / "notime.csv").write_text(header.replace("time", "t") + "\n" + row + "\n")
    (folder / "empty.csv").write_text("")
    (folder / "header_only.csv").write_text(header + "\n")
    (folder / "binary.csv").write_bytes(b"\xff\xfe\x00garbage")
    bad = folder / "bad_dataset" / "meta"
    bad.mkdir(parents=True)
    (bad / "info.json").write_text("{not json")
    old = folder / "old_dataset" / "meta"
    old.mkdir(parents=True)
    (old / "info.json").write_text(json.dumps({"codebase_version": "v2.1", "features": {}}))
    notactile = folder / "robot_dataset" / "meta"
    notactile.mkdir(parents=True)
    (notactile / "info.json").write_text(
        json.dumps({"codebase_version": "v3.0", "fps": 30, "features": {"action": {}}})
    )
    (folder / "fake_bag").mkdir()
    (folder / "fake_bag" / "metadata.yaml").write_text("rosbag2_bagfile_information: 3\n")
    # an MCAP export whose TactileState is not on the topic asked for
    assert runner.invoke(app, ["export", str(folder / "rec.h5"), "--out",
                               str(folder / "rec.mcap")]).exit_code == 0  # fmt: skip
    return folder


CASES = [
    # (command line, what the message must name)
    ("import DIR/missing.mcap --out OUT", "missing.mcap does not exist"),
    ("import DIR/a_dir --out OUT", "neither a LeRobot dataset"),
    ("import DIR/notes.txt --out OUT", "unknown kind of file .txt"),
    ("import DIR/junk.mcap --out OUT", "junk.mcap is not a readable MCAP file"),
    ("import DIR/junk.xdf --out OUT", "junk.xdf is not a readable XDF file"),
    ("import DIR/text.xdf --out OUT", "text.xdf is not a readable XDF file"),
    ("import DIR/good.csv --out OUT", "pass --sensor"),
    ("import DIR/good.csv --sensor bogus --out OUT", "--sensor"),
    (
        "import DIR/good.csv --sensor pad4 --out OUT",
        "64 value columns; sensor 'pad4' has 4 x 4 = 16 taxels",
    ),
    ("import DIR/short.csv --sensor initial --out OUT", "2 value columns"),
    ("import DIR/nan.csv --sensor initial --out OUT", "line 3"),
    ("import DIR/ragged.csv --sensor initial --out OUT", "line 3: 2 fields"),
    ("import DIR/notime.csv --sensor initial --out OUT", "--time-column"),
    ("import DIR/empty.csv --sensor initial --out OUT", "empty.csv is empty"),
    ("import DIR/header_only.csv --sensor initial --out OUT", "no frames"),
    ("import DIR/binary.csv --sensor initial --out OUT", "not a text (UTF-8) CSV"),
    ("import DIR/bad_dataset --out OUT", "info.json is not readable JSON"),
    ("import DIR/old_dataset --out OUT", "codebase_version 'v2.1'"),
    ("import DIR/robot_dataset --out OUT", "no observation.tactile feature"),
    ("import DIR/fake_bag --out OUT", "not a readable rosbag2 bag"),
    ("import DIR/rec.mcap --topic /nope --out OUT", "no tactile_msgs/msg/TactileState topic"),
    ("import DIR/rec.mcap --sensor pad4 --out OUT", "64 values"),
    ("import DIR/rec.mcap --out DIR/rec.h5", "exists"),
    ("export REC --format lerobot --out DIR/a_dir", "exists"),
    ("export REC --format lerobot --episode-split 0 --out OUT", "--episode-split"),
    ("export REC --episode-split 10 --out OUT.mcap", "applies to --format lerobot only"),
    ("export REC --out OUT.rrd --frame-id x", "apply to --format mcap only"),
    ("export REC --out OUT.mcap --start-time -5", "--start-time"),
    ("export REC --out OUT.mcap --start-time nan", "--start-time"),
    ("export DIR/good.csv --format lerobot --out OUT", "good.csv"),
]


@pytest.mark.parametrize("line, names", CASES, ids=[line for line, _ in CASES])
def test_bad_data_input(workspace, line, names):
    out = workspace / "never_written"
    args = (
        line.replace("REC", str(workspace / "rec.h5"))
        .replace("OUT", str(out))
        .replace("DIR", str(workspace))
        .split()
    )
    result = runner.invoke(app, args)
    message = " ".join(result.output.split())
    assert result.exit_code == 2, message
    assert "Traceback" not in message, message
    assert names in message, message
    assert not out.exists() and not (workspace / "never_written.mcap").exists()
    assert not list(workspace.glob(".never_written*"))  # no temporary left either
