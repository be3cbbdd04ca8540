"""``tactsense batch``: many recordings located on a Dask cluster."""

from __future__ import annotations

from enum import StrEnum
from pathlib import Path
from typing import Annotated

import typer
from rich.console import Console
from rich.table import Table

from tactsense._validation import TactsenseInputError
from tactsense.cli._common import (
    ContactThresholdOption,
    atomic_output,
    console,
    fail,
    progress_bar,
    same_file,
)


def _has_bokeh() -> bool:
    from importlib.util import find_spec

    return find_spec("bokeh") is not None


class OutputFormat(StrEnum):
    parquet = "parquet"
    csv = "csv"
    h5 = "h5"


def batch(
    recordings: Annotated[
        list[str],
        typer.Argument(help="Recordings (HDF5) or glob patterns, e.g. 'lab/*.h5' (quoted)."),
    ],
    out: Annotated[
        Path,
        typer.Option(
            "--out",
            "-o",
            help="Folder for one output per recording (created if its parent exists) and "
            "summary.csv (rewritten by every run; a skipped recording keeps its row). "
            "It may be the recordings' folder unless an output would replace an input.",
        ),
    ],
    format: Annotated[
        OutputFormat, typer.Option("--format", help="Format of the outputs.")
    ] = OutputFormat.parquet,
    calibration: Annotated[
        Path | None,
        typer.Option(help="Calibration JSON applied to every recording (same sensor)."),
    ] = None,
    threshold: ContactThresholdOption = None,
    workers: Annotated[
        int,
        typer.Option(
            min=1, max=256, help="Worker processes of the local Dask cluster (one core each)."
        ),
    ] = 2,
    scheduler: Annotated[
        str | None,
        typer.Option(
            help="Address of an existing Dask scheduler (tcp://HOST:PORT) instead of a "
            "local cluster; its workers must see the same files and have tactsense."
        ),
    ] = None,
    split_frames: Annotated[
        int | None,
        typer.Option(
            min=1000,
            max=10**9,
            help="Split a recording of more frames than this into ranges of this many, "
            "one task each, joined in order: the same output (with a creep calibration, "
            "a first pass finds the compensation's memories at the start of each range).",
        ),
    ] = None,
    quiet: Annotated[bool, typer.Option("--quiet", "-q", help="No progress bar.")] = False,
) -> None:
    """Locate every frame of many recordings on a Dask cluster, one task per recording.

    A finger's output has one row per frame; a pad's or a point set's every contact,
    tracked, as 'locate' writes them (its 'contacts' column in summary.csv then counts
    contacts, not frames; such a recording is never split).

    Resumable: a recording whose output is complete and newer is skipped (its row in
    summary.csv keeps the numbers of the run that wrote it). summary.csv has one column
    per loss counter of a recording (lost_frames, gaps, bad_check, truncated, garbage,
    timeouts, duplicates), never their sum. The Dask dashboard's address is printed
    when it is served (bokeh installed: the dask extra ``diagnostics``). A failed
    recording is listed with its reason in the summary and does not stop the others; a
    worker that dies has its tasks run again elsewhere. Exit status 1 if any failed.
    """
    import logging

    from tactsense import cluster

    try:
        paths = cluster.expand(recordings)
        if out.exists() and not out.is_dir():
            fail(f"--out {out} is a file; expected a folder")
        if not out.parent.is_dir():
            fail(f"folder {out.parent} of --out {out} does not exist; create it first")
        if calibration is not None and not calibration.is_file():
            fail(f"--calibration {calibration} is not a file")
        # an output never replaces an input: <name>.<format> and summary.csv in OUT
        targets = [cluster.output_for(p, out, format.value) for p in paths]
        for target in [*targets, out / "summary.csv"]:
            for source in [*paths, calibration]:
                if source is not None and same_file(target, source):
                    fail(
                        f"output {target} would replace the input {source}; an output never "
                        "replaces an input: choose another --out folder or --format"
                    )
        if scheduler is not None and not scheduler.startswith(("tcp://", "tls://", "inproc://")):
            fail(f"--scheduler {scheduler!r} is not a scheduler address (tcp://HOST:PORT)")
        out.mkdir(exist_ok=True)
        from dask.distributed import Client, LocalCluster

        if scheduler is None:
            local = LocalCluster(
                n_workers=workers,
                threads_per_worker=1,
                processes=True,
                dashboard_address="127.0.0.1:0",
                silence_logs=logging.ERROR,
            )
            client = Client(local)
        else:
            local = None
            client = Client(scheduler, timeout=10)
        try:
            if _has_bokeh():  # the dashboard is served only with bokeh installed
                console.print(f"Dask dashboard: {client.dashboard_link}")
            with progress_bar("recordings", eta=False, quiet=quiet) as bar:
                task = bar.add_task("batch", total=len(paths))
                rows = cluster.run_batch(
                    paths,
                    out,
                    fmt=format.value,
                    calibration=calibration,
                    threshold=threshold,
                    client=client,
                    split_frames=split_frames,
                    progress=lambda done, total: bar.update(task, completed=done, total=total),
                )
        finally:
            client.close()
            if local is not None:
                local.close()
        with atomic_output(out / "summary.csv") as temporary:
            cluster.write_summary(temporary, rows)
    except (TactsenseInputError, FileExistsError) as error:
        fail(str(error))
    except OSError as error:
        fail(f"cannot reach the scheduler or the files: {error}")
    table = Table(title=f"{len(rows)} recordings -> {out}")
    for column in ("recording", "status", "frames", "contacts", "mean force [N]", "reason"):
        table.add_column(column)
    for row in rows:
        table.add_row(
            Path(row["recording"]).name,
            row["status"],
            "" if row["frames"] is None else f"{row['frames']:,}",
            "" if row["contacts"] is None else f"{row['contacts']:,}",
            "" if row["force_mean_n"] is None else f"{row['force_mean_n']:.3f}",
            row["reason"] or "",
        )
    Console(stderr=True).print(table)
    failed = sum(row["status"] == "failed" for row in rows)
    console.print(f"summary: {out / 'summary.csv'}; {failed} failed")
    if failed:
        raise typer.Exit(code=1)
