"""The bad-input matrix: every command, given a bad path or a bad option value, ends
with exit status 2, a short message naming what was wrong, no traceback, and nothing at
the output name. A new option joins the matrix when it is added."""

import os
import signal
import subprocess
import sys
import time

import pytest
from typer.testing import CliRunner

import tactsense as ts
from tactsense.cli import app

runner = CliRunner()


@pytest.fixture(scope="module")
def workspace(tmp_path_factory):
    folder = tmp_path_factory.mktemp("matrix")
    spec = ts.fearing1990_initial()
    ts.write_recording(folder / "rec.h5", ts.simulate(spec, ts.probe_sweep(spec), rng=0))
    (folder / "a_file").write_text("x")
    (folder / "a_dir").mkdir()
    return folder


BAD_OPTIONS = [
    # (command line, the option or file the message must name)
    ("design aliasing --spacing 0", "--spacing"),
    ("design aliasing --spacing -1", "--spacing"),
    ("design aliasing --depth nan", "--depth"),
    ("design aliasing --poisson 0.7", "--poisson"),
    ("design strip --modulus 0", "--modulus"),
    ("design strip --modulus -5", "--modulus"),
    ("design strip --thickness -1", "--thickness"),
    ("design strip --separation 0", "--separation"),
    ("design strip --backing -1", "--backing"),
    ("design bound --axial 100", "axial position 100 mm is off the finger"),
    ("design bound --force-g 0", "--force-g"),
    ("design bound --diameter -1", "--diameter"),
    ("simulate --seed -1 --out OUT", "--seed"),
    ("simulate --out OUT", "a recording is an HDF5 file; use the extension .h5"),
    ("simulate --lift-s -1 --out OUT", "--lift-s"),
    ("simulate --dwell-s 0 --out OUT", "--dwell-s"),
    ("simulate --force-g nan --out OUT", "--force-g"),
    ("simulate --repeats 0 --out OUT", "--repeats"),
    ("simulate --increment 0 --out OUT", "--increment"),
    ("simulate --row -1 --out OUT", "--row"),
    ("simulate --scenario knife-edge --force-g 10 --out OUT", "--force-g does not apply"),
    ("simulate --scenario knife-edge --dwell-s 1 --lift-s 1 --out OUT", "--dwell-s, --lift-s"),
    ("simulate --scenario calibration --row 2 --out OUT", "--row does not apply"),
    ("simulate --scenario sweep-around --col 2 --out OUT", "--col does not apply"),
    ("simulate --repeats 5 --out OUT", "which uses --col, --force-g"),
    ("simulate --forward bogus --out OUT", "expected one of twin, finger3d, finger3d-foam"),
    ("simulate --forward finger3d-foam --sensor pad4 --out OUT", "'pad4' is a pad"),
    ("emulate --scenario calibration --lift-s 1", "--lift-s does not apply"),
    ("locate REC --threshold -1 --out OUT", "--threshold"),
    ("locate REC --threshold nan --out OUT", "--threshold"),
    ("locate REC --baseline-frames 0 --out OUT", "--baseline-frames"),
    ("locate REC --chunk-frames 0 --out OUT", "--chunk-frames"),
    ("locate REC --workers 0 --out OUT", "--workers"),
    ("locate REC --out OUT.txt", "use the extension .csv, .parquet or .h5"),
    ("calibrate REC --probe-g 0 --out OUT", "--probe-g"),
    ("calibrate REC --baseline-frames 0 --out OUT", "--baseline-frames"),
    ("emulate --speed -1", "--speed"),
    ("emulate --drop 2", "--drop"),
    ("emulate --garbage -0.1", "--garbage"),
    ("emulate --stall-s nan", "--stall-s"),
    ("emulate --port 70000", "--port"),
    ("record loop:// --frames 0 --out OUT", "--frames"),
    ("record loop:// --duration -1 --out OUT", "--duration"),
    ("record loop:// --timeout 0 --out OUT", "--timeout"),
    ("live loop:// --threshold 2", "--threshold"),
    ("live loop:// --baseline-frames 0", "--baseline-frames"),
    ("live loop:// --method bogus", "--method 'bogus': expected one of"),
    ("live loop:// --max-contacts 0", "--max-contacts"),
    ("live loop:// --drift-s -1", "--drift-s"),
    ("live loop:// --drift-s nan", "--drift-s"),
    ("reproduce --sensor bogus --out OUT", "bogus"),
    ("design sweep --depth 0:3:4 --out OUT", "--depth"),
    ("design sweep --spacing x --out OUT", "--spacing"),
    ("design sweep --poisson 0.6 --out OUT", "--poisson"),
    ("design sweep --workers -1 --out OUT", "--workers"),
    ("batch REC --workers 0 --out OUT", "--workers"),
    ("batch REC --format xml --out OUT", "--format"),
    ("batch REC --threshold 0 --out OUT", "--threshold"),
    ("batch REC --split-frames 10 --out OUT", "--split-frames"),
    ("view REC --port 70000", "--port"),
    ("view REC --port -1", "--port"),
    ("view REC --speed 0", "--speed"),
    ("view REC --speed nan", "--speed"),
    ("view REC --threshold 2", "--threshold"),
    ("view REC --baseline-frames 0", "--baseline-frames"),
    ("view REC --sensor improved", "--sensor applies to a device"),
    ("view REC --timeout 1", "--timeout applies to a device"),
    ("view loop:// --speed 2", "--speed applies to recordings"),
    ("view no_such_recording.h5", "no recording at no_such_recording.h5"),
    ("view REC --host 203.0.113.9", "cannot listen on 203.0.113.9"),
    ("export REC --out OUT.txt", "say --format mcap or rerun"),
    ("export REC --format xml --out OUT", "--format"),
    ("export REC --threshold 0 --out OUT", "--threshold"),
    ("export REC --baseline-frames 0 --out OUT", "--baseline-frames"),
    ("export no_such.h5 --out OUT.mcap", "no_such.h5"),
    ("sensor import no_such.urdf", "cannot read no_such.urdf"),
    ("sensor import REC", "not XML"),
    ("sensor import REC --extends bogus", "--extends"),
    ("sensor export", "say which format: --urdf"),
    ("sensor export --urdf --sensor bogus", "presets: initial, improved"),
    ("record lsl: --out OUT.h5", "lsl: needs an outlet name"),
    ("record loop:// --format xml --out OUT", "--format"),
    ("live lsl:", "lsl: needs an outlet name"),
    # ---- foxglove live (r6-fox) ----
    ("live loop:// --foxglove abc", "--foxglove"),
    ("live loop:// --foxglove 70000", "--foxglove"),
    ("live loop:// --foxglove ::1:8765", "--foxglove"),
    ("live loop:// --foxglove 127.0.0.1:", "--foxglove"),
    ("view REC --foxglove host:", "--foxglove"),
    ("view REC --foxglove -1", "--foxglove"),
    ("view REC --foxglove 203.0.113.9:0", "cannot serve Foxglove on 203.0.113.9:0"),
    # ---- /foxglove live (r6-fox) ----
    # ---- live --ros2 (r6-ros2) ----
    ("live loop:// --namespace /a", "--namespace applies to --ros2"),
    ("live loop:// --ros2-config REC", "--ros2-config applies to --ros2"),
    ("live loop:// --ros2 --namespace /9a", "--namespace '/9a'"),
    ("live loop:// --ros2 --namespace /a//b", "--namespace"),
    ("live loop:// --ros2 --ros2-config no_such.xml", "--ros2-config no_such.xml: cannot read"),
    ("live loop:// --ros2 --ros2-config REC", "--ros2-config"),
    # ---- /live --ros2 (r6-ros2) ----
    # ---- fix37 (r6-fix37) ----
    ("live loop:// --ros2 --namespace /a/", "--namespace '/a/': it ends with /"),
    ("live loop:// --ros2 --namespace /" + "a" * 300, "301 characters"),
    # ---- /fix37 (r6-fix37) ----
    # ---- design bound --noise-fs (r6-bounds) ----
    ("design bound --sensor pad16 --noise-fs 0", "--noise-fs"),
    ("design bound --sensor pad16 --noise-fs -1", "--noise-fs"),
    ("design bound --sensor pad16 --noise-fs 51", "--noise-fs"),
    ("design bound --sensor pad16 --noise-fs nan", "--noise-fs"),
    ("design bound --sensor initial --noise-fs 1", "--noise-fs is for pads"),
    # ---- /design bound --noise-fs (r6-bounds) ----
]


