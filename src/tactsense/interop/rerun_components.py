"""A recording of taxels of several components (three-axis taxels) as a Rerun file.

Entities, on the timeline ``time`` (the frames' times on the device clock), under
``<kind>/`` (``triaxial/`` for the three-axis pad); every value is a change from the
baseline (the median of the first ``baseline_frames`` frames, per taxel and component)
in counts:

* ``<kind>/normal``: an RGB ``Image`` of the last component's change (z, the outward
  normal, for three-axis taxels), rows down (y = row) and columns across (x = column),
  through viridis over one fixed range for the whole file;
* ``<kind>/normal/shear``: ``Arrows2D`` on that image, one per taxel from its pixel's
  centre (x = column + 0.5, y = row + 0.5), the tangential change: the x component (along
  the rows) drawn down the image, the y component (along the columns) across, scaled so
  that the largest tangential change of the file is one pixel long;
* ``<kind>/values``: a ``Tensor`` of every change, dims ``(row, col, component)``
  (components in the sensor's order, x, y, z), ``value_range`` the range of all;
* ``<kind>/taxels`` (static) ``Points3D`` [mm] and ``<kind>/shear``: ``Arrows3D`` at the
  taxels [mm], the tangential change scaled as on the image (the largest is half a
  pitch long).

The recording property ``tactsense`` says the units, the baseline and the arrows' scale
[counts per pixel, counts per mm]. Contacts are not drawn: the kind's contact estimate
is not part of this file yet.
"""

from __future__ import annotations

import uuid

import numpy as np


def export_components_rerun(
    rr, reader, recording, out, *, baseline_frames: int, value_range, recording_id, progress
) -> dict:
    """:func:`tactsense.interop.rerun.export_rerun` of a sensor whose taxels report several
    components: the normal map, the tangential arrows and the values (module doc).

    Returns ``frames``, ``contacts`` (None: not estimated), ``recording_id``,
    ``deflection_range`` (the colour range of the normal map [counts]), ``kind`` and
    ``arrow_scale_counts_per_pixel``.
    """
    from matplotlib import colormaps

    from tactsense.interop._rerun_common import _checked_range, _open_stream

    sensor = reader.sensor
    root = sensor.kind
    recording_id = recording_id or str(uuid.uuid4())
    viridis = colormaps["viridis"]
    baseline = np.median(reader.frames(0, max(1, baseline_frames)).astype(float), axis=0)
    tangential = list(range(sensor.components - 1))  # x, y: the last one is the normal

    low, high, normal_low, normal_high, largest = 0.0, 0.0, 0.0, 0.0, 0.0
    for _, counts, _ in reader.chunks():  # a first pass: the file's ranges
        change = counts.astype(float) - baseline
        low, high = min(low, float(change.min())), max(high, float(change.max()))
        normal = change[..., -1]
        normal_low = min(normal_low, float(normal.min()))
        normal_high = max(normal_high, float(normal.max()))
        shear = np.linalg.norm(change[..., tangential], axis=-1)
        largest = max(largest, float(shear.max()))
    if value_range is not None:  # the normal map's colours and the tensor's range
        low, high = normal_low, normal_high = _checked_range("value", value_range)
    high = high if high > low else low + 1.0
    normal_high = normal_high if normal_high > normal_low else normal_low + 1.0
    per_pixel = largest if largest > 0 else 1.0  # counts drawn one pixel long
    per_mm = per_pixel / (0.5 * _pitch_mm(sensor))  # the largest: half a pitch
    stream = _open_stream(
        rr, out, recording, recording_id, sensor=sensor.name, kind=sensor.kind,
        value_units="counts, change from the baseline (median of the first frames)",
        baseline_frames=int(baseline_frames), components=list(sensor.component_names),
        value_range=[low, high], normal_range=[normal_low, normal_high],
        arrow_scale_counts_per_pixel=per_pixel, arrow_scale_counts_per_mm=per_mm,
        position_units="mm", time_units="s (device clock)",
    )  # fmt: skip
    positions = np.asarray(sensor.taxel_positions_mm(), dtype=float)
    rows, cols = sensor.shape
    r, c = np.meshgrid(np.arange(rows), np.arange(cols), indexing="ij")
    pixels = np.column_stack([c.ravel() + 0.5, r.ravel() + 0.5])
    stream.log(f"{root}/taxels", rr.Points3D(positions, radii=0.3), static=True)
    frames = 0
    for start, counts, time_s in reader.chunks():
        change = counts.astype(float) - baseline
        scaled = np.clip((change[..., -1] - normal_low) / (normal_high - normal_low), 0, 1)
        colours = (viridis(scaled)[..., :3] * 255).round().astype(np.uint8)
        for k, t in enumerate(time_s):
            stream.set_time("time", duration=float(t))
            stream.log(f"{root}/normal", rr.Image(colours[k], color_model="RGB"))
            tx = change[k, ..., 0].ravel()
            ty = change[k, ..., 1].ravel()
            stream.log(
                f"{root}/normal/shear",
                rr.Arrows2D(origins=pixels, vectors=np.column_stack([ty, tx]) / per_pixel),
            )
            vectors = np.column_stack([tx, ty, np.zeros_like(tx)]) / per_mm
            stream.log(f"{root}/shear", rr.Arrows3D(origins=positions, vectors=vectors))
            stream.log(
                f"{root}/values",
                rr.Tensor(
                    np.ascontiguousarray(change[k], dtype=np.float32),
                    dim_names=("row", "col", "component"), value_range=(low, high),
                ),
            )  # fmt: skip
            frames += 1
        if progress is not None:
            progress(start + len(time_s), reader.n_frames)
    stream.flush()
    stream.disconnect()
    return {
        "frames": frames, "contacts": None, "recording_id": recording_id,
        "deflection_range": (normal_low, normal_high), "kind": sensor.kind,
        "arrow_scale_counts_per_pixel": per_pixel,
    }  # fmt: skip


def _pitch_mm(sensor) -> float:
    """The smallest distance between two taxels [mm] (the arrows' length scale)."""
    positions = np.asarray(sensor.taxel_positions_mm(), dtype=float)
    if len(positions) < 2:
        return 1.0
    gaps = np.linalg.norm(positions[:, None, :] - positions[None, :, :], axis=-1)
    gaps[gaps == 0] = np.inf
    return float(gaps.min())
