"""``tactsense grasp``: an object pressing several patches of a robot's skin at once,
simulated into a robot recording (:mod:`tactsense.simulate.grasp`, docs/robot.md)."""

from __future__ import annotations

import math
from enum import StrEnum
from pathlib import Path
from typing import Annotated

import typer

from tactsense.cli._common import console, fail, inside, new_group, print_table, progress_bar
from tactsense.simulate.dataset import PER_FRAME_FLAWS

app = new_group("Simulated grasps on a robot's skin.")

DEFAULT_DURATIONS = "0.2,0.3,0.5,0.3"


class ObjectShape(StrEnum):
    sphere = "sphere"
    cylinder = "cylinder"
    box = "box"


def _numbers(option: str, text: str, counts: tuple[int, ...], unit: str) -> list[float]:
    """A comma list of finite numbers, ``counts`` of them, or a one-line error."""
    try:
        values = [float(v) for v in text.split(",")]
    except ValueError:
        values = []
    if len(values) not in counts or not all(math.isfinite(v) for v in values):
        wanted = " or ".join(str(c) for c in counts)
        fail(f"{option} {text!r}: expected {wanted} finite number(s), comma-separated [{unit}]")
    return values


def _pairs(option: str, text: str, unit: str) -> dict[str, float]:
    """``name=value,...`` as a dict of finite numbers, or a one-line error."""
    out: dict[str, float] = {}
    for item in text.split(","):
        name, equals, value = item.partition("=")
        try:
            number = float(value)
        except ValueError:
            number = math.nan
        if not equals or not name.strip() or not math.isfinite(number):
            fail(f"{option} {text!r}: expected name=value pairs, comma-separated [{unit}]")
        if name.strip() in out:
            fail(f"{option}: {name.strip()!r} is given twice")
        out[name.strip()] = number
    return out


def _force(text: str) -> float | dict[str, float]:
    forces = (
        _pairs("--force-n", text, "N")
        if "=" in text
        else {"": _numbers("--force-n", text, (1,), "N")[0]}
    )
    for name, value in forces.items():
        if not 0 < value <= 1e4:
            what = f" for {name!r}" if name else ""
            fail(f"--force-n {text!r}: the force{what} must be more than 0 and at most 10,000 [N]")
    return forces if "=" in text else forces[""]


def _grasp_from_options(
    shape, size_mm, pose, joints, force_n, stiffness, load_n, durations, flaws, seed
):
    from tactsense.robot import Pose
    from tactsense.simulate.grasp import Grasp, GraspObject, Timing

    if shape is None or size_mm is None:
        fail("give the object (--object and --size-mm) or a grasp file (--grasp)")
    xyz = _numbers("--pose", pose, (3, 6), "mm, then deg")
    placed = Pose(
        tuple(1e-3 * v for v in xyz[:3]),
        tuple(math.radians(v) for v in (xyz[3:] or (0.0, 0.0, 0.0))),
    )
    counts = {"sphere": (1,), "cylinder": (2,), "box": (3,)}[shape.value]
    size = _numbers("--size-mm", size_mm, counts, "mm")
    if not all(0 < v <= 10_000 for v in size):
        fail(f"--size-mm {size_mm!r}: each size must be more than 0 and at most 10,000 [mm]")
    if not 0 < stiffness <= 1e6:  # NaN fails too
        fail(f"--stiffness-n-per-mm {stiffness:g}: expected more than 0 and at most 1e6 [N/mm]")
    load = None if load_n is None else _numbers("--load-n", load_n, (3,), "N")
    if load is not None and not all(abs(v) <= 1e4 for v in load):
        fail(f"--load-n {load_n!r}: each component at most 10,000 in size [N]")
    phases = _numbers("--duration-s", durations, (4,), "s")
    if not all(0 <= v <= 600 for v in phases) or sum(phases) <= 0:
        fail(f"--duration-s {durations!r}: each phase 0 to 600 [s], more than 0 in all")
    return Grasp(
        object=GraspObject(shape.value, tuple(size), placed),
        joints=_pairs("--joints", joints, "rad or m") if joints else {},
        force_n=None if force_n is None else _force(force_n),
        stiffness_n_per_mm=stiffness,
        load_n=None if load is None else tuple(load),
        timing=Timing(*phases),
        flaws=flaws,
        seed=seed,
    )


