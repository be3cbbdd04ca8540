"""A recording as a Rerun ``.rrd`` file: the unwrapped heat map, the contact, the force.

Entities, on the timeline ``time`` (the frames' times on the device clock):

* ``finger/deflection``: an RGB ``Image`` of the fractional deflection (eq. 4) through
  the viridis colour map over one fixed range for the whole file (so a colour means the
  same deflection in every frame); the finger unwrapped, along it across (x = row, the
  tip row at x = 0) and around it down (y = column);
* ``finger/deflection/contact``: a ``Points2D`` at the estimated contact, in the
  image's pixels (x = row + 0.5, y = column + 0.5), present only while touching;
* ``finger/deflection_values``: a ``Tensor`` of the same deflections as numbers
  (dimensionless fractions of the undeflected reading: 0.05 = 5 %), dims
  ``(around, along)``, ``value_range`` the same fixed range. Not a ``DepthImage``: Rerun
  reads a depth image's values as metres;
* ``finger/force_g``: a ``Scalars`` with the estimated force [g] (0 without contact),
  its series named ``force [g]``.

A pad or a point set (``<kind>`` is ``pad`` or ``points``), with every contact
``locate`` finds and tracks (its long table):

* ``pad/signal``: an RGB ``Image`` of the taxels' signal (fractional deflection for
  capacitive taxels, strain for resistive ones), rows down (y = row) and columns across
  (x = column), through viridis over one fixed range for the whole file;
* ``<kind>/signal_values``: a ``Tensor`` of the signal, dims ``(row, col)`` on a pad,
  ``(taxel,)`` on a point set (its taxels in the sensor's order), ``value_range`` that
  range;
* ``<kind>/signal/contacts``: a pad's contacts as ``Points2D`` in the image's pixels
  (x = column + 0.5, y = row + 0.5), labelled with their tracked ids;
* ``<kind>/taxels`` (static) and ``<kind>/contacts``: ``Points3D`` of the taxels and of
  the contacts [mm] in the sensor's frame, the contacts labelled with their ids;
* ``<kind>/force_g``: the frame's total force [g] (series ``force [g]``), and
  ``<kind>/contact_force_g/<id>`` each contact's force while it lasts.

Each export gets a recording id of its own (a UUID: two files exported from
recordings of the same name do not merge when opened together); the file's recording
properties (``tactsense``) hold that id, the source recording, the sensor, the
deflection range and the units.

Open the file with ``rerun file.rrd`` (``pip install rerun-sdk`` brings the viewer).
"""

from __future__ import annotations

import uuid
from pathlib import Path

import numpy as np

from tactsense._validation import TactsenseInputError
from tactsense.interop._rerun_common import _checked_range, _open_stream
from tactsense.kinds import kind_of


def _rerun():
    try:
        import rerun
    except ImportError:
        raise TactsenseInputError(
            'Rerun files need the rerun extra: pip install "tactsense[rerun]"'
        ) from None
    return rerun


