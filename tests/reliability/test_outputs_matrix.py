"""The outputs matrix: an output never replaces an input of the same command (with or
without --force, however the path is spelled: relative, absolute, ``./``, ``..``, a
symlink, a hard link), leftovers of killed runs are removed, and errors name the output
the user gave. Each case: exit status 2, one line naming the clash, no traceback, and
the input unchanged byte for byte."""

import csv
import hashlib
import os
import shlex
import subprocess
import sys

import h5py
import pytest
from typer.testing import CliRunner

import tactsense as ts
from tactsense.cli import app

runner = CliRunner()


def digest(path):
    return hashlib.sha256(open(path, "rb").read()).hexdigest()


@pytest.fixture(scope="module")
def folder(tmp_path_factory):
    folder = tmp_path_factory.mktemp("outputs")
    spec = ts.fearing1990_initial()
    ts.write_recording(folder / "rec.h5", ts.simulate(spec, ts.probe_sweep(spec), rng=0))
    spec.to_toml(folder / "finger.toml")
    (folder / "arm.urdf").write_text("<robot name='r'/>")
    (folder / "cal.json").write_text("{}")
    (folder / "cal.csv").write_text("{}")  # a calibration named like an output
    (folder / "report").mkdir()
    spec.to_toml(folder / "report" / "inside.toml")
    return folder


# (command line, the input it names); OUT is the input spelled another way
CLASHES = [
    ("locate rec.h5 --out {rec} --force", "rec.h5"),
    ("locate rec.h5 --calibration cal.csv --out {cal.csv} --force", "cal.csv"),
    ("calibrate rec.h5 --out {rec} --force", "rec.h5"),
    ("calibrate rec.h5 --steps cal.json --out {cal.json} --force", "cal.json"),
    ("calibrate rec.h5 --knife cal.json --out {cal.json} --force", "cal.json"),
    ("export rec.h5 --out {rec} --format mcap --force", "rec.h5"),
    ("export rec.h5 --out {rec} --format rerun --force", "rec.h5"),
    ("export rec.h5 --calibration cal.json --out {cal.json} --format mcap --force", "cal.json"),
    ("simulate --sensor finger.toml --out {finger.toml} --force", "finger.toml"),
    ("sensor show --sensor finger.toml --out {finger.toml} --force", "finger.toml"),
    ("sensor export --sensor finger.toml --urdf --out {finger.toml} --force", "finger.toml"),
    ("sensor import arm.urdf --out {arm.urdf} --force", "arm.urdf"),
    ("design sweep --sensor finger.toml --out {finger.toml} --force", "finger.toml"),
    ("record rec.h5 --out {rec} --force", "rec.h5"),
    ("record loop:// --sensor finger.toml --out {finger.toml} --force", "finger.toml"),
    ("live loop:// --calibration cal.json --out {cal.json} --force", "cal.json"),
    ("live loop:// --sensor finger.toml --out {finger.toml} --force", "finger.toml"),
]

SPELLINGS = ["same", "dot", "absolute", "dotdot", "symlink", "hardlink"]


def spelled(folder, name, how):
    """``name`` (a file in ``folder``, the working directory) spelled another way."""
    if how == "same":
        return name
    if how == "dot":
        return f"./{name}"
    if how == "absolute":
        return str(folder / name)
    if how == "dotdot":
        return f"../{folder.name}/{name}"
    link = folder / f"{how}-{name}"
    link.unlink(missing_ok=True)
    if how == "symlink":
        link.symlink_to(folder / name)
    else:
        os.link(folder / name, link)
    return link.name


@pytest.mark.parametrize("how", SPELLINGS)
@pytest.mark.parametrize(
    ("line", "source"), CLASHES, ids=[c[0].split(" --out")[0] for c in CLASHES]
)
def test_an_output_never_replaces_its_input(folder, monkeypatch, line, source, how):
    monkeypatch.chdir(folder)
    before = digest(folder / source)
    name = line[line.index("{") + 1 : line.index("}")]
    name = "rec.h5" if name == "rec" else name
    line = line.replace("{" + line[line.index("{") + 1 : line.index("}")] + "}",
                        spelled(folder, name, how))  # fmt: skip
    result = runner.invoke(app, shlex.split(line))
    message = result.output.strip()
    assert result.exit_code == 2, message
    assert "never replaces an input" in message, message
    assert "Traceback" not in message and len(message.splitlines()) == 1, message
    assert digest(folder / source) == before


