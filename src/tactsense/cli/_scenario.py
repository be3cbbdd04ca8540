"""The scenario options shared by ``simulate`` and ``emulate``, and the scenario they build."""

from __future__ import annotations

import math
from enum import StrEnum
from typing import Annotated

import numpy as np
import typer

from tactsense._validation import TactsenseInputError
from tactsense.cli._common import progress_bar
from tactsense.kinds import kind_of, kinds
from tactsense.physics.contact import grams_force
from tactsense.physics.flaws import FLAW_NAMES
from tactsense.sensor import SensorSpec


class ScenarioKind(StrEnum):
    sweep_axial = "sweep-axial"
    sweep_around = "sweep-around"
    repeated = "repeated"
    calibration = "calibration"
    knife = "knife-edge"
    press = "press"
    hold = "hold"
    two_probes = "two-probes"
    slide = "slide"
    sweep = "sweep"
    punch = "punch"
    loads = "loads"
    # ---- r8-triphys ----
    shear = "shear"
    slide_to_slip = "slide-to-slip"


ScenarioOption = Annotated[
    ScenarioKind | None,
    typer.Option(
        help="What touches the sensor. A finger: 'sweep-axial' (the default) steps a probe "
        "along the finger (Fig. 7), 'sweep-around' steps it around (Fig. 13), 'repeated' "
        "applies it again and again above one tactel (Figs. 10-12; also the force steps "
        "for 'calibrate --steps'), 'calibration' sweeps the probe along every column "
        "(section 3.1, for 'calibrate'), 'knife-edge' steps a 0.5-N knife edge past "
        "tactel (row, col) (section 4.1, for 'calibrate --knife'). A pad or a point set: "
        "'press' (the default) presses an indenter and lifts it, 'hold' presses and holds "
        "(creep, section 3.4), 'two-probes' presses two spheres --separation-mm apart, "
        "'slide' slides a sphere across at --speed-mm-s, 'sweep' presses a sphere every "
        "--increment mm along y (Fig. 7 on a pad), 'knife-edge' presses a knife edge "
        "across the middle, 'punch' a flat punch (a uniform press), 'calibration' a "
        "sphere on every taxel in turn (for 'calibrate'; on a three-axis pad, "
        "each also pushed by --shear-ratio along --shear-angle-deg: the x and y "
        "sweeps), 'loads' presses a sphere with each of --forces-g in turn, lifted "
        "between (a box of weights, or a load cell: "
        "for 'calibrate --force-log', with the log --force-log writes or a CSV of the "
        "masses in order). A three-axis pad also: 'shear' presses a sphere and ramps a "
        "tangential force to --shear-ratio, holds and releases it, 'slide-to-slip' ramps "
        "it past --friction until the contact slides (docs/triaxial.md)."
    ),
]
XOption = Annotated[
    float | None,
    typer.Option("--x-mm", min=-1e4, max=1e4,
                 help="Pads: where the indenter presses ('two-probes': the pair's centre, "
                 "'loads': where the presses are), along x (the rows) [mm] "
                 "[default: the middle; 'loads': the taxel nearest it]; point sets: in the "
                 "tangent plane of taxel 0."),
]  # fmt: skip
YOption = Annotated[
    float | None,
    typer.Option("--y-mm", min=-1e4, max=1e4,
                 help="Pads: where the indenter presses ('two-probes': the pair's centre, "
                 "'loads': where the presses are), along y (the columns) [mm] "
                 "[default: the middle; 'loads': the taxel nearest it]."),
]  # fmt: skip
SeparationOption = Annotated[
    float | None,
    typer.Option("--separation-mm", min=1e-3, max=1e4,
                 help="'two-probes': distance between the two spheres' centres [mm] "
                 "[default: 5]."),
]  # fmt: skip
IndenterOption = Annotated[
    str | None,
    typer.Option(help="'press' and 'hold': sphere (Hertz), disc (uniform), punch (rigid "
                 "flat, round), knife, square (a rigid flat square stamp) or cylinder (a "
                 "5-mm-radius cylinder lying on the surface, Hertz line contact) "
                 "[default: sphere]."),
]  # fmt: skip
SizeOption = Annotated[
    float | None,
    typer.Option("--size-mm", min=1e-3, max=1e3,
                 help="Pads: the indenter's radius (sphere, disc, punch), a knife edge's or "
                 "a cylinder's length, or a square stamp's side [mm] [default: 1.6, the "
                 "paper's 3.2-mm probe; punch 3; knife and cylinder 10; square 5]."),
]  # fmt: skip
SpeedOption = Annotated[
    float | None,
    typer.Option("--speed-mm-s", min=1e-3, max=1e4,
                 help="'slide': speed of the sliding sphere [mm/s] [default: 10]."),
]  # fmt: skip
AngleOption = Annotated[
    float | None,
    typer.Option("--angle-deg", min=-360.0, max=360.0,
                 help="'knife-edge' on a pad, and 'press'/'hold' with a knife, square or "
                 "cylinder: its axis' angle from the x axis [deg] "
                 "[default: 0]; 'two-probes': the axis the pair is separated along, from "
                 "the x axis [deg] [default: 90, along y]."),
]  # fmt: skip
ForcesGOption = Annotated[
    str | None,
    typer.Option("--forces-g", metavar="A,B,C|START:STOP:COUNT",
                 help="'loads': the press forces in grams-force, a list (20,50,100) or "
                 "COUNT evenly spaced from START to STOP (10:100:8), each 0.001-100000 g "
                 "[default: 10:100:8]."),
]  # fmt: skip
RowOption = Annotated[
    int | None,
    typer.Option(
        min=0,
        max=254,
        help="Row of the tactel: fixes the axial position of a sweep "
        "around, or the tactel loaded by 'repeated' or passed by 'knife-edge' "
        "(0 = tip row) [default: 4, the paper's; the middle row of an array of fewer "
        "than 8 rows].",
    ),
]
ColOption = Annotated[
    int | None,
    typer.Option(
        min=0,
        max=254,
        help="Column of the tactel: fixes the angle of a sweep along the "
        "finger, or the tactel loaded by 'repeated' or passed by 'knife-edge' [default: 0].",
    ),
]
ForceGOption = Annotated[
    float | None,
    typer.Option(
        min=1e-3,
        max=1e5,
        help="Probe load in grams-force (the paper's unit) [g] [default: 50].",
    ),
]
IncrementOption = Annotated[
    float | None,
    typer.Option(
        min=1e-3,
        max=90.0,
        help="Step between probe positions: mm for sweep-axial, calibration and "
        "knife-edge (default 0.6), "
        "deg for sweep-around (default 3); on a pad, mm for 'sweep' (default 0.5) and "
        "'slide' (default 0.25).",
    ),
]
DwellOption = Annotated[
    float | None,
    typer.Option(
        min=1e-3,
        max=3600.0,
        help="Time the probe is held at each position or application, at least one scan "
        "period of the sensor [s] [default: 0.5, or one scan period if that is longer].",
    ),
]
LiftOption = Annotated[
    float | None,
    typer.Option(
        min=0.0,
        max=3600.0,
        help="Time the probe is lifted between positions or applications "
        "(0 = it slides from one to the next in a sweep) [s] [default: 0 in a sweep; "
        "for 'repeated' the longer of this and --dwell-s].",
    ),
]
RepeatsOption = Annotated[
    int | None,
    typer.Option(min=1, max=1_000_000, help="Applications for 'repeated' [default: 100]."),
]

