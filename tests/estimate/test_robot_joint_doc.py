"""docs/robot.md, "Broad contacts: --method joint": each figure its prose quotes is one of
the rows scripts/hand_joint_numbers.py wrote in the generated block (a regenerated block
whose rows moved makes this fail until the prose follows)."""

from __future__ import annotations

import re
from pathlib import Path

DOC = Path(__file__).resolve().parents[2] / "docs" / "robot.md"


def _parts():
    doc = DOC.read_text()
    block = doc.split("<!-- hand-joint-numbers -->")[1].split("<!-- /hand-joint-numbers -->")[0]
    prose = doc.split("<!-- /hand-joint-numbers -->")[1].split("<!-- /r7-handloc -->")[0]
    return block, " ".join(prose.split())


def test_prose_figures_are_the_blocks():
    block, prose = _parts()
    cells = {c.strip() for line in block.splitlines() if line.startswith("|")
             for c in line.strip("|").split("|")}  # fmt: skip
    words = set(" ".join(cells).split()) | set(re.findall(r"[-+]?[\d,]+\.?\d*", block))
    quoted = {
        "2.00", "1.99", "-0.5", "0.30", "-85.0", "-12.2", "-17.5", "-33.3", "-5.4", "+3.2",
        "2.06", "17 of 25", "+45.4", "-23.5", "+26.7",
    }  # fmt: skip
    for figure in quoted:
        assert figure in prose.replace(" %", ""), figure
        assert figure in words or figure in cells or figure.replace(",", "") in cells, figure


def test_the_ten_places_read_by_seven_or_more_taxels_are_within_two_per_cent():
    """The prose: noise-free, within 2 % wherever 7 or more taxels read (10 of 10), and
    interpolate 32.2-88.0 % low there."""
    block, prose = _parts()
    assert "(10 of 10 places)" in prose and "32.2-88.0 % low" in prose
    joint, interp = [], []
    for line in block.splitlines():
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if len(cells) != 9 or cells[2] != "none":
            continue
        taxels = [int(v) for v in cells[3].split()]
        for n, i, j in zip(taxels, cells[4].split(), cells[6].split(), strict=True):
            if n >= 7:
                joint.append(float(j))
                interp.append(float(i))
    assert len(joint) == 10
    assert max(abs(v) for v in joint) <= 2.0
    assert (min(interp), max(interp)) == (-88.0, -32.2)