def _bad_files(folder):
    """Files that are wrong in content, each made from a good one."""
    import json

    import h5py
    import numpy as np

    result = runner.invoke(
        app,
        ["calibrate", str(folder / "rec.h5"), "--partial", "--out", str(folder / "good.json")],
    )
    assert result.exit_code == 0, result.output
    good = json.loads((folder / "good.json").read_text())
    for name, value in (("nan_gain", float("nan")), ("zero_gain", 0.0)):
        data = json.loads(json.dumps(good))
        data["gains"][4][3] = value
        # json writes NaN as the bare word NaN, which Python's reader accepts
        (folder / f"{name}.json").write_text(json.dumps(data))
    data = json.loads(json.dumps(good))
    data["baseline_counts"][2][2] = -5.0
    (folder / "bad_baseline.json").write_text(json.dumps(data))
    rec = ts.read_recording(folder / "rec.h5")
    ts.write_recording(folder / "strings.h5", rec)
    with h5py.File(folder / "strings.h5", "r+") as h5:
        del h5["frames"]
        h5["frames"] = np.full(rec.frames.shape, b"12", dtype="S2")
    for name, scenario in (("knife", "knife-edge"), ("steps", "repeated")):
        args = ["simulate", "--scenario", scenario, "--out", str(folder / f"{name}.h5")]
        assert runner.invoke(app, args).exit_code == 0
    (folder / "empty.toml").write_text("")
    (folder / "partial.toml").write_text("[array]\nspacing_axial_mm = 3.0\n")
    (folder / "unknown.toml").write_text('extends = "initial"\n[array]\ncolz = 3\n')


BAD_FILES = [
    # (command line, what the message must say)
    ("calibrate REC --out OUT", "the sweep reached only 7 of 64 tactels"),
    ("calibrate REC --partial --steps REC --out OUT", "delayed fraction stopped at its bound"),
    ("calibrate REC --partial --knife DIR/knife.h5 --col 1 --out OUT", "nu 0.500"),
    (
        "calibrate REC --partial --knife DIR/steps.h5 --out OUT",
        "distinct position(s); a knife-edge fit",
    ),
    ("calibrate REC --partial --steps DIR/steps.h5 --col 3 --out OUT", "residual is"),
    ("locate REC --calibration REC --out OUT", "not JSON text"),
    ("locate REC --calibration DIR/nan_gain.json --out OUT", "gains of 1 tactel(s)"),
    ("locate REC --calibration DIR/zero_gain.json --out OUT", "at (4, 3)"),
    ("locate REC --calibration DIR/bad_baseline.json --out OUT", "baseline_counts of 1"),
    ("live loop:// --calibration DIR/zero_gain.json", "not a positive finite number"),
    ("locate DIR/strings.h5 --out OUT", "/frames holds |S2 values; expected numbers"),
    ("info DIR/strings.h5", "expected numbers"),
    ("sensor check DIR/empty.toml", "no sections ([array]"),
    ("sensor check DIR/partial.toml", "[elastic] is missing"),
    ("sensor check DIR/unknown.toml", "unknown key 'colz' in [array]"),
    ("simulate --sensor DIR/partial.toml --out OUT", "[body] is missing"),
    ("simulate --sensor bogus --out OUT", "presets: initial, improved"),
    ("design bound --sensor bogus", "presets: initial, improved"),
    ("view REC --calibration REC", "not JSON text"),
    ("view DIR/strings.h5", "/frames holds |S2 values; expected numbers"),
    ("view loop:// --calibration DIR/zero_gain.json", "not a positive finite number"),
    ("export REC --calibration DIR/zero_gain.json --out DIR/x.mcap", "at (4, 3)"),
    ("sensor import DIR/empty.toml", "not XML"),
    ("live REC", "is a recording; this command reads a device"),
    ("record REC --out OUT", "is a recording; this command reads a device"),
]


DEADLINE_S = 120
"""Longest a bad-input case may take [s]: a command that accepts the bad input and goes on
(a view serving, a live stream reading) fails the case instead of hanging the suite."""


def _invoke_with_deadline(args: list[str]):
    """``runner.invoke(app, args)``, interrupted by SIGALRM after :data:`DEADLINE_S`."""

    def expire(signum, frame):
        raise TimeoutError(f"tactsense {' '.join(args)} still ran after {DEADLINE_S} s")

    previous = signal.signal(signal.SIGALRM, expire)
    signal.alarm(DEADLINE_S)
    try:
        return runner.invoke(app, args)
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, previous)


@pytest.mark.parametrize("line, names", BAD_FILES, ids=[line for line, _ in BAD_FILES])
def test_bad_files(workspace, line, names):
    if not (workspace / "strings.h5").exists():
        _bad_files(workspace)
    out = workspace / "never_written.csv"
    args = (
        line.replace("REC", str(workspace / "rec.h5"))
        .replace("OUT", str(out))
        .replace("DIR", str(workspace))
        .split()
    )
    result = _invoke_with_deadline(args)
    _check(result, names)
    assert not out.exists()


BAD_OUTPUTS = {
    "simulate": "simulate --out {out}",
    "simulate --plot": "simulate --out {ok}/s.h5 --plot {out}",
    "locate": "locate {rec} --out {out}",
    "calibrate": "calibrate {rec} --out {out}",
    "sensor show": "sensor show --out {out}",
    "record": "record loop:// --out {out}",
    "live": "live loop:// --out {out}",
    "design sweep": "design sweep --depth 3.8 --spacing 3.8 --out {out}",
    "export": "export {rec} --format mcap --out {out}",
    "sensor export": "sensor export --urdf --out {out}",
}
BAD_PATHS = {
    "missing folder": ("no_such_folder/x.out", "does not exist"),
    "a directory": ("a_dir", "is a directory"),
    "under a file": ("a_file/x.out", "is a file"),
    "existing file": ("a_file", "exists; pass --force"),
}


def _check(result, names: str, forbidden=None):
    message = " ".join(result.output.split())  # rich wraps long lines at the terminal width
    assert result.exit_code == 2, message
    assert "Traceback" not in message
    assert names in message, message
    if forbidden is not None:
        assert not forbidden.exists() or forbidden.read_text() == "x"


@pytest.mark.parametrize("line, names", BAD_OPTIONS, ids=[line for line, _ in BAD_OPTIONS])
def test_bad_option_values(workspace, line, names):
    out = workspace / "never_written.csv"
    args = line.replace("REC", str(workspace / "rec.h5")).replace("OUT", str(out)).split()
    result = runner.invoke(app, args)
    _check(result, names)
    assert not out.exists()


@pytest.mark.parametrize("kind", list(BAD_PATHS))
@pytest.mark.parametrize("command", list(BAD_OUTPUTS))
def test_bad_output_paths_are_refused_before_any_work(workspace, command, kind):
    path, names = BAD_PATHS[kind]
    target = workspace / path
    line = BAD_OUTPUTS[command].format(out=target, ok=workspace, rec=workspace / "rec.h5")
    result = runner.invoke(app, line.split())
    _check(result, names, forbidden=target if kind == "existing file" else None)
    assert not (workspace / "s.h5").exists()
    assert not [p for p in workspace.iterdir() if ".partial" in p.name]


@pytest.mark.parametrize("kind", ["missing folder", "under a file"])
def test_bad_report_directory(workspace, kind):
    path, names = BAD_PATHS[kind]
    result = runner.invoke(app, ["reproduce", "--quick", "--out", str(workspace / path)])
    _check(result, names)
    result = runner.invoke(app, ["reproduce", "--quick", "--out", str(workspace / "a_file")])
    _check(result, "is a file")


@pytest.mark.parametrize("case", ["empty", "nan"])
def test_info_on_empty_and_nan_recordings(tmp_path, case):
    import dataclasses

    import numpy as np

    spec = ts.fearing1990_initial()
    rec = ts.simulate(spec, ts.probe_sweep(spec), rng=0)
    if case == "empty":
        rec = dataclasses.replace(rec, frames=rec.frames[:0], time_s=rec.time_s[:0], truth={})
        expected = "none (no frames)"
    else:
        frames = rec.frames.astype(float)
        frames[3] = np.nan
        rec = dataclasses.replace(rec, frames=frames)
        expected = "1 frames hold NaN"
    ts.write_recording(tmp_path / "r.h5", rec)
    result = runner.invoke(app, ["info", str(tmp_path / "r.h5")])
    assert result.exit_code == 0 and "Traceback" not in result.output
    assert expected in " ".join(result.output.split())


def test_csv_time_keeps_full_precision(tmp_path):
    import numpy as np

    spec = ts.fearing1990_initial()
    rec = ts.simulate(spec, ts.probe_sweep(spec), rng=0)
    late = rec.time_s + 100_000.0  # 100,000 s in: %.6g would give equal stamps
    est = ts.locate(rec.frames, spec, baseline=ts.baseline_from(rec.frames))
    ts.estimate.write_estimates_csv(tmp_path / "e.csv", est, late)
    written = np.genfromtxt(tmp_path / "e.csv", delimiter=",", skip_header=1, usecols=1)
    np.testing.assert_array_equal(written, late)


INTERRUPTIONS = [
    # (command, signal, seconds after start): 0.4 s lands in the imports, 2.5 s in the work
    ("simulate", signal.SIGINT, 2.5),
    ("locate", signal.SIGINT, 2.5),
    ("reproduce", signal.SIGINT, 2.5),
    ("simulate", signal.SIGINT, 0.4),
    ("reproduce", signal.SIGINT, 0.4),
    ("simulate", signal.SIGKILL, 3.0),
    ("locate", signal.SIGKILL, 2.5),
    ("reproduce", signal.SIGKILL, 3.0),
]