# ---- shear and slip options (r8-triphys) ----
ShearRatioOption = Annotated[
    float | None,
    typer.Option("--shear-ratio", min=1e-3, max=10.0,
                 help="'shear' and 'slide-to-slip': the tangential force ramped to, over the "
                 "normal force (Q/P) [-], 0.001-10; 'shear' below --friction, "
                 "'slide-to-slip' above it [default: 0.3 and 1.5]; 'calibration' on a "
                 "three-axis pad: each press also pushes so [default: no push]."),
]  # fmt: skip
ShearAngleOption = Annotated[
    float | None,
    typer.Option("--shear-angle-deg", min=-360.0, max=360.0,
                 help="'shear', 'slide-to-slip' and a pushing 'calibration': the tangential "
                 "force's direction from the x axis (the rows) [deg], -360 to 360 "
                 "[default: 0]."),
]  # fmt: skip
FrictionOption = Annotated[
    float | None,
    typer.Option("--friction", min=0.05, max=5.0,
                 help="'shear', 'slide-to-slip' and a pushing 'calibration': the coefficient "
                 "of friction mu between sphere and skin [-], 0.05-5 [default: 1]."),
]  # fmt: skip
RampOption = Annotated[
    float | None,
    typer.Option("--ramp-s", min=1e-3, max=3600.0,
                 help="'shear' and 'slide-to-slip': how long the tangential force takes to "
                 "ramp up (and, 'shear', down) [s], 0.001-3600, at least one scan period "
                 "[default: 0.5 and 1]."),
]  # fmt: skip
SHEAR_OPTIONS = ("shear_ratio", "shear_angle_deg", "friction", "ramp_s")
"""The options of the shear scenarios, passed to the builders under these names
(``shear_angle_deg`` as ``angle_deg``)."""
# ---- /shear and slip options (r8-triphys) ----