def export_rerun(
    recording: str | Path,
    out: str | Path,
    *,
    calibration=None,
    baseline_frames: int = 5,
    threshold: float | None = None,
    deflection_range: tuple[float, float] | None = None,
    recording_id: str | None = None,
    progress=None,
    drift_s: float | None = 2.0,
) -> dict:
    """Write a recording's heat maps, contacts and force to a Rerun file, a piece at a time.

    Parameters
    ----------
    deflection_range : (low, high), optional
        Fractional deflection [-] at the two ends of the colour map, the same for every
        frame; default: from 0 (or the lowest deflection, if below 0) to the highest
        deflection of the recording (a first pass over it, a piece at a time). On a pad
        or a point set, the signal (strain for resistive taxels).
    drift_s : float, optional
        A pad or a point set: the time constant [s] with which the contacts' baseline
        follows drift, as in ``locate`` (the heat map's baseline stays the first
        frames').
    recording_id : str, optional
        Rerun's recording id; default a new UUID.

    Returns ``frames``, ``contacts``, ``recording_id`` and ``deflection_range``.
    """
    from matplotlib import colormaps

    from tactsense.batch import iter_locate
    from tactsense.estimate import Flag
    from tactsense.estimate.finger.deflection import deflection_from_counts
    from tactsense.estimate.finger.locate import CONTACT_THRESHOLD
    from tactsense.io.recording import RecordingReader
    from tactsense.physics.contact import newtons_to_grams

    rr = _rerun()
    viridis = colormaps["viridis"]
    recording_id = recording_id or str(uuid.uuid4())
    frames_written = contacts = 0
    with RecordingReader(recording) as reader:
        sensor = reader.sensor
        if sensor.components > 1:  # ---- several components a taxel (r8-triinterop) ----
            from tactsense.interop.rerun_components import export_components_rerun

            return export_components_rerun(
                rr, reader, recording, out, baseline_frames=baseline_frames,
                value_range=deflection_range, recording_id=recording_id, progress=progress,
                calibration=calibration, threshold=threshold,
            )  # fmt: skip
        if kind_of(sensor).multi_contact:  # every contact, tracked
            return _export_array(
                rr, reader, recording, out, calibration=calibration,
                baseline_frames=baseline_frames, threshold=threshold,
                signal_range=deflection_range, recording_id=recording_id, progress=progress,
                drift_s=drift_s,
            )  # fmt: skip
        baseline = None
        if calibration is None:
            baseline = np.median(reader.frames(0, baseline_frames).astype(float), axis=0)

        def deflections(counts):
            if calibration is None:
                return deflection_from_counts(counts, baseline, sensor)[0]
            return calibration.apply(counts, sensor)[0]

        if deflection_range is None:
            low, high = 0.0, 0.0
            for _, counts, _ in reader.chunks():
                values = deflections(counts)
                if np.isfinite(values).any():
                    low = min(low, float(np.nanmin(values)))
                    high = max(high, float(np.nanmax(values)))
            deflection_range = (low, high if high > low else low + 1e-3)
        low, high = _checked_range("deflection", deflection_range)
        stream = _open_stream(
            rr, out, recording, recording_id, sensor=sensor.name,
            deflection_units="1 (fraction of the undeflected reading, eq. 4)",
            deflection_range=[low, high], force_units="g", time_units="s (device clock)",
        )  # fmt: skip
        stream.log("finger/force_g", rr.SeriesLines(names="force [g]"), static=True)
        pieces = iter_locate(
            reader,
            baseline=baseline,
            calibration=calibration,
            threshold=CONTACT_THRESHOLD if threshold is None else threshold,
        )
        for start, time_s, est in pieces:
            deflection = deflections(reader.frames(start, start + len(time_s)))
            scaled = np.clip((np.nan_to_num(deflection) - low) / (high - low), 0.0, 1.0)
            colours = (viridis(scaled)[..., :3] * 255).round().astype(np.uint8)
            touching = ((est.flags & int(Flag.NO_CONTACT)) == 0) & np.isfinite(est.force_n)
            grams = np.where(touching, newtons_to_grams(np.nan_to_num(est.force_n)), 0.0)
            for k, t in enumerate(time_s):
                stream.set_time("time", duration=float(t))
                image = np.ascontiguousarray(colours[k].transpose(1, 0, 2))
                stream.log("finger/deflection", rr.Image(image, color_model="RGB"))
                values = np.ascontiguousarray(deflection[k].T, dtype=np.float32)
                stream.log(
                    "finger/deflection_values",
                    rr.Tensor(values, dim_names=("around", "along"), value_range=(low, high)),
                )
                if touching[k]:
                    point = [[float(est.row[k]) + 0.5, float(est.col[k]) + 0.5]]
                    stream.log("finger/deflection/contact", rr.Points2D(point, radii=0.15))
                    contacts += 1
                else:
                    stream.log("finger/deflection/contact", rr.Clear(recursive=False))
                stream.log("finger/force_g", rr.Scalars([float(grams[k])]))
                frames_written += 1
            if progress is not None:
                progress(start + len(time_s), reader.n_frames)
        stream.flush()
        stream.disconnect()
    return {
        "frames": frames_written,
        "contacts": contacts,
        "recording_id": recording_id,
        "deflection_range": (low, high),
    }


def _range_of(chunks, signal) -> tuple[float, float]:
    """From 0 (or the lowest value, if below 0) to the highest value of the signal."""
    low, high = 0.0, 0.0
    for _, counts, _ in chunks:
        values = signal(counts)
        if np.isfinite(values).any():
            low = min(low, float(np.nanmin(values)))
            high = max(high, float(np.nanmax(values)))
    return low, high if high > low else low + 1e-3