def test_simulate_and_design_refuse_one_name_for_out_and_plot(folder, monkeypatch):
    monkeypatch.chdir(folder)
    for line in (
        "simulate --out twin.h5 --plot ./twin.h5 --force",
        f"design sweep --out map.csv --plot {folder / 'map.csv'} --force",
    ):
        result = runner.invoke(app, shlex.split(line))
        assert result.exit_code == 2 and "same file" in result.output, result.output
        assert not (folder / "twin.h5").exists() and not (folder / "map.csv").exists()


def test_reproduce_refuses_a_report_folder_holding_its_sensor(folder, monkeypatch):
    monkeypatch.chdir(folder)
    before = digest(folder / "report" / "inside.toml")
    result = runner.invoke(
        app, ["reproduce", "--sensor", "report/inside.toml", "--out", "./report", "--force"]
    )
    assert result.exit_code == 2 and "never replaces an input" in result.output, result.output
    assert digest(folder / "report" / "inside.toml") == before


def test_batch_refuses_outputs_over_its_recordings(folder, tmp_path):
    # --out the recordings' own folder with --format h5: rec.h5 -> rec.h5
    before = digest(folder / "rec.h5")
    result = runner.invoke(
        app, ["batch", str(folder / "rec.h5"), "--out", str(folder), "--format", "h5"]
    )
    assert result.exit_code == 2 and "never replaces an input" in result.output, result.output
    assert digest(folder / "rec.h5") == before
    # a calibration named summary.csv in --out
    (tmp_path / "summary.csv").write_text("{}")
    result = runner.invoke(
        app,
        ["batch", str(folder / "rec.h5"), "--out", str(tmp_path),
         "--calibration", str(tmp_path / "summary.csv")],
    )  # fmt: skip
    assert result.exit_code == 2 and "never replaces an input" in result.output, result.output
    assert (tmp_path / "summary.csv").read_text() == "{}"


def test_different_files_are_still_replaced_with_force(folder, tmp_path):
    out = tmp_path / "est.csv"
    out.write_text("old")
    result = runner.invoke(app, ["locate", str(folder / "rec.h5"), "--out", str(out), "--force"])
    assert result.exit_code == 0, result.output
    assert out.read_text().startswith('"frame"')


def _dead_pid():
    """A process id that is not running (a child that has exited and been reaped)."""
    child = subprocess.Popen([sys.executable, "-c", "pass"])
    child.wait()
    return child.pid


def test_stale_partials_of_any_name_are_removed(folder, tmp_path):
    dead = _dead_pid()
    stale = [
        tmp_path / f".other.{dead}.partial.h5",  # a killed locate toward another name
        tmp_path / f".a.b.{dead}.partial.parquet",
        tmp_path / f".paper-report.{dead}.partial",  # a killed reproduce (a folder)
    ]
    for path in stale[:2]:
        path.write_bytes(b"x" * 1000)
    stale[2].mkdir()
    (stale[2] / "fig.png").write_bytes(b"x")
    kept = [
        tmp_path / f".live.{os.getpid()}.partial.h5",  # its writer is running
        tmp_path / ".notes.partial.txt",  # not tactsense's pattern (no pid)
        tmp_path / f"visible.{dead}.partial.h5",  # not hidden: not ours
        tmp_path / f".x.{dead}.partialfoo",
    ]
    for path in kept:
        path.write_text("keep")
    result = runner.invoke(
        app, ["locate", str(folder / "rec.h5"), "--out", str(tmp_path / "est.parquet")]
    )
    assert result.exit_code == 0, result.output
    assert [p for p in stale if p.exists()] == []
    assert all(p.exists() for p in kept)


def test_an_unwritable_output_is_named_not_its_temporary(folder):
    for suffix in (".csv", ".parquet"):
        result = runner.invoke(app, ["locate", str(folder / "rec.h5"), "--out", f"/proc/x{suffix}"])
        assert result.exit_code == 2, result.output
        assert f"/proc/x{suffix}" in result.output and "partial" not in result.output


