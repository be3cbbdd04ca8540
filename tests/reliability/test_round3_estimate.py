"""Round three (issue 31), estimation: each case failed before its fix.

Item 1: ``locate`` writes the same file whatever the size of the pieces it reads, in
every output format, also when a piece has no contact at all (its columns are empty, so
no type can be inferred from them) or an optional column holds no number (all NaN, all
empty). The file's column types come from the table's definition.
"""

import h5py
import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import pytest
from typer.testing import CliRunner

import tactsense as ts
from tactsense.cli import app

runner = CliRunner()


def cli(*args):
    done = runner.invoke(app, [str(a) for a in args])
    assert done.exit_code == 0, (done.output, done.exception)
    return " ".join(done.output.split())


def read(path):
    """A table as its format's own reader gives it: name -> numpy array."""
    path = str(path)
    if path.endswith(".parquet"):
        table = pq.read_table(path)
    else:
        with h5py.File(path, "r") as f:
            return {
                name: f[name][:].astype(str) if f[name].dtype == object else f[name][:]
                for name in f
                if isinstance(f[name], h5py.Dataset)
            }
    return {name: table[name].to_numpy(zero_copy_only=False) for name in table.column_names}


def same(a, b):
    assert list(a) == list(b)
    for name in a:
        x, y = np.asarray(a[name]), np.asarray(b[name])
        assert x.shape == y.shape, name
        if x.dtype.kind == "f":
            np.testing.assert_array_equal(x, y, err_msg=name)  # NaN equals NaN here
        else:
            assert (x.astype(str) == y.astype(str)).all(), name


@pytest.fixture(scope="module")
def recordings(tmp_path_factory):
    folder = tmp_path_factory.mktemp("r3estimate")
    cli("simulate", "--sensor", "pad16", "--scenario", "two-probes", "--out", folder / "two.h5")
    cli("simulate", "--sensor", "dome12", "--scenario", "press", "--out", folder / "dome.h5")
    spec = ts.fearing1990_initial()
    ts.write_recording(folder / "finger.h5", ts.simulate(spec, ts.probe_sweep(spec), rng=0))
    return folder


# (recording, extra options, frames per piece): the first pieces are the untouched
# frames that make the baseline, so they hold no contact
CHUNKED = {
    "pad": ("two.h5", [], 10),
    "points": ("dome.h5", [], 5),
    "finger-contacts": ("finger.h5", ["--contacts"], 3),
}


@pytest.mark.parametrize("fmt", ["parquet", "h5"])  # CSV never failed: checked elsewhere
@pytest.mark.parametrize("case", list(CHUNKED))
def test_locate_in_pieces_with_no_contact_writes_the_same_file(recordings, case, fmt):
    """Issue 31 item 1: ``event: null vs event: string`` (Parquet), ``Object dtype has
    no native HDF5 equivalent`` (HDF5) when a piece is quiet; the file must equal the
    one written in one piece."""
    name, options, piece = CHUNKED[case]
    whole = recordings / f"{case}-whole.{fmt}"
    pieces = recordings / f"{case}-pieces.{fmt}"
    cli("locate", recordings / name, *options, "--out", whole, "-q", "--force")
    cli("locate", recordings / name, *options, "--out", pieces, "-q", "--force",
        "--chunk-frames", piece)  # fmt: skip
    a, b = read(whole), read(pieces)
    assert len(a["frame"]) > 0
    same(a, b)


@pytest.mark.parametrize("fmt", ["parquet", "h5"])  # CSV never failed: checked elsewhere
def test_contacts_writer_types_come_from_the_definition(tmp_path, fmt):
    """A quiet first piece (no row), then a piece whose force is all NaN and whose
    events are all empty: every column has the type the definition gives it."""
    from tactsense.estimate.contacts import ContactTable
    from tactsense.estimate.output import ContactsWriter, contacts_schema

    def tracked(table):
        n = len(table)
        table.id = np.arange(n, dtype=np.int64)
        table.vx_mm_s = table.vy_mm_s = table.vz_mm_s = np.zeros(n)
        table.slip = np.zeros(n, bool)
        return table

    quiet = tracked(ContactTable.empty(10))
    n = 3
    busy = tracked(
        ContactTable(
            frame=np.arange(10, 10 + n), contact=np.zeros(n, np.int32), x_mm=np.ones(n),
            y_mm=np.ones(n), z_mm=np.zeros(n), row=np.full(n, np.nan), col=np.full(n, np.nan),
            force_n=np.full(n, np.nan), peak=np.ones(n), major_mm=np.ones(n),
            minor_mm=np.ones(n), orientation_deg=np.zeros(n), taxels=np.ones(n, np.int32),
            flags=np.zeros(n, np.int64), n_frames=n,
        )
    )  # fmt: skip
    path = tmp_path / f"c.{fmt}"
    with ContactsWriter(path) as writer:
        writer.write_contacts(np.zeros(0), quiet)
        writer.write_contacts(np.arange(n) * 0.01, busy)
    got = read(path)
    assert len(got["frame"]) == n
    assert np.isnan(got["force_n"]).all()
    assert (got["event"].astype(str) == "").all()
    if fmt == "parquet":
        schema = pq.read_schema(path)
        assert schema.field("event").type == pa.string()
        assert schema.field("contact").type == pa.int64()
        assert schema.remove_metadata().equals(contacts_schema(schema.names))
    if fmt == "h5":
        with h5py.File(path) as f:
            assert f["contact"].dtype == np.int64 and f["slip"].dtype == bool


