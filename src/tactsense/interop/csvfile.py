"""A recording's frames as a CSV file, the layout ``tactsense import X.csv`` reads.

One header line, then one frame per row: ``time`` (the frame's time on the device
clock [s]), ``host_time`` when the recording holds the host's arrival times (Unix time
[s]; a recorded stream), then the taxels' readings in row-major order, named
``r<row>c<col>`` (a point set: ``r0c<k>``, its taxels in the sensor's order); a taxel of
several components (a three-axis taxel) has a column per component, ``r<row>c<col>x``,
``...y``, ``...z``, together and in that order (:mod:`tactsense.interop.components`). Counts
are written as integers; a recording of fractional counts with 17 significant digits,
a lost reading as ``nan``. ``import`` takes counts the converter's range holds
(0..2**adc_bits - 1; fractions too, as an unquantized simulation writes them) or
``nan``, and refuses any other value with its line and column. Times with 17 significant digits. The file holds frames only: the sensor is
given again on import (``--sensor``).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

TIME_COLUMN = "time"
HOST_TIME_COLUMN = "host_time"
"""The optional column of host arrival times (Unix time [s]) that ``import`` keeps as
the recording's host times."""


def taxel_columns(shape: tuple[int, int]) -> list[str]:
    """The names of a scalar frame's columns, row-major: ``r<row>c<col>``."""
    rows, cols = shape
    return [f"r{r}c{c}" for r in range(rows) for c in range(cols)]


def value_columns(sensor) -> list[str]:
    """The names of a frame's columns for this sensor: ``r<row>c<col>`` per taxel, or
    ``r<row>c<col><component>`` per taxel and component (component fastest)."""
    from tactsense.interop.components import value_names

    return value_names(sensor)


def export_csv(recording: str | Path, out: str | Path, *, progress=None) -> dict:
    """Write a recording's frames to ``out`` as CSV, a piece at a time (bounded memory).

    ``out`` is written as named (the command line writes to a temporary name and moves
    it into place). Returns ``frames`` and ``host_time`` (whether that column is there).
    """
    from tactsense.io.recording import RecordingReader

    with RecordingReader(recording) as reader, open(out, "w", encoding="utf-8") as stream:
        sensor = reader.sensor
        host = reader.has_host_time
        names = [TIME_COLUMN, *([HOST_TIME_COLUMN] if host else []), *value_columns(sensor)]
        stream.write(",".join(names) + "\n")
        written = 0
        for start, frames, time_s in reader.chunks():
            n = len(time_s)
            values = np.asarray(frames).reshape(n, -1)
            whole = np.issubdtype(values.dtype, np.integer)
            columns = [np.asarray(time_s, dtype=np.float64)[:, None]]
            if host:
                columns.append(reader.host_time_s(start, start + n)[:, None])
            times = np.hstack(columns)
            time_text = _format(times, "%.17g")
            value_text = _format(values, "%d" if whole else "%.17g")
            stream.writelines(f"{t},{v}\n" for t, v in zip(time_text, value_text, strict=True))
            written += n
            if progress is not None:
                progress(start + n, reader.n_frames)
    return {"frames": written, "host_time": host}


def _format(values: np.ndarray, fmt: str) -> list[str]:
    """Each row of a 2-D array as comma-separated text (``nan`` for NaN)."""
    row = ",".join([fmt] * values.shape[1])
    return [row % tuple(r) for r in values.tolist()]
