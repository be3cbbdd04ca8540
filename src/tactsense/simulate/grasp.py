"""Simulated grasps: an object pressing several patches of a robot's skin at once.

A :class:`Grasp` is an object (:class:`GraspObject`: a sphere, cylinder or box, its size
[mm] and pose in the robot's base frame), a joint state, the forces and a time course.
:func:`simulate_grasp` finds where the object touches each patch (one contact per patch:
:mod:`tactsense.simulate._grasp_geometry`), gives each contact its normal force, and
makes every patch's frames at the patch's own scan rate with its own flaws
(:func:`~tactsense.simulate.frames_from_contacts`), into a
:class:`~tactsense.io.robot_recording.RobotRecording` with the truth in every stream.

Forces, one of two rules:

* **commanded** (``force_n``): a force [N] per finger (every finger the object touches,
  when one number; or by name), shared among the finger's touched patches in proportion
  to their penetration volumes, or a force per patch by the patch's name. A *finger* is
  the subtree of links under one child link of the base link, named by that child link
  (patches on the base link itself form the finger named by the base link: a palm).
* **penetration stiffness** (``force_n`` None): each touched patch pushes back with
  ``stiffness_n_per_mm`` [N/mm] times the object's deepest penetration into it [mm], a
  linear spring per patch.

The indenter's radius comes from the object's curvature: a sphere's radius, a cylinder's
radius across its axis (the contact is taken as a point contact of that radius; the line
along the axis is not modelled), a box's flat face as uniform pressure on a disc of the
contact's area. Tangential forces come from a load on the object (``load_n``, its
weight say), shared among the touched patches by normal force, the part tangent to the
skin at each contact (no slip is modelled).

Time course (:class:`Timing`): approach (nothing touches), squeeze (every force ramps
linearly from 0 to its full value), hold (full force), release (linearly back to 0). The
contacts stay where they are at the given pose: only their forces follow the course.
Each frame takes the force at the start of its scan (``time_s = i / rate``).

:func:`plan_grasp` checks everything and finds the contacts and forces
(:class:`GraspPlan`) before any frame is made; :func:`write_grasp` writes the folder
block by block (bounded memory), :func:`simulate_grasp` gives it in memory.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from tactsense.io.recording import Recording
from tactsense.io.robot_recording import RobotRecording
from tactsense.kinds import kind_of
from tactsense.physics.transduction import sample_offsets
from tactsense.robot import RobotSkin, RobotSkinError
from tactsense.simulate._grasp_file import grasp_from_dict, grasp_from_toml
from tactsense.simulate._grasp_frames import frame_count, patch_frames, takes_grasp
from tactsense.simulate._grasp_geometry import (
    FLAT_BOX_SHAPE,
    OBJECTS,
    SIZES,
    GraspError,
    GraspObject,
    PatchContact,
    patch_contact,
    surface_sample,
)
from tactsense.simulate._grasp_spec import Grasp
from tactsense.simulate._grasp_timing import MAX_PHASE_S, PHASES, Timing
from tactsense.simulate._grasp_truth import TIME_KEYS, TRUTH_KEYS, stream_truth
from tactsense.simulate.contact_frames import check_gains, resolve_flaws


def fingers(skin: RobotSkin) -> dict[str, str]:
    """Each patch's finger: the child link of the base link its link lies under, or the
    base link for a patch on the base link itself."""
    parent = {joint.child: joint.parent for joint in skin.joints}
    out = {}
    for patch in skin.patches:
        link = patch.link
        while link != skin.base_link and parent.get(link) != skin.base_link:
            link = parent[link]
        out[patch.name] = link
    return out


def joint_state(skin: RobotSkin, joints: Mapping[str, float]) -> dict[str, float]:
    """Every movable joint's position [rad or m]: ``joints``' where given, else its rest
    position (0 clipped into its limits: a joint whose range leaves out 0 rests at the
    nearer limit). Names are checked by :meth:`RobotSkin.link_poses`."""
    state = {j.name: min(max(0.0, j.lower), j.upper) for j in skin.joints if j.type != "fixed"}
    state.update({str(k): float(v) for k, v in joints.items()})
    return state


def _nearest_patch(skin: RobotSkin, grasp: Grasp) -> str:
    """Which patch's taxels come nearest the object's surface, and how far [mm]: a hint
    for an object that touches nothing."""
    placed = skin.taxels_in_base(joint_state(skin, grasp.joints))
    gaps = {
        name: float(np.min(grasp.object.signed_distance_mm(1e3 * positions)))
        for name, (positions, _normals) in placed.items()
        if takes_grasp(skin.patch(name).sensor) and len(positions)
    }
    if not gaps:
        return "no patch takes a grasp"
    name = min(gaps, key=gaps.get)
    return f"the nearest patch is {name!r}, {gaps[name]:.1f} mm from its surface"


def grasp_contacts(skin: RobotSkin, grasp: Grasp) -> dict[str, PatchContact]:
    """The contact of the object on each patch it touches, in the patch's sensor frame,
    at the grasp's joint state (patches it does not touch are left out)."""
    try:
        poses = skin.link_poses(joint_state(skin, grasp.joints))
    except RobotSkinError as error:
        raise GraspError(str(error)) from None
    out = {}
    for patch in skin.patches:
        if not takes_grasp(patch.sensor):
            continue
        pose = poses[patch.link] @ patch.origin.matrix()
        contact = patch_contact(grasp.object, surface_sample(patch.sensor), pose)
        if contact is not None:
            out[patch.name] = contact
    return out