# ---- item 5: BELOW_BASELINE means a fault, calibrated forces are never negative ------


@pytest.fixture(scope="module")
def capacitive(tmp_path_factory):
    """A capacitive pad and a point set pressed after untouched frames."""
    folder = tmp_path_factory.mktemp("capacitive")
    for name in ("pad4", "dome12"):
        cli("simulate", "--sensor", name, "--scenario", "press", "--out", folder / f"{name}.h5")
    return folder


@pytest.mark.parametrize("name", ["pad4", "dome12"])
def test_tension_beside_a_contact_is_not_below_baseline(capacitive, name):
    """Issue 31 item 5: the neighbours of a press on a capacitive array read tension
    (below the baseline: 52 of 53 rows of pad4, 25 of 33 of dome12 were flagged, with
    the warning that the baseline was touched). The baseline was taken untouched: no row
    may carry BELOW_BASELINE and there is no warning. A baseline taken under the press
    (``--baseline-frames 50``) still warns."""
    out = capacitive / f"{name}.parquet"
    line = cli("locate", capacitive / f"{name}.h5", "--out", out, "-q", "--force")
    flags = pq.read_table(out)["flags"].to_numpy()
    assert len(flags) > 20
    assert not (flags & int(ts.Flag.BELOW_BASELINE)).any()
    assert "below the baseline" not in line
    late = capacitive / f"{name}-late.parquet"
    line = cli("locate", capacitive / f"{name}.h5", "--baseline-frames", 50, "--out", late,
               "-q", "--force")  # fmt: skip
    assert "below the baseline" in line


@pytest.mark.parametrize(("name", "quoted"), [("pad4", 0.84), ("dome12", 0.18)])
def test_tension_depth_quoted_in_contacts_md(capacitive, name, quoted):
    """The numbers docs/contacts.md quotes for the rule (not a fault case): the deepest
    tension beside a press over the press's peak, on the `press` scenario; below 1, as
    the rule of BELOW_BASELINE assumes."""
    rec = ts.read_recording(capacitive / f"{name}.h5")
    frames = rec.frames.astype(float).reshape(len(rec.frames), -1)
    base = np.median(frames[:5], axis=0)
    signal = (frames - base) / frames  # eq. 4
    touched = signal.max(axis=1) > 0.005
    ratio = -signal[touched].min(axis=1) / signal[touched].max(axis=1)
    assert round(float(ratio.max()), 2) == quoted


def test_a_calibrated_force_is_never_negative():
    """Issue 31 item 5: the force curve extended below its first knot went negative (26
    of 100 rows of a calibrated pad). Knots (0.1, 0.05) and (0.2, 0.5) extend to -0.175 N
    at 0.05 N estimated; the force is clamped at zero, NaN stays NaN."""
    from tactsense.estimate.contacts.array_calibration import ArrayCalibration

    pad = ts.preset("pad4")
    ones = np.ones(pad.shape)
    cal = ArrayCalibration(
        pad.to_toml_string(), ones * 2000, ones, ones < 0, ([0.1, 0.2], [0.05, 0.5])
    )
    out = cal.force([0.05, 0.1, 0.15, -0.2, np.nan])
    np.testing.assert_allclose(out[:4], [0.0, 0.05, 0.275, 0.0])
    assert np.isnan(out[4])


@pytest.fixture(scope="module")
def bench(tmp_path_factory):
    """The bench of tests/estimate/test_array_calibration.py: a 50-g probe on every taxel
    of pad4, 24 presses of 0.1-1 N and the load cell's log of them, and logs gone wrong."""
    import csv

    from tactsense import flat_scenarios as fs
    from tests.estimate.test_array_calibration import _loads, _log

    folder = tmp_path_factory.mktemp("bench")
    pad = ts.preset("pad4")
    ts.write_recording(folder / "bench.h5", ts.simulate(pad, fs.raster(pad), rng=1))
    loads = _loads(pad)
    ts.write_recording(folder / "loads.h5", loads)
    _log(loads, folder / "loads.csv")
    with open(folder / "loads.csv", newline="") as stream:
        rows = list(csv.reader(stream))
    # the same log negated (compression negative), in grams, and of another session
    # (the 24 presses' forces in another order on the same clock)
    steps = np.array_split(np.arange(len(rows) - 1), 24)
    order = np.random.default_rng(0).permutation(24)
    other = [rows[1 + i][1] for k in order for i in steps[k]]
    variants = {
        "negated": lambda k, f: -f,
        "grams": lambda k, f: f * 1000 / 9.80665,
        "other": lambda k, f: float(other[k]),
    }
    for name, change in variants.items():
        with open(folder / f"{name}.csv", "w", newline="") as stream:
            writer = csv.writer(stream)
            writer.writerow(rows[0])
            for k, row in enumerate(rows[1:]):
                writer.writerow([row[0], f"{change(k, float(row[1])):.6f}", row[2]])
    return folder


