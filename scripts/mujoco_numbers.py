"""The numbers and the figure of docs/mujoco.md: the example model's frames beside MuJoCo's
own touch sensor and touch grid, and the adapter's checks (force with the sensor's
calibration, contact centroid, slip onset) measured on it.

Run: ``python scripts/mujoco_numbers.py`` (about seven minutes on a shared core)
rewrites the blocks ``<!-- begin mujoco numbers -->`` ... ``<!-- end mujoco numbers -->``
and ``<!-- begin mujoco sampling numbers -->`` ... ``<!-- end mujoco sampling numbers
-->`` in docs/mujoco.md and writes ``docs/images/mujoco_side_by_side.png``.

How the numbers are made (seeded, so a run repeats them):

* **The example**: ``tactsense mujoco --out ex.h5 --seed 2`` (the example model, its
  controls, pad16 with all its per-frame flaws). The figure's frames are the same frames
  (``frame_blocks`` with the same seed), with MuJoCo's ``touch`` sensor and touch grid
  read at each frame's instant (``on_read``).
* **Calibration**: twelve presses of the finger on the ball (``PRESS_DEPTHS_M``) recorded
  the same way (seed 1), MuJoCo's force on each press's plateau as the weights log,
  ``tactsense calibrate weights.h5 --force-log weights.csv`` (the weight curve); then
  ``tactsense locate ex.h5 --calibration cal.json``: each frame's summed contact force
  against MuJoCo's normal force sum, per phase of the motion.
* **Centroid**: ``tactsense locate ex.h5 --method fit`` (uncalibrated): the located
  contacts' force-weighted centroid against MuJoCo's (the truth's ``step_x_mm``,
  ``step_y_mm``).
* **The calibration joined with the joint fit** (issue 38 item 2), on the example's
  sampling pad (``mujoco_finger_pad.toml``: pad16's grid under a 6-mm layer, recorded
  the same way, seed 2) and on the preset pad16 (its phases' frames only): the gains
  and baseline of a probe sweep (``simulate --scenario calibration --seed 1``,
  ``calibrate``), a force curve fitted to the joint fit's own force on the twelve
  presses (``interop._mujoco_calibrate.joint_force_calibration``), then
  ``find_contacts(..., method="joint")`` with it: each frame's summed force and
  force-weighted centroid against MuJoCo's (a rod's two end contacts so merged into one
  load). The aliasing table: the ball at sub-taxel offsets, noise-free frames, each
  pad's joint fit.
* **Slip**: MuJoCo's onset (the first frame with a contact at the friction cone's limit
  after the ball press) against the first frame of the slide that ``locate`` flags
  ``slip`` (a contact moving under a steady force).
* **The finger** (``tactsense mujoco --example fingertip --seed 3``: the paper's finger
  slid along its axis over a ball; it takes the axial shear): ``tactsense locate``'s skew
  index per frame turned into ``tan(alpha)`` (``skew / k(nu)``, section 9 of the paper,
  ``angle_from_skew``) against MuJoCo's friction over normal force, in the stick before
  the onset and while sliding.
"""

from __future__ import annotations

import subprocess
import sys
import tempfile
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import mujoco
import numpy as np
import pandas as pd

sys.path.insert(0, str(Path(__file__).resolve().parent))
from docblock import replace_block, save_figure

from tactsense.estimate.contacts.calibration import load_calibration
from tactsense.estimate.contacts.find import find_contacts
from tactsense.interop import mujoco as adapter
from tactsense.interop._mujoco_calibrate import joint_force_calibration
from tactsense.io.recording import read_recording
from tactsense.sensor import load_sensor

ROOT = Path(__file__).resolve().parents[1]
DOC = ROOT / "docs" / "mujoco.md"
FIGURE = ROOT / "docs" / "images" / "mujoco_side_by_side.png"
PHASES = {
    "ball, held (1.5-1.8 s)": range(150, 180),
    "ball, sliding (2.3-3.7 s)": range(230, 370),
    "rod, held (6.7-7.1 s)": range(670, 710),
    "rod, sliding (7.4-9.0 s)": range(740, 900),
}
SHOWN = {"ball, held": 165, "ball, sliding": 300, "rod, sliding": 850}
PRESS_DEPTHS_M = np.linspace(-0.0305, -0.0375, 12)
PITCH_MM = 2.5


