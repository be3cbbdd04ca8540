"""``tactsense sensor show|check|export|list`` for a robot skin (many sensors on one robot).

The sensor commands hand a ``--sensor`` value (or ``check``'s path) here when it names a
robot skin: a skin preset (``hand4``, ``icub_hand``), a skin TOML (one with a
``base_link``) or a URDF file (links, joints and any number of tactile sensors).
"""

from __future__ import annotations

import tomllib
from pathlib import Path
from typing import Annotated

import typer
from rich.table import Table

from tactsense._validation import TactsenseInputError
from tactsense.cli._common import (
    SensorOption,
    atomic_output,
    check_output,
    console,
    fail,
    print_table,
)
from tactsense.kinds import kind_of
from tactsense.robot import (
    SKIN_PRESETS,
    RobotSkin,
    skin_from_dict,
    skin_to_toml_string,
)

SKIN_HELP = (
    " Or a robot skin: the skin presets 'hand4' (a four-finger hand, 20 patches) and "
    "'icub_hand' (iCub's five fingertips), a skin TOML or a URDF with several sensors "
    "(docs/robot.md)."
)
"""Appended to ``--sensor``'s help where the command takes a robot skin."""

SkinOrSensorOption = Annotated[
    str, typer.Option("--sensor", help=SensorOption.__metadata__[0].help + SKIN_HELP)
]
"""``--sensor`` of the sensor commands that take a robot skin too."""

WhatArgument = Annotated[
    str | None,
    typer.Argument(
        help="The sensor or robot skin (the same as --sensor): a preset, a skin preset "
        "(hand4, icub_hand), a sensor or skin TOML, or a URDF.",
        metavar="SENSOR",
        show_default=False,
    ),
]
"""``sensor show``'s positional sensor or skin."""


def one_sensor(what: str | None, sensor: str) -> str:
    """The sensor given positionally or by ``--sensor`` (refused when both differ)."""
    if what is None:
        return sensor
    if sensor not in ("initial", what):
        fail(f"give the sensor once: {what!r} or --sensor {sensor!r}, not both")
    return what


SKIN_FORMATS = ("toml", "urdf")
"""What ``sensor export --format`` writes a skin as."""

OVERLAP_M = 0.5e-3
"""``sensor check`` warns of taxels of two patches closer than this [m] (0.5 mm)."""


def _read_toml(path: Path) -> dict | None:
    try:
        return tomllib.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, tomllib.TOMLDecodeError):
        return None


def is_skin(value: str | Path | None) -> bool:
    """Whether a ``--sensor`` value names a robot skin rather than one sensor."""
    if value is None:
        return False
    text = str(value)
    if text in SKIN_PRESETS:
        return True
    path = Path(text)
    if path.suffix.lower() == ".urdf":
        return True
    if path.suffix.lower() == ".toml" and path.is_file():
        data = _read_toml(path)
        return isinstance(data, dict) and "base_link" in data
    return False


def skin_inputs(value: str | Path) -> list[Path]:
    """The files a skin is read from: its own and the sensor TOML files it names."""
    path = Path(str(value))
    if not path.is_file():
        return []
    found = [path]
    data = _read_toml(path) if path.suffix.lower() == ".toml" else None
    for table in (data or {}).get("sensors", []) if isinstance(data, dict) else []:
        sensor = table.get("sensor") if isinstance(table, dict) else None
        if isinstance(sensor, str):
            candidate = Path(sensor) if Path(sensor).is_absolute() else path.parent / sensor
            if candidate.is_file():
                found.append(candidate)
    return found


def read_skin(value: str | Path) -> RobotSkin:
    """A skin from a preset's name, a skin TOML or a URDF file."""
    import warnings

    from tactsense.interop.robot_urdf import UrdfPhysicsWarning, load_robot_skin

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", UrdfPhysicsWarning)
        skin = load_robot_skin(value)
    for warning in caught:
        if issubclass(warning.category, UrdfPhysicsWarning):
            console.print(f"warning: {warning.message}", soft_wrap=True, markup=False)
        else:
            warnings.warn_explicit(
                warning.message, warning.category, warning.filename, warning.lineno
            )
    return skin


