"""``tactsense locate`` on pads and with ``--contacts``: the long table of tracked
contacts, its events, and the summary line equal to what the file holds."""

import re
import subprocess
import sys

import h5py
import numpy as np
import pandas as pd
import pyarrow.parquet as pq
import pytest

import tactsense as ts


def run(*args, cwd):
    done = subprocess.run(
        [sys.executable, "-m", "tactsense.cli", *args],
        capture_output=True, text=True, cwd=cwd, timeout=600,
    )  # fmt: skip
    assert done.returncode == 0, done.stderr
    return " ".join(done.stderr.split())


@pytest.fixture(scope="module")
def two(tmp_path_factory):
    folder = tmp_path_factory.mktemp("two")
    run("simulate", "--sensor", "pad16", "--scenario", "two-probes", "--out", "two.h5", cwd=folder)
    return folder


def _summary(line):
    numbers = re.search(
        r"(\d+) frames, (\d+) contact rows in (\d+) frames \(at most (\d+) at once\), (\d+) "
        r"tracked ids; (\d+) births, (\d+) deaths, (\d+) merges, (\d+) splits",
        line,
    )
    assert numbers, line
    return [int(x) for x in numbers.groups()]


def test_the_issue_line_two_probes_two_ids(two):
    """The done-when line of issue 24: two contacts with stable ids."""
    line = run("locate", "two.h5", "--out", "est.parquet", cwd=two)
    frames, rows, with_contact, most, ids, births, deaths, merges, splits = _summary(line)
    table = pd.read_parquet(two / "est.parquet")
    assert len(table) == rows and table["frame"].nunique() == with_contact
    assert table.groupby("frame").size().max() == most == 2
    assert table["id"].nunique() == ids
    events = pq.read_metadata(two / "est.parquet").metadata[b"events"]
    assert events.count(b'"birth"') == births and events.count(b'"death"') == deaths
    assert events.count(b'"merge"') == merges and events.count(b'"split"') == splits
    # while both probes press (0.2-0.7 s), the same two ids in every frame, 5 mm apart
    loaded = table[(table.time_s > 0.25) & (table.time_s < 0.65)]
    assert loaded.groupby("frame").size().eq(2).all()
    assert loaded["id"].nunique() == 2
    per_id = loaded.groupby("id")["y_mm"].mean().sort_values()
    assert per_id.diff().iloc[1] == pytest.approx(5.0, abs=2.5)
    assert (table["event"] == "birth").sum() == births
    assert frames == ts.read_recording(two / "two.h5").frames.shape[0]


def test_csv_has_an_events_file_and_h5_an_events_group(two):
    run("locate", "two.h5", "--out", "est.csv", cwd=two)
    table = pd.read_csv(two / "est.csv")
    events = pd.read_csv(two / "est.events.csv")
    assert set(events["kind"]) <= {"birth", "death", "merge", "split"}
    assert (events["kind"] == "birth").sum() == table["id"].nunique()
    assert {"x_mm", "y_mm", "force_n", "major_mm", "slip", "flag_names"} <= set(table.columns)
    run("locate", "two.h5", "--out", "est.h5", cwd=two)
    with h5py.File(two / "est.h5") as h5:
        assert h5.attrs["format"] == "tactsense-contacts"
        np.testing.assert_array_equal(h5["id"][:], table["id"].to_numpy())
        np.testing.assert_allclose(h5["x_mm"][:], table["x_mm"].to_numpy())
        assert list(h5["events"]["kind"].asstr()[:]) == list(events["kind"])


def test_finger_contacts_option(tmp_path):
    run("simulate", "--out", "rec.h5", cwd=tmp_path)
    run("locate", "rec.h5", "--out", "one.csv", cwd=tmp_path)
    line = run("locate", "rec.h5", "--contacts", "--out", "long.csv", cwd=tmp_path)
    one = pd.read_csv(tmp_path / "one.csv")
    long = pd.read_csv(tmp_path / "long.csv")
    assert {"axial_mm", "angle_deg", "id", "x_mm"} <= set(long.columns)
    assert "axial_mm" in one.columns and "id" not in one.columns
    assert _summary(line)[1] == len(long)


def test_drift_baseline_and_the_touched_baseline_warning(two, tmp_path):
    """``--drift-s``: the baseline follows untouched taxels (fewer phantom contacts after
    the repeated loads creep); a baseline made of pressed frames is warned about."""
    run("simulate", "--scenario", "repeated", "--repeats", "40", "--out", "rep.h5", cwd=tmp_path)
    fixed = _summary(run("locate", "rep.h5", "--contacts", "--drift-s", "0", "--out", "f.csv",
                         cwd=tmp_path))  # fmt: skip
    follows = _summary(run("locate", "rep.h5", "--contacts", "--out", "d.csv", cwd=tmp_path))
    # frames with a contact: the loaded half only with the drift baseline (the test of
    # DriftBaseline holds the count of lifted frames); nearly all with a fixed one
    assert fixed[2] > 0.9 * fixed[0]
    assert follows[2] < 0.6 * follows[0]
    # two-probes presses from 0.2 s (frame 20): a baseline from the first 60 frames
    # holds the press, and the frames after the lift read below it
    line = run("locate", "two.h5", "--baseline-frames", "60", "--out", "late.csv", cwd=two)
    assert re.search(r"warning: (\d+) frames read below the baseline", line), line
    clean = run("locate", "two.h5", "--out", "clean.csv", cwd=two)
    assert "warning" not in clean


def test_a_nan_in_the_baseline_frames_does_not_kill_its_taxel(tmp_path):
    """One unreadable value among the untouched frames: the baseline is the median of the
    others there, not NaN (which would flag every contact DEAD_TACTEL)."""
    import dataclasses

    from tactsense import flat_scenarios as fs
    from tactsense.batch import contacts_file
    from tactsense.estimate import Flag

    pad = ts.preset("pad16")
    rec = ts.simulate(pad, fs.two_probes(pad), rng=0)
    frames = rec.frames.astype(float)
    frames[1, 3, 3] = np.nan
    ts.write_recording(tmp_path / "nan.h5", dataclasses.replace(rec, frames=frames))
    contacts_file(tmp_path / "nan.h5", tmp_path / "nan.parquet")
    table = pd.read_parquet(tmp_path / "nan.parquet")
    assert len(table) > 0
    assert not (table["flags"] & int(Flag.DEAD_TACTEL)).any()


@pytest.mark.parametrize("method", ["interpolate", "joint"])
def test_a_recording_without_contacts_gets_the_methods_columns(tmp_path, method):
    """A recording with no contact at all still gets a file with its method's columns
    (``--method joint`` adds some): a traceback before (trial 36)."""
    import pyarrow.parquet

    from tactsense.batch import contacts_file
    from tactsense.io.recording import Recording, write_recording
    from tactsense.sensor import preset

    spec = preset("pad4")
    rest = np.full((12, *spec.shape), spec.electronics.nominal_counts, np.uint16)
    write_recording(
        tmp_path / "rest.h5",
        Recording(rest, np.arange(12) * 0.01, np.zeros(spec.shape), spec),
    )
    out = tmp_path / f"{method}.parquet"
    assert contacts_file(tmp_path / "rest.h5", out, method=method)["rows"] == 0
    columns = pyarrow.parquet.read_schema(out).names
    assert ("contact_radius_mm" in columns) == (method == "joint")
