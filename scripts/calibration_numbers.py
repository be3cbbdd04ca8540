"""Regenerate the numbers docs/calibration.md quotes for its own command lines.

Run: ``python scripts/calibration_numbers.py`` (runs the commands of the document's
"Command line" section in a temporary folder, about half a minute, and rewrites the
text between the markers ``<!-- commands:start -->`` and ``<!-- commands:end -->`` of
docs/calibration.md). ``tests/test_calibration_doc.py`` checks that the document holds
what :func:`block` computes, so the numbers are never typed by hand.
"""

from __future__ import annotations

import tempfile
from pathlib import Path

DOC = Path(__file__).resolve().parents[1] / "docs" / "calibration.md"
START, END = "<!-- commands:start -->", "<!-- commands:end -->"

COMMANDS = [
    "simulate --scenario calibration --out sweep.h5",
    "simulate --scenario knife-edge --out knife.h5",
    "simulate --scenario repeated --repeats 5 --dwell-s 3 --out steps.h5",
    "calibrate sweep.h5 --out calibration.json --steps steps.h5 --knife knife.h5 --row 4 --col 0",
    "calibrate sweep.h5 --out knife_alone.json --knife knife.h5 --row 4 --col 0",
]
"""The document's commands (the last: the knife-edge fit without --steps)."""


def run(folder: Path) -> dict:
    """Run :data:`COMMANDS` in ``folder``; the calibrations they write."""
    import os

    from typer.testing import CliRunner

    from tactsense.cli import app
    from tactsense.estimate.finger.calibrate import Calibration

    runner = CliRunner()
    here = os.getcwd()
    os.chdir(folder)
    try:
        for line in COMMANDS:
            result = runner.invoke(app, line.split())
            if result.exit_code != 0:
                raise RuntimeError(f"tactsense {line}: {result.output}")
        return {name: Calibration.load(name) for name in ("calibration.json", "knife_alone.json")}
    finally:
        os.chdir(here)


def block() -> str:
    """The Markdown between the markers, from a run of the commands."""
    with tempfile.TemporaryDirectory() as folder:
        cals = run(Path(folder))
    v = cals["calibration.json"].viscoelastic
    fit, alone = cals["calibration.json"].model_fit, cals["knife_alone.json"].model_fit
    rows = [
        "| what the commands above give | value |",
        "|---|---|",
        f"| creep model from `steps.h5` | delayed {v.delayed_fraction:.3f} x "
        f"{1e3 * v.delayed_time_constant_s:.1f} ms, creep {v.creep_fraction:.3f} x "
        f"{v.creep_time_constant_s:.1f} s |",
        f"| plane-stress fit to `knife.h5`, creep compensated (with `--steps`) | depth "
        f"{fit.depth_mm:.2f} mm, nu {fit.poisson_ratio:.3f}, RMS {fit.rms_percent:.2f} % |",
        f"| the same fit without `--steps` (creep left in) | depth {alone.depth_mm:.2f} mm, "
        f"nu {alone.poisson_ratio:.3f}, RMS {alone.rms_percent:.2f} % |",
    ]
    return f"{START}\n" + "\n".join(rows) + f"\n{END}"


def main() -> None:
    text = DOC.read_text(encoding="utf-8")
    head, rest = text.split(START, 1)
    _, tail = rest.split(END, 1)
    new = block()
    DOC.write_text(head + new + tail, encoding="utf-8")
    print(new)


if __name__ == "__main__":
    main()