def _rate(patch) -> str:
    return f"{patch.sensor.electronics.scan_rate_hz:g} Hz"


def _numbers(values, scale: float) -> str:
    return ", ".join(f"{v * scale:.4g}" for v in values)


def patch_table(skin: RobotSkin) -> Table:
    """One row per patch (link, its pose there: xyz [mm] and rpy [deg], kind, taxels, rate,
    device) and a row of totals."""
    import math

    table = Table(title=f"{skin.name}: {skin.description}".rstrip(": "))
    columns = ("patch", "link", "xyz [mm]", "rpy [deg]", "kind", "sensor", "taxels", "rate")
    for column in (*columns, "device"):
        table.add_column(column, justify="right" if column == "taxels" else "left")
    for patch in skin.patches:
        table.add_row(
            patch.name,
            patch.link,
            _numbers(patch.origin.xyz_m, 1e3),
            _numbers(patch.origin.rpy_rad, 180 / math.pi),
            kind_of(patch.sensor).label,
            patch.sensor.name,
            str(patch.n_taxels),
            _rate(patch),
            patch.device,
        )
    rates = sorted({p.sensor.electronics.scan_rate_hz for p in skin.patches})
    table.add_section()
    table.add_row(
        f"{len(skin.patches)} patches",
        f"{len(skin.links)} links, {len(skin.movable_joints)} moving joints",
        "",
        "",
        "",
        "",
        str(skin.n_taxels),
        " / ".join(f"{r:g}" for r in rates) + " Hz",
        f"{len(skin.devices)} devices",
    )
    return table


def joint_table(skin: RobotSkin) -> Table:
    """One row per moving joint: type, parent, child, axis, limits [rad or m]."""
    table = Table(title=f"{skin.name}: moving joints (base link {skin.base_link!r})")
    for column in ("joint", "type", "parent", "child", "axis", "lower", "upper"):
        table.add_column(column)
    for joint in skin.joints:
        if joint.type == "fixed":
            continue
        unit = "m" if joint.type == "prismatic" else "rad"
        table.add_row(
            joint.name,
            joint.type,
            joint.parent,
            joint.child,
            _numbers(joint.axis, 1.0),
            f"{joint.lower:.4g} {unit}",
            f"{joint.upper:.4g} {unit}",
        )
    return table


def show_skin(value: str, out: Path | None, force: bool) -> None:
    """``sensor show`` for a skin: the patch table, or its TOML written to ``out``."""
    if out is not None:
        check_output(out, force, inputs=skin_inputs(value))
    try:
        skin = read_skin(value)
        if out is None:
            print_table(patch_table(skin))
            print_table(joint_table(skin))
            console.print(
                "poses: each patch's sensor frame in its link's frame (xyz [mm], URDF "
                "roll-pitch-yaw [deg]); tactsense.robot's skin.taxels_in_base(joints) places "
                "every taxel in the base frame",
                soft_wrap=True,
                markup=False,
                highlight=False,
            )
            return
        text = skin_to_toml_string(skin)
        with atomic_output(out) as temporary:
            Path(temporary).write_text(text, encoding="utf-8")
        console.print(f"wrote {out}: {skin.name}, {len(skin.patches)} sensors")
    except (TactsenseInputError, FileExistsError) as error:
        fail(str(error))


def export_skin(value: str, fmt: str | None, out: Path | None, force: bool) -> None:
    """``sensor export --format toml|urdf`` for a skin (to ``out`` or standard output)."""
    if fmt is None:
        fail(f"{value!r} is a robot skin: say which format, --format {'|'.join(SKIN_FORMATS)}")
    if fmt not in SKIN_FORMATS:
        fail(f"--format {fmt!r}: a robot skin is written as {' or '.join(SKIN_FORMATS)}")
    if out is not None:
        check_output(out, force, inputs=skin_inputs(value))
    try:
        skin = read_skin(value)
        if fmt == "urdf":
            from tactsense.interop.robot_urdf import robot_skin_to_urdf

            text = robot_skin_to_urdf(skin)
        else:
            text = skin_to_toml_string(skin)
        if out is None:
            typer.echo(text, nl=False)
            return
        with atomic_output(out) as temporary:
            Path(temporary).write_text(text, encoding="utf-8")
        console.print(f"wrote {out}: {skin.name}, {len(skin.patches)} sensors as {fmt.upper()}")
    except (TactsenseInputError, FileExistsError) as error:
        fail(str(error))