@app.command("grasp")
def grasp_command(
    skin: Annotated[
        str,
        typer.Argument(
            help="The robot's skin: a preset ('hand4', 'icub_hand'), a skin TOML or a URDF "
            "with tactile sensors "
            "(tactsense sensor show SKIN lists its patches with their links and poses, and "
            "its joints with their limits: where to put the object)."
        ),
    ],
    out: Annotated[
        Path,
        typer.Option(
            "--out",
            "-o",
            help="The robot recording to write (a new folder: robot.json, skin.toml, "
            "streams/PATCH.h5). An existing one is replaced only with --force.",
        ),
    ],
    grasp_file: Annotated[
        Path | None,
        typer.Option(
            "--grasp",
            help="A grasp file (TOML: [object], [joints], force_n, [timing], ...; "
            "docs/robot.md) instead of the options below.",
        ),
    ] = None,
    shape: Annotated[
        ObjectShape | None, typer.Option("--object", help="The grasped object's shape.")
    ] = None,
    size_mm: Annotated[
        str | None,
        typer.Option(
            "--size-mm",
            metavar="SIZES",
            help="The object's size [mm], each more than 0 and at most 10,000: a sphere's "
            "diameter; a cylinder's 'diameter,length' (axis along its own z); a box's "
            "'x,y,z' edges.",
        ),
    ] = None,
    pose: Annotated[
        str,
        typer.Option(
            "--pose",
            metavar="X,Y,Z[,ROLL,PITCH,YAW]",
            help="The object's centre in the robot's base frame [mm] and, optionally, its "
            "URDF roll, pitch, yaw [deg].",
        ),
    ] = "0,0,0",
    joints: Annotated[
        str | None,
        typer.Option(
            "--joints",
            metavar="NAME=POS,...",
            help="Joint positions [rad, or m for a prismatic joint], each within the "
            "joint's limits; joints left out rest at 0 clipped into their limits.",
        ),
    ] = None,
    force_n: Annotated[
        str | None,
        typer.Option(
            "--force-n",
            metavar="F | NAME=F,...",
            help="Commanded normal force [N], more than 0 and at most 10,000: one number "
            "for every finger the object touches (shared among the finger's touched "
            "patches by penetration volume), or per finger (the base link's child link "
            "it hangs from; the palm: the base link) or patch by name. Default: the "
            "penetration-stiffness rule (--stiffness-n-per-mm).",
        ),
    ] = None,
    stiffness: Annotated[
        float,
        typer.Option(
            "--stiffness-n-per-mm",
            help="Without --force-n: each touched patch's force is this [N/mm], more than 0 "
            "and at most 1e6, times the object's deepest penetration into it [mm].",
        ),
    ] = 1.0,
    load_n: Annotated[
        str | None,
        typer.Option(
            "--load-n",
            metavar="FX,FY,FZ",
            help="A force on the object the contacts carry, in the base frame [N], each "
            "at most 10,000 in size (its weight: 0,0,-m*g): each touched patch takes a "
            "share by its normal force, the part tangent to the skin is its tangential "
            "force (in the truth; pads and point sets do not sense it). Default: none.",
        ),
    ] = None,
    durations: Annotated[
        str,
        typer.Option(
            "--duration-s",
            metavar="APPROACH,SQUEEZE,HOLD,RELEASE",
            help="Durations of the four phases [s], each 0 to 600, more than 0 in all: "
            "approach (no contact), squeeze (forces ramp up), hold, release (ramp down).",
        ),
    ] = DEFAULT_DURATIONS,
    flaws: Annotated[
        str,
        typer.Option(
            help="Per-frame flaws of each patch's sensor: 'all' (all of these), 'none' or a "
            f"comma list of {', '.join(PER_FRAME_FLAWS)}; their sizes come from each sensor's "
            "description (the flaws with memory and jitter are refused)."
        ),
    ] = "all",
    seed: Annotated[int, typer.Option(min=0, help="Seed of the read noise [-], >= 0.")] = 0,
    force: Annotated[
        bool, typer.Option("--force", help="Replace an existing robot recording at --out.")
    ] = False,
    quiet: Annotated[bool, typer.Option("--quiet", "-q", help="No progress bar.")] = False,
) -> None:
    """Simulate an object (sphere, cylinder or box) grasped by a robot's skin: every patch's
    frames at its own scan rate with its flaws, the contacts' truth in every stream, into a
    robot recording folder (docs/robot.md, "Simulated grasps")."""
    from tactsense.cli import _robot_sensor
    from tactsense.simulate.grasp import (
        fingers,
        grasp_from_toml,
        plan_grasp,
        write_grasp,
    )

    object_options = [
        name
        for name, value in (
            ("--object", shape),
            ("--size-mm", size_mm),
            ("--pose", None if pose == "0,0,0" else pose),
            ("--joints", joints),
            ("--force-n", force_n),
            ("--duration-s", None if durations == DEFAULT_DURATIONS else durations),
            ("--stiffness-n-per-mm", None if stiffness == 1.0 else stiffness),
            ("--load-n", load_n),
            ("--flaws", None if flaws == "all" else flaws),
            ("--seed", None if seed == 0 else seed),
        )
        if value is not None
    ]
    if grasp_file is not None and object_options:
        fail(f"--grasp {grasp_file} describes the grasp; drop {', '.join(object_options)}")
    robot = _robot_sensor.read_skin(skin)  # r7-fixb: a URDF's physics warning, one line
    if grasp_file is not None:
        grasp = grasp_from_toml(grasp_file)
    else:
        grasp = _grasp_from_options(
            shape, size_mm, pose, joints, force_n, stiffness, load_n, durations, flaws, seed
        )
    _check_out(out, force, [Path(skin), grasp_file])
    plan = plan_grasp(robot, grasp)  # every check before any frame is made
    contacts, forces = plan.contacts, plan.forces
    with progress_bar("grasp", unit="frames", quiet=quiet) as bar:
        task = bar.add_task("grasp", total=None)
        plan = write_grasp(
            out,
            robot,
            grasp,
            overwrite=force,
            progress=lambda done, total: bar.update(task, completed=done, total=total),
        )
    finger_of = fingers(robot)
    rows = []
    for name, contact in contacts.items():
        rows.append(
            (
                name,
                robot.patch(name).link,
                finger_of[name],
                f"{forces[name]:.3g}",
                f"{contact.depth_mm:.3g}",
                f"{robot.patch(name).sensor.electronics.scan_rate_hz:g}",
                str(plan.n_frames(name)),
            )
        )
    from rich.markup import escape
    from rich.table import Table

    headers = ("patch", "link", "finger", "force [N]", "depth [mm]", "rate [Hz]", "frames")
    table = Table(*(escape(h) for h in headers))
    for row in rows:
        table.add_row(*(escape(cell) for cell in row))
    print_table(table)
    console.print(
        f"wrote {out}: {len(robot.patches)} streams, {len(contacts)} "
        f"{'patch' if len(contacts) == 1 else 'patches'} touched, "
        f"{grasp.timing.total_s:g} s"
    )


def _check_out(out: Path, force: bool, inputs: list[Path | None]) -> None:
    """The output folder: its parent exists, it is not an input nor holds one, and an
    existing one is replaced only with --force (and only if it is a robot recording)."""
    from tactsense.io.robot_recording import is_robot_recording

    parent = out.parent if str(out.parent) else Path(".")
    if not parent.is_dir():
        fail(f"folder {parent} of --out {out} does not exist; create it first")
    for source in inputs:
        if source is not None and source.exists() and inside(source, out):
            fail(f"--out {out} holds the input {source}; an output never replaces an input")
    if out.exists():
        if not force:
            fail(f"--out {out} exists; pass --force to replace it, or choose another name")
        if not is_robot_recording(out):
            fail(f"--out {out} exists and is not a robot recording; it is never replaced")