def _tactsense(*args: str) -> None:
    subprocess.run([sys.executable, "-m", "tactsense", *args], check=True, capture_output=True)


def _side_by_side(spec):
    """Frames and MuJoCo's own sensors at every frame of the example (seed 2)."""
    model = adapter.load_model(adapter.example_model_path())
    controls = adapter.read_controls(adapter.example_controls_path(), model)
    sensor = adapter.MujocoSensor(model, spec, geom="pad")
    ids = {
        name: mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SENSOR, name)
        for name in ("pad_touch", "pad_grid")
    }
    touch, grid, contacts = {}, {}, {}

    def read(j, data):
        a = model.sensor_adr[ids["pad_touch"]]
        touch[j] = float(data.sensordata[a])
        a, n = model.sensor_adr[ids["pad_grid"]], model.sensor_dim[ids["pad_grid"]]
        image = data.sensordata[a : a + n].reshape(3, 16, 16)[0]
        grid[j] = np.flipud(image).T.copy()  # the plugin's [i, j] is the pad's (row j, col 15 - i)
        contacts[j] = sensor.read(data)

    n = adapter.frame_count(spec, 10.0)
    data = mujoco.MjData(model)
    frames = np.concatenate(
        [c for _, _, c, _ in adapter.frame_blocks(
            sensor, data, n_frames=n, controls=controls, rng=2, on_read=read)]
    )  # fmt: skip
    return frames, touch, grid, contacts


def _figure(spec, frames, touch, grid, contacts) -> None:
    baseline = frames[:50].mean(axis=0)
    fig, axes = plt.subplots(len(SHOWN), 3, figsize=(10.5, 3.2 * len(SHOWN)))
    extent = (-PITCH_MM / 2, 16 * PITCH_MM - PITCH_MM / 2) * 2
    for row, (label, j) in enumerate(SHOWN.items()):
        c = contacts[j]
        panels = (
            (frames[j] - baseline, "tactsense pad16 [counts above rest]"),
            (grid[j], "MuJoCo touch grid, normal [N]"),
        )
        for col, (image, title) in enumerate(panels):
            ax = axes[row, col]
            shown = ax.imshow(image.T, origin="lower", extent=extent, cmap="magma")
            ax.plot(*c.position_mm.T, "c+", ms=12, mew=2)
            ax.set_title(f"{label}: {title}", fontsize=8)
            ax.set_xlabel("x [mm] (rows)", fontsize=8)
            ax.set_ylabel("y [mm] (columns)", fontsize=8)
            fig.colorbar(shown, ax=ax, fraction=0.046)
        ax = axes[row, 2]
        ax.axis("off")
        lines = [
            f"frame {j} ({(j + 0.5) * spec.scan_period_s:.3f} s)",
            f"MuJoCo touch sensor: {touch[j]:.3f} N (one number)",
            f"touch grid, sum of normal: {grid[j].sum():.3f} N",
            f"contacts read ({len(c)}):",
        ]
        for p, f, t, s in zip(
            c.position_mm, c.normal_force_n, c.tangential_force_n, c.slipping, strict=True
        ):
            lines.append(f"  ({p[0]:.1f}, {p[1]:.1f}) mm, {f:.3f} N" + (", sliding" if s else ""))
            lines.append(f"    friction ({t[0]:+.3f}, {t[1]:+.3f}) N")
        ax.text(0, 0.95, "\n".join(lines), va="top", family="monospace", fontsize=7.5)
    fig.tight_layout()
    save_figure(fig, FIGURE)


def _centroid(table):
    """Each frame's force-weighted contact centroid [mm] from a ``locate`` table."""
    weighted = table.assign(wx=table.x_mm * table.force_n, wy=table.y_mm * table.force_n)
    sums = weighted.groupby("frame")[["wx", "wy", "force_n"]].sum()
    return pd.DataFrame(np.c_[sums.wx / sums.force_n, sums.wy / sums.force_n], index=sums.index)


def _force_error(total, force, frames) -> str:
    """Median and largest error [%] of the summed force against MuJoCo's."""
    error = 100 * (total.reindex(frames).fillna(0).to_numpy() / force[frames] - 1)
    return f"{np.median(error):+.2f}, {error[np.argmax(np.abs(error))]:+.2f}"


