"""Bad input to ``tactsense import`` of an iCub grasp trial (``--format icub-grasp``):
exit status 2, one line naming the line and what was expected, no traceback, nothing
at the output."""

import pytest
from typer.testing import CliRunner

from tactsense.cli import app

runner = CliRunner()

ENCODERS = "20.7 81.0 15.3 0.5 40.3 66.6 36.2 55.5 2.0"
MAXIMA = "14.0 15.0 11.0 14.0 11.0"
TAXELS = " ".join(["243.0"] * 12)
SLICE = [ENCODERS, MAXIMA, *[TAXELS] * 5]


def _trial(*slices, header="-10000"):
    lines = [header] if header is not None else []
    for s in slices:
        lines += s
    return "\n".join(lines) + "\n"


def _replaced(slot, text):
    lines = list(SLICE)
    lines[slot] = text
    return lines


@pytest.fixture(scope="module")
def workspace(tmp_path_factory):
    folder = tmp_path_factory.mktemp("icub_matrix")
    files = {
        "good.txt": _trial(SLICE, SLICE),
        "truncated.txt": _trial(SLICE, SLICE[:4]),
        "short_line.txt": _trial(SLICE, _replaced(4, " ".join(["243.0"] * 11))),
        "long_encoders.txt": _trial(_replaced(0, ENCODERS + " 1.0")),
        "short_maxima.txt": _trial(_replaced(1, "14.0 15.0 11.0 14.0")),
        "word.txt": _trial(SLICE, _replaced(6, TAXELS.replace("243.0", "abc", 1))),
        "nan.txt": _trial(_replaced(3, TAXELS.replace("243.0", "nan", 1))),
        "above_8_bits.txt": _trial(_replaced(2, TAXELS.replace("243.0", "300.0", 1))),
        "negative.txt": _trial(_replaced(5, TAXELS.replace("243.0", "-1.0", 1))),
        "no_header.txt": _trial(SLICE, header=None),
        "header_only.txt": "-10000\n",
        "empty.txt": "",
    }
    for name, text in files.items():
        (folder / name).write_text(text)
    (folder / "binary.txt").write_bytes(b"-10000\n\xff\xfe\x00 garbage\n")
    (folder / "good.csv").write_text("time," + ",".join(f"v{k}" for k in range(12)) + "\n")
    return folder


ICUB = "--format icub-grasp --finger index"
CASES = [
    # (command line, what the message must name)
    (f"import DIR/truncated.txt {ICUB} --out OUT", "starts on line 9 has 4 of its 7 lines"),
    (
        f"import DIR/short_line.txt {ICUB} --out OUT",
        "line 13: 11 numbers; line 5 of a time slice holds the middle taxels, 12 numbers",
    ),
    (f"import DIR/long_encoders.txt {ICUB} --out OUT", "line 2: 10 numbers"),
    (f"import DIR/short_maxima.txt {ICUB} --out OUT", "fingertip maxima, 5 numbers"),
    (f"import DIR/word.txt {ICUB} --out OUT", "line 15: 'abc' is not a number"),
    (f"import DIR/nan.txt {ICUB} --out OUT", "line 5: a value is not a finite number"),
    (f"import DIR/above_8_bits.txt {ICUB} --out OUT", "the reading 300 is outside 0-255"),
    (f"import DIR/negative.txt {ICUB} --out OUT", "the reading -1 is outside 0-255"),
    (f"import DIR/no_header.txt {ICUB} --out OUT", "starts with the line -10000"),
    (f"import DIR/header_only.txt {ICUB} --out OUT", "no time slice after it"),
    (f"import DIR/empty.txt {ICUB} --out OUT", "empty.txt is empty"),
    (f"import DIR/binary.txt {ICUB} --out OUT", "not a text file of numbers"),
    ("import DIR/good.txt --out OUT", "say which with --finger"),
    ("import DIR/good.txt --finger pinky --out OUT", "'pinky' is not an iCub fingertip"),
    ("import DIR/good.txt --finger index --sensor pad4 --out OUT", "has 4 x 4 taxels"),
    ("import DIR/good.txt --finger index --period 0 --out OUT", "--period"),
    ("import DIR/good.txt --finger index --period nan --out OUT", "NaN is not a number"),
    ("import DIR/good.txt --finger index --format icub --out OUT", "--format 'icub'"),
    ("import DIR/good.csv --sensor pad4 --finger index --out OUT", "--finger applies to"),
    ("import DIR --format icub-grasp --finger index --out OUT", "reads one trial file"),
    ("import DIR/no_header.txt --finger index --out OUT", "its first line is not -10000"),
]


@pytest.mark.parametrize("line, names", CASES, ids=[line for line, _ in CASES])
def test_bad_icub_grasp_input(workspace, line, names):
    out = workspace / "never_written.h5"
    args = line.replace("OUT", str(out)).replace("DIR", str(workspace)).split()
    result = runner.invoke(app, args)
    message = " ".join(result.output.split())
    assert result.exit_code == 2, message
    assert "Traceback" not in message, message
    assert names in message, message
    assert not out.exists()
    assert not list(workspace.glob(".never_written*"))  # no temporary left either


def test_the_good_trial_imports(workspace, tmp_path):
    """The matrix's own well-formed trial imports (so its cases fail for their fault)."""
    out = tmp_path / "good.h5"
    result = runner.invoke(app, ["import", str(workspace / "good.txt"), "--finger", "index",
                                 "--out", str(out)])  # fmt: skip
    said = " ".join(result.output.split())
    assert result.exit_code == 0, said
    assert "2 frames of icub_fingertip (1 x 12)" in said, said