def _export_array(
    rr, reader, recording, out, *, calibration, baseline_frames, threshold, signal_range,
    recording_id, progress, drift_s,
) -> dict:  # fmt: skip
    """:func:`export_rerun` of a pad or a point set: every contact, tracked."""
    from matplotlib import colormaps

    from tactsense.batch import iter_contacts
    from tactsense.estimate.contacts import signal_from_counts
    from tactsense.estimate.contacts.array_calibration import ArrayCalibration
    from tactsense.physics.contact import newtons_to_grams

    sensor = reader.sensor
    root = sensor.kind  # the entity path's root: pad/..., points/...
    picture = kind_of(sensor).image_grid  # a grid of taxels: a heat map to picture
    viridis = colormaps["viridis"]
    pieces = iter_contacts(reader, baseline_frames=baseline_frames, calibration=calibration,
                           threshold=threshold, drift_s=drift_s)  # fmt: skip
    if isinstance(calibration, ArrayCalibration):

        def signal(counts):
            return calibration.signal(counts, sensor)[0]
    else:
        if calibration is not None:  # iter_contacts has refused it already
            raise TactsenseInputError(f"a finger's calibration does not apply to {sensor.name!r}")
        start = np.nanmedian(reader.frames(0, baseline_frames).astype(float), axis=0)

        def signal(counts):
            return signal_from_counts(counts, start, sensor)[0]

    if signal_range is None:
        signal_range = _range_of(reader.chunks(), signal)
    low, high = _checked_range("signal", signal_range)
    stream = _open_stream(
        rr, out, recording, recording_id, sensor=sensor.name, kind=sensor.kind,
        signal_units="1 (fractional deflection, or strain for resistive taxels)",
        signal_range=[low, high], force_units="g", position_units="mm",
        time_units="s (device clock)",
    )  # fmt: skip
    stream.log(f"{root}/force_g", rr.SeriesLines(names="force [g]"), static=True)
    stream.log(f"{root}/taxels", rr.Points3D(sensor.taxel_positions_mm(), radii=0.3), static=True)
    frames_written = contacts = 0
    for start_frame, n, time_s, table, _ in pieces:
        values = signal(reader.frames(start_frame, start_frame + n))
        scaled = np.clip((np.nan_to_num(values) - low) / (high - low), 0.0, 1.0)
        colours = (viridis(scaled)[..., :3] * 255).round().astype(np.uint8)  # pictures only
        bounds = np.searchsorted(table.frame, np.arange(start_frame, start_frame + n + 1))
        force_g = newtons_to_grams(np.asarray(table.force_n, dtype=float))
        for k, t in enumerate(time_s):
            stream.set_time("time", duration=float(t))
            frame = np.ascontiguousarray(values[k], dtype=np.float32)
            if picture:
                stream.log(f"{root}/signal", rr.Image(colours[k], color_model="RGB"))
                tensor = rr.Tensor(frame, dim_names=("row", "col"), value_range=(low, high))
            else:  # a point set: no grid to picture; its taxels in order
                tensor = rr.Tensor(frame.ravel(), dim_names=("taxel",), value_range=(low, high))
            stream.log(f"{root}/signal_values", tensor)
            rows = slice(bounds[k], bounds[k + 1])
            ids = [str(i) for i in table.id[rows]]
            if ids:
                xyz = np.column_stack([table.x_mm[rows], table.y_mm[rows], table.z_mm[rows]])
                stream.log(f"{root}/contacts", rr.Points3D(xyz, labels=ids, radii=0.5))
                if picture:
                    pixels = np.column_stack([table.col[rows] + 0.5, table.row[rows] + 0.5])
                    stream.log(f"{root}/signal/contacts",
                               rr.Points2D(pixels, labels=ids, radii=0.15))  # fmt: skip
                for i, grams in zip(ids, force_g[rows], strict=True):
                    if np.isfinite(grams):
                        stream.log(f"{root}/contact_force_g/{i}", rr.Scalars([float(grams)]))
                contacts += len(ids)
            else:
                stream.log(f"{root}/contacts", rr.Clear(recursive=False))
                if picture:
                    stream.log(f"{root}/signal/contacts", rr.Clear(recursive=False))
            finite = force_g[rows][np.isfinite(force_g[rows])]
            stream.log(f"{root}/force_g", rr.Scalars([float(finite.sum())]))
            frames_written += 1
        if progress is not None:
            progress(start_frame + n, reader.n_frames)
    stream.flush()
    stream.disconnect()
    return {
        "frames": frames_written, "contacts": contacts, "recording_id": recording_id,
        "deflection_range": (low, high), "kind": sensor.kind,
    }  # fmt: skip