@pytest.mark.parametrize(
    ("log", "expected"),
    [
        ("negated", "positive in compression"),
        ("grams", "must be in newtons"),
        ("other", "does not rise with the recording's force"),
    ],
)
def test_a_force_log_gone_wrong_is_refused(bench, log, expected):
    """Issue 31 item 5: --force-log took a negated log (every press mapped to 0.0022 N)
    or a log in grams (100x) with exit 0. Each is refused: exit 2, one line, no file."""
    out = bench / f"cal_{log}.json"
    done = runner.invoke(app, ["calibrate", str(bench / "bench.h5"), "--loads",
                               str(bench / "loads.h5"), "--force-log", str(bench / f"{log}.csv"),
                               "--out", str(out)])  # fmt: skip
    assert done.exit_code == 2, done.output
    assert expected in " ".join(done.output.split())
    assert "Traceback" not in done.output
    assert not out.exists()


def test_the_force_log_checks_are_reported(bench):
    """The right log passes, and the calibration says what was checked; the scale
    quoted in LOG_SCALE_LIMIT's docstring."""
    import json

    out = bench / "cal.json"
    line = cli("calibrate", bench / "bench.h5", "--loads", bench / "loads.h5", "--force-log",
               bench / "loads.csv", "--out", out)  # fmt: skip
    assert "force log checked" in line
    notes = json.loads(out.read_text())["notes"]
    assert round(notes["force_log_scale"], 2) == 1.90  # with the twin's creep taken out
    assert notes["force_log_rank_correlation"] > 0.5


# ---- item 13 (estimation): messages that say where and what ------------------------


@pytest.mark.parametrize("reader", ["read_force_log", "read_stage_log"])
def test_a_blank_cell_in_a_log_names_its_line(tmp_path, reader):
    """Issue 31 item 13: a blank cell in a knife (stage) log or a force log said
    "could not convert string to float: ''", no line. Now: the line and the column."""
    from tactsense.estimate.contacts import array_calibration

    path = tmp_path / "log.csv"
    path.write_text("time_s,position_mm,force_n\n0.0,1.0,0.0\n0.1,1.0,0.5\n0.2,1.0,\n0.3,1.0,0.0\n")
    with pytest.raises(array_calibration.ArrayCalibrationError) as error:
        getattr(array_calibration, reader)(path)
    assert str(error.value) == f"{path}, line 4: force_n is blank; expected a number"


def test_a_damaged_array_calibration_names_the_missing_key(bench):
    """Issue 31 item 13: "badcal.json is damaged: 'sensor_toml'". Now the key is named
    as missing, and what the file should be is said; exit 2, no traceback."""
    import json

    good = bench / "cal.json"
    if not good.exists():
        cli("calibrate", bench / "bench.h5", "--out", good)
    data = json.loads(good.read_text())
    del data["sensor_toml"]
    bad = bench / "badcal.json"
    bad.write_text(json.dumps(data))
    done = runner.invoke(app, ["locate", str(bench / "loads.h5"), "--calibration", str(bad),
                               "--out", str(bench / "x.csv")])  # fmt: skip
    said = " ".join(done.output.split())
    assert done.exit_code == 2, said
    assert "the key 'sensor_toml' is missing" in said
    assert "array calibration is the JSON file 'tactsense calibrate' writes" in said


def test_a_damaged_finger_calibration_names_the_missing_key(tmp_path):
    import json

    from tactsense.estimate.finger.calibrate import FORMAT, Calibration, CalibrationError

    path = tmp_path / "badcal.json"
    path.write_text(json.dumps({"format": FORMAT, "version": 1}))
    with pytest.raises(CalibrationError, match="the key 'threshold_g_per_count' is missing"):
        Calibration.load(path)


def test_a_repeated_taxel_position_is_said_in_plain_numbers(tmp_path):
    """Issue 31 item 13: the duplicate-taxel error printed np.float64(0.0)."""
    import dataclasses

    dome = ts.preset("dome12")
    positions = list(dome.taxels.positions_mm)
    positions[5] = positions[0]
    taxels = dataclasses.replace(dome.taxels, positions_mm=tuple(positions))
    with pytest.raises(ts.SensorSpecError) as error:
        dataclasses.replace(dome, taxels=taxels)
    said = str(error.value)
    assert "positions_mm[5] = [0.0, 0.0, 7.5] repeats another taxel's position (taxel 0's)" in said
    assert "np.float64" not in said
