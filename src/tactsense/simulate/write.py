"""Writing a simulation to an HDF5 recording as its frames are made (bounded memory)."""

from __future__ import annotations

import json
from collections.abc import Callable

import numpy as np

from tactsense.kinds import kind_of
from tactsense.sensor import SensorSpec
from tactsense.simulate.run import _frame_blocks, _frame_steps, _prepare, _truth
from tactsense.simulate.scenario import Scenario

_WRITE_FRAMES = 1024
"""Frames per HDF5 chunk and per write of :func:`simulate_to_file` [-]."""


def simulate_to_file(
    spec: SensorSpec,
    scenario: Scenario,
    path,
    *,
    flaws="all",
    rng=None,
    gains: np.ndarray | None = None,
    progress: Callable[[int, int], None] | None = None,
    forward: str = "twin",
) -> int:
    """Run a scenario and write the recording to a new HDF5 file as its frames are made.

    The same recording as ``write_recording(path, simulate(...))`` (the same layout,
    the same frames for the same ``rng``), in memory that does not grow with its length:
    frames, their times and the step of each frame go to the file
    :data:`_WRITE_FRAMES` at a time. The caller chooses the name (the command line
    writes to a temporary one and moves it into place); an existing file is refused.

    Parameters
    ----------
    path : path
        The new file.
    spec, scenario, flaws, rng, gains, progress
        As for :func:`simulate`.

    Returns
    -------
    int
        Frames written [-].
    """
    import datetime as _dt
    from pathlib import Path

    import h5py

    from tactsense._version import __version__
    from tactsense.io.recording import FORMAT, FORMAT_VERSION

    path = Path(path)
    if path.exists():
        raise FileExistsError(f"{path} exists; choose a new name")
    run = _prepare(spec, scenario, flaws, rng, gains, forward)
    n, shape = run.n_frames, spec.frame_shape
    dtype = np.uint16 if "quantization" in run.active else np.float64
    chunk = max(1, min(n, _WRITE_FRAMES))
    try:
        with h5py.File(path, "w", libver=("earliest", "latest")) as h5:
            h5.attrs["format"] = FORMAT
            h5.attrs["format_version"] = FORMAT_VERSION
            h5.attrs["tactsense_version"] = __version__
            h5.attrs["created"] = _dt.datetime.now(_dt.UTC).isoformat(timespec="seconds")
            h5.attrs["sensor_toml"] = spec.to_toml_string()
            h5.attrs["scenario_json"] = json.dumps(
                {**scenario.to_dict(), "forward_model": run.forward}
            )
            h5.attrs["flaws"] = ",".join(run.active)
            h5.attrs["scan_rate_hz"] = spec.electronics.scan_rate_hz
            h5.attrs["source"] = ""
            frames = h5.create_dataset(
                "frames",
                (n, *shape),
                dtype,
                chunks=(chunk, *shape),
                maxshape=(None, *shape),
                compression="gzip",
                fletcher32=True,
            )
            frames.attrs["units"] = "counts"
            frames.attrs["axes"] = kind_of(spec).frame_axes
            times = h5.create_dataset("time", (n,), float, chunks=(chunk,), fletcher32=True)
            times.attrs["units"] = "s"
            h5.create_dataset("sample_offset", data=run.offsets).attrs["units"] = "s"
            h5.create_dataset("gains", data=run.gains).attrs["units"] = "1"
            truth = h5.create_group("truth")
            frame_step = truth.create_dataset(
                "frame_step", (n,), np.int64, chunks=(chunk,), compression="gzip", fletcher32=True
            )
            frame_step.attrs["units"] = "1"
            pending: list[np.ndarray] = []
            written = 0
            for _, last, counts in _frame_blocks(spec, run):
                pending.append(counts)
                if last - written >= chunk or last == n:
                    block = np.concatenate(pending).astype(dtype, copy=False)
                    pending.clear()
                    frames[written:last] = block
                    times[written:last] = np.arange(written, last) * spec.scan_period_s
                    frame_step[written:last] = _frame_steps(spec, run, written, last)
                    written = last
                if progress is not None:
                    progress(last, n)
            units = {
                "step_axial_mm": "mm",
                "step_angle_deg": "deg",
                "step_x_mm": "mm",
                "step_y_mm": "mm",
                "step_force_n": "N",
                "step_shear_x_n": "N",  # r8-triphys
                "step_shear_y_n": "N",  # r8-triphys
            }
            for key, value in _truth(spec, run.applied, np.zeros(0, np.int64)).items():
                if key == "frame_step":
                    continue
                if isinstance(value, str):
                    truth.attrs[key] = value
                else:
                    truth.create_dataset(key, data=value).attrs["units"] = units.get(key, "1")
    except BaseException:
        path.unlink(missing_ok=True)  # interrupted: leave nothing behind
        raise
    return written