def _centroid_error(located, centre, frames) -> str:
    """Median and largest centroid error [mm] (and the largest in pitches)."""
    gap = np.hypot(*(located.reindex(frames).to_numpy() - centre[frames]).T)
    return f"{np.nanmedian(gap):.3f}, {np.nanmax(gap):.3f} ({np.nanmax(gap) / PITCH_MM:.2f})"


def _presses(folder: Path, name: str, sensor: str) -> Path:
    """Twelve presses of the finger on the ball (``PRESS_DEPTHS_M``), recorded (seed 1)."""
    controls = folder / "presses.csv"
    rows, t = [(0.0, 0.0, 0.0, 0.0)], 0.0
    for z in PRESS_DEPTHS_M:
        rows += [(t + 0.3, 0, 0, -0.028), (t + 0.6, 0, 0, z), (t + 1.4, 0, 0, z),
                 (t + 1.7, 0, 0, -0.028)]  # fmt: skip
        t += 1.7
    rows.append((t + 0.3, 0.0, 0.0, 0.0))
    controls.write_text("time_s,x,y,z\n" + "".join(",".join(map(str, r)) + "\n" for r in rows))
    out = folder / name
    _tactsense("mujoco", "--controls", str(controls), "--sensor", sensor, "--out", str(out),
               "--seed", "1", "-q")  # fmt: skip
    return out


