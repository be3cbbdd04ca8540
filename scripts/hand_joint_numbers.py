"""The hand's force with the joint fit (issue 34 item 1 on a robot): the figures of
docs/robot.md's "Broad contacts: --method joint" block.

    python scripts/hand_joint_numbers.py [--every 5]

1. The docs' simulated grasp (``scripts/grasp_numbers.py``'s: ``hand4``, a 40-mm sphere
   pressed 1.5 mm into ``palm_0``, 2 N), with every per-frame flaw and without flaws:
   every ``--every``-th hold frame located as hand frames (all 20 patches) by
   :class:`~tactsense.estimate.robot.HandLocator` with ``interpolate`` and with
   ``joint``; the grasp's total force (the norm of the total wrench's force [N]) against
   the truth's, and the time per hand frame (this process, one core), touched (hold)
   and untouched (before the approach).
2. The palm's pad alone (hand4's 18 x 18, 2-mm pitch) under spheres of 10 and 20 mm
   radius at 0.5 and 2 N, at four places within a taxel, without flaws and with every
   flaw: the total located force of each method against the truth.

The text replaces the block between ``<!-- hand-joint-numbers -->`` markers.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "scripts"))
from docblock import replace_block  # noqa: E402

BEGIN, END = "<!-- hand-joint-numbers -->", "<!-- /hand-joint-numbers -->"
METHODS = ("interpolate", "joint")


def _grasp(skin, flaws: str):
    """The docs' grasp (grasp_numbers.py's placement) simulated in memory."""
    from tactsense.robot import Pose
    from tactsense.simulate.grasp import Grasp, GraspObject, simulate_grasp

    largest = max(skin.patches, key=lambda p: p.n_taxels)
    positions, normals = skin.taxels_in_base()[largest.name]
    normal = normals.mean(axis=0)
    normal /= np.linalg.norm(normal)
    radius_mm, depth_mm = 20.0, 1.5
    centre_mm = 1e3 * positions.mean(axis=0) + (radius_mm - depth_mm) * normal
    centre_mm = np.round(centre_mm, 2)  # as the command line's --pose
    item = GraspObject("sphere", (2 * radius_mm,), Pose(tuple(centre_mm / 1e3), (0.0, 0.0, 0.0)))
    return largest.name, simulate_grasp(skin, Grasp(item, force_n=2.0, flaws=flaws))


def _off_taxel_forces(locator, streams, name: str, frames) -> np.ndarray:
    """The forces [N] ``find_contacts(method="joint")`` gives the contacts it fits off the
    patch's taxels (beyond ``OFF_TAXELS``), which the hand lists without force."""
    from tactsense.estimate.contacts import find_contacts
    from tactsense.estimate.robot import OFF_TAXELS

    p = locator.patch_names.index(name)
    sensor = locator.skin.patches[p].sensor
    shape = tuple(sensor.shape)
    off, size = locator._offset[p], int(np.prod(shape))
    table = find_contacts(
        streams[name].frames[frames], sensor,
        baseline=locator._baseline[off : off + size].reshape(shape),
        dead=locator._unusable[off : off + size].reshape(shape), method="joint",
    )  # fmt: skip
    rows, cols = shape
    beyond = (table.row < -OFF_TAXELS) | (table.row > rows - 1 + OFF_TAXELS)
    beyond |= (table.col < -OFF_TAXELS) | (table.col > cols - 1 + OFF_TAXELS)
    return np.column_stack([table.force_n, table.row, table.col])[beyond]


def _off_list(rows) -> str:
    found = "; ".join(f"{f:,.1f} N at row {r:.2f}, column {c:.2f}" for f, r, c in rows)
    return found or "none"