@pytest.mark.parametrize(
    "command, sent, delay",
    INTERRUPTIONS,
    ids=[f"{c}-{s.name}-{d}s" for c, s, d in INTERRUPTIONS],
)
def test_interruption_leaves_nothing_and_the_rerun_works(tmp_path, command, sent, delay):
    import dataclasses

    import numpy as np

    spec = ts.fearing1990_initial()
    rec = tmp_path / "rec.h5"
    short = ts.simulate(spec, ts.repeated_load(spec, repeats=40), rng=0)
    # 300,000 frames: several seconds of locate, so the signal lands in its work
    tiles = -(-300_000 // len(short.frames))
    frames = np.tile(short.frames, (tiles, 1, 1))
    period = spec.scan_period_s
    long = dataclasses.replace(
        short, frames=frames, time_s=np.arange(len(frames)) * period, truth={}
    )
    ts.write_recording(rec, long)
    out = tmp_path / {"reproduce": "out", "simulate": "out.h5", "locate": "out.csv"}[command]
    lines = {
        "simulate": ["simulate", "--scenario", "repeated", "--repeats", "3000", "--out", str(out)],
        "locate": ["locate", str(rec), "--out", str(out)],
        "reproduce": ["reproduce", "--quick", "--out", str(out)],
    }
    cli = [sys.executable, "-m", "tactsense_launcher", *lines[command]]
    process = subprocess.Popen(cli, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    time.sleep(delay)
    process.send_signal(sent)
    _, err = process.communicate(timeout=60)
    assert "Traceback" not in err and "Exception ignored" not in err, err
    if process.returncode != 0:  # interrupted in time: nothing at the final name
        if sent == signal.SIGINT:
            assert process.returncode == 1 and "interrupted" in err
            assert not [p for p in os.listdir(tmp_path) if ".partial" in p]
            assert not out.exists()
        else:
            assert process.returncode == -signal.SIGKILL
            # killed before the output was moved into place: nothing there; killed
            # after (a fast machine finishes in the delay): the whole file, never a part
            if out.exists():
                if command == "simulate":
                    assert ts.read_recording(out).closed_cleanly
                    out.unlink()
                elif command == "locate":  # every frame's row, and the header
                    with open(out) as stream:
                        assert sum(1 for _ in stream) == len(frames) + 1
                    out.unlink()
                else:
                    import shutil

                    assert (out / "report.md").exists()
                    shutil.rmtree(out)
    rerun = subprocess.run(cli, capture_output=True, text=True, timeout=300)
    if process.returncode != 0:
        assert rerun.returncode == 0, rerun.stderr
        assert out.exists()
    # a killed run's temporary output is removed by the next run toward the same name
    assert not [p for p in os.listdir(tmp_path) if ".partial" in p]


def test_import_and_locate_without_a_writable_numba_cache():
    """Item 11: no cache folder Numba can write (read-only install, read-only $HOME).

    As root every folder is writable, so the condition is made the way Numba sees it:
    no cache locator accepts the source file. Before the fix this was
    ``RuntimeError: cannot cache function`` at ``import tactsense``.
    """
    code = (
        "import numba.core.caching as c\n"
        "c.CacheImpl._locator_classes = []\n"
        "import numpy as np, tactsense as ts\n"
        "from tactsense.simulate import repeated_load\n"
        "spec = ts.fearing1990_initial()\n"
        "rec = ts.simulate(spec, repeated_load(spec, repeats=2), rng=1)\n"
        "est = ts.locate(rec.frames, spec, baseline=rec.frames[0])\n"
        "print(int(np.count_nonzero(np.isfinite(est.force_n) & (est.force_n > 0.1))))\n"
    )
    result = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, timeout=300
    )
    assert result.returncode == 0, result.stderr
    assert int(result.stdout.strip()) > 0


def test_view_port_in_use(workspace):
    import socket

    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen(1)
        port = taken.getsockname()[1]
        result = runner.invoke(app, ["view", str(workspace / "rec.h5"), "--port", str(port)])
    _check(result, f"cannot listen on 127.0.0.1:{port}")


# ---- the MuJoCo adapter's command (r6-mujoco) ----
BAD_MUJOCO = [
    # (command line, what the message must say); MODEL: the example model
    ("mujoco --seconds 0 --out OUT.h5", "--seconds"),
    ("mujoco --example bogus --out OUT.h5", "expected one of gripper, fingertip"),
    ("mujoco --frames-path quick --out OUT.h5", "expected one of auto, fast, reference"),
    ("mujoco --seconds nan --out OUT.h5", "--seconds"),
    ("mujoco --seconds 0.001 --out OUT.h5", "shorter than one scan"),
    ("mujoco --flat-radius-mm 0 --out OUT.h5", "--flat-radius-mm"),
    ("mujoco --seed -1 --out OUT.h5", "--seed"),
    ("mujoco --flaws viscoelastic --out OUT.h5", "need the frame sequence"),
    ("mujoco --flaws bogus --out OUT.h5", "unknown flaw(s) bogus"),
    ("mujoco --geom nope --out OUT.h5", "--geom nope: the model has no geom"),
    ("mujoco MODEL --out OUT.h5", "say which geom"),
    ("mujoco MODEL --geom pad --site pad_grid --out OUT.h5", "give one"),
    ("mujoco MODEL --site nope --out OUT.h5", "--site nope"),
    ("mujoco --sensor initial --out OUT.h5", "mount it on a capsule or a cylinder"),
    ("mujoco MODEL --site pad_grid --sensor initial --out OUT.h5", "mount it on a geom"),
    ("mujoco --out OUT.csv", "use the extension .h5"),
    ("mujoco REC --geom pad --out OUT.h5", "MuJoCo cannot load it"),
    ("mujoco no_such.xml --geom pad --out OUT.h5", "no such model file"),
    ("mujoco --controls REC --out OUT.h5", "not a text CSV file"),
    ("mujoco --controls DIR/a_file --out OUT.h5", "expected a CSV with a header"),
    ("mujoco --controls DIR/bad_controls.csv --out OUT.h5", "no actuator named wrist"),
]


@pytest.mark.parametrize("line, names", BAD_MUJOCO, ids=[line for line, _ in BAD_MUJOCO])
def test_bad_mujoco_input(workspace, line, names):
    pytest.importorskip("mujoco")
    from tactsense.interop.mujoco import example_model_path

    (workspace / "bad_controls.csv").write_text("time_s,wrist\n0,0\n1,0.1\n")
    out = workspace / "never_written"
    args = (
        line.replace("MODEL", str(example_model_path()))
        .replace("REC", str(workspace / "rec.h5"))
        .replace("OUT", str(out))
        .replace("DIR", str(workspace))
        .split()
    )
    result = _invoke_with_deadline(args)
    _check(result, names)
    assert not list(workspace.glob("never_written*"))


# ---- tactsense dataset (r6-data) ----
DATASET_BAD_OPTIONS = [
    ("dataset --episodes 0 --out OUT", "--episodes"),
    ("dataset --frames 5 --out OUT", "--frames"),
    ("dataset --force-n 1 0.5 --out OUT", "--force-n"),
    ("dataset --force-n nan 1 --out OUT", "--force-n"),
    ("dataset --radius-mm 0 1 --out OUT", "--radius-mm"),
    ("dataset --speed-mm-s -1 2 --out OUT", "--speed-mm-s"),
    ("dataset --friction 0.5 20 --out OUT", "--friction"),
    ("dataset --tasks poke --out OUT", "--tasks"),
    ("dataset --flaws bogus --out OUT", "unknown flaw(s) bogus"),
    ("dataset --sensor initial --out OUT", "has none (use a pad)"),
    ("dataset --sensor bogus --out OUT", "bogus"),
    ("dataset --format hdf5 --out OUT", "a file named .h5"),
    ("dataset --format xml --out OUT", "--format"),
    ("dataset --workers -1 --out OUT", "--workers"),
    ("dataset --episodes-per-task 0 --out OUT", "--episodes-per-task"),
    ("dataset --scheduler localhost:1 --out OUT", "--scheduler"),
    ("dataset --out no_such_folder/set", "does not exist"),
    ("dataset --out REC", "is never replaced"),
    ("dataset --out REC.h5", "a LeRobot dataset is a folder"),
]


@pytest.mark.parametrize(
    "line, names", DATASET_BAD_OPTIONS, ids=[line for line, _ in DATASET_BAD_OPTIONS]
)
def test_dataset_bad_options(workspace, line, names):
    out = workspace / "never_written"
    args = line.replace("REC", str(workspace / "rec.h5")).replace("OUT", str(out)).split()
    result = runner.invoke(app, args)
    _check(result, names)
    assert not out.exists()
    assert not [p for p in workspace.iterdir() if ".partial" in p.name]


# ---- /r6-data ----


# ---- fix38 (r6-fix38) ----
FIX38_DATASET_FLAWS = [
    # a flaw a data set's frames never have is refused, not recorded in meta unapplied
    ("dataset --flaws viscoelastic --out OUT", "viscoelastic need the frame sequence"),
    ("dataset --flaws noise,jitter --out OUT", "jitter need the frame sequence"),
    ("dataset --flaws hysteresis,drift --out OUT", "hysteresis, drift need the frame"),
]


@pytest.mark.parametrize(
    "line, names", FIX38_DATASET_FLAWS, ids=[line for line, _ in FIX38_DATASET_FLAWS]
)
def test_fix38_dataset_refuses_flaws_it_never_applies(workspace, line, names):
    out = workspace / "never_written"
    result = runner.invoke(app, line.replace("OUT", str(out)).split())
    _check(result, names)
    assert not out.exists()


def test_fix38_dataset_help_lists_only_the_flaws_that_apply():
    from tactsense.simulate.dataset import PER_FRAME_FLAWS

    result = runner.invoke(app, ["dataset", "--help"], terminal_width=400)
    text = " ".join(result.output.split())
    assert "'all' (all of these)" in text
    assert ", ".join(PER_FRAME_FLAWS) in text
    assert "jitter" not in PER_FRAME_FLAWS and "viscoelastic" not in PER_FRAME_FLAWS


def test_fix38_mujoco_seconds_help_range_is_the_one_checked(workspace):
    """--help's declared range of --seconds is the one enforced: (0, 1e6], no '0.0<=x'."""
    help_text = " ".join(
        runner.invoke(app, ["mujoco", "--help"], terminal_width=400).output.split()
    )
    assert "(0, 1e6]" in help_text and "0.0<=x" not in help_text
    out = workspace / "never.h5"
    for value, names in (("-1", "--seconds -1"), ("0", "--seconds 0"), ("2e6", "--seconds")):
        _check(runner.invoke(app, ["mujoco", "--seconds", value, "--out", str(out)]), names)
    assert not out.exists()


# ---- /r6-fix38 ----


# ---- robot skins in the sensor commands (r7-skin) ----
SKIN_BAD_INPUT = [
    # (command line, what the message must say); DIR: the workspace
    ("sensor export --sensor hand4 --out OUT", "say which format, --format toml|urdf"),
    ("sensor export --sensor hand4 --format png --out OUT", "--format 'png'"),
    ("sensor export --sensor pad4 --format toml --out OUT", "--format 'toml': one sensor"),
    ("sensor export --sensor DIR/skin.toml --format toml --out DIR/skin.toml", "input"),
    ("sensor export --sensor DIR/no_such.urdf --format toml --out OUT", "does not exist"),
    ("sensor show --sensor DIR/skin_loop.toml", "close a loop"),
    ("sensor show --sensor DIR/a_file.urdf", "not XML"),
    ("sensor check DIR/skin_loop.toml", "the joints close a loop: b -> c -> b"),
    ("sensor check DIR/skin_badsensor.toml", "sensors[0]"),
    ("sensor check hand4 --probe-g 50", "--probe-g maps the blind spots of one pad"),
]


def _skin_files(folder):
    good = (
        'name = "s"\nbase_link = "a"\nlinks = ["a", "b"]\n'
        '[[joints]]\nname = "j"\ntype = "revolute"\nparent = "a"\nchild = "b"\n'
        "lower = -1.0\nupper = 1.0\n"
        '[[sensors]]\nname = "p"\nlink = "b"\nsensor = "pad4"\n'
    )
    (folder / "skin.toml").write_text(good)
    (folder / "skin_loop.toml").write_text(
        'name = "s"\nbase_link = "a"\nlinks = ["a", "b", "c"]\n'
        '[[joints]]\nname = "j1"\ntype = "fixed"\nparent = "b"\nchild = "c"\n'
        '[[joints]]\nname = "j2"\ntype = "fixed"\nparent = "c"\nchild = "b"\n'
        '[[sensors]]\nname = "p"\nlink = "a"\nsensor = "pad4"\n'
    )
    (folder / "skin_badsensor.toml").write_text(
        'name = "s"\nbase_link = "a"\n[[sensors]]\nname = "p"\nlink = "a"\n'
        'sensor = {kind = "pad", grid = {rows = 0}}\n'
    )
    (folder / "a_file.urdf").write_text("x")


@pytest.mark.parametrize("line, names", SKIN_BAD_INPUT, ids=[line for line, _ in SKIN_BAD_INPUT])
def test_skin_bad_input(workspace, line, names):
    _skin_files(workspace)
    out = workspace / "never_written.out"
    args = line.replace("OUT", str(out)).replace("DIR", str(workspace)).split()
    result = runner.invoke(app, args)
    _check(result, names)
    assert not out.exists()
    assert (workspace / "skin.toml").read_text().startswith('name = "s"')


# ---- /r7-skin ----


# ---- tactsense grasp (r7-grasp) ----
_GRASP_SPHERE = "grasp hand4 --object sphere --size-mm 20 --pose 0,0,500"
GRASP_BAD_OPTIONS = [
    ("grasp hand4 --out OUT", "give the object (--object and --size-mm)"),
    ("grasp bogus_skin --object sphere --size-mm 20 --out OUT", "bogus_skin"),
    ("grasp hand4 --object cone --size-mm 20 --out OUT", "--object"),
    ("grasp hand4 --object sphere --size-mm 0 --out OUT", "--size-mm"),
    ("grasp hand4 --object sphere --size-mm nan --out OUT", "--size-mm"),
    ("grasp hand4 --object sphere --size-mm 20000 --out OUT", "--size-mm"),
    ("grasp hand4 --object cylinder --size-mm 20 --out OUT", "--size-mm"),
    ("grasp hand4 --object box --size-mm 20,20 --out OUT", "--size-mm"),
    ("grasp hand4 --object sphere --size-mm 20 --pose 1,2 --out OUT", "--pose"),
    ("grasp hand4 --object sphere --size-mm 20 --pose 0,0,inf --out OUT", "--pose"),
    (f"{_GRASP_SPHERE} --force-n 0 --out OUT", "--force-n"),
    (f"{_GRASP_SPHERE} --force-n 2e4 --out OUT", "--force-n"),
    (f"{_GRASP_SPHERE} --force-n palm=nan --out OUT", "--force-n"),
    (f"{_GRASP_SPHERE} --force-n palm=1,palm=2 --out OUT", "'palm' is given twice"),
    (f"{_GRASP_SPHERE} --stiffness-n-per-mm 0 --out OUT", "--stiffness-n-per-mm"),
    (f"{_GRASP_SPHERE} --stiffness-n-per-mm nan --out OUT", "--stiffness-n-per-mm"),
    (f"{_GRASP_SPHERE} --load-n 1,2 --out OUT", "--load-n"),
    (f"{_GRASP_SPHERE} --load-n 0,0,2e4 --out OUT", "--load-n"),
    (f"{_GRASP_SPHERE} --duration-s 1,1,1 --out OUT", "--duration-s"),
    (f"{_GRASP_SPHERE} --duration-s 0,0,0,0 --out OUT", "--duration-s"),
    (f"{_GRASP_SPHERE} --duration-s 0,1,1,700 --out OUT", "--duration-s"),
    (f"{_GRASP_SPHERE} --duration-s 0,-1,1,1 --out OUT", "--duration-s"),
    (f"{_GRASP_SPHERE} --joints bogus --out OUT", "--joints"),
    (f"{_GRASP_SPHERE} --joints no_such_joint=0.1 --out OUT", "not a movable joint"),
    (f"{_GRASP_SPHERE} --flaws bogus --out OUT", "unknown flaw(s) bogus"),
    (f"{_GRASP_SPHERE} --flaws viscoelastic --out OUT", "need a frame sequence"),
    (f"{_GRASP_SPHERE} --seed -1 --out OUT", "--seed"),
    (f"{_GRASP_SPHERE} --out OUT", "touches no patch"),
    (f"{_GRASP_SPHERE} --out no_such_folder/run", "does not exist"),
    (f"{_GRASP_SPHERE} --out REC", "exists"),
    (f"{_GRASP_SPHERE} --out REC --force", "is not a robot recording"),
    ("grasp hand4 --grasp DIR/no_such.toml --out OUT", "does not exist"),
    ("grasp hand4 --grasp DIR/a_file --out OUT", "grasp file"),
    ("grasp hand4 --grasp DIR/a_file --object sphere --out OUT", "drop --object"),
]


@pytest.mark.parametrize(
    "line, names", GRASP_BAD_OPTIONS, ids=[line for line, _ in GRASP_BAD_OPTIONS]
)
def test_grasp_bad_options(workspace, line, names):
    out = workspace / "never_written"
    args = (
        line.replace("REC", str(workspace / "rec.h5"))
        .replace("OUT", str(out))
        .replace("DIR", str(workspace))
        .split()
    )
    result = runner.invoke(app, args)
    _check(result, names)
    assert not out.exists()
    assert (workspace / "rec.h5").is_file()
    assert not [p for p in workspace.iterdir() if ".partial" in p.name]


# ---- /r7-grasp ----


# ---- several devices of a robot skin (r7-capture) ----
BAD_CAPTURE = [
    ("record loop:// loop:// --out OUT", "give one SOURCE, or several with --skin"),
    ("record loop:// --dropout-s 5 --out OUT", "--dropout-s applies with --skin"),
    ("live loop:// --dropout-s 5", "--dropout-s applies with --skin"),
    ("record --skin nope loop:// --out OUT", "--skin: robot skin 'nope'"),
    ("record --skin hand4 a b c d e f g h i --out OUT", "9 sources for the"),
    ("record --skin hand4 board_thumb=x y --out OUT", "DEVICE=SOURCE or none"),
    ("record --skin hand4 board_nope=x --out OUT", "'board_nope' is no device of 'hand4'"),
    ("record --skin hand4 loop:// --dropout-s 0 --out OUT", "--dropout-s"),
    ("record --skin hand4 loop:// --dropout-s nan --out OUT", "--dropout-s"),
    ("record --skin hand4 loop:// --duration 0 --out OUT", "--duration"),
    ("record --skin hand4 loop:// --frames 5 --out OUT", "--frames does not apply"),
    ("record --skin hand4 loop:// --format mcap --out OUT", "--record-format does not apply"),
    ("record --skin hand4 loop:// --out OUT.h5", "the recording is a folder"),
    ("live --skin hand4 loop:// --lsl", "--lsl does not apply"),
    ("live --skin hand4 loop:// --dropout-s -1", "--dropout-s"),
    ("emulate --drift-ppm 5", "apply with --skin"),
    ("emulate --skin hand4 --drift-ppm 5000", "--drift-ppm"),
    ("emulate --skin hand4 --drift-ppm nan", "--drift-ppm"),
    ("emulate --skin hand4 --clock-offset-s -1", "--clock-offset-s"),
    ("emulate --skin hand4 --row 2", "--skin excludes --row"),
    ("emulate --skin hand4 --format text", "--skin excludes --format"),
    ("emulate --skin hand4 --port 65533", "beyond 65535"),
    ("emulate --skin hand4 --recording REC", "with --skin, a robot recording"),
    ("emulate --skin nope", "--skin: robot skin 'nope'"),
]


@pytest.mark.parametrize("line, names", BAD_CAPTURE, ids=[line for line, _ in BAD_CAPTURE])
def test_capture_bad_input(workspace, line, names):
    out = workspace / "never_written"
    args = line.replace("REC", str(workspace / "rec.h5")).replace("OUT", str(out)).split()
    result = runner.invoke(app, args)
    _check(result, names)
    assert not out.exists() and not (workspace / "never_written.h5").exists()


def test_capture_refuses_to_replace_a_folder_that_is_no_robot_recording(workspace):
    result = runner.invoke(
        app, ["record", "--skin", "hand4", "loop://", "--out", str(workspace / "a_dir"), "--force"]
    )
    _check(result, "is not a robot recording")
    assert (workspace / "a_dir").is_dir()


# ---- /r7-capture ----


# ---- locate on a robot recording (r7-handloc) ----
HANDLOC_BAD = [
    ("locate RUN --joints elbow=1 --out OUT", "'elbow': not a movable joint"),
    ("locate RUN --joints j3=5 --out OUT", "joint 'j3' at 5.0: outside its limits"),
    ("locate RUN --joints j1 --out OUT", "NAME=POSITION"),
    ("locate RUN --joints j1=inf --out OUT", "finite position"),
    ("locate RUN --joints-csv DIR/a_file --out OUT", "expected 'time_s'"),
    ("locate RUN --joints-csv DIR/no_such.csv --out OUT", "cannot read it"),
    ("locate RUN --joints-bag DIR/a_dir --out OUT", "not a rosbag2 bag"),
    ("locate RUN --joints-topic /js --out OUT", "add --joints-bag"),
    ("locate RUN --joints j1=0 --joints-csv DIR/a_file --out OUT", "give one of --joints"),
    ("locate RUN --method fit --out OUT", "--method applies to a single array"),
    ("locate RUN --workers 2 --out OUT", "--workers applies to a single array"),
    ("locate RUN --out DIR/x.h5", "go to .parquet or .csv"),
    ("locate RUN --out OUT --wrenches DIR/w.txt", "--wrenches"),
    ("locate RUN --out OUT --wrenches OUT", "same file as --out"),
    ("locate RUN --out RUN/x.parquet", "lies inside the robot recording"),
    ("locate RUN --max-contacts 0 --out OUT", "--max-contacts"),
    ("locate RUN --threshold -1 --out OUT", "--threshold"),
    ("locate REC --joints j1=0 --out OUT", "apply to a robot recording's folder"),
]


@pytest.fixture(scope="module")
def handloc_run(workspace):
    from tests.estimate._robot_sim import write_pressed_recording
    from tests.estimate.test_robot_locate import small_skin

    return write_pressed_recording(workspace / "robot_run", small_skin(), frames=8)


@pytest.mark.parametrize("line, names", HANDLOC_BAD, ids=[line for line, _ in HANDLOC_BAD])
def test_handloc_bad_options(workspace, handloc_run, line, names):
    out = workspace / "never_written.parquet"
    args = (
        line.replace("RUN", str(handloc_run)).replace("REC", str(workspace / "rec.h5"))
        .replace("OUT", str(out)).replace("DIR", str(workspace)).split()
    )  # fmt: skip
    _check(runner.invoke(app, args), names)
    assert not out.exists()
    assert not (workspace / "never_written_wrenches.parquet").exists()
    assert not [p for p in workspace.iterdir() if ".partial" in p.name]
    assert not [p for p in handloc_run.iterdir() if p.name not in ("robot.json", "skin.toml",
                                                                    "streams")]  # fmt: skip


# ---- /r7-handloc ----


# ---- view of a hand (r7-hand3d) ----
HAND_VIEW_BAD = [
    # (command line, what the message must say); RUN: a robot recording of a small hand
    # with one joint, 'knuckle' in [-0.2, 1.6] rad
    ("view RUN --joints bogus=1", "--joints: joint position for 'bogus': not a movable"),
    ("view RUN --joints knuckle=abc", "--joints knuckle='abc': not a number"),
    ("view RUN --joints knuckle=nan", "outside its limits"),
    ("view RUN --joints knuckle=9", "--joints: joint 'knuckle' at 9.0: outside its limits"),
    ("view RUN --joints knuckle", "expected NAME=POSITION"),
    ("view RUN --joints knuckle=0.1,knuckle=0.2", "names joint 'knuckle' twice"),
    ("view RUN --sensor pad16", "--sensor applies to one array"),
    ("view RUN --calibration REC", "--calibration applies to one array"),
    ("view RUN --foxglove 0", "--foxglove applies to one array"),
    ("view RUN --timeout 1", "--timeout applies to devices"),
    ("view RUN RUN", "give --skin SKIN"),
    ("view REC --joints knuckle=0", "--joints and --joints-csv apply to a robot skin's view"),
    ("view REC --joints-csv DIR/a_file", "--joints and --joints-csv apply to a robot skin's"),
    ("view RUN --joints-csv DIR/no_such.csv", "--joints-csv: no file at"),
    ("view RUN --joints-csv DIR/a_file", "expected 'time_s' then one column per joint"),
    ("view RUN --joints-csv DIR/bogus_joints.csv", "joint 'bogus' is not a movable joint"),
    ("view RUN --joints-csv DIR/far_joints.csv", "outside its limits"),
    ("view RUN --joints knuckle=0 --joints-csv DIR/a_file", "give the joint state once"),
    ("view --skin hand4 loop:// --joints-csv DIR/a_file", "--joints-csv applies to a recording"),
    ("view --skin hand4 socket://127.0.0.1:1 --speed 2", "--speed applies to recordings"),
    ("view --skin bogus socket://127.0.0.1:1", "'bogus' is neither a preset"),
    ("view --skin hand4 a b c d e f", "6 sources for the 4 devices of 'hand4'"),
    ("view --skin hand4 --joints bogus=0 loop://", "--joints: joint position for 'bogus'"),
    ("view --skin hand4 socket://127.0.0.1:1", "cannot open socket://127.0.0.1:1"),
]


@pytest.mark.parametrize("line, names", HAND_VIEW_BAD, ids=[line for line, _ in HAND_VIEW_BAD])
def test_hand_view_bad_input(workspace, line, names):
    from tests.view.test_browser_hand import hand_recording

    run = workspace / "hand_run"
    if not run.exists():
        hand_recording(run, pressed=None, seconds=0.1)
        (workspace / "bogus_joints.csv").write_text("time_s,bogus\n0,0\n1,0\n")
        (workspace / "far_joints.csv").write_text("time_s,knuckle\n0,0\n1,3\n")
    args = (
        line.replace("RUN", str(run))
        .replace("REC", str(workspace / "rec.h5"))
        .replace("DIR", str(workspace))
        .split()
    )
    result = _invoke_with_deadline(args)
    _check(result, names)


# ---- /view of a hand (r7-hand3d) ----


# ---- robot export/import (r7-handio) ----
@pytest.fixture(scope="module")
def robot_workspace(workspace):
    """A robot recording of icub_hand (constant frames), its MCAP and an iCub trial."""
    import numpy as np

    from tactsense.interop.robot_mcap import export_robot_mcap
    from tactsense.io.recording import Recording
    from tactsense.io.robot_recording import RobotRecording, write_robot_recording
    from tactsense.physics.transduction import sample_offsets
    from tactsense.robot import skin_preset

    skin = skin_preset("icub_hand")
    streams = {
        p.name: Recording(
            frames=np.full((8, *p.sensor.shape), 240, np.uint16),
            time_s=np.arange(8) / 50,
            sample_offset_s=sample_offsets(p.sensor),
            sensor=p.sensor,
        )
        for p in skin.patches
    }
    run = workspace / "robot_io_run"
    if not (workspace / "robot_io_trial_1.txt").exists():  # the last one written
        write_robot_recording(run, RobotRecording(skin=skin, streams=streams))
        export_robot_mcap(run, workspace / "robot_io.mcap", contacts=False)
        slice_ = ["1 " * 9, "0 " * 5] + ["240 " * 12] * 5
        (workspace / "robot_io_trial_1.txt").write_text("\n".join(["-10000", *slice_]) + "\n")
    return workspace


ROBOT_BAD_OPTIONS = [
    ("export RUN --format csv --out OUT.csv", "a robot recording exports to mcap or lerobot"),
    ("export RUN --out OUT.txt", "say --format mcap or lerobot"),
    ("export RUN --frame-id x --out OUT.mcap", "--frame-id"),
    ("export RUN --format lerobot --fps 0 --out OUT", "--fps"),
    ("export RUN --format lerobot --fps 20000 --out OUT", "--fps"),
    ("export RUN --format mcap --fps 10 --out OUT.mcap", "--fps apply to --format lerobot"),
    ("export RUN --format lerobot --start-time 5 --out OUT", "--start-time"),
    ("export RUN --format lerobot --out OUT.h5", "a LeRobot dataset is a folder"),
    ("export RUN --format mcap --out RUN/x.mcap", "inside the input"),
    ("export REC --fps 10 --out OUT.mcap", "--fps applies to a robot recording"),
    ("import MCAP --skin bogus --out OUT", "--skin"),
    ("import MCAP --skin hand4 --out OUT", "topic /tactile_states/"),
    ("import MCAP --out OUT.h5", "a robot recording is a folder"),
    ("import MCAP --out RUN", "exists; pass --force"),
    ("import MCAP --out MCAP/x", "overlap"),
    ("import REC --skin icub_hand --out OUT", "expected an MCAP file"),
    ("import TRIAL --skin hand4 --out OUT", "no patch little_tip"),
    ("import TRIAL --skin icub_hand --sensor pad4 --out OUT", "--sensor do not apply"),
    ("import TRIAL --skin icub_hand --period 0 --out OUT", "--period"),
    ("import MCAP --skin icub_hand --period 1 --out OUT", "--period applies to iCub"),
    ("import MCAP --skin icub_hand --map x --out OUT", "--map 'x': expected NAME=PATCH"),
    ("import MCAP --skin icub_hand --map a=palm --out OUT", "has no patch 'palm'"),
    ("import MCAP --skin icub_hand --map a=thumb_tip --map a=index_tip --out OUT", "twice"),
    ("import TRIAL --skin icub_hand --map a=thumb_tip --out OUT", "--map applies to bags"),
    ("import REC --map a=b --out OUT.h5", "--map applies to a robot import"),
]


@pytest.mark.parametrize(
    "line, names", ROBOT_BAD_OPTIONS, ids=[line for line, _ in ROBOT_BAD_OPTIONS]
)
def test_robot_io_bad_options(robot_workspace, line, names):
    folder = robot_workspace
    out = folder / "never_written_robot"
    replaced = (
        line.replace("REC", str(folder / "rec.h5")).replace("RUN", str(folder / "robot_io_run"))
        .replace("MCAP", str(folder / "robot_io.mcap"))
        .replace("TRIAL", str(folder / "robot_io_trial_1.txt"))
        .replace("OUT", str(out))
    )  # fmt: skip
    result = runner.invoke(app, replaced.split())
    _check(result, names)
    assert not [p for p in folder.iterdir() if p.name.startswith("never_written_robot")]
    assert not [p for p in folder.iterdir() if ".partial" in p.name]
    assert not (folder / "robot_io_run" / "x.mcap").exists()


# ---- /robot export/import (r7-handio) ----


# ---- (r7-fixb) ----
FIXB_BAD_INPUT = [
    # (command line, what the message must say); DIR: the workspace
    ("sensor show hand4 --sensor icub_hand", "give the sensor once"),
    ("sensor show hand4 pad4", "unexpected extra argument"),
    ("sensor show DIR/fixb_edited.urdf", "not where the URDF's geometry places"),
    ("sensor export --sensor DIR/fixb_yaml.urdf --format toml --out OUT", "only 'toml' is read"),
    ("sensor show DIR/fixb_badtoml.urdf", "its <tactsense:sensor> description"),
    ("grasp hand4 --object sphere --size-mm 40 --pose 36.5,-56.5,-28.5 --out OUT", "nearest patch"),
]


def _fixb_files(folder):
    from tactsense.interop.robot_urdf import robot_skin_to_urdf
    from tactsense.robot import Patch, Pose, RobotSkin
    from tactsense.sensor import preset

    skin = RobotSkin(
        name="s", base_link="a", links=("a",), joints=(),
        patches=(Patch("p", preset("pad4"), "a", Pose(), "board"),),
    )  # fmt: skip
    text = robot_skin_to_urdf(skin)
    (folder / "fixb_edited.urdf").write_text(text.replace('rows="4"', 'rows="3"'))
    (folder / "fixb_yaml.urdf").write_text(text.replace('format="toml"', 'format="yaml"'))
    (folder / "fixb_badtoml.urdf").write_text(text.replace("[grid]", "[grid"))


@pytest.mark.parametrize("line, names", FIXB_BAD_INPUT, ids=[line for line, _ in FIXB_BAD_INPUT])
def test_fixb_bad_input(workspace, line, names):
    _fixb_files(workspace)
    out = workspace / "never_written_fixb"
    args = line.replace("OUT", str(out)).replace("DIR", str(workspace)).split()
    result = runner.invoke(app, args)
    _check(result, names)
    assert not out.exists()
    assert not [p for p in workspace.iterdir() if ".partial" in p.name]


# ---- /(r7-fixb) ----
# ---- (r7-fixa) ----
FIXA_BAD = [  # trial 36 item 1: an output never replaces a joint-state input, --force or not
    ("locate RUN --joints-csv J.csv --out J.csv --force", "never replaces an input"),
    ("locate RUN --joints-csv J.csv --out OUT --wrenches J.csv --force", "never replaces"),
    ("locate RUN --joints-bag BAG --out BAG/c.parquet", "inside the input"),
]


@pytest.mark.parametrize("line, names", FIXA_BAD, ids=[line for line, _ in FIXA_BAD])
def test_fixa_locate_never_replaces_its_joint_input(workspace, handloc_run, line, names):
    joints = workspace / "fixa_joints.csv"
    joints.write_text("time_s,j1\n0,0.1\n100,0.1\n")
    bag = workspace / "fixa_bag"
    bag.mkdir(exist_ok=True)
    (bag / "metadata.yaml").write_text("")
    out = workspace / "never_written_fixa.parquet"
    args = (
        line.replace("RUN", str(handloc_run)).replace("J.csv", str(joints))
        .replace("BAG", str(bag)).replace("OUT", str(out)).split()
    )  # fmt: skip
    _check(runner.invoke(app, args), names)
    assert joints.read_text() == "time_s,j1\n0,0.1\n100,0.1\n"
    assert not out.exists() and sorted(p.name for p in bag.iterdir()) == ["metadata.yaml"]


# ---- /r7-fixa ----
# ---- (r7-fixc) ----
FIXC_BAD = [
    ("record board_a=socket://127.0.0.1:1 board_b=loop:// --out OUT", "add --skin SKIN"),
    ("record board_a=socket://127.0.0.1:1 --out OUT", "add --skin SKIN"),
    ("record --skin hand4 loop://", "give --out RUN"),
    ("emulate --recording RUN", "is a robot recording (a folder): add --skin SKIN"),
    ("view RUN/streams", "is a folder"),
]


@pytest.mark.parametrize("line, names", FIXC_BAD, ids=[line for line, _ in FIXC_BAD])
def test_fixc_bad_input(robot_workspace, line, names):
    folder = robot_workspace
    out = folder / "never_written_fixc"
    args = line.replace("RUN", str(folder / "robot_io_run")).replace("OUT", str(out)).split()
    result = runner.invoke(app, args)
    _check(result, names)
    assert not out.exists()


def test_fixc_info_describes_a_robot_recording(robot_workspace):
    run = robot_workspace / "robot_io_run"
    result = runner.invoke(app, ["info", str(run)])
    text = " ".join(result.output.split())
    assert result.exit_code == 0, text
    assert "a robot recording" in text and "icub_hand" in text and "index_tip" in text
    # 8 frames at 50 Hz: 0.160 s
    assert "0.160 s (longest stream)" in text, text


def test_fixc_info_duration_counts_from_the_first_frame(tmp_path):
    spec = ts.fearing1990_initial()
    recording = ts.simulate(spec, ts.probe_sweep(spec), rng=0)
    shifted = recording.__class__(
        frames=recording.frames, time_s=recording.time_s + 90.0,
        sample_offset_s=recording.sample_offset_s, sensor=recording.sensor,
    )  # fmt: skip
    ts.write_recording(tmp_path / "late.h5", shifted)
    span = float(recording.time_s[-1] - recording.time_s[0]) + spec.scan_period_s
    result = runner.invoke(app, ["info", str(tmp_path / "late.h5")])
    assert result.exit_code == 0, result.output
    assert f"{span:.3f} s at" in result.output, result.output


# ---- /(r7-fixc) ----


# ---- three-axis frames in other tools' files (r8-triinterop) ----
def _triinterop_files(folder):
    """Files of three-axis frames that cannot be imported as mag4x4 (4 x 4 taxels x 3)."""
    names = [f"r{r}c{c}{p}" for r in range(4) for c in range(4) for p in "xyz"]
    row = ",".join(["32768"] * 48)
    good = [",".join(["time", *names])] + [f"{k * 0.01},{row}" for k in range(3)]
    (folder / "triinterop_swapped.csv").write_text(
        "\n".join([good[0].replace("r1c2x,r1c2y", "r1c2y,r1c2x"), *good[1:]]) + "\n"
    )
    scalar = [",".join(["time", *(f"r{r}c{c}" for r in range(4) for c in range(4))])]
    scalar += [f"{k * 0.01}," + ",".join(["1"] * 16) for k in range(3)]
    (folder / "triinterop_scalar.csv").write_text("\n".join(scalar) + "\n")
    short = [*good[:2], good[2].rsplit(",", 1)[0]]
    (folder / "triinterop_short_row.csv").write_text("\n".join(short) + "\n")


TRIINTEROP_BAD = [
    ("import DIR/triinterop_swapped.csv --sensor mag4x4 -o OUT",
     "value column 19 is 'r1c2y'; sensor 'mag4x4' names it 'r1c2x'"),
    ("import DIR/triinterop_scalar.csv --sensor mag4x4 -o OUT",
     "16 value columns; sensor 'mag4x4' has 4 x 4 = 16 taxels x 3 components (x, y, z) = 48 "
     "values"),
    ("import DIR/triinterop_short_row.csv --sensor mag4x4 -o OUT", "line 3: 48 fields"),
]  # fmt: skip


@pytest.mark.parametrize("line, names", TRIINTEROP_BAD, ids=[line for line, _ in TRIINTEROP_BAD])
def test_triinterop_bad_three_axis_files(workspace, line, names):
    _triinterop_files(workspace)
    out = workspace / "never_written_triinterop.h5"
    args = line.replace("DIR", str(workspace)).replace("OUT", str(out)).split()
    _check(runner.invoke(app, args), names)
    assert not out.exists()


# ---- /three-axis frames in other tools' files (r8-triinterop) ----


# ---- (r8-triphys) ----
TRIPHYS_BAD = [  # the shear scenarios' options (issue 35 item 5)
    ("simulate --sensor mag4x4 --scenario shear --shear-ratio 1.2 -o OUT", "friction"),
    ("simulate --sensor mag4x4 --scenario shear --shear-ratio 0", "--shear-ratio"),
    ("simulate --sensor mag4x4 --scenario shear --shear-ratio 11 -o OUT", "--shear-ratio"),
    ("simulate --sensor mag4x4 --scenario slide-to-slip --shear-ratio 0.5 -o OUT", "never slip"),
    ("simulate --sensor mag4x4 --scenario shear --friction 0 -o OUT", "--friction"),
    ("simulate --sensor mag4x4 --scenario shear --ramp-s 0.001 -o OUT", "scan period"),
    ("simulate --sensor mag4x4 --scenario shear --shear-angle-deg 400 -o OUT", "--shear-angle"),
    ("simulate --sensor mag4x4 --scenario press --shear-ratio 0.3 -o OUT", "does not apply"),
    ("simulate --sensor mag4x4 --scenario shear --separation-mm 3 -o OUT", "does not apply"),
    ("simulate --sensor pad16 --scenario shear -o OUT", "three-axis pad"),
    ("simulate --sensor mag4x4 --scenario sweep-axial -o OUT", "--scenario sweep-axial"),
    ("simulate --sensor mag4x4 --scenario slide-to-slip --speed-mm-s 500 -o OUT", "off the"),
]


@pytest.mark.parametrize("line, names", TRIPHYS_BAD, ids=[line for line, _ in TRIPHYS_BAD])
def test_triphys_shear_scenarios_bad_input(tmp_path, line, names):
    out = tmp_path / "triphys_never_written.h5"
    result = runner.invoke(app, line.replace("OUT", str(out)).split())
    _check(result, names)
    assert not out.exists()


# ---- /(r8-triphys) ----


# ---- values per taxel on the line: --components and components=N (r8-triwire) ----
TRIWIRE_BAD = [
    ("record loop:// --components 3 --out OUT", "--components applies to text, marker"),
    ("live loop:// --components 3", "--components applies to text, marker"),
    ("record text:loop:// --components 5 --out OUT", "--components 5: expected a whole"),
    ("record text:loop:// --components 0 --out OUT", "--components 0: expected a whole"),
    ("record justfloat:loop:// --components -1 --out OUT", "--components -1"),
    ("record text,components=7:loop:// --out OUT", "components='7' must be a whole number"),
    ("record marker,components=x:loop:// --out OUT", "components='x' must be a whole number"),
    ("record text,components=1:loop:// --components 3 --out OUT", "disagrees with the source"),
    (
        "record text:loop:// --components 3 --sensor pad16 --out OUT",
        "components=3, but the sensor 'pad16' reports 1 per taxel",
    ),
    ("record --skin hand4 loop:// --components 3 --out OUT", "not to --skin"),
    ("emulate --components 3", "--components applies to another wire format"),
    ("emulate --format text --components 9", "--components 9: expected a whole"),
    (
        "emulate --sensor mag4x4 --format marker,components=1",
        "components=1, but the sensor 'mag4x4' reports 3 per taxel (x, y, z)",
    ),
    ("record text,offset=1.5:loop:// --out OUT", "offset='1.5' must be whole counts"),
    ("record justfloat,offset=-70000:loop:// --out OUT", "offset='-70000' must be whole"),
    ("emulate --format marker,signed=maybe", "signed='maybe' must be no or yes"),
]


@pytest.mark.parametrize("line, names", TRIWIRE_BAD, ids=[line for line, _ in TRIWIRE_BAD])
def test_triwire_components_bad_input(workspace, line, names):
    out = workspace / "never_written_triwire.h5"
    result = runner.invoke(app, line.replace("OUT", str(out)).split())
    _check(result, names)
    assert not out.exists()


# ---- /values per taxel on the line (r8-triwire) ----


# ---- three-axis pads in view (r8-triview) ----
TRIVIEW_BAD = [
    # --threshold on a three-axis pad: a fraction of full scale, as locate's (r8-fixb8);
    # beyond (0, 1] refused as everywhere
    ("view TRIVIEW_REC --threshold 2", "must be a number in (0, 1]"),
]


@pytest.mark.parametrize("line, names", TRIVIEW_BAD, ids=[line for line, _ in TRIVIEW_BAD])
def test_triview_bad_options(tmp_path, line, names):
    spec = ts.preset("mag4x4")
    rec = tmp_path / "triview_rec.h5"
    scenario = ts.Scenario((ts.Step((), 0.1),))
    ts.write_recording(rec, ts.simulate(spec, scenario, rng=0))
    result = runner.invoke(app, line.replace("TRIVIEW_REC", str(rec)).split())
    _check(result, names)


# ---- /three-axis pads in view (r8-triview) ----


# ---- three-axis locate and calibrate (r8-triest) ----
TRIEST_BAD = [
    ("locate MAG --friction 0 -o OUT", "--friction must be a coefficient in 0.05-5"),
    ("locate MAG --friction nan -o OUT", "--friction must be a coefficient in 0.05-5"),
    ("locate MAG --friction 9 -o OUT", "--friction must be a coefficient in 0.05-5"),
    ("locate REC --friction 0.5 -o OUT", "--friction applies to three-axis sensors"),
    ("locate MAG --method fit -o OUT", "--method fit is for pads"),
    ("locate MAG --calibration PADCAL -o OUT", "is not a three-axis calibration"),
    ("calibrate MAG --shear-sweep MISSING -o OUT", "triest_missing.h5 does not exist"),
    ("calibrate MAG --press -o OUT", "--press is not for three-axis sensors"),
    ("calibrate MAGNOTRUTH -o OUT", "has no known loads"),
    ("calibrate REC --shear-sweep MAG -o OUT", "--shear-sweep is for three-axis sensors"),
]


@pytest.fixture(scope="module")
def triest_workspace(tmp_path_factory):
    import json

    import h5py

    from tactsense.flat_scenarios import SCENARIOS

    folder = tmp_path_factory.mktemp("triest_matrix")
    spec = ts.preset("mag4x4")
    recording = ts.simulate(spec, SCENARIOS["press"](spec), rng=0)
    ts.write_recording(folder / "triest_mag.h5", recording)
    ts.write_recording(folder / "triest_mag_no_truth.h5", recording)
    with h5py.File(folder / "triest_mag_no_truth.h5", "a") as f:
        for group in ("truth",):
            if group in f:
                del f[group]
    pad = ts.fearing1990_initial()
    ts.write_recording(folder / "triest_rec.h5", ts.simulate(pad, ts.probe_sweep(pad), rng=0))
    (folder / "triest_pad_cal.json").write_text(json.dumps({"format": "something-else"}))
    return folder


@pytest.mark.parametrize("line, names", TRIEST_BAD, ids=[line for line, _ in TRIEST_BAD])
def test_triest_bad_input(triest_workspace, line, names):
    folder = triest_workspace
    out = folder / "never_written_triest.csv"
    args = (
        line.replace("MAGNOTRUTH", str(folder / "triest_mag_no_truth.h5"))
        .replace("MAG", str(folder / "triest_mag.h5"))
        .replace("REC", str(folder / "triest_rec.h5"))
        .replace("PADCAL", str(folder / "triest_pad_cal.json"))
        .replace("MISSING", str(folder / "triest_missing.h5"))
        .replace("OUT", str(out))
        .split()
    )
    _check(runner.invoke(app, args), names)
    assert not out.exists()


# ---- /r8-triest ----


# ---- the three-axis MuJoCo slip example (r8-mjslip) ----
MJSLIP_BAD = [
    ("mujoco --example slips --out OUT", "expected one of gripper, fingertip, slip"),
    ("mujoco --example slip --geom nothere --out OUT", "--geom nothere: the model has no geom"),
    ("mujoco --example slip --flaws viscoelastic --out OUT", "need the frame sequence"),
    ("mujoco --example slip --seconds 0.001 --out OUT", "shorter than one scan of 'mag4x4'"),
]


@pytest.mark.parametrize("line, names", MJSLIP_BAD, ids=[line for line, _ in MJSLIP_BAD])
def test_mjslip_bad_input(tmp_path, line, names):
    pytest.importorskip("mujoco")
    out = tmp_path / "never_written_mjslip.h5"
    _check(runner.invoke(app, line.replace("OUT", str(out)).split()), names)
    assert not out.exists()


# ---- /the three-axis MuJoCo slip example (r8-mjslip) ----


# ---- trial8 fixes (r8-fixc8) ----
FIXC8_BAD = [
    ("emulate --sensor mag4x4 --scenario shear --shear-angle-deg nan", "--shear-angle-deg"),
    ("emulate --sensor mag4x4 --scenario shear --shear-ratio 0", "--shear-ratio"),
    ("emulate --sensor mag4x4 --scenario shear --friction 9", "--friction"),
    ("emulate --sensor mag4x4 --scenario slide-to-slip --shear-ratio 0.5", "does not exceed"),
    ("emulate --sensor pad4 --scenario press --ramp-s 1", "--ramp-s does not apply"),
    ("emulate --recording REC --shear-ratio 0.5", "--recording excludes --shear-ratio"),
    ("simulate --sensor mag4x4 --scenario calibration --shear-ratio 1.2", "above the friction"),
    ("simulate --sensor mag4x4 --scenario calibration --ramp-s 1", "--ramp-s does not apply"),
    ("simulate --sensor pad4 --scenario calibration --shear-ratio 0.3", "does not apply"),
    ("simulate --scenario calibration --shear-angle-deg 90", "does not apply"),
]


@pytest.mark.parametrize("line, names", FIXC8_BAD, ids=[line for line, _ in FIXC8_BAD])
def test_fixc8_bad_input(workspace, line, names):
    out = workspace / "fixc8_never_written.h5"
    args = line.replace("REC", str(workspace / "rec.h5")).split()
    tail = ["--port", "0"] if args[0] == "emulate" else ["-o", str(out)]
    _check(runner.invoke(app, [*args, *tail]), names)
    assert not out.exists()


# ---- /trial8 fixes (r8-fixc8) ----
# ---- trial8 fixes (r8-fixb8) ----
FIXB8_CSV = [("big", "70000", "is beyond 65535"), ("neg", "-7", "is negative"),
             ("big-fraction", "65535.5", "is beyond 65535"),
             ("empty", "", "column r0c0z")]  # fmt: skip


@pytest.mark.parametrize("name, cell, names", FIXB8_CSV, ids=[c[0] for c in FIXB8_CSV])
def test_fixb8_csv_counts_the_converter_cannot_give(tmp_path, name, cell, names):
    # a three-axis CSV with one bad cell: refused with its line and column, not imported
    # as float frames reading as a phantom contact
    spec = ts.preset("mag4x4")
    columns = [f"r{r}c{c}{a}" for r in range(4) for c in range(4) for a in "xyz"]
    rows = [["0.01", *(["32768"] * len(columns))], ["0.02", *(["32768"] * len(columns))]]
    rows[1][3] = cell
    source = tmp_path / f"fixb8_{name}.csv"
    source.write_text("\n".join(",".join(r) for r in [["time", *columns], *rows]) + "\n")
    out = tmp_path / "fixb8_never.h5"
    result = runner.invoke(app, ["import", str(source), "--sensor", spec.name, "-o", str(out)])
    for words in ("line 3, column r0c0z", names):
        _check(result, words)
    assert not out.exists()


# ---- /trial8 fixes (r8-fixb8) ----
# ---- trial8 fixes (r8-fixa8) ----
FIXA8_BAD = [
    ("sensor check fixa8_nosuch", "cannot read sensor file fixa8_nosuch"),
    ("sensor check mag4x4 --probe-g 50", "--probe-g maps the blind spots of a pad"),
]


@pytest.mark.parametrize("line, names", FIXA8_BAD, ids=[line for line, _ in FIXA8_BAD])
def test_fixa8_bad_input(tmp_path, monkeypatch, line, names):
    monkeypatch.chdir(tmp_path)  # 'fixa8_nosuch' is looked for here, and is not a preset
    _check(runner.invoke(app, line.split()), names)


def test_fixa8_rest_field_on_the_rail_is_a_warning_not_silence(tmp_path):
    """A description whose magnets saturate the converter at rest: 'sensor check' and
    'simulate' name the axis and the count (a warning: the description is valid)."""
    import re

    text = ts.preset("mag4x4").to_toml_string()
    path = tmp_path / "fixa8_bigm.toml"
    path.write_text(re.sub(r"^moment_a_m2 = .*$", "moment_a_m2 = 0.01", text, flags=re.M))
    out = str(tmp_path / "fixa8_bigm.h5")
    for args in (["sensor", "check", str(path)], ["simulate", "--sensor", str(path), "-o", out]):
        message = " ".join(runner.invoke(app, args).output.split())
        assert "Traceback" not in message
        assert "warning: 'mag4x4': the rest field saturates the converter on the z axis" in message
        assert "129160 counts untouched; the range is 0 .. 65535" in message


# ---- /trial8 fixes (r8-fixa8) ----


# ---- the indenter's radius on three-axis taxels (r9-mjslip2) ----
MJSLIP2_BAD = [
    ("locate MAG --indenter-radius 0 -o OUT", "--indenter-radius: the indenter's radius must"),
    ("locate MAG --indenter-radius nan -o OUT", "a number of millimetres in 0.2-50"),
    ("locate MAG --indenter-radius 100 -o OUT", "a number of millimetres in 0.2-50; got 100"),
    ("locate REC --indenter-radius 2 -o OUT", "--indenter-radius applies to three-axis sensors"),
]


@pytest.fixture(scope="module")
def mjslip2_workspace(tmp_path_factory):
    folder = tmp_path_factory.mktemp("mjslip2_matrix")
    spec = ts.preset("mag4x4")
    ts.write_recording(
        folder / "mjslip2_mag.h5", ts.simulate(spec, ts.Scenario((ts.Step((), 0.1),)), rng=0)
    )
    pad = ts.fearing1990_initial()
    ts.write_recording(folder / "mjslip2_rec.h5", ts.simulate(pad, ts.probe_sweep(pad), rng=0))
    return folder


@pytest.mark.parametrize("line, names", MJSLIP2_BAD, ids=[line for line, _ in MJSLIP2_BAD])
def test_mjslip2_bad_input(mjslip2_workspace, line, names):
    folder = mjslip2_workspace
    out = folder / "mjslip2_never_written.csv"
    args = (
        line.replace("MAG", str(folder / "mjslip2_mag.h5"))
        .replace("REC", str(folder / "mjslip2_rec.h5"))
        .replace("OUT", str(out))
        .split()
    )
    _check(runner.invoke(app, args), names)
    assert not out.exists()


# ---- /r9-mjslip2 ----


# ---- hand joint fit (r10-handjoint) ----
HANDJOINT_BAD = [
    # --method on a robot recording's folder: 'interpolate' or 'joint' only; with joint,
    # the other single-array options are still refused, and so are the robot's bad ones
    ("locate RUN --method cop --out OUT", "takes --method interpolate or joint"),
    ("locate RUN --method bogus --out OUT", "--method 'bogus' is not a method"),
    ("locate RUN --method joint --workers 2 --out OUT", "--workers applies to a single array"),
    ("locate RUN --method joint --drift-s 0 --out OUT", "--drift-s applies to a single array"),
    ("locate RUN --method joint --friction 1 --out OUT", "--friction applies to a single array"),
    ("locate RUN --indenter-radius 5 --out OUT", "--indenter-radius applies to a single"),
    ("locate RUN --method joint --joints j3=5 --out OUT", "outside its limits"),
    ("locate RUN --method joint --max-contacts 99 --out OUT", "--max-contacts"),
    ("locate RUN --method joint --out DIR/x.h5", "go to .parquet or .csv"),
    ("locate REC --method joint --joints j1=0 --out OUT", "apply to a robot recording's folder"),
]


@pytest.mark.parametrize("line, names", HANDJOINT_BAD, ids=[line for line, _ in HANDJOINT_BAD])
def test_handjoint_bad_options(workspace, handloc_run, line, names):
    # the hand locator's checks, with its run folder left as it was
    test_handloc_bad_options(workspace, handloc_run, line, names)


# ---- /hand joint fit (r10-handjoint) ----