def _numbers(folder: Path, spec, touch, grid) -> str:
    ex = folder / "ex.h5"
    _tactsense("mujoco", "--out", str(ex), "--seed", "2", "-q")
    truth = read_recording(ex).truth
    force, centre = truth["step_force_n"], np.c_[truth["step_x_mm"], truth["step_y_mm"]]
    # the calibration: presses on the ball, MuJoCo's plateau forces as the weights
    weights = _presses(folder, "weights.h5", "pad16")
    pressed = read_recording(weights).truth["step_force_n"]
    edges = np.flatnonzero(np.diff((pressed > 0.05).astype(int)))
    loads = [np.median(pressed[s + (e - s) // 2 : e - (e - s) // 10])
             for s, e in zip(edges[::2] + 1, edges[1::2] + 1, strict=True)]  # fmt: skip
    log = folder / "weights.csv"
    log.write_text("press,force_n\n" + "".join(f"{i + 1},{f:.6f}\n" for i, f in enumerate(loads)))
    cal = folder / "cal.json"
    _tactsense("calibrate", str(weights), "--force-log", str(log), "--out", str(cal))
    _tactsense("locate", str(ex), "--calibration", str(cal), "--out", str(folder / "cal.csv"))
    _tactsense("locate", str(ex), "--method", "fit", "--out", str(folder / "fit.csv"))
    calibrated = pd.read_csv(folder / "cal.csv")
    fitted = pd.read_csv(folder / "fit.csv")
    total = calibrated.groupby("frame").force_n.sum()
    located = _centroid(fitted)
    out = [
        "| phase | MuJoCo force [N] | force error, calibrated: median, largest [%] | "
        "centroid error (fit): median, largest [mm] (pitch) |",
        "|---|---|---|---|",
    ]
    for label, frames in PHASES.items():
        frames = list(frames)
        out.append(
            f"| {label} | {force[frames].mean():.3f} | {_force_error(total, force, frames)} | "
            f"{_centroid_error(located, centre, frames)} |"
        )
    onset = 180 + int(np.argmax(truth["mujoco_slip"][180:]))
    flagged = fitted[(fitted.frame >= 180) & (fitted.frame < 420) & fitted.slip]
    first_flag = int(flagged.frame.min()) if len(flagged) else None
    ours = np.array([force[j] for j in sorted(touch)])
    touch_gap = np.max(np.abs(ours - np.array([touch[j] for j in sorted(touch)])))
    grid_gap = np.max(np.abs(ours - np.array([grid[j].sum() for j in sorted(grid)])))
    lag = "never" if first_flag is None else f"frame {first_flag} ({first_flag - onset:+d} frames)"
    out += [
        "",
        f"* Slip on the ball: MuJoCo's onset (friction at the cone's limit) at frame {onset} "
        f"({(onset + 0.5) * spec.scan_period_s:.3f} s); `locate`'s `slip` flag first at {lag}.",
        f"* Normal force read by the adapter against MuJoCo's `touch` sensor, every frame: "
        f"largest difference {touch_gap:.1e} N; against the touch grid's summed normal "
        f"channel: {grid_gap:.1e} N.",
        f"* Calibration: {len(loads)} presses, {min(loads):.3f}-{max(loads):.3f} N.",
        _fingertip(folder),
    ]
    return "\n".join(out), _sampling_pad(folder, ex, truth)


def _sampling_pad(folder: Path, ex: Path, truth) -> str:
    """The joined calibration and joint fit on the example's sampling pad and on the
    preset pad16 (its phases only), and the aliasing table."""
    thick = str(adapter.example_pad_path())
    ex_thick = folder / "ex_thick.h5"
    _tactsense("mujoco", "--sensor", thick, "--out", str(ex_thick), "--seed", "2", "-q")
    located_thick, cal_thick = _joined(folder, thick, ex_thick)
    phase_frames = np.concatenate([list(f) for f in PHASES.values()])
    located_preset, cal_preset = _joined(folder, "pad16", ex, frames=phase_frames)
    out = [
        "| pad | phase | force error, calibration + joint fit: median, largest [%] | "
        "centroid error: median, largest [mm] (largest in pitch) | contacts found per "
        "frame |",
        "|---|---|---|---|---|",
        *_joined_rows("pad16, 6-mm layer (`mujoco_finger_pad.toml`)", located_thick, truth),
        *_joined_rows("pad16 (preset)", located_preset, truth),
    ]
    force = truth["step_force_n"]
    total = located_thick.groupby("frame").force_n.sum().reindex(range(len(force))).fillna(0)
    pressed = np.flatnonzero(force >= 0.05)
    error = 100 * (total.to_numpy()[pressed] / force[pressed] - 1)
    rows, cols = load_sensor(thick).shape
    x, y = located_thick.x_mm, located_thick.y_mm
    off = located_thick[(x < -PITCH_MM) | (y < -PITCH_MM) | (x > rows * PITCH_MM)
                        | (y > cols * PITCH_MM)]  # fmt: skip
    slide = np.array(list(PHASES["ball, sliding (2.3-3.7 s)"]))
    slide_error = 100 * (total.to_numpy()[slide] / force[slide] - 1)
    out += [
        "",
        f"* The 6-mm pad, every frame with MuJoCo's force >= 0.05 N ({len(pressed)} frames): "
        f"{np.mean(np.abs(error) <= 2):.1%} within 2 %, median {np.median(error):+.2f} %, "
        f"5-95 % {np.percentile(error, 5):+.2f} to {np.percentile(error, 95):+.2f} %; "
        f"frames with a contact placed more than a pitch outside the taxels: "
        f"{off.frame.nunique()} (that contact's force: {off.force_n.min():.1f} to "
        f"{off.force_n.max():.1f} N). The sliding ball: {np.sum(np.abs(slide_error) > 2)} of "
        f"{len(slide)} frames off by more than 2 %.",
        f"* Calibrations (gains from a probe sweep, a force curve on the joint fit's force "
        f"from the twelve presses): the 6-mm pad's curve maps "
        f"{cal_thick.force_curve[0][-1]:.3f} to {cal_thick.force_curve[1][-1]:.3f} N (the "
        f"transduction's saturation); the preset's {cal_preset.force_curve[0][-1]:.3f} to "
        f"{cal_preset.force_curve[1][-1]:.3f} N.",
        "",
        "Why the preset pad16 misses: the example's ball (8 mm, 1.9 N) at sub-taxel offsets "
        "from taxel (7, 7), noise-free frames (no flaws), each pad's joint fit uncalibrated:",
        "",
        *_aliasing([("pad16", load_sensor("pad16")), ("6-mm layer", load_sensor(thick))]),
    ]
    return "\n".join(out)


def _joined(folder: Path, sensor: str, ex: Path, frames=None):
    """The pad's calibration joined with the joint fit (issue 38 item 2): the gains and
    baseline of a probe sweep (``simulate --scenario calibration``, ``calibrate``), a
    force curve fitted to the joint fit's own force on the twelve presses (every third
    frame, MuJoCo's normal force at each as the load cell), then ``method="joint"``
    with that calibration on the example's frames (``frames``: only those). Returns the
    located contacts as a table (frame, force_n, x_mm, y_mm) and the calibration."""
    tag = Path(sensor).stem
    sweep, gains = folder / f"{tag}_sweep.h5", folder / f"{tag}_gains.json"
    _tactsense("simulate", "--scenario", "calibration", "--sensor", sensor, "--out", str(sweep),
               "--seed", "1")  # fmt: skip
    _tactsense("calibrate", str(sweep), "--out", str(gains))
    presses = read_recording(_presses(folder, f"{tag}_presses.h5", sensor))
    calibration = joint_force_calibration(
        load_calibration(gains), presses.sensor, presses.frames[::3],
        presses.truth["step_force_n"][::3],
    )  # fmt: skip
    recording = read_recording(ex)
    chosen = np.arange(len(recording.frames)) if frames is None else np.asarray(frames)
    table = find_contacts(recording.frames[chosen], recording.sensor, calibration=calibration,
                          method="joint")  # fmt: skip
    located = pd.DataFrame({"frame": chosen[table.frame], "force_n": table.force_n,
                            "x_mm": table.x_mm, "y_mm": table.y_mm})  # fmt: skip
    return located, calibration


def _joined_rows(label: str, located, truth) -> list[str]:
    """Rows of the joined table: per phase, the summed force and its centroid against
    MuJoCo's (a rod's two end contacts merged into one load: their sum and centroid)."""
    force, centre = truth["step_force_n"], np.c_[truth["step_x_mm"], truth["step_y_mm"]]
    total = located.groupby("frame").force_n.sum()
    counts = located.groupby("frame").size()
    rows = []
    for phase, frames in PHASES.items():
        frames = list(frames)
        n = counts.reindex(frames).fillna(0)
        rows.append(
            f"| {label} | {phase} | {_force_error(total, force, frames)} | "
            f"{_centroid_error(_centroid(located), centre, frames)} | "
            f"{n.min():.0f}-{n.max():.0f} |"
        )
    return rows


ALIAS_OFFSETS = np.array([0.0, 0.125, 0.25, 0.375, 0.5])
"""Offsets of the ball's centre from a taxel's centre [pitch] (along x, then diagonal)."""


def _aliasing(specs, force_n=1.9, radius_mm=8.0) -> list[str]:
    """Why the preset pad16 misses: the example's ball (8 mm, 1.9 N, Hertz radius) at
    sub-taxel offsets, noise-free frames (no flaws), for each pad: the sum of its
    readings above rest, the taxels read, and the joint fit's force error."""
    from tactsense.simulate import ContactBatch, frames_from_contacts

    p = PITCH_MM
    places = [(d, 0.0) for d in ALIAS_OFFSETS] + [(d, d) for d in ALIAS_OFFSETS[1:]]
    centre = 7 * p  # taxel (7, 7), near the pad's middle (surface coordinates from taxel 0)
    at = np.array(
        [[(centre, centre)]] + [[(centre + dx * p, centre + dy * p)] for dx, dy in places]
    )
    n = len(at)
    batch = ContactBatch(
        position_mm=at, normal_force_n=np.r_[0.0, np.full(n - 1, force_n)][:, None],
        radius_mm=np.full((n, 1), radius_mm), shape="sphere",
    )  # fmt: skip
    columns = {}
    for name, spec in specs:
        frames = frames_from_contacts(spec, batch, flaws="none", fast=False)
        frames = frames.reshape(n, *spec.shape)
        up = frames[1:] - frames[0]
        table = find_contacts(frames[1:], spec, baseline=frames[0], method="joint")
        fitted = np.zeros(n - 1)
        np.add.at(fitted, table.frame, np.nan_to_num(table.force_n))
        total = up.sum(axis=(1, 2))
        columns[name] = (100 * (total / total.mean() - 1), (up > 10).sum(axis=(1, 2)),
                         100 * (fitted / force_n - 1))  # fmt: skip
    names = [name for name, _ in specs]
    out = [
        "| ball's offset from a taxel's centre, x, y [pitch] | "
        + " | ".join(
            f"{m}: sum of readings against its mean [%] | {m}: taxels read | "
            f"{m}: joint fit's force error [%]"
            for m in names
        )
        + " |",
        "|---" * (1 + 3 * len(names)) + "|",
    ]
    for i, (dx, dy) in enumerate(places):
        cells = [f"{c[0][i]:+.1f} | {c[1][i]:d} | {c[2][i]:+.2f}" for c in columns.values()]
        out.append(f"| {dx:.3f}, {dy:.3f} | " + " | ".join(cells) + " |")
    spread = {m: (np.ptp(c[0]), np.min(c[2]), np.max(c[2])) for m, c in columns.items()}
    out += ["", "* Over these offsets: " + "; ".join(
        f"{m}: the sum of readings spans {s:.1f} %, the joint fit's force {lo:+.2f} to "
        f"{hi:+.2f} %" for m, (s, lo, hi) in spread.items()) + "."]  # fmt: skip
    from tactsense.analysis.aliasing import reconstruction_error

    xi = {}
    for m, spec in specs:
        layer = spec.layer
        xi[m] = float(reconstruction_error(layer.sensing_depth_mm, PITCH_MM, layer.poisson_ratio))
    out.append(
        "* The paper's eq. 45 (the share of the strain's energy the grid cannot sample, for a "
        "half space read at the sensing depth; `reconstruction_error`): "
        + "; ".join(
            f"{m}: xi {x:.4f} (RMS amplitude error sqrt(xi) {x**0.5:.3f})" for m, x in xi.items()
        )
        + "."
    )
    return out


def _fingertip(folder: Path) -> str:
    """The finger's slip onset in MuJoCo against the force angle its frames give."""
    from tactsense.physics.halfplane import line_load_skew_coefficient

    rec, table = folder / "fingertip.h5", folder / "fingertip.csv"
    _tactsense("mujoco", "--example", "fingertip", "--out", str(rec), "--seed", "3", "-q")
    _tactsense("locate", str(rec), "--out", str(table))
    recording = read_recording(rec)
    truth, period = recording.truth, recording.sensor.scan_period_s
    true_ratio = truth["mujoco_tangential_force_n"][:, 0] / np.maximum(truth["step_force_n"], 1e-12)
    estimate = pd.read_csv(table).set_index("frame")["skew"].reindex(range(len(true_ratio)))
    estimated = estimate.to_numpy() / line_load_skew_coefficient(0.5)
    slip = truth["mujoco_slip"]
    onset = int(np.argmax(slip))
    sliding = np.flatnonzero(slip)
    stick = np.flatnonzero((true_ratio > 0.01) & ~slip & (np.arange(len(slip)) < onset))
    return (
        f"* The finger (`--example fingertip`, {1 / period:g} Hz): MuJoCo's onset at frame "
        f"{onset} ({(onset + 0.5) * period:.2f} s), friction over normal force rising "
        f"{true_ratio[stick].min():.3f}-{true_ratio[stick].max():.3f} in the {len(stick)} "
        f"frames of stick before it; the frames' skew gives tan(alpha) "
        f"{np.nanmin(estimated[stick]):+.3f} to {np.nanmax(estimated[stick]):+.3f} there, "
        f"and {np.nanmin(estimated[sliding]):+.3f} to {np.nanmax(estimated[sliding]):+.3f} "
        f"over the {len(sliding)} sliding frames (MuJoCo: {true_ratio[sliding].mean():.3f})."
    )


def main() -> None:
    spec = load_sensor("pad16")
    frames, touch, grid, contacts = _side_by_side(spec)
    _figure(spec, frames, touch, grid, contacts)
    with tempfile.TemporaryDirectory() as folder:
        text, sampling = _numbers(Path(folder), spec, touch, grid)
    begin, end = "<!-- begin mujoco numbers -->", "<!-- end mujoco numbers -->"
    replace_block(DOC, begin, end, f"{begin}\n{text}\n{end}")
    begin, end = "<!-- begin mujoco sampling numbers -->", "<!-- end mujoco sampling numbers -->"
    replace_block(DOC, begin, end, f"{begin}\n{sampling}\n{end}")
    print(text)
    print(sampling)


if __name__ == "__main__":
    main()