def edge_sentence() -> str:
    """A 1-N sphere (5-mm radius) one pitch beyond the palm pad's first row, noise-free:
    what the joint fit gives it."""
    from tactsense.estimate.contacts import find_contacts
    from tactsense.robot import load_skin
    from tactsense.simulate import ContactBatch, frames_from_contacts

    sensor = load_skin("hand4").patch("palm_0").sensor
    where = np.array([[[-2.0, 10.0]]])
    frames = frames_from_contacts(sensor, ContactBatch(where, [[1.0]], radius_mm=5.0),
                                  flaws="none")  # fmt: skip
    rest = frames_from_contacts(sensor, ContactBatch(where, [[0.0]]), flaws="none")
    table = find_contacts(frames.reshape(sensor.shape), sensor,
                          baseline=rest.reshape(sensor.shape), method="joint")  # fmt: skip
    found = ", ".join(
        f"row {r:.2f}, column {c:.2f} with {f:.1f} N" for r, c, f in
        zip(table.row, table.col, table.force_n, strict=True)
    ) or "nothing"  # fmt: skip
    return (
        "A 1-N sphere of 5-mm radius one pitch beyond the palm pad's first row (row -1, "
        f"column 5), without flaws: the joint fit finds {found}."
    )


def grasp_rows(every: int) -> tuple[list[str], dict]:
    from tactsense.estimate.robot import HandLocator
    from tactsense.robot import load_skin
    from tactsense.simulate.grasp import PHASES

    skin = load_skin("hand4")
    rows, notes = [], {}
    for flaws, label in (("all", "every per-frame flaw"), ("none", "no flaw")):
        name, recording = _grasp(skin, flaws)
        streams = recording.streams
        palm = streams[name]
        step = palm.truth["frame_step"]
        hold = np.flatnonzero(step == PHASES.index("hold"))[::every]
        idle = np.flatnonzero(step == 0)[: len(hold)]
        truth = sum(
            np.nansum(s.truth["contact_normal_force_n"][hold], axis=1) for s in streams.values()
        )
        baselines = {n: np.median(s.frames[:5], axis=0) for n, s in streams.items()}
        joints = palm.scenario["joints"]
        for method in METHODS:
            locator = HandLocator(skin, baselines, method=method)
            seconds = {}
            for what, chosen in (("hold", hold), ("idle", idle)):
                counts = locator.pack({n: s.frames[chosen] for n, s in streams.items()})
                started = time.perf_counter()
                result = locator.locate(counts, joints)
                seconds[what] = (time.perf_counter() - started) / len(chosen)
                if what == "hold":
                    force = np.linalg.norm(result.total[:, :3], axis=1)
                    per_frame = np.bincount(result.contacts["frame"], minlength=len(chosen))
                    no_force = int(np.isnan(result.contacts["force_n"]).sum())
            if method == "joint" and flaws == "all":  # the fit's own force of those
                notes["raw"] = _off_taxel_forces(locator, streams, name, hold)
            error = 100.0 * (force / truth - 1.0)
            within = int(np.sum(np.abs(error) <= 5.0))
            rows.append(
                f"| {label} | `{method}` | {len(hold)} | {np.median(truth):.2f} | "
                f"{np.median(force):.2f} | {np.median(error):+.1f} | "
                f"{error.min():+.1f} to {error.max():+.1f} | {within} of {len(hold)} | "
                f"{int(per_frame.min())}-{int(per_frame.max())} | {no_force} | "
                f"{1e3 * seconds['hold']:.0f} | {1e3 * seconds['idle']:.1f} |"
            )
            notes[(flaws, method)] = error
        notes["hold"] = len(np.flatnonzero(step == PHASES.index("hold")))
        notes["patch"] = name
    return rows, notes