DEFAULTS = {
    "row": None,
    "col": None,
    "force_g": 50.0,
    "dwell_s": 0.5,
    "lift_s": 0.0,
    "repeats": 100,
}
"""The value of each scenario option the user did not give (row and col None: the
sensor's own default tactel, :func:`tactsense.simulate.default_row`; dwell_s is
lengthened to one scan period on a slow sensor)."""

USES = {
    ScenarioKind.press: (
        "x_mm",
        "y_mm",
        "force_g",
        "indenter",
        "size_mm",
        "angle_deg",
        "dwell_s",
        "lift_s",
        "repeats",
    ),
    ScenarioKind.hold: (
        "x_mm",
        "y_mm",
        "force_g",
        "indenter",
        "size_mm",
        "angle_deg",
        "dwell_s",
        "lift_s",
    ),
    ScenarioKind.two_probes: (
        "x_mm",
        "y_mm",
        "separation_mm",
        "angle_deg",
        "force_g",
        "size_mm",
        "dwell_s",
    ),
    ScenarioKind.slide: ("force_g", "size_mm", "speed_mm_s", "increment"),
    ScenarioKind.loads: ("x_mm", "y_mm", "forces_g", "size_mm", "dwell_s", "lift_s", "repeats"),
    ScenarioKind.sweep: ("x_mm", "force_g", "size_mm", "increment", "dwell_s"),
    ScenarioKind.punch: ("force_g", "size_mm", "dwell_s"),
    ScenarioKind.sweep_axial: ("col", "force_g", "increment", "dwell_s", "lift_s"),
    ScenarioKind.sweep_around: ("row", "force_g", "increment", "dwell_s", "lift_s"),
    ScenarioKind.repeated: ("row", "col", "force_g", "dwell_s", "lift_s", "repeats"),
    ScenarioKind.calibration: ("force_g", "increment"),
    ScenarioKind.knife: ("row", "col", "increment"),
    # ---- r8-triphys ----
    ScenarioKind.shear: ("x_mm", "y_mm", "force_g", "size_mm", "dwell_s", *SHEAR_OPTIONS),
    ScenarioKind.slide_to_slip: (
        "x_mm",
        "y_mm",
        "force_g",
        "size_mm",
        "speed_mm_s",
        "dwell_s",
        *SHEAR_OPTIONS,
    ),
}
"""The options each scenario reads (where a kind's differ: ``Kind.scenario_options``, e.g.
'knife-edge' and 'calibration' on a pad or a point set); any other scenario option given
is an error. Which scenarios a kind takes: ``Kind.scenarios``."""


def _flag(name: str) -> str:
    return "--" + name.replace("_", "-")


