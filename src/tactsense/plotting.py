"""Plots of recordings (matplotlib, written to PNG)."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from tactsense._validation import TactsenseInputError
from tactsense.io.recording import Recording, RecordingError
from tactsense.physics.flaws import FLAW_NAMES
from tactsense.physics.transduction import fractional_deflection


def check_plot_format(path: str | Path, option: str = "--plot") -> Path:
    """Refuse a plot name whose extension matplotlib cannot write, before any work starts.

    The format is taken from the extension (as :meth:`matplotlib.figure.Figure.savefig`
    does); the supported ones are those of the Agg canvas (png, pdf, svg, ...).

    Raises
    ------
    TactsenseInputError
        Naming the option, the extension and the formats matplotlib writes.
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    path = Path(path)
    # pgf needs a LaTeX installation; every other format is Agg's or Pillow's own
    formats = sorted(set(FigureCanvasAgg.get_supported_filetypes()) - {"pgf"})
    suffix = path.suffix.lower().lstrip(".")
    if suffix not in formats:
        said = f"'.{suffix}'" if suffix else "no extension"
        raise TactsenseInputError(
            f"{option} {path}: matplotlib cannot write {said}; end the name with one of "
            + ", ".join(f".{f}" for f in formats)
        )
    return path


def sweep_responses(recording: Recording):
    """Fractional deflection of the swept tactels against probe position.

    For a recording of :func:`tactsense.probe_sweep`: the baseline is the
    mean of the untouched frames; each frame is placed at the probe position
    that was applied during it.

    Returns
    -------
    position : ndarray, shape (T',)
        Probe position [mm] (axial sweep) or [deg] (around).
    deflection : ndarray, shape (T', n)
        Fractional deflection of the n swept tactels [-].
    labels : list of str
        Tactel of each column of ``deflection``.
    unit : str
    """
    params = recording.scenario.get("parameters", {})
    along = params.get("along")
    if along not in ("axial", "around"):
        raise RecordingError("this recording is not a probe sweep (no 'along' parameter)")
    baseline_idx = recording.baseline_frames
    if baseline_idx.size == 0:
        raise RecordingError("the recording has no untouched frames to take a baseline from")
    frames = recording.frames.astype(float)
    baseline = frames[baseline_idx].mean(axis=0)
    step = np.asarray(recording.truth["frame_step"])
    touched = np.asarray(recording.truth["step_n_contacts"])[step] > 0
    key = "step_axial_mm" if along == "axial" else "step_angle_deg"
    position = np.asarray(recording.truth[key])[step][touched]
    deflection = fractional_deflection(frames[touched], baseline)
    if along == "axial":
        col = int(params.get("col", 0))
        return position, deflection[:, :, col], [f"row {r}" for r in range(frames.shape[1])], "mm"
    row = int(params.get("row", 0))
    return position, deflection[:, row, :], [f"col {c}" for c in range(frames.shape[2])], "deg"


def plot_sweep(recording: Recording, path: str | Path, *, overwrite: bool = False) -> Path:
    """Draw the tactel responses of a probe sweep (like Fig. 7 / Fig. 13 of the paper)."""
    path = Path(path)
    if path.exists() and not overwrite:
        raise FileExistsError(f"{path} exists; pass --force to replace it")
    position, deflection, labels, unit = sweep_responses(recording)
    params = recording.scenario["parameters"]
    fig, ax = plt.subplots(figsize=(8, 4.5), constrained_layout=True)
    for k, label in enumerate(labels):
        ax.plot(position, 100.0 * deflection[:, k], ".-", ms=3, lw=1, label=label)
    what = "along the finger" if unit == "mm" else "around the circumference"
    ax.set_xlabel(f"probe position {what} [{unit}]")
    ax.set_ylabel("fractional deflection [%]")
    force_g = params.get("force_n", float("nan")) / 9.80665e-3
    flaws = "all" if set(recording.flaws) == set(FLAW_NAMES) else ", ".join(recording.flaws)
    ax.set_title(
        f"Tactel responses for a {force_g:.0f}-g probe swept {what}\n"
        f"{recording.sensor.name}; flaws: {flaws or 'none'}",
        fontsize=10,
    )
    ax.axhline(0.0, color="0.6", lw=0.8)
    ax.grid(alpha=0.3)
    ax.legend(ncol=4, fontsize=8, loc="upper right")
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path
