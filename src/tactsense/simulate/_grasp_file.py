"""The grasp file (TOML) ``tactsense grasp --grasp`` reads: :func:`grasp_from_toml`."""

from __future__ import annotations

import math
import tomllib
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from tactsense.robot import Pose, RobotSkinError
from tactsense.simulate._grasp_geometry import GraspError, GraspObject
from tactsense.simulate._grasp_spec import Grasp
from tactsense.simulate._grasp_timing import Timing

_KEYS = {
    "object": {"shape", "size_mm", "xyz_mm", "rpy_deg"},
    "timing": {"approach_s", "squeeze_s", "hold_s", "release_s"},
    "": {"object", "joints", "force_n", "stiffness_n_per_mm", "load_n", "timing", "flaws", "seed"},
}


def grasp_from_dict(data: Mapping[str, Any], *, source: str = "grasp") -> Grasp:
    """A :class:`Grasp` from the grasp file's content (docs/robot.md, "Simulated grasps"):
    ``[object]`` shape, size_mm, xyz_mm [mm], rpy_deg [deg]; ``[joints]`` name = rad;
    ``force_n`` a number or a table of finger/patch = N; ``stiffness_n_per_mm``;
    ``load_n`` [N] (three numbers, base frame);
    ``[timing]`` approach_s, squeeze_s, hold_s, release_s; ``flaws``; ``seed``."""
    for section, allowed in _KEYS.items():
        table = data if not section else data.get(section, {})
        if not isinstance(table, Mapping):
            raise GraspError(f"{source}: [{section}] must be a table")
        unknown = sorted(set(table) - allowed)
        if unknown:
            where = f"[{section}]" if section else "the top level"
            raise GraspError(
                f"{source}: unknown key(s) {', '.join(unknown)} in {where}; expected "
                + ", ".join(sorted(allowed))
            )
    if "object" not in data:
        raise GraspError(f"{source}: no [object] table (shape, size_mm, xyz_mm, rpy_deg)")
    item = data["object"]
    try:
        pose = Pose(
            tuple(1e-3 * float(v) for v in item.get("xyz_mm", (0, 0, 0))),
            tuple(math.radians(float(v)) for v in item.get("rpy_deg", (0, 0, 0))),
        )
        size = item.get("size_mm", ())
        grasped = GraspObject(
            str(item.get("shape", "")), tuple(size) if isinstance(size, list | tuple) else (size,),
            pose,
        )  # fmt: skip
        joints = data.get("joints", {})
        if not isinstance(joints, Mapping):
            raise GraspError("[joints] must be a table of joint = position [rad or m]")
        force = data.get("force_n")
        return Grasp(
            object=grasped,
            joints={str(k): _finite(f"joint {k!r}", v) for k, v in joints.items()},
            force_n=dict(force) if isinstance(force, Mapping) else force,
            stiffness_n_per_mm=data.get("stiffness_n_per_mm", 1.0),
            load_n=data.get("load_n"),
            timing=Timing(**{k: float(v) for k, v in data.get("timing", {}).items()}),
            flaws=str(data.get("flaws", "all")),
            seed=data.get("seed", 0),
        )
    except (GraspError, RobotSkinError) as error:
        raise GraspError(f"{source}: {error}") from None
    except (TypeError, ValueError) as error:
        raise GraspError(f"{source}: {error}") from None


def _finite(name: str, value: Any) -> float:
    try:
        number = float(value)
    except (TypeError, ValueError):
        number = math.nan
    if not math.isfinite(number):
        raise GraspError(f"{name} = {value!r}: expected a finite number [rad or m]")
    return number


def grasp_from_toml(path: str | Path) -> Grasp:
    """A :class:`Grasp` from a grasp file (:func:`grasp_from_dict`)."""
    path = Path(path)
    try:
        data = tomllib.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise GraspError(f"grasp file {path} does not exist") from None
    except (OSError, UnicodeDecodeError, tomllib.TOMLDecodeError) as error:
        raise GraspError(f"grasp file {path}: unreadable ({error})") from None
    return grasp_from_dict(data, source=str(path))