def _uses(scenario: ScenarioKind, kind: str) -> tuple[str, ...]:
    """The options ``scenario`` reads on a sensor of ``kind`` (its name): the kind's own
    where it has them (``Kind.scenario_options``), else :data:`USES`."""
    uses = kind_of(kind).scenario_options.get(scenario.value, USES[scenario])
    # r8-fixc8: a kind that takes 'shear' pushes in its calibration (the tangential sweeps)
    if scenario is ScenarioKind.calibration and "shear" in kind_of(kind).scenarios:
        uses = (*uses, "shear_ratio", "shear_angle_deg", "friction")
    return uses


def check_scenario_options(scenario: ScenarioKind, given: dict, kind: str = "finger") -> dict:
    """Refuse options the scenario does not use; fill in the defaults of the rest."""
    uses = _uses(scenario, kind)
    unused = [name for name, value in given.items() if value is not None]
    unused = [name for name in unused if name not in uses]
    if unused:
        raise TactsenseInputError(
            f"{', '.join(_flag(n) for n in unused)} does not apply to --scenario "
            f"{scenario.value}, which uses {', '.join(_flag(n) for n in uses)}"
        )
    return {name: DEFAULTS.get(name) if value is None else value for name, value in given.items()}


def resolve_scenario(spec, scenario: ScenarioKind | None) -> ScenarioKind:
    """The scenario asked for, or the sensor's default; one the sensor cannot run is an
    error naming those it can."""
    kind = kind_of(spec)
    allowed = kind.scenarios
    if scenario is None:
        return ScenarioKind(allowed[0])
    if scenario.value not in allowed:
        others = [k.plural for k in kinds().values() if scenario.value in k.scenarios]
        raise TactsenseInputError(
            f"--scenario {scenario.value} is for {' and '.join(others)}; "
            f"{spec.name!r} is a {kind.label}, which takes {', '.join(allowed)}"
        )
    return scenario


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


def _round_up(value: float, digits: int = 4) -> float:
    """``value`` rounded up to ``digits`` significant digits (a printed minimum that the
    same number typed back satisfies)."""
    scale = 10.0 ** (digits - 1 - math.floor(math.log10(value)))
    return math.ceil(value * scale - 1e-9) / scale


def check_timing(spec: SensorSpec, dwell_s: float | None, lift_s: float | None) -> None:
    """Refuse a dwell (or a lift) shorter than one scan period of the sensor.

    A probe held for less than a scan period moves on before the array is read: the
    recording would hold frames of nothing (``--dwell-s 0.001`` gave 7 untouched frames).
    """
    period = spec.scan_period_s
    least = _round_up(period)
    rate = spec.electronics.scan_rate_hz
    for flag, value, what in (
        ("--dwell-s", dwell_s, "the probe would move on before the array is read"),
        ("--lift-s", lift_s, "the lift would fall between two readings of the array"),
    ):
        if value is not None and 0 < value < period:
            zero = " (or 0: no lift)" if flag == "--lift-s" else ""
            raise TactsenseInputError(
                f"{flag} {value:g} s is shorter than one scan period of sensor {spec.name!r} "
                f"({period:.4g} s at {rate:g} Hz): {what}; give at least {least:g} s{zero}"
            )