def grasp_forces(
    skin: RobotSkin, grasp: Grasp, contacts: Mapping[str, PatchContact]
) -> dict[str, float]:
    """The full normal force [N] of each touched patch (:func:`grasp_contacts`), by the
    grasp's rule (module docstring)."""
    if grasp.force_n is None:
        return {name: grasp.stiffness_n_per_mm * c.depth_mm for name, c in contacts.items()}
    finger_of = fingers(skin)
    by_finger: dict[str, list[str]] = {}
    for name in contacts:
        by_finger.setdefault(finger_of[name], []).append(name)
    if not isinstance(grasp.force_n, Mapping):
        commanded = dict.fromkeys(by_finger, float(grasp.force_n))
        by_patch: dict[str, float] = {}
    else:
        commanded, by_patch = {}, {}
        finger_names = set(finger_of.values())
        for key, value in grasp.force_n.items():
            if key in finger_names:
                commanded[key] = value
            elif key in finger_of:
                by_patch[key] = value
            else:
                raise GraspError(
                    f"force for {key!r}: not a finger ({', '.join(sorted(finger_names))}) nor a "
                    f"patch of {skin.name!r}"
                )
    out: dict[str, float] = {}
    for name, value in by_patch.items():
        if name not in contacts:
            raise GraspError(f"force for patch {name!r}: the object does not touch it")
        if finger_of[name] in commanded:
            raise GraspError(
                f"force for patch {name!r} and for its finger {finger_of[name]!r}: give one"
            )
        out[name] = value
    for finger, value in commanded.items():
        touched = by_finger.get(finger, [])
        if not touched:
            raise GraspError(f"force for finger {finger!r}: the object touches none of its patches")
        volume = sum(contacts[name].volume_mm3 for name in touched)
        for name in touched:
            out[name] = value * contacts[name].volume_mm3 / volume
    unforced = sorted(set(contacts) - set(out))
    if unforced:
        raise GraspError(
            "the object touches " + ", ".join(unforced) + " but no force is given for them; "
            "name their fingers or patches, or give one force for every finger"
        )
    return out


BLOCK_FRAMES = 1024
"""Frames of one patch made (and written) at a time [-]."""


