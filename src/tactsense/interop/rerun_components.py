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

SHEAR_MM_PER_N = 10.0
"""Length of a contact's shear arrow per newton of tangential force [mm/N] (0.1 N: 1 mm)."""


def export_components_rerun(
    rr, reader, recording, out, *, baseline_frames: int, value_range, recording_id, progress,
    calibration=None, threshold=None,
) -> dict:  # fmt: skip
    """:func:`tactsense.interop.rerun.export_rerun` of a sensor whose taxels report several
    components: the normal map, the tangential arrows and the values (module doc).

    With the three-axis contact estimator (:func:`~tactsense.interop.components.
    component_contacts`) the contacts too: ``<kind>/contacts`` (``Points3D`` [mm], labelled
    with their ids), ``<kind>/normal/contacts`` (``Points2D`` on the map),
    ``<kind>/contact_shear`` (``Arrows3D`` from each contact, its tangential force at
    :data:`SHEAR_MM_PER_N`), ``<kind>/force_g`` and ``<kind>/shear_g`` (the frame's summed
    normal force and the length of its summed tangential force [g]); without it the
    options of contacts (``calibration``, ``threshold``) are refused.

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
    from tactsense.interop.components import (
        component_contacts,
        refuse_contact_options,
        table_column,
    )

    found = component_contacts(reader, baseline_frames=baseline_frames,
                               calibration=calibration, threshold=threshold)  # fmt: skip
    estimated = found is not None
    if not estimated:
        refuse_contact_options(sensor, calibration, threshold)
        found = ((start, len(t), t, None, None) for start, _, t in reader.chunks())
    stream = _open_stream(
        rr, out, recording, recording_id, sensor=sensor.name, kind=sensor.kind,
        value_units="counts, change from the baseline (median of the first frames)",
        baseline_frames=int(baseline_frames), components=list(sensor.component_names),
        value_range=[low, high], normal_range=[normal_low, normal_high],
        arrow_scale_counts_per_pixel=per_pixel, arrow_scale_counts_per_mm=per_mm,
        contact_shear_mm_per_n=SHEAR_MM_PER_N, force_units="g",
        position_units="mm", time_units="s (device clock)",
    )  # fmt: skip
    positions = np.asarray(sensor.taxel_positions_mm(), dtype=float)
    rows, cols = sensor.shape
    r, c = np.meshgrid(np.arange(rows), np.arange(cols), indexing="ij")
    pixels = np.column_stack([c.ravel() + 0.5, r.ravel() + 0.5])
    stream.log(f"{root}/taxels", rr.Points3D(positions, radii=0.3), static=True)
    frames = contacts = 0
    for start, n, time_s, table, _ in found:
        counts = reader.frames(start, start + n)
        change = counts.astype(float) - baseline
        if table is not None:
            bounds = np.searchsorted(table.frame, np.arange(start, start + n + 1))
            xyz = np.column_stack([table.x_mm, table.y_mm, table.z_mm])
            shear = np.column_stack([np.nan_to_num(table_column(table, "shear_x_n")),
                                     np.nan_to_num(table_column(table, "shear_y_n"))])  # fmt: skip
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
            if table is not None:
                contacts += _log_contacts(rr, stream, root, table, slice(bounds[k],
                                          bounds[k + 1]), xyz, shear)  # fmt: skip
            frames += 1
        if progress is not None:
            progress(start + len(time_s), reader.n_frames)
    stream.flush()
    stream.disconnect()
    return {
        "frames": frames, "contacts": contacts if estimated else None,
        "recording_id": recording_id,
        "deflection_range": (normal_low, normal_high), "kind": sensor.kind,
        "arrow_scale_counts_per_pixel": per_pixel,
    }  # fmt: skip


def _log_contacts(rr, stream, root, table, rows, xyz, shear) -> int:
    """One frame's contacts (the table's ``rows``): points, shear arrows and the sums."""
    from tactsense.physics.contact import newtons_to_grams

    keep = np.flatnonzero(np.isfinite(xyz[rows]).all(axis=1)) + rows.start
    force = np.asarray(table.force_n, dtype=float)[keep]
    if len(keep):
        ids = [str(i) for i in table.id[keep]]
        stream.log(f"{root}/contacts", rr.Points3D(xyz[keep], labels=ids, radii=0.5))
        pixels = np.column_stack([table.col[keep] + 0.5, table.row[keep] + 0.5])
        stream.log(f"{root}/normal/contacts", rr.Points2D(pixels, labels=ids, radii=0.15))
        vectors = np.column_stack([shear[keep], np.zeros(len(keep))]) * SHEAR_MM_PER_N
        stream.log(f"{root}/contact_shear", rr.Arrows3D(origins=xyz[keep], vectors=vectors))
    else:
        for path in ("contacts", "normal/contacts", "contact_shear"):
            stream.log(f"{root}/{path}", rr.Clear(recursive=False))
    total = float(np.nansum(force)) if len(keep) else 0.0
    stream.log(f"{root}/force_g", rr.Scalars([float(newtons_to_grams(total))]))
    summed = shear[keep].sum(axis=0) if len(keep) else np.zeros(2)
    stream.log(f"{root}/shear_g", rr.Scalars([float(newtons_to_grams(np.hypot(*summed)))]))
    return len(keep)


def _pitch_mm(sensor) -> float:
    """The smallest distance between two taxels [mm] (the arrows' length scale)."""
    positions = np.asarray(sensor.taxel_positions_mm(), dtype=float)
    if len(positions) < 2:
        return 1.0
    gaps = np.linalg.norm(positions[:, None, :] - positions[None, :, :], axis=-1)
    gaps[gaps == 0] = np.inf
    return float(gaps.min())