@pytest.mark.parametrize("value", ["nan", "inf", "0", "-1", "1.5"])
def test_threshold_must_be_a_number_in_0_1(folder, tmp_path, value):
    out = tmp_path / "e.csv"
    result = runner.invoke(
        app, ["locate", str(folder / "rec.h5"), "--threshold", value, "--out", str(out)]
    )
    assert result.exit_code == 2
    assert "(0, 1]" in result.output and "less than or equal" not in result.output
    assert not out.exists()


def test_version():
    result = subprocess.run(
        [sys.executable, "-m", "tactsense.cli", "--version"], capture_output=True, text=True
    )
    assert result.returncode == 0
    assert result.stdout.strip() == f"tactsense {ts.__version__}"


def test_one_column_naming_in_every_format(folder, tmp_path):
    import pyarrow.parquet as pq

    from tactsense.stream.live import FIELDS

    names = {}
    for suffix in (".csv", ".parquet", ".h5"):
        out = tmp_path / f"e{suffix}"
        located = runner.invoke(app, ["locate", str(folder / "rec.h5"), "--out", str(out)])
        assert located.exit_code == 0, located.output
        if suffix == ".csv":
            names[suffix] = next(csv.reader(out.open()))
        elif suffix == ".parquet":
            names[suffix] = pq.read_schema(out).names
        else:
            with h5py.File(out) as h5:
                names[suffix] = list(h5)
    assert names[".csv"][: len(names[".parquet"])] == names[".parquet"]
    assert set(names[".h5"]) == set(names[".parquet"])
    # the estimate columns `live` also writes carry the same names
    shared = {"row", "col", "axial_mm", "angle_deg", "force_n", "skew", "peak_deflection",
              "flags", "flag_names"}  # fmt: skip
    assert shared <= set(FIELDS) and shared <= set(names[".csv"])
    assert not any("[" in name for name in names[".csv"])


def test_hdf5_estimates_are_compressed_checksummed_and_small(folder, tmp_path):
    import pyarrow.parquet as pq

    h5_out, pq_out = tmp_path / "e.h5", tmp_path / "e.parquet"
    for out in (h5_out, pq_out):
        located = runner.invoke(app, ["locate", str(folder / "rec.h5"), "--out", str(out)])
        assert located.exit_code == 0, located.output
    frames = pq.read_metadata(pq_out).num_rows
    with h5py.File(h5_out) as h5:
        for name in h5:
            assert h5[name].compression == "gzip" and h5[name].fletcher32
            assert h5[name].chunks[0] <= max(1024, frames)
    # uncompressed 65,536-row chunks made 154 frames 5.9 MB; 12 columns of 8 bytes
    # per frame is the data itself: allow HDF5's headers on top
    assert h5_out.stat().st_size < 100_000 + 12 * 8 * frames


def test_batch_summary_gives_every_loss_counter_its_own_column(tmp_path):
    import dataclasses

    import pyarrow.csv as pa_csv

    from tactsense import cluster

    spec = ts.fearing1990_initial()
    counts = {"lost": 104, "gaps": 3, "bad_check": 200, "truncated": 5, "garbage": 30,
              "garbage_bytes": 517, "timeouts": 2}  # fmt: skip
    recording = dataclasses.replace(ts.simulate(spec, ts.probe_sweep(spec), rng=0), losses=counts)
    ts.write_recording(tmp_path / "r.h5", recording)
    row = cluster.process_recording(str(tmp_path / "r.h5"), str(tmp_path / "r.parquet"))
    row.update(recording=str(tmp_path / "r.h5"), output=str(tmp_path / "r.parquet"), status="done")
    cluster.write_summary(tmp_path / "summary.csv", [row])
    written = pa_csv.read_csv(tmp_path / "summary.csv").to_pylist()[0]
    assert "losses" not in written  # no sum of different things
    assert written["lost_frames"] == 104
    for kind in ("gaps", "bad_check", "truncated", "garbage", "garbage_bytes", "timeouts"):
        assert written[kind] == counts[kind], kind
    assert written["duplicates"] == 0