def build_scenario(
    spec: SensorSpec,
    scenario: ScenarioKind,
    *,
    row: int | None,
    col: int | None,
    force_g: float | None,
    increment: float | None,
    dwell_s: float | None,
    lift_s: float | None,
    repeats: int | None,
    x_mm: float | None = None,
    y_mm: float | None = None,
    separation_mm: float | None = None,
    indenter: str | None = None,
    size_mm: float | None = None,
    speed_mm_s: float | None = None,
    angle_deg: float | None = None,
    forces_g: str | None = None,
    shear: dict | None = None,
):
    """The :class:`~tactsense.simulate.Scenario` the command-line options describe.

    ``shear``: the shear scenarios' options (:data:`SHEAR_OPTIONS` -> value or None).

    Options left as None take :data:`DEFAULTS` (a pad's scenarios: the builders' own
    defaults, :mod:`tactsense.flat_scenarios`); an option given to a scenario that does
    not use it (:data:`USES`) is a :class:`TactsenseInputError`.
    """
    scenario = resolve_scenario(spec, scenario)
    if kind_of(spec).surface_scenarios:
        given = dict(
            row=row, col=col, force_g=force_g, increment=increment, dwell_s=dwell_s,
            lift_s=lift_s, repeats=repeats, x_mm=x_mm, y_mm=y_mm,
            separation_mm=separation_mm, indenter=indenter, size_mm=size_mm,
            speed_mm_s=speed_mm_s, angle_deg=angle_deg, forces_g=forces_g,
        )  # fmt: skip
        given.update({name: (shear or {}).get(name) for name in SHEAR_OPTIONS})  # r8-triphys
        check_scenario_options(scenario, given, spec.kind)
        check_timing(spec, dwell_s, lift_s)
        _check_ramp(spec, given["ramp_s"])  # r8-triphys
        return _flat_scenario(spec, scenario, given)
    if any(value is not None for value in (shear or {}).values()):  # r8-triphys
        check_scenario_options(scenario, {k: v for k, v in shear.items() if v is not None})
    from tactsense.simulate import calibration_sweep, knife_edge_sweep, probe_sweep, repeated_load

    dwell = dwell_s
    values = check_scenario_options(
        scenario,
        dict(
            row=row,
            col=col,
            force_g=force_g,
            increment=increment,
            dwell_s=dwell_s,
            lift_s=lift_s,
            repeats=repeats,
        ),
    )
    if forces_g is not None:
        check_scenario_options(scenario, {"forces_g": forces_g})
    row, col, force_g = values["row"], values["col"], values["force_g"]
    dwell_s, lift_s, repeats = values["dwell_s"], values["lift_s"], values["repeats"]
    check_timing(spec, dwell, lift_s)
    if dwell is None:  # the default fits the sensor: at least one scan period
        dwell_s = max(dwell_s, spec.scan_period_s)
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


def _check_ramp(spec, ramp_s: float | None) -> None:
    """Refuse a ``--ramp-s`` shorter than one scan period (r8-triphys): the ramp would
    fall between two readings of the array."""
    period = spec.scan_period_s
    if ramp_s is not None and ramp_s < period:
        raise TactsenseInputError(
            f"--ramp-s {ramp_s:g} s is shorter than one scan period of sensor {spec.name!r} "
            f"({period:.4g} s at {spec.electronics.scan_rate_hz:g} Hz): the ramp would fall "
            f"between two readings; give at least {_round_up(period):g} s"
        )


def parse_forces_g(text: str) -> list[float]:
    """``--forces-g``: 'A,B,C' or 'START:STOP:COUNT' (COUNT 1-10000), each value
    0.001-100000 g, as a list of grams [g]."""
    expected = (
        f"--forces-g {text!r}: expected grams-force as A,B,C or START:STOP:COUNT "
        "(COUNT 1-10000), each from 0.001 to 100000 g"
    )
    try:
        if ":" in text:
            start, stop, count = text.split(":")
            n = int(count)
            if not 1 <= n <= 10_000:
                raise ValueError
            values = [float(v) for v in np.linspace(float(start), float(stop), n)]
        else:
            values = [float(v) for v in text.split(",")]
    except ValueError:
        raise TactsenseInputError(expected) from None
    if not values or not all(math.isfinite(v) and 1e-3 <= v <= 1e5 for v in values):
        raise TactsenseInputError(expected)
    return values


def _check_place(spec, x_mm: float | None, y_mm: float | None) -> None:
    """Refuse a ``--x-mm`` or ``--y-mm`` off a pad, naming the option and the pad's range."""
    kind = kind_of(spec)
    grid = kind.surface_grid(spec)
    if grid is None:  # no grid to fall off: a place in a taxel's tangent plane
        return
    (row_pitch, rows), (col_pitch, cols) = grid
    for flag, value, pitch, n, axis in (
        ("--x-mm", x_mm, row_pitch, rows, "x"),
        ("--y-mm", y_mm, col_pitch, cols, "y"),
    ):
        low, high = -0.5 * pitch, (n - 0.5) * pitch
        if value is not None and not low <= value <= high:
            raise TactsenseInputError(
                f"{flag} {value:g} is off the {rows}x{cols} {kind.label} {spec.name!r}: "
                f"{axis} runs from {low:g} to {high:g} mm (taxel centres 0 to "
                f"{(n - 1) * pitch:g} mm)"
            )


