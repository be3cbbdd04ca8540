"""Usage errors (unknown option, value out of range, NaN, missing argument, unknown
command) are one line ``error: ...`` naming the option and the command's help, exit 2,
not click's four-line usage block."""

import subprocess
import sys

import pytest

CASES = [
    # (arguments, what the one line must name)
    (["design", "aliasing", "--spacing", "0"], "'--spacing': Input should be greater"),
    (["design", "aliasing", "--spacing", "nan"], "'--spacing': NaN is not a number"),
    (["simulate", "--bogus"], "No such option: --bogus"),
    (["locate"], "Missing argument"),
    (["bogus"], "No such command 'bogus'"),
]


@pytest.mark.parametrize(("args", "names"), CASES, ids=[" ".join(a) for a, _ in CASES])
def test_usage_errors_are_one_line(args, names):
    done = subprocess.run(
        [sys.executable, "-m", "tactsense.cli", *args],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert done.returncode == 2
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1, done.stderr
    assert lines[0].startswith("error: ")
    assert names in lines[0]
    assert "--help')" in lines[0]
    assert "Usage:" not in done.stderr and "Traceback" not in done.stderr


def test_tables_are_not_wrapped_when_piped(capsys):
    """Piped, a table keeps every cell on one line (rich would wrap at 80 columns)."""
    from rich.table import Table

    from tactsense.cli._common import print_table

    table = Table()
    long_cell = "localization_circumference_deg_" + "x" * 60
    for name in ("claim", "basis", "verdict"):
        table.add_column(name)
    table.add_row(long_cell, "a basis text that is long " * 3, "agrees")
    print_table(table)
    out = capsys.readouterr().out
    assert any(long_cell in line and "agrees" in line for line in out.splitlines())