def _sensor_problems(path: Path) -> list[str]:
    """Each sensor's problems of a skin TOML, one sensor at a time (all of them, not the
    first)."""
    data = _read_toml(path)
    if not isinstance(data, dict) or not isinstance(data.get("sensors"), list):
        return []
    problems = []
    for i, table in enumerate(data["sensors"]):
        if not isinstance(table, dict):
            continue
        one = {
            "name": "check",
            "base_link": "base",
            "links": ["base"],
            "sensors": [{**table, "link": "base", "name": str(table.get("name", i))}],
        }
        try:
            skin_from_dict(one, source=str(path), folder=path.parent)
        except TactsenseInputError as error:
            # the one-sensor skin calls it sensors[0]: give it its place in the file
            mine, theirs = f"{path}: sensors[0]", f"{path}: sensors[{i}]"
            problems.append(str(error).replace(mine, theirs, 1))
    return problems


def skin_warnings(skin: RobotSkin) -> list[str]:
    """What is valid but probably not meant: a board reading patches at different rates,
    taxels of two patches on top of each other (at the zero joint state)."""
    warnings = []
    for device, names in skin.devices.items():
        rates = {skin.patch(n).sensor.electronics.scan_rate_hz for n in names}
        if len(rates) > 1:
            listed = ", ".join(f"{r:g}" for r in sorted(rates))
            warnings.append(
                f"device {device!r} reads its patches at different rates ({listed} Hz); a board "
                "scans all its patches at one rate"
            )
    from scipy.spatial import cKDTree

    placed = skin.taxels_in_base()
    names = list(placed)
    trees = {name: cKDTree(placed[name][0]) for name in names}
    for i, first in enumerate(names):
        for second in names[i + 1 :]:
            close = trees[first].count_neighbors(trees[second], OVERLAP_M)
            if close:
                warnings.append(
                    f"patches {first!r} and {second!r}: {close} pair(s) of taxels closer than "
                    f"{OVERLAP_M * 1e3:g} mm at the zero joint state (placed on top of each "
                    "other?)"
                )
    return warnings


def check_skin(path: str | Path) -> None:
    """``sensor check`` for a skin: the skin's problems and each sensor's, then warnings."""
    text = str(path)
    problems = [] if text in SKIN_PRESETS else _sensor_problems(Path(text))
    try:
        skin = read_skin(text)
    except TactsenseInputError as error:
        message = str(error)
        for problem in dict.fromkeys(problems):  # one line per problem, in file order
            if problem not in message:
                message += f"\n  - {problem}"
        fail(message)
    table = patch_table(skin)
    table.title = f"{skin.name}: valid ({len(skin.patches)} sensors, {skin.n_taxels} taxels)"
    print_table(table)
    for patch in skin.patches:
        for problem in patch.sensor.problems():
            console.print(f"warning: patch {patch.name!r}: {problem}", markup=False)
    for warning in skin_warnings(skin):
        console.print(f"warning: {warning}", soft_wrap=True, markup=False, highlight=False)


def skin_list_table() -> Table:
    """The skin presets: name, patches, taxels, devices, what each is."""
    table = Table(
        title="robot skins (tactsense sensor show NAME lists a skin's patches and joints)"
    )
    for column in ("name", "patches", "taxels", "devices", "description"):
        table.add_column(column)
    for name, make in SKIN_PRESETS.items():
        skin = make()
        first = skin.description.split(". ")[0].rstrip(".")
        table.add_row(
            name, str(len(skin.patches)), str(skin.n_taxels), str(len(skin.devices)), first
        )
    return table
