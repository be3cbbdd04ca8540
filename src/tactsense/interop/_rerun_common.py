"""What the Rerun exports share (:mod:`tactsense.interop.rerun`,
:mod:`tactsense.interop.rerun_components`): the colour range check and the stream with
its recording properties. It imports neither."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from tactsense._validation import TactsenseInputError


def _checked_range(what: str, value_range) -> tuple[float, float]:
    """``(low, high)`` of a colour scale, refused unless finite with low < high."""
    low, high = map(float, value_range)
    if not (np.isfinite(low) and np.isfinite(high) and high > low):
        raise TactsenseInputError(
            f"{what} range ({low}, {high}) must be two finite numbers, low < high"
        )
    return low, high


def _open_stream(rr, out, recording, recording_id: str, **properties):
    """A Rerun stream saved to ``out``, named after the recording, with the recording
    property ``tactsense`` (its id, source and ``properties``)."""
    stream = rr.RecordingStream("tactsense", recording_id=recording_id)
    stream.save(str(out))
    stream.send_recording_name(Path(recording).stem)
    stream.send_property(
        "tactsense",
        rr.AnyValues(recording_id=recording_id, source=str(recording), **properties),
    )
    return stream
