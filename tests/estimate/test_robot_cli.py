"""``tactsense locate RUN/`` on a robot recording: the contacts and wrench tables."""

from __future__ import annotations

import numpy as np
import pyarrow.compute
import pyarrow.csv
import pyarrow.parquet
import pytest
from typer.testing import CliRunner

from tactsense.cli import app
from tactsense.estimate.robot import CONTACT_COLUMNS, WRENCH_COLUMNS
from tests.estimate._robot_sim import write_pressed_recording
from tests.estimate.test_robot_locate import small_skin

runner = CliRunner()


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    return write_pressed_recording(tmp_path_factory.mktemp("robot") / "run", small_skin())


def test_locate_writes_both_tables(run, tmp_path):
    out = tmp_path / "contacts.parquet"
    result = runner.invoke(
        app, ["locate", str(run), "--joints", "j1=0.3,j2=-0.2", "--out", str(out)]
    )
    assert result.exit_code == 0, result.output
    contacts = pyarrow.parquet.read_table(out)
    wrenches = pyarrow.parquet.read_table(tmp_path / "contacts_wrenches.parquet")
    assert contacts.column_names == list(CONTACT_COLUMNS)
    assert wrenches.column_names == list(WRENCH_COLUMNS)
    patch = contacts.column("patch").to_pylist()
    assert set(patch) == {"pad"} and len(patch) == 25  # pressed from frame 5 of 30
    assert "25 contact rows over 30 hand frames" in " ".join(result.output.split())
    total = wrenches.filter(pyarrow.compute.equal(wrenches.column("what"), "total"))
    assert total.num_rows == 30
    fz = np.asarray(total.column("force_x_n")) ** 2 + np.asarray(total.column("force_z_n")) ** 2
    assert (fz[5:] > 0).all() and (fz[:5] == 0).all()


def test_locate_csv_and_no_overwrite(run, tmp_path):
    out = tmp_path / "c.csv"
    wrenches = tmp_path / "w.csv"
    args = ["locate", str(run), "--out", str(out), "--wrenches", str(wrenches)]
    assert runner.invoke(app, args).exit_code == 0
    assert pyarrow.csv.read_csv(out).num_rows == 25
    assert pyarrow.csv.read_csv(wrenches).num_rows == 30 * 3  # link2, link3, total
    again = runner.invoke(app, args)
    assert again.exit_code == 2 and "exists" in again.output
