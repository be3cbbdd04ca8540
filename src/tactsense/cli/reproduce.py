"""``tactsense reproduce``: the main job."""

from __future__ import annotations

import os
import shutil
from pathlib import Path
from typing import Annotated

import typer
from rich.table import Table

from tactsense._validation import TactsenseInputError
from tactsense.cli._common import (
    SensorOption,
    console,
    fail,
    inside,
    new_group,
    print_table,
    progress_bar,
    remove_stale_partials,
    sensor_file,
)
from tactsense.kinds import KindNotSupported, kind_of, kinds
from tactsense.sensor import load_sensor

app = new_group("The paper's experiments on the twin.")


@app.command()
def reproduce(
    out: Annotated[
        Path,
        typer.Option(
            "--out",
            "-o",
            help="New directory for the figures, report.md, report.html and results.json.",
        ),
    ] = Path("paper-report"),
    quick: Annotated[
        bool,
        typer.Option(
            help="Fewer positions and repetitions: a reduced run for tests and a first look."
        ),
    ] = False,
    sensor: SensorOption = "initial",
    force: Annotated[
        bool,
        typer.Option(
            "--force",
            help="Write into OUT even if it exists (its report files "
            "are replaced; nothing else in it is touched).",
        ),
    ] = False,
) -> None:
    """Run the paper's experiments on the digital twin and write the claims report."""
    from tactsense.reproduce import reproduce as run_reproduce

    try:
        spec = load_sensor(sensor)
        kind = kind_of(spec)
        if kind.design_model != "paper":  # the paper's experiments need the paper's model
            paper = " and ".join(f"{k.name} sensors" for k in kinds().values()
                                 if k.design_model == "paper")  # fmt: skip
            raise KindNotSupported(f"reproduce (the paper's experiments) works on {paper}; "
                                   f"{spec.name!r} is a {kind.label}")  # fmt: skip
        if out.exists() and not out.is_dir():
            fail(f"{out} is a file; expected a directory for the report")
        for source in sensor_file(sensor):
            if inside(source, out):
                fail(
                    f"the report directory {out} holds the input --sensor {source}; an output "
                    "never replaces an input: choose another directory"
                )
        if out.exists() and not force:
            fail(f"{out} exists; pass --force to write into it, or choose another directory")
        parent = out.parent
        if parent.exists() and not parent.is_dir():
            fail(f"{parent} in the report directory {out} is a file, not a folder")
        if not parent.is_dir():
            fail(f"folder {parent} of the report directory {out} does not exist; create it first")
        if not os.access(parent, os.W_OK | os.X_OK):
            fail(f"cannot write the report: folder {parent} is not writable")
        # a new report is built in a hidden folder and renamed into place when complete
        remove_stale_partials(parent)
        target = out if out.exists() else parent / f".{out.name}.{os.getpid()}.partial"
        with progress_bar("{task.description:<36}") as bar:
            task = bar.add_task("experiments", total=None)

            def update(name: str, done: int, total: int) -> None:
                bar.update(task, description=name, completed=done, total=total)

            try:
                result = run_reproduce(
                    target, quick=quick, force=True, sensor=spec, progress=update
                )
            except BaseException:
                if target != out:
                    shutil.rmtree(target, ignore_errors=True)
                raise
        if target != out:
            target.rename(out)
    except (TactsenseInputError, FileExistsError) as error:
        fail(str(error))
    from tactsense.reproduce.report import summary

    claims = list(result["claims"].values())
    table = claims_table(
        claims, f"{len(result['figures'])} figures and {len(claims)} claims in {out}"
    )
    print_table(table)
    console.print(
        f"{summary(claims)} Open {out / 'report.html'} for the figures and the reasons "
        "behind each difference."
    )


def claims_table(claims, title: str) -> Table:
    """The terminal table of claims: every claim id whole, however narrow the terminal.

    The ids are what the report and results.json are searched by (three begin with
    "localization"), so their column is never shortened; the basis column, the one to
    give way, wraps instead.
    """
    table = Table(title=title)
    width = max((len(claim.id) for claim in claims), default=5)
    table.add_column("claim", no_wrap=True, min_width=width, overflow="fold")
    for column in ("paper", "tactsense"):
        table.add_column(column, no_wrap=True, justify="right")
    table.add_column("unit", overflow="fold")
    table.add_column("basis", overflow="fold")
    table.add_column("verdict", overflow="fold")
    for claim in claims:
        table.add_row(
            claim.id,
            "-" if claim.paper is None else f"{claim.paper:.4g}",
            f"{claim.computed:.4g}",
            claim.unit,
            claim.basis,
            claim.verdict,
        )
    return table