def _flat_scenario(spec, scenario: ScenarioKind, given: dict):
    """A pad's or a point set's scenario from the options given (None: the builder's
    default)."""
    from tactsense.flat_scenarios import SCENARIOS

    names = {"dwell_s": "dwell_s", "lift_s": "lift_s", "repeats": "repeats", "x_mm": "x_mm",
             "y_mm": "y_mm", "separation_mm": "separation_mm", "indenter": "indenter",
             "speed_mm_s": "speed_mm_s", "angle_deg": "angle_deg"}  # fmt: skip
    options = {names[k]: v for k, v in given.items() if k in names and v is not None}
    _check_place(spec, given.get("x_mm"), given.get("y_mm"))
    # the help's default, 50 g, for every scenario (a knife edge included)
    options["force_n"] = grams_force(
        DEFAULTS["force_g"] if given["force_g"] is None else given["force_g"]
    )
    if given["increment"] is not None:
        options["increment_mm"] = given["increment"]
    if scenario is ScenarioKind.loads:
        del options["force_n"]
        text = given.get("forces_g") or "10:100:8"
        options["forces_n"] = [grams_force(g) for g in parse_forces_g(text)]
    if given["size_mm"] is not None:
        key = {"knife-edge": "length_mm", "punch": "radius_mm"}.get(scenario.value, "size_mm")
        options[key] = given["size_mm"]
    # ---- r8-triphys ----
    for name in SHEAR_OPTIONS:
        if given.get(name) is not None:
            options["angle_deg" if name == "shear_angle_deg" else name] = given[name]
    if scenario is ScenarioKind.hold and "dwell_s" in options:
        options["hold_s"] = options.pop("dwell_s")
    no_grid = kind_of(spec).surface_grid(spec) is None
    if no_grid and scenario in (ScenarioKind.press, ScenarioKind.hold):
        options.setdefault("at_taxel", 0)  # in the tangent plane of taxel 0
    if scenario in (ScenarioKind.press, ScenarioKind.hold):
        default_size = {"knife": 10.0, "cylinder": 10.0, "square": 5.0}
        if options.get("indenter") in default_size:
            options.setdefault("size_mm", default_size[options["indenter"]])
    return SCENARIOS[scenario.value](spec, **options)


MAX_FRAMES = 100_000_000
"""Most frames one ``simulate`` or ``emulate`` run makes (about 13 GB of 8x8 counts)."""


def run_scenario(
    spec: SensorSpec, scene, *, flaws: str, seed: int | None, path=None, forward: str = "twin"
):
    """Simulate ``scene`` with a progress bar on the terminal.

    Without ``path``, the :class:`Recording` (in memory); with it, the recording is
    written to that new file as it is made (memory bounded however long the scenario)
    and the number of frames written is returned.
    """
    from tactsense.simulate import simulate, simulate_to_file

    frames = scene.duration_s / spec.scan_period_s
    if frames > MAX_FRAMES:
        gigabytes = frames * spec.n_taxels * 2 / 1e9
        raise TactsenseInputError(
            f"the scenario lasts {scene.duration_s:.4g} s: {frames:.3g} frames of "
            f"{spec.shape[0]}x{spec.shape[1]} (about {gigabytes:.3g} GB of counts); at most "
            f"{MAX_FRAMES:,} frames are simulated in one run: shorten --repeats, --dwell-s "
            "or --lift-s"
        )

    with progress_bar("simulating", unit="frames") as bar:
        task = bar.add_task("frames", total=None)

        def update(done: int, total: int) -> None:
            bar.update(task, completed=done, total=total)

        if path is not None:
            return simulate_to_file(
                spec, scene, path, flaws=flaws, rng=seed, progress=update, forward=forward
            )
        return simulate(spec, scene, flaws=flaws, rng=seed, progress=update, forward=forward)
