"""MuJoCo in, taxel frames out: a sensor's frames from a MuJoCo model's contacts.

A tactile sensor is mounted on one geom of a MuJoCo model (or on a site: every geom of
the site's body). At every frame of the sensor's scan the model's contacts on it are
read (:meth:`MujocoSensor.read`): the contact points in the sensor's surface coordinates
[mm], the normal force pressing on it and the friction force in its plane [N] (from
``mujoco.mj_contactForce``, turned into the sensor's frame), the radius of the body
pressing [mm], and whether the contact slides (its friction at the friction cone's
limit). Those contacts, a chunk of frames at a time, go through
:func:`tactsense.simulate.frames_from_contacts`: the sensor's layer, transduction and
per-frame flaws (gain spread, noise, quantization, saturation, dead taxels, crosstalk,
nonlinearity). :func:`record_mujoco` steps a model and writes the frames as a
tactsense recording, with MuJoCo's contacts as its truth, which ``locate``, ``view``
and ``export`` read.

The sensor's frame
------------------
The sensing face is the geom's (or the site's) local **+z face**; surface coordinates
are the local x and y [mm], shifted so that the face's centre is the centre of the
sensor's taxel grid (a pad: x along rows, y along columns, taxel (0, 0) at
``(-(rows - 1) / 2 * row_pitch, -(cols - 1) / 2 * col_pitch)`` from the centre). Turn
the geom in the model so that its +z face is the pad's outer face (the example model
does: ``euler="180 0 0"`` on a pad that faces down).

A skin around an axis (a kind whose surface coordinates are an axial position [mm] and
an angle [deg]: the paper's finger) is mounted on a capsule or cylinder geom whose local
z is its axis, the tip at +z: the axial position is measured from the end of the
geom's cylinder at +z toward -z, the angle from the local x axis about z, and the
normal force is the one pressing toward the axis; the tangential force is given along
the axis (toward the base) and around it. A contact on a capsule's hemispherical end is
projected onto the axis (a negative axial position).

What a contact becomes
----------------------
* A sphere, capsule or cylinder pressing: a sphere of its radius (Hertz contact, radius
  growing with force, as ``frames_from_contacts`` applies it); an ellipsoid: a sphere of
  its smallest semi-axis. A box, plane, mesh or height field: each of MuJoCo's contact
  points a sphere of ``flat_radius_mm`` (MuJoCo reports a face as up to four points;
  the layer under a face sees those points' loads, not a uniform pressure).
* Only the scan's middle instant of each frame is read (the taxels of one frame share
  one contact state; ``sample_offset`` of the recording says so: half a period).
* Memory flaws (creep, hysteresis, drift) need the frame sequence; ``frames_from_contacts``
  leaves them out, and so does this adapter.

Slip: a contact slides when its friction force reaches the friction cone's limit,
``|f_t| >= mu f_n`` (MuJoCo's elliptic cone, ``sqrt((f1/mu1)^2 + (f2/mu2)^2) >= f_n``;
``SLIP_TOLERANCE`` of rounding), as MuJoCo's solver computes the force. A kind that does
not sense shear (the pads: their layer model takes normal loads) cannot see that onset;
the recording carries it as truth (``truth/mujoco_slip``), and ``locate``'s ``slip``
(a tracked contact moving under a steady force) reports gross sliding once the contact
moves across the taxels (``docs/mujoco.md``).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from tactsense.interop._mujoco_calibrate import joint_force_calibration
from tactsense.interop._mujoco_contacts import (
    DEFAULT_FLAT_RADIUS_MM,
    SLIP_TOLERANCE,
    Controls,
    MujocoError,
    MujocoSensor,
    SurfaceContacts,
    _mujoco,
    contact_batch,
    contact_labels,
    example_controls_path,
    example_model_path,
    example_pad_path,
    fingertip_model_path,
    load_model,
    read_controls,
)
from tactsense.kinds import kind_of

__all__ = [
    "AUTO_FAST_FRAMES",
    "CHUNK_FRAMES",
    "DEFAULT_FLAT_RADIUS_MM",
    "SLIP_TOLERANCE",
    "Controls",
    "MujocoError",
    "MujocoSensor",
    "SurfaceContacts",
    "active_flaws",
    "contact_batch",
    "contact_labels",
    "example_controls_path",
    "example_model_path",
    "example_pad_path",
    "fingertip_model_path",
    "frame_blocks",
    "frame_count",
    "joint_force_calibration",
    "load_model",
    "read_controls",
    "record_mujoco",
]

# ---- stepping a model: frames at the sensor's scan rate ------------------------------

AUTO_FAST_FRAMES = 20_000
"""From this many frames on, :func:`record_mujoco` takes ``frames_from_contacts``'s fast
path by default [-]: the fast path tabulates the layer's response once per process and
is then many times faster than the reference, which has no start-up
(``benchmarks/bench_mujoco.py``, docs/performance.md)."""

CHUNK_FRAMES = 256
"""Frames made by one call of ``frames_from_contacts`` and written at a time [-]."""


def active_flaws(flaws) -> tuple[str, ...]:
    """``flaws`` ('all', 'none' or a comma list) as the per-frame flaws switched on
    (``frames_from_contacts``'s); a one-line error for an unknown name, or for a flaw
    with memory (or ``jitter``) asked by name, which frames made one instant at a time
    cannot have."""
    from tactsense.simulate.contact_frames import LEFT_OUT_FLAWS, resolve_flaws
    from tactsense.simulate.run import _resolve_flaws

    if flaws not in (None, "all", "none"):
        left_out = [n for n in _resolve_flaws(flaws) if n in LEFT_OUT_FLAWS]
        if left_out:
            raise MujocoError(
                f"flaw(s) {', '.join(left_out)} need the frame sequence (memory or jitter); "
                "frames from MuJoCo's contacts take the per-frame flaws only "
                "(gain_spread, noise, quantization, dead, crosstalk, nonlinearity)"
            )
    return resolve_flaws(flaws)


def frame_count(spec, seconds: float) -> int:
    """Frames of the sensor's scan in ``seconds`` [s]; a one-line error below one frame."""
    if not (isinstance(seconds, float | int) and math.isfinite(seconds) and 0 < seconds <= 1e6):
        raise MujocoError(f"--seconds {seconds!r}: expected a time in (0, 1e6] [s]")
    n = math.floor(seconds / spec.scan_period_s + 1e-9)
    if n < 1:
        raise MujocoError(
            f"--seconds {seconds:g} is shorter than one scan of {spec.name!r} "
            f"({spec.scan_period_s:g} s)"
        )
    return n


def frame_blocks(
    sensor: MujocoSensor,
    data,
    *,
    n_frames: int,
    controls: Controls | None = None,
    flaws="all",
    rng=None,
    gains: np.ndarray | None = None,
    chunk_frames: int = CHUNK_FRAMES,
    on_read=None,
    fast: bool | None = None,
):
    """Step the model and yield the sensor's frames a chunk at a time.

    Frame ``j``'s contacts are read at the model step nearest the middle of its scan,
    ``t0 + (j + 1/2) period`` (``t0``: ``data.time`` at the start); before every step the
    controls at the step's time are applied. ``on_read(j, data)``, if given, is called
    at that instant (to read the model's own sensors beside the frames); ``fast`` is
    ``frames_from_contacts``'s (False: the reference, the kind's frame-by-frame path;
    None: fast from :data:`AUTO_FAST_FRAMES` frames on).

    Yields
    ------
    first, last : int
        The frames of the block (``last`` exclusive).
    counts : ndarray, shape (last - first, *spec.frame_shape)
        A/D counts [counts], as ``frames_from_contacts`` makes them (a three-axis
        kind's component axis last).
    labels : dict of ndarray
        :func:`contact_labels` of those frames (MuJoCo's contacts).
    """
    from tactsense.simulate import frames_from_contacts

    mujoco = _mujoco()
    model, spec = sensor.model, sensor.spec
    active = active_flaws(flaws)
    rng = np.random.default_rng(rng)
    period, dt, t0 = spec.scan_period_s, model.opt.timestep, float(data.time)
    shear = kind_of(spec).senses_shear  # a kind without shear is not given it
    fast = n_frames >= AUTO_FAST_FRAMES if fast is None else fast
    for first in range(0, n_frames, chunk_frames):
        last = min(n_frames, first + chunk_frames)
        readings = []
        for j in range(first, last):
            due = t0 + (j + 0.5) * period
            while data.time + 0.5 * dt < due:
                if controls is not None:
                    data.ctrl[:] = controls.at(data.time - t0)
                mujoco.mj_step(model, data)
            readings.append(sensor.read(data))
            if on_read is not None:
                on_read(j, data)
        batch = contact_batch(readings, shear=shear)
        counts = frames_from_contacts(spec, batch, flaws=active, rng=rng, gains=gains, fast=fast)
        yield (
            first,
            last,
            np.asarray(counts).reshape(last - first, *spec.frame_shape),
            (contact_labels(readings)),
        )


_TRUTH_UNITS = {
    "frame_step": "1",
    "step_x_mm": "mm",
    "step_y_mm": "mm",
    "step_force_n": "N",
    "step_n_contacts": "1",
    "mujoco_tangential_force_n": "N",
    "mujoco_slip": "1",
}


def record_mujoco(
    path,
    sensor: MujocoSensor,
    *,
    seconds: float,
    controls: Controls | None = None,
    flaws="all",
    rng=None,
    model_path=None,
    progress=None,
    fast: bool | None = None,
) -> int:
    """Step a model for ``seconds`` and write the sensor's frames to a new recording.

    The recording (``tactsense-recording``, as ``simulate`` writes) holds the frames,
    their times (frame ``j`` starts at ``j`` periods), every taxel's sample offset (half
    a period: the contacts are read at the middle of the scan), the gains, and as truth
    MuJoCo's contacts per frame (each frame its own step): ``step_force_n`` (total
    normal force [N]), ``step_x_mm``, ``step_y_mm`` (the force-weighted contact
    centroid [mm], NaN without contact), ``step_n_contacts``, and
    ``mujoco_tangential_force_n`` (friction (x, y) [N]) and ``mujoco_slip`` (a contact
    at the friction cone's limit). Frames go to the file a chunk at a time (memory does
    not grow with the run); an existing file is refused, and an interrupted run leaves
    none behind. ``fast``: ``frames_from_contacts``'s path; None (the default) the fast
    one from :data:`AUTO_FAST_FRAMES` frames on, the reference below.

    Returns
    -------
    int
        Frames written [-].
    """
    import datetime as _dt
    import json

    import h5py

    from tactsense._version import __version__
    from tactsense.io.recording import FORMAT, FORMAT_VERSION
    from tactsense.physics.flaws import draw_gains

    mujoco = _mujoco()
    path = Path(path)
    if path.exists():
        raise FileExistsError(f"{path} exists; choose a new name")
    spec, model = sensor.spec, sensor.model
    n = frame_count(spec, seconds)
    active = active_flaws(flaws)
    gains = draw_gains(spec) if "gain_spread" in active else np.ones(spec.shape)
    data = mujoco.MjData(model)
    dtype = np.uint16 if "quantization" in active else np.float64
    chunk = max(1, min(n, CHUNK_FRAMES))
    scenario = {
        "description": f"MuJoCo model {Path(model_path).name if model_path else ''}".strip(),
        "source": "mujoco",
        "mujoco_version": mujoco.__version__,
        "model": str(model_path) if model_path else "",
        "mount": {"geom" if sensor.geom_id >= 0 else "site": sensor.name},
        "timestep_s": float(model.opt.timestep),
        "flat_radius_mm": sensor.flat_radius_mm,
        "contacts_read": "at the middle of each frame's scan",
    }
    try:
        with h5py.File(path, "w", libver=("v110", "v110")) as h5:
            h5.attrs.update(
                format=FORMAT,
                format_version=FORMAT_VERSION,
                tactsense_version=__version__,
                created=_dt.datetime.now(_dt.UTC).isoformat(timespec="seconds"),
                sensor_toml=spec.to_toml_string(),
                scenario_json=json.dumps(scenario),
                flaws=",".join(active),
                scan_rate_hz=spec.electronics.scan_rate_hz,
                source=f"mujoco:{Path(model_path).name}" if model_path else "mujoco",
            )
            options = {"compression": "gzip", "fletcher32": True}
            frames = h5.create_dataset(
                "frames", (n, *spec.frame_shape), dtype, chunks=(chunk, *spec.frame_shape),
                maxshape=(None, *spec.frame_shape), **options,
            )  # fmt: skip
            frames.attrs["units"] = "counts"
            frames.attrs["axes"] = kind_of(spec).frame_axes
            times = h5.create_dataset("time", (n,), float, chunks=(chunk,), fletcher32=True)
            times.attrs["units"] = "s"
            offset = np.full(spec.shape, 0.5 * spec.scan_period_s)
            h5.create_dataset("sample_offset", data=offset).attrs["units"] = "s"
            h5.create_dataset("gains", data=gains).attrs["units"] = "1"
            truth = h5.create_group("truth")
            shapes = {"mujoco_tangential_force_n": (n, 2)}
            kinds = {"frame_step": np.int64, "step_n_contacts": np.int64, "mujoco_slip": bool}
            sets = {}
            for key, unit in _TRUTH_UNITS.items():
                shape = shapes.get(key, (n,))
                sets[key] = truth.create_dataset(
                    key, shape, kinds.get(key, float), chunks=(chunk, *shape[1:]), **options
                )
                sets[key].attrs["units"] = unit
            written = 0
            blocks = frame_blocks(
                sensor, data, n_frames=n, controls=controls, flaws=flaws, rng=rng, gains=gains,
                fast=fast,
            )  # fmt: skip
            for first, last, counts, labels in blocks:
                frames[first:last] = np.clip(counts, 0, np.inf).astype(dtype, copy=False)
                times[first:last] = np.arange(first, last) * spec.scan_period_s
                sets["frame_step"][first:last] = np.arange(first, last)
                sets["step_x_mm"][first:last] = labels["centroid_mm"][:, 0]
                sets["step_y_mm"][first:last] = labels["centroid_mm"][:, 1]
                sets["step_force_n"][first:last] = labels["force_n"]
                sets["step_n_contacts"][first:last] = labels["n_contacts"]
                sets["mujoco_tangential_force_n"][first:last] = labels["tangential_force_n"]
                sets["mujoco_slip"][first:last] = labels["slip"]
                written = last
                if progress is not None:
                    progress(last, n)
    except BaseException:
        path.unlink(missing_ok=True)  # interrupted: leave nothing behind
        raise
    return written