@dataclass(frozen=True)
class GraspPlan:
    """A grasp checked against a skin, ready to make frames: the touched patches'
    contacts and full forces [N], the links' poses, the scenario and each patch's seed."""

    skin: RobotSkin
    grasp: Grasp
    contacts: Mapping[str, PatchContact]
    forces: Mapping[str, float]
    poses: Mapping[str, np.ndarray]
    scenario: dict
    seeds: tuple

    def n_frames(self, name: str) -> int:
        """Frames of patch ``name`` over the whole course [-]."""
        rate = self.skin.patch(name).sensor.electronics.scan_rate_hz
        return frame_count(self.grasp.timing.total_s, rate)

    def blocks(self, name: str, block_frames: int | None = None):
        """Yield ``(first, last, frames (last - first, rows, cols) [counts], truth)`` for
        patch ``name``, ``block_frames`` at a time (default :data:`BLOCK_FRAMES`: memory
        does not grow with the course's length); ``truth`` holds those frames' part of
        :data:`TRUTH_KEYS` (and the keys that do not run along time, whole). The gains
        are :meth:`gains`'."""
        patch = self.skin.patch(name)
        spec, grasp, timing = patch.sensor, self.grasp, self.grasp.timing
        rate = spec.electronics.scan_rate_hz
        contact = self.contacts.get(name)
        sensor_in_base = self.poses[patch.link] @ patch.origin.matrix()
        shear = _tangential(grasp, contact, self.forces, name, sensor_in_base)
        radius = 1.0 if contact is None else contact.radius_mm(grasp.object)
        shape = "sphere" if grasp.object.curvature_radius_mm is not None else FLAT_BOX_SHAPE
        rng = np.random.default_rng(self.seeds[self.skin.patches.index(patch)])
        n = self.n_frames(name)
        block_frames = block_frames or BLOCK_FRAMES
        for first in range(0, max(n, 1), block_frames):
            last = min(n, first + block_frames)
            time_s = np.arange(first, last) / rate
            scale = timing.scale(time_s)
            force = self.forces.get(name, 0.0) * scale
            tangential = scale[:, None] * shear
            frames, _ = patch_frames(
                spec, contact, force, tangential_n=tangential, radius_mm=radius, shape=shape,
                flaws=grasp.flaws, rng=rng,
            )  # fmt: skip
            truth = stream_truth(
                patch, contact, force, tangential, radius, timing.phase(time_s), sensor_in_base
            )
            yield first, last, frames, truth

    def gains(self, name: str) -> np.ndarray:
        """Per-taxel gains [-] of patch ``name``'s frames (its sensor's own)."""
        spec = self.skin.patch(name).sensor
        return check_gains(spec, None, resolve_flaws(self.grasp.flaws))


def plan_grasp(skin: RobotSkin, grasp: Grasp) -> GraspPlan:
    """Check ``grasp`` on ``skin`` and find its contacts and forces (:class:`GraspPlan`);
    every error a simulation can meet is raised here, before any frame is made.

    Raises
    ------
    GraspError
        The object touches no patch, a force names what it does not touch, a joint
        state is invalid, or a patch's kind does not take a grasp.
    """
    if not isinstance(skin, RobotSkin):
        raise GraspError(f"skin must be a RobotSkin; got {type(skin).__name__}")
    if not isinstance(grasp, Grasp):
        raise GraspError(f"grasp must be a Grasp; got {type(grasp).__name__}")
    for patch in skin.patches:
        if not takes_grasp(patch.sensor):
            raise kind_of(patch.sensor).unsupported(
                patch.sensor, f"a simulated grasp (patch {patch.name!r})"
            )
    contacts = grasp_contacts(skin, grasp)
    if not contacts:
        raise GraspError(
            f"the {grasp.object.shape} touches no patch of {skin.name!r} at this pose and "
            f"joint state; move it into the hand ({_nearest_patch(skin, grasp)}; "
            f"'tactsense sensor show {skin.name}' lists each patch's link and pose)"
        )
    forces = grasp_forces(skin, grasp, contacts)
    scenario = grasp_scenario(skin, grasp, forces)
    scenario["description"] = (
        f"simulated grasp on {skin.name}: {grasp.object.shape} "
        f"{_numbers(grasp.object.size_mm)} mm, {scenario['force_rule']} forces, "
        f"{len(contacts)} of {len(skin.patches)} patches touched"
    )
    return GraspPlan(
        skin=skin,
        grasp=grasp,
        contacts=contacts,
        forces=forces,
        poses=skin.link_poses(joint_state(skin, grasp.joints)),
        scenario=scenario,
        seeds=tuple(np.random.SeedSequence(grasp.seed).spawn(len(skin.patches))),
    )


