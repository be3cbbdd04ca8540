"""``tactsense dataset``: a labelled data set of simulated episodes, on Dask."""

from __future__ import annotations

from enum import StrEnum
from pathlib import Path
from typing import Annotated

import typer

from tactsense._validation import TactsenseInputError
from tactsense.cli._common import console, fail, new_group, progress_bar, remove_stale_partials
from tactsense.simulate.dataset import PER_FRAME_FLAWS

app = new_group("Labelled data sets of simulated episodes.")


class DatasetFormat(StrEnum):
    lerobot = "lerobot"
    hdf5 = "hdf5"


def _pair(name: str, unit: str, default: str, what: str):
    return typer.Option(
        name,
        metavar="LOW HIGH",
        help=f"{what}: each episode draws it uniformly between LOW and HIGH [{unit}] "
        f"(default {default}).",
    )


def _start_cluster(scheduler, workers: int, log_level: int):
    """(local cluster or None, client): a local Dask cluster of ``workers`` processes, or
    a client of the scheduler at ``scheduler``."""
    from dask.distributed import Client, LocalCluster

    if scheduler is not None:
        return None, Client(scheduler, timeout=10)
    local = LocalCluster(
        n_workers=workers,
        threads_per_worker=1,
        processes=True,
        dashboard_address="127.0.0.1:0",
        silence_logs=log_level,
    )
    try:
        return local, Client(local)
    except BaseException:
        local.close()
        raise


