"""A recording as a Rerun ``.rrd`` file: the unwrapped heat map, the contact, the force.

Entities, on the timeline ``time`` (the frames' times on the device clock):

* ``finger/deflection``: a ``DepthImage`` of the fractional deflection (eq. 4) with the
  viridis colour map; the finger unwrapped, along it across (x = row, the tip row at
  x = 0) and around it down (y = column);
* ``finger/deflection/contact``: a ``Points2D`` at the estimated contact, in the
  image's pixels (x = row + 0.5, y = column + 0.5), present only while touching;
* ``finger/force_g``: a ``Scalars`` with the estimated force [g] (0 without contact).

Open the file with ``rerun file.rrd`` (``pip install rerun-sdk`` brings the viewer).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from tactsense._validation import TactsenseInputError


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
    progress=None,
) -> dict:
    """Write a recording's heat maps, contacts and force to a Rerun file, a piece at a time.

    Returns ``frames`` and ``contacts`` written.
    """
    from tactsense.batch import iter_locate
    from tactsense.estimate import Flag
    from tactsense.estimate.deflection import deflection_from_counts
    from tactsense.estimate.locate import CONTACT_THRESHOLD
    from tactsense.io.recording import RecordingReader
    from tactsense.physics.contact import newtons_to_grams

    rr = _rerun()
    frames_written = contacts = 0
    with RecordingReader(recording) as reader:
        sensor = reader.sensor
        stream = rr.RecordingStream("tactsense", recording_id=Path(recording).stem)
        stream.save(str(out))
        baseline = None
        if calibration is None:
            baseline = np.median(reader.frames(0, baseline_frames).astype(float), axis=0)
        pieces = iter_locate(
            reader,
            baseline=baseline,
            calibration=calibration,
            threshold=CONTACT_THRESHOLD if threshold is None else threshold,
        )
        for start, time_s, est in pieces:
            counts = reader.frames(start, start + len(time_s))
            if calibration is None:
                deflection, _ = deflection_from_counts(counts, baseline, sensor)
            else:
                deflection, _ = calibration.apply(counts, sensor)
            touching = ((est.flags & int(Flag.NO_CONTACT)) == 0) & np.isfinite(est.force_n)
            grams = np.where(touching, newtons_to_grams(np.nan_to_num(est.force_n)), 0.0)
            for k, t in enumerate(time_s):
                stream.set_time("time", duration=float(t))
                image = np.ascontiguousarray(deflection[k].T, dtype=np.float32)
                stream.log("finger/deflection", rr.DepthImage(image, colormap="viridis"))
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
    return {"frames": frames_written, "contacts": contacts}