def simulate_grasp(
    skin: RobotSkin,
    grasp: Grasp,
    *,
    progress: Callable[[int, int], None] | None = None,
) -> RobotRecording:
    """Frames of every patch of ``skin`` under ``grasp``, at each patch's own scan rate,
    in memory (:func:`write_grasp` writes them to a folder in bounded memory).

    Parameters
    ----------
    skin : RobotSkin
    grasp : Grasp
    progress : callable, optional
        Called with (patches done, patches) as each patch's frames are made.

    Returns
    -------
    RobotRecording
        One stream per patch, each with :data:`TRUTH_KEYS` in its truth, and the grasp
        in its scenario.

    Raises
    ------
    GraspError
        As :func:`plan_grasp`.
    """
    plan = plan_grasp(skin, grasp)
    streams = {}
    for done, patch in enumerate(skin.patches):
        spec = patch.sensor
        blocks = list(plan.blocks(patch.name))
        n = plan.n_frames(patch.name)
        truth = {
            key: np.concatenate([b[3][key] for b in blocks])[:n]
            if key in TIME_KEYS
            else blocks[0][3][key]
            for key in blocks[0][3]
        }
        streams[patch.name] = Recording(
            frames=np.concatenate([b[2] for b in blocks])[:n],
            time_s=np.arange(n) / spec.electronics.scan_rate_hz,
            sample_offset_s=sample_offsets(spec),
            sensor=spec,
            scenario=plan.scenario,
            flaws=resolve_flaws(grasp.flaws),
            truth=truth,
            gains=plan.gains(patch.name),
        )
        if progress is not None:
            progress(done + 1, len(skin.patches))
    return RobotRecording(skin=skin, streams=streams, description=plan.scenario["description"])


def _tangential(grasp, contact, forces, name, sensor_in_base) -> np.ndarray:
    """The full tangential force [N] the object applies to patch ``name`` at its contact,
    in its sensor frame, (3,): its share of the grasp's load (by normal force), less the
    part along the skin's normal."""
    if grasp.load_n is None or contact is None:
        return np.zeros(3)
    share = forces[name] / sum(forces.values()) * np.asarray(grasp.load_n)
    local = sensor_in_base[:3, :3].T @ share
    return local - (local @ contact.normal) * contact.normal


def _numbers(values) -> str:
    return " x ".join(f"{v:g}" for v in values)


def grasp_scenario(skin: RobotSkin, grasp: Grasp, forces: Mapping[str, float]) -> dict:
    """The grasp as a recording's scenario (plain JSON): the object, joint state, rule,
    each touched patch's full force [N] and the phases as steps."""
    g = grasp.object
    return {
        "kind": "grasp",
        "skin": skin.name,
        "object": {
            "shape": g.shape,
            "size_mm": list(g.size_mm),
            "xyz_m": list(g.pose.xyz_m),
            "rpy_rad": list(g.pose.rpy_rad),
        },
        "joints": joint_state(skin, grasp.joints),
        "force_rule": "penetration stiffness" if grasp.force_n is None else "commanded",
        "stiffness_n_per_mm": grasp.stiffness_n_per_mm,
        "load_n": None if grasp.load_n is None else list(grasp.load_n),
        "patch_force_n": {k: float(v) for k, v in forces.items()},
        "steps": [
            {"name": name, "duration_s": d}
            for name, d in zip(PHASES, grasp.timing.durations_s, strict=True)
        ],
    }


def write_grasp(
    path: str | Path,
    skin: RobotSkin,
    grasp: Grasp,
    *,
    overwrite: bool = False,
    progress: Callable[[int, int], None] | None = None,
) -> GraspPlan:
    """Simulate ``grasp`` on ``skin`` into a robot recording folder at ``path``, block by
    block (memory holds one block of one patch, :data:`BLOCK_FRAMES` frames), under a
    temporary name moved into place when whole.

    Parameters
    ----------
    progress : callable, optional
        Called with (frames written, frames) over every patch's frames.

    Returns
    -------
    GraspPlan
        The grasp's contacts and forces.
    """
    from tactsense.simulate._grasp_write import write_grasp_folder

    plan = plan_grasp(skin, grasp)
    write_grasp_folder(path, plan, overwrite=overwrite, progress=progress)
    return plan


__all__ = [
    "MAX_PHASE_S",
    "OBJECTS",
    "PHASES",
    "SIZES",
    "TRUTH_KEYS",
    "Grasp",
    "GraspError",
    "GraspObject",
    "GraspPlan",
    "PatchContact",
    "Timing",
    "fingers",
    "grasp_contacts",
    "grasp_forces",
    "grasp_from_dict",
    "grasp_from_toml",
    "grasp_scenario",
    "joint_state",
    "plan_grasp",
    "simulate_grasp",
    "write_grasp",
]
