"""docs/contacts.md holds what its commands and scripts give: the generated resolution and
accuracy block, the summary line of its example, and a pandas example that runs."""

import importlib.util
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[2]
DOC = ROOT / "docs" / "contacts.md"


def _script():
    spec = importlib.util.spec_from_file_location(
        "contacts_numbers", ROOT / "scripts" / "contacts_numbers.py"
    )
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _cli(*args, cwd):
    done = subprocess.run([sys.executable, "-m", "tactsense.cli", *args], cwd=cwd,
                          capture_output=True, text=True, timeout=300)  # fmt: skip
    assert done.returncode == 0, done.stderr
    return " ".join(done.stderr.split())


@pytest.fixture(scope="module")
def example(tmp_path_factory):
    folder = tmp_path_factory.mktemp("doc")
    _cli("simulate", "--sensor", "pad16", "--scenario", "two-probes", "--out", "two.h5",
         cwd=folder)  # fmt: skip
    return folder


def test_the_generated_block_is_what_the_script_gives():
    doc = DOC.read_text(encoding="utf-8")
    assert _script().block() in doc


def test_the_accuracy_block_is_what_the_script_gives():
    doc = (ROOT / "docs" / "accuracy.md").read_text(encoding="utf-8")
    assert _script().accuracy_block() in doc


def test_the_example_lines_are_what_locate_prints(example):
    doc = " ".join(DOC.read_text(encoding="utf-8").split())
    line = _cli("locate", "two.h5", "--out", "est.parquet", cwd=example)
    said = re.search(r"wrote est\.parquet: .* splits; creep: [a-z]+( \([a-z ]+\))?", line).group(0)
    assert said in doc
    warning = _cli("locate", "two.h5", "--baseline-frames", "60", "--out", "late.csv",
                   cwd=example)  # fmt: skip
    said = re.search(r"warning: .* untouched frames first", warning).group(0)
    assert said in doc


def test_the_pandas_example_runs(example):
    _cli("locate", "two.h5", "--out", "est.parquet", "--force", cwd=example)
    text = DOC.read_text(encoding="utf-8")
    code = re.search(r"### Loading it in pandas\n\n```python\n(.*?)```", text, re.S).group(1)
    done = subprocess.run([sys.executable, "-c", code], cwd=example, capture_output=True,
                          text=True, timeout=120)  # fmt: skip
    assert done.returncode == 0, done.stderr
    assert re.fullmatch(r"2 ids, at most 2 at once, 2 births\n", done.stdout), done.stdout


def test_the_column_table_names_every_column(example):
    import pandas as pd

    _cli("locate", "two.h5", "--out", "cols.parquet", cwd=example)
    text = DOC.read_text(encoding="utf-8")
    table = text.split("## The long table", 1)[1].split("### Loading", 1)[0]
    named, joint = set(), set()
    for row in table.splitlines():
        if row.startswith("| `"):
            names = set(re.findall(r"`([a-z_0-9]+)`", row.split("|")[1]))
            # the rows of `--method joint`'s extras: the columns of that method's table
            (joint if "(`--method joint`)" in row else named).update(names)
    assert named == set(pd.read_parquet(example / "cols.parquet").columns)
    from tactsense.estimate.contacts import find_contacts
    from tactsense.sensor.registry import load_sensor

    spec = load_sensor("pad4")
    frame = np.zeros(spec.shape)
    frame[1:3, 1:3] = 0.02  # one contact's worth of signal [-]
    assert joint == set(find_contacts(frame, spec, counts=False, method="joint").extra)
