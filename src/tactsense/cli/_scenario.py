"""The scenario options shared by ``simulate`` and ``emulate``, and the scenario they build."""

from __future__ import annotations

from enum import StrEnum
from typing import Annotated

import typer
from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeRemainingColumn

from tactsense.cli._common import console
from tactsense.io.recording import Recording
from tactsense.physics.contact import grams_force
from tactsense.physics.flaws import FLAW_NAMES
from tactsense.sensor import SensorSpec


class ScenarioKind(StrEnum):
    sweep_axial = "sweep-axial"
    sweep_around = "sweep-around"
    repeated = "repeated"
    calibration = "calibration"
    knife = "knife-edge"


ScenarioOption = Annotated[
    ScenarioKind,
    typer.Option(
        help="What touches the finger: 'sweep-axial' steps a probe along the finger "
        "(Fig. 7), 'sweep-around' steps it around (Fig. 13), 'repeated' applies it "
        "again and again above one tactel (Figs. 10-12; also the force steps for "
        "'calibrate --steps'), 'calibration' sweeps the probe along every column "
        "(section 3.1, for 'calibrate'), 'knife-edge' steps a 0.5-N knife edge past "
        "tactel (row, col) (section 4.1, for 'calibrate --knife')."
    ),
]
RowOption = Annotated[
    int,
    typer.Option(
        min=0,
        max=254,
        help="Row of the tactel: fixes the axial position of a sweep "
        "around, or the tactel loaded by 'repeated' (0 = tip row).",
    ),
]
ColOption = Annotated[
    int,
    typer.Option(
        min=0,
        max=254,
        help="Column of the tactel: fixes the angle of a sweep along the "
        "finger, or the tactel loaded by 'repeated'.",
    ),
]
ForceGOption = Annotated[
    float, typer.Option(min=1e-3, max=1e5, help="Probe load in grams-force (the paper's unit) [g].")
]
IncrementOption = Annotated[
    float | None,
    typer.Option(
        min=1e-3,
        max=90.0,
        help="Step between probe positions: mm for sweep-axial (default 0.6), "
        "deg for sweep-around (default 3).",
    ),
]
DwellOption = Annotated[
    float,
    typer.Option(
        min=1e-3, max=3600.0, help="Time the probe is held at each position or application [s]."
    ),
]
LiftOption = Annotated[
    float,
    typer.Option(
        min=0.0,
        max=3600.0,
        help="Time the probe is lifted between positions or applications "
        "(0 = it slides from one to the next in a sweep) [s].",
    ),
]
RepeatsOption = Annotated[
    int, typer.Option(min=1, max=1_000_000, help="Applications for 'repeated'.")
]
FlawsOption = Annotated[
    str,
    typer.Option(
        help="Flaws to switch on: 'all', 'none' or a comma list of "
        + ", ".join(FLAW_NAMES)
        + ". Their sizes come from the sensor description."
    ),
]
SeedOption = Annotated[
    int | None, typer.Option(min=0, help="Seed of every random draw, for a repeatable run.")
]


def build_scenario(
    spec: SensorSpec,
    scenario: ScenarioKind,
    *,
    row: int,
    col: int,
    force_g: float,
    increment: float | None,
    dwell_s: float,
    lift_s: float,
    repeats: int,
):
    """The :class:`~tactsense.simulate.Scenario` the command-line options describe."""
    from tactsense.simulate import calibration_sweep, knife_edge_sweep, probe_sweep, repeated_load

    force_n = grams_force(force_g)
    if scenario is ScenarioKind.calibration:
        return calibration_sweep(spec, force_n=force_n, increment=increment or 0.6)
    if scenario is ScenarioKind.knife:
        return knife_edge_sweep(spec, row=row, col=col, increment=increment or 0.6)
    if scenario is ScenarioKind.repeated:
        return repeated_load(
            spec,
            row=row,
            col=col,
            force_n=force_n,
            repeats=repeats,
            on_s=dwell_s,
            off_s=max(lift_s, dwell_s),
        )
    along = "axial" if scenario is ScenarioKind.sweep_axial else "around"
    return probe_sweep(
        spec,
        along=along,
        row=row,
        col=col,
        increment=increment,
        force_n=force_n,
        dwell_s=dwell_s,
        lift_s=lift_s,
    )


def run_scenario(spec: SensorSpec, scene, *, flaws: str, seed: int | None) -> Recording:
    """Simulate ``scene`` with a progress bar on the terminal."""
    from tactsense.simulate import simulate

    with Progress(
        TextColumn("simulating"),
        BarColumn(),
        MofNCompleteColumn(),
        TextColumn("frames"),
        TimeRemainingColumn(),
        console=console,
        disable=None,
    ) as bar:
        task = bar.add_task("frames", total=None)

        def update(done: int, total: int) -> None:
            bar.update(task, completed=done, total=total)

        return simulate(spec, scene, flaws=flaws, rng=seed, progress=update)