@app.command("dataset")
def dataset(
    out: Annotated[
        Path,
        typer.Option(
            "--out",
            "-o",
            help="The new data set: a folder for --format lerobot (a LeRobot v3.0 dataset), "
            "a .h5 file for --format hdf5 (a tactsense recording with /episodes and "
            "/labels). Never replaced: choose a new name.",
        ),
    ],
    format: Annotated[
        DatasetFormat, typer.Option("--format", help="The data set's format.")
    ] = DatasetFormat.lerobot,
    sensor: Annotated[
        str,
        typer.Option(
            "--sensor",
            help="A pad preset ('pad4', 'pad16', 'pad12x32', 'fsr16', 'dsa9205') or the path "
            "of a pad's sensor TOML file: contacts are placed on its taxel grid.",
        ),
    ] = "pad16",
    episodes: Annotated[
        int, typer.Option(min=1, max=10_000_000, help="Episodes [-], 1 to 10,000,000.")
    ] = 100,
    frames: Annotated[
        int,
        typer.Option(
            min=10,
            max=1_000_000,
            help="Frames per episode [-], 10 to 1,000,000, at the sensor's scan rate.",
        ),
    ] = 200,
    tasks: Annotated[
        str,
        typer.Option(
            help="Episode kinds drawn from, a comma list of 'press', 'slide' and 'grasp' "
            "(docs/datasets.md).",
        ),
    ] = "press,slide,grasp",
    force_n: Annotated[
        tuple[float, float],
        _pair("--force-n", "N, 1e-4 to 1000", "0.05 0.8", "Peak normal force (a grasp: its grip)"),
    ] = (0.05, 0.8),
    radius_mm: Annotated[
        tuple[float, float],
        _pair("--radius-mm", "mm, 0.05 to 100", "1 3", "Sphere radius of each contact"),
    ] = (1.0, 3.0),
    speed_mm_s: Annotated[
        tuple[float, float],
        _pair("--speed-mm-s", "mm/s, 0 to 10000", "2 20", "Speed of a slide or a slip"),
    ] = (2.0, 20.0),
    friction: Annotated[
        tuple[float, float],
        _pair("--friction", "-, 0.01 to 10", "0.3 1", "Static friction coefficient"),
    ] = (0.3, 1.0),
    flaws: Annotated[
        str,
        typer.Option(
            help="Per-frame flaws to switch on: 'all' (all of these), 'none' or a comma list "
            f"of {', '.join(PER_FRAME_FLAWS)}. Their sizes come from the sensor description; "
            "the flaws with memory (viscoelastic, hysteresis, drift) and jitter need a frame "
            "sequence and are refused.",
        ),
    ] = "all",
    seed: Annotated[
        int, typer.Option(min=0, help="Seed of every random draw [-]: the same set again.")
    ] = 0,
    workers: Annotated[
        int,
        typer.Option(
            min=0,
            max=256,
            help="Worker processes of a local Dask cluster (one core each), 0 to 256; 0: "
            "in this process, no cluster.",
        ),
    ] = 2,
    scheduler: Annotated[
        str | None,
        typer.Option(
            help="Address of an existing Dask scheduler (tcp://HOST:PORT) instead of a "
            "local cluster; its workers must have tactsense."
        ),
    ] = None,
    episodes_per_task: Annotated[
        int | None,
        typer.Option(
            min=1,
            max=100_000,
            help="Episodes per Dask task [-], 1 to 100,000 (default: about 20,000 frames).",
        ),
    ] = None,
    quiet: Annotated[bool, typer.Option("--quiet", "-q", help="No progress bar.")] = False,
) -> None:
    """Generate a labelled data set: presses, slides and grasps on a pad, their frames
    and their ground truth (contact positions, normal and tangential forces, radii, slip
    flags, contact ids) per frame, to LeRobot v3 or HDF5, on a Dask cluster in bounded
    memory (docs/datasets.md)."""
    import logging

    from tactsense.interop.datasets import write_dataset
    from tactsense.sensor import load_sensor
    from tactsense.simulate.contact_frames import resolve_flaws
    from tactsense.simulate.dataset import TASKS, DatasetPlan, surface_area

    try:
        for option, (low, high), (low_limit, high_limit), unit in (
            ("--force-n", force_n, (1e-4, 1e3), "N"),
            ("--radius-mm", radius_mm, (0.05, 100.0), "mm"),
            ("--speed-mm-s", speed_mm_s, (0.0, 1e4), "mm/s"),
            ("--friction", friction, (0.01, 10.0), "-"),
        ):
            if not low_limit <= low <= high <= high_limit:  # NaN fails too
                fail(
                    f"{option} {low:g} {high:g}: need {low_limit:g} <= LOW <= HIGH <= "
                    f"{high_limit:g} [{unit}]"
                )
        names = tuple(t.strip() for t in tasks.split(",") if t.strip())
        unknown = [t for t in names if t not in TASKS]
        if unknown or not names:
            fail(f"--tasks {tasks!r}: choose from {', '.join(TASKS)} (a comma list)")
        resolve_flaws(flaws)
        spec = load_sensor(sensor)
        surface_area(spec)  # a pad: contacts go on its grid
        plan = DatasetPlan(
            episodes=episodes,
            frames=frames,
            tasks=names,
            force_n=force_n,
            radius_mm=radius_mm,
            speed_mm_s=speed_mm_s,
            friction=friction,
            seed=seed,
            flaws=flaws,
        )
        parent = out.parent if str(out.parent) else Path(".")
        if not parent.is_dir():
            fail(f"folder {parent} of --out {out} does not exist; create it first")
        if out.exists():
            fail(f"--out {out} exists; a data set is never replaced: choose a new name")
        if format is DatasetFormat.hdf5 and out.suffix.lower() not in (".h5", ".hdf5"):
            fail(f"--out {out}: an HDF5 data set is a file named .h5 (or .hdf5)")
        if format is DatasetFormat.lerobot and out.suffix.lower() in (".h5", ".hdf5"):
            fail(f"--out {out}: a LeRobot dataset is a folder; drop the .h5 or use --format hdf5")
        if scheduler is not None and not scheduler.startswith(("tcp://", "tls://", "inproc://")):
            fail(f"--scheduler {scheduler!r} is not a scheduler address (tcp://HOST:PORT)")
        remove_stale_partials(parent)
        client = local = None
        try:  # the cluster is closed on an interrupt while it starts too
            if scheduler is not None or workers > 0:
                from tactsense._signals import deferred_interrupts

                # a Ctrl-C while the cluster starts is held until it has started (an
                # interrupted LocalCluster is left to Dask's exit hook, which fails)
                with deferred_interrupts():
                    # the workers' own logs stay quiet (a task's error reaches this
                    # process as the task's exception; a worker closed mid-task on
                    # Ctrl-C would print heartbeat tracebacks)
                    local, client = _start_cluster(scheduler, workers, logging.CRITICAL)
            with progress_bar("frames", quiet=quiet) as bar:
                task = bar.add_task("dataset", total=plan.total_frames)
                summary = write_dataset(
                    spec,
                    plan,
                    out,
                    fmt=format.value,
                    client=client,
                    episodes_per_task=episodes_per_task,
                    progress=lambda done, total: bar.update(task, completed=done, total=total),
                )
        finally:
            if client is not None:
                client.close()
            if local is not None:
                local.close()
    except (TactsenseInputError, FileExistsError) as error:
        fail(str(error))
    except OSError as error:
        fail(f"cannot write the data set or reach the scheduler: {error}")
    drawn = ", ".join(f"{n:,} {task}" for task, n in summary["episodes_per_task"].items())
    console.print(
        f"wrote {out}: {summary['frames']:,} frames in {summary['episodes']:,} "
        f"{'episode' if summary['episodes'] == 1 else 'episodes'} "
        f"({drawn}) at {summary['fps']} fps ({spec.name}, {format.value})"
    )