def palm_rows() -> list[str]:
    from tactsense.estimate.contacts import default_threshold, find_contacts
    from tactsense.estimate.reading import signal_from_counts
    from tactsense.robot import load_skin
    from tactsense.simulate import ContactBatch, frames_from_contacts

    sensor = load_skin("hand4").patch("palm_0").sensor
    shape = tuple(sensor.shape)
    places = np.array([[17.0, 17.0], [17.5, 17.0], [18.0, 18.0], [17.3, 17.7]])
    rows = []
    for radius in (10.0, 20.0):
        for force in (0.5, 2.0):
            batch = ContactBatch(places[:, None, :], np.full((len(places), 1), force),
                                 radius_mm=radius)  # fmt: skip
            for flaws in ("none", "all"):
                frames = frames_from_contacts(sensor, batch, flaws=flaws, rng=0)
                frames = frames.reshape(len(places), *shape)
                rest = frames_from_contacts(
                    sensor, ContactBatch(np.zeros((5, 1, 2)), np.zeros((5, 1))),
                    flaws=flaws, rng=1,
                )  # fmt: skip
                baseline = np.median(rest.reshape(5, *shape), axis=0)
                signal, _ = signal_from_counts(frames, baseline, sensor)
                read = (signal > default_threshold(sensor)).sum(axis=(1, 2))
                cells = [" ".join(str(int(r)) for r in read)]
                for method in METHODS:
                    started = time.perf_counter()
                    table = find_contacts(frames, sensor, baseline=baseline, method=method)
                    seconds = (time.perf_counter() - started) / len(places)
                    total = np.bincount(table.frame, table.force_n, minlength=len(places))
                    error = 100.0 * (total / force - 1.0)
                    count = np.bincount(table.frame, minlength=len(places))
                    cells.append(
                        f"{' '.join(f'{e:+.1f}' for e in error)} | {count.max()}"
                        + (f" | {1e3 * seconds:.0f}" if method == "joint" else "")
                    )
                rows.append(
                    f"| {radius:g} | {force:g} | {'none' if flaws == 'none' else 'every'} | "
                    f"{' | '.join(cells)} |"
                )
    return rows


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--every", type=int, default=5, help="every N-th hold frame")
    args = parser.parse_args()
    grasp, notes = grasp_rows(args.every)
    palm = palm_rows()
    text = "\n".join(
        [
            BEGIN,
            "Generated by `python scripts/hand_joint_numbers.py`. The docs' simulated grasp "
            "above (`hand4`, a 40-mm sphere 1.5 mm into "
            f"`{notes['patch']}`, 2 N), every {args.every}th of its {notes['hold']} hold "
            "frames located as whole hand frames (all 20 patches) by `HandLocator`; the "
            "grasp's total force is the norm of the total wrench's force; times per hand "
            "frame in one process on this shared 2-core machine (touched: the hold frames; "
            "untouched: frames before the approach, where the joint fit finds nothing to "
            "fit):",
            "",
            "| flaws | method | hand frames | truth [N] | located, median [N] | error, median "
            "[%] | range [%] | within 5 % | contacts per frame | contacts without force | "
            "ms per touched frame | ms per untouched frame |",
            "|---|---|---|---|---|---|---|---|---|---|---|---|",
            *grasp,
            "",
            "The palm's pad alone (hand4's 18 x 18 pad, 2-mm pitch) under one sphere at four "
            "places within a taxel ((17, 17), (17.5, 17), (18, 18), (17.3, 17.7) mm), "
            "`find_contacts` (the hand's rows are its, tested exactly): the total located "
            "force's error [%] at each place, the taxels above the threshold at each place, the "
            "most contacts a frame was split into, and the joint fit's time per frame:",
            "",
            "| sphere radius [mm] | force [N] | flaws | taxels above the threshold | "
            "`interpolate` error [%] | contacts | `joint` error [%] | contacts | `joint` ms "
            "per frame |",
            "|---|---|---|---|---|---|---|---|---|",
            *palm,
            "",
            "Contacts the joint fit placed off the palm's taxels in the grasp's hold frames "
            "above (every flaw; the hand lists them without force): "
            + _off_list(notes["raw"])
            + ".",
            edge_sentence(),
            END,
        ]
    )
    replace_block(ROOT / "docs" / "robot.md", BEGIN, END, text)
    print(text)


if __name__ == "__main__":
    main()
