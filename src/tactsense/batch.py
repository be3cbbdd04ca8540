"""Recordings of any length in bounded memory: locate piece by piece, write as you go.

:func:`iter_locate` reads a recording chunk by chunk (the HDF5 chunks) and yields the
estimates of each piece; :class:`EstimatesWriter` appends them to a CSV, Parquet or HDF5
file chosen by the extension; :func:`locate_file` joins the two with a progress callback.
Peak memory is that of one piece (65,536 frames of 8 x 8: about 35 MB of float64 and
the estimates), whatever the length of the recording.

Examples
--------
>>> from tactsense.batch import locate_file
>>> summary = locate_file("long.h5", "estimates.parquet")  # doctest: +SKIP
>>> summary["frames"], summary["contacts"]  # doctest: +SKIP
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from dataclasses import fields
from pathlib import Path

import h5py
import numpy as np
import pyarrow as pa
import pyarrow.csv as pa_csv
import pyarrow.parquet as pq

from tactsense._validation import TactsenseInputError
from tactsense.estimate.deflection import Flag
from tactsense.estimate.locate import CONTACT_THRESHOLD, Estimates, locate
from tactsense.io.recording import RecordingReader

FORMATS = {".csv": "csv", ".parquet": "parquet", ".h5": "h5", ".hdf5": "h5"}
"""Output formats by file extension."""

_NAMES = [f.name for f in fields(Estimates)]


def output_format(path: str | Path) -> str:
    """The format an output file's extension asks for, or a clear error."""
    suffix = Path(path).suffix.lower()
    if suffix not in FORMATS:
        raise TactsenseInputError(
            f"cannot tell the format of {path}: use the extension .csv, .parquet or .h5"
        )
    return FORMATS[suffix]


def iter_locate(
    reader: RecordingReader,
    *,
    baseline=None,
    baseline_frames: int = 5,
    calibration=None,
    threshold: float = CONTACT_THRESHOLD,
    chunk_frames: int | None = None,
    workers: int = 1,
) -> Iterator[tuple[int, np.ndarray, Estimates]]:
    """Estimates of a recording, one piece at a time: ``(first frame, time_s, estimates)``.

    The same numbers as :func:`~tactsense.estimate.locate` on the whole recording: the
    baseline is the median of the first ``baseline_frames`` frames (or given), and a
    calibration's creep compensation carries its state from piece to piece.
    """
    sensor = reader.sensor
    compensator = None
    if calibration is not None:
        calibration.check_sensor(sensor)
        compensator = calibration.compensator(sensor.scan_period_s, sensor.shape)
    elif baseline is None:
        if reader.n_frames < baseline_frames:
            raise TactsenseInputError(
                f"{reader.path} has {reader.n_frames} frames; need {baseline_frames} "
                "untouched frames at the start for the baseline"
            )
        baseline = np.median(reader.frames(0, baseline_frames).astype(float), axis=0)
    for start, frames, time_s in reader.chunks(chunk_frames):
        if calibration is not None:
            estimates = locate(
                frames,
                sensor,
                calibration=calibration,
                compensator=compensator,
                threshold=threshold,
                workers=workers,
            )
        else:
            estimates = locate(
                frames, sensor, baseline=baseline, threshold=threshold, workers=workers
            )
        yield start, time_s, estimates


def _flag_names(flags: np.ndarray) -> np.ndarray:
    values, inverse = np.unique(flags, return_inverse=True)
    names = np.array([Flag.describe(int(v)) for v in values], dtype=object)
    return names[inverse]


class EstimatesWriter:
    """Append estimates to a CSV, Parquet or HDF5 file (by extension), piece by piece.

    CSV has one header line with units (``frame, time [s], row [tactel], ...``) and
    flags by name; Parquet and HDF5 have the field names of :class:`Estimates` with
    ``frame`` and ``time_s``, units in the metadata, and flags as integers (bits of
    :class:`~tactsense.estimate.deflection.Flag`). Floats keep full precision.
    """

    def __init__(self, path: str | Path):
        self.path = Path(path)
        self.format = output_format(self.path)
        self.rows = 0
        self._writer = None
        self._h5 = None

    def __enter__(self) -> EstimatesWriter:
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def _table(self, start: int, time_s, estimates: Estimates) -> pa.Table:
        n = len(estimates)
        columns = {
            "frame": np.arange(start, start + n, dtype=np.int64),
            "time_s": np.asarray(time_s, dtype=float),
        }
        for name in _NAMES:
            value = np.ravel(getattr(estimates, name))
            if name == "flags":
                value = value.astype(np.int64)
                if self.format == "csv":
                    value = _flag_names(value)
            elif name == "iterations":
                value = value.astype(np.int64)
            elif name == "converged":
                value = value.astype(bool)
            columns[name] = value
        table = pa.table(columns)
        if self.format == "csv":
            labels = {
                "time_s": "time [s]",
                "axial_mm": "axial [mm]",
                "angle_deg": "angle [deg]",
                "force_n": "force [N]",
                "peak_deflection": "peak deflection [1]",
            }
            names = ["frame"] + [
                labels.get(name) or f"{name} [{Estimates.UNITS.get(name, '1')}]"
                for name in table.column_names[1:]
            ]
            table = table.rename_columns(names)
        return table

    def write(self, start: int, time_s, estimates: Estimates) -> None:
        """Append the estimates of frames ``start ...`` with their times [s]."""
        table = self._table(start, time_s, estimates)
        if self.format == "csv":
            if self._writer is None:
                self._writer = pa_csv.CSVWriter(str(self.path), table.schema)
            self._writer.write_table(table)
        elif self.format == "parquet":
            if self._writer is None:
                units = {"time_s": "s", **Estimates.UNITS, "flags": "Flag bits"}
                schema = table.schema.with_metadata({"units": str(units)})
                self._writer = pq.ParquetWriter(str(self.path), schema)
            self._writer.write_table(table.replace_schema_metadata(self._writer.schema.metadata))
        else:
            self._write_h5(table)
        self.rows += table.num_rows

    def _write_h5(self, table: pa.Table) -> None:
        if self._h5 is None:
            self._h5 = h5py.File(self.path, "w")
            self._h5.attrs["format"] = "tactsense-estimates"
            units = {"time_s": "s", **Estimates.UNITS, "flags": "Flag bits"}
            for name in table.column_names:
                column = table.column(name).to_numpy()
                data = self._h5.create_dataset(
                    name, shape=(0,), maxshape=(None,), dtype=column.dtype, chunks=(65_536,)
                )
                data.attrs["units"] = units.get(name, "1")
        n = table.num_rows
        for name in table.column_names:
            data = self._h5[name]
            data.resize((self.rows + n,))
            data[self.rows :] = table.column(name).to_numpy()

    def close(self) -> None:
        if self._writer is not None:
            self._writer.close()
            self._writer = None
        if self._h5 is not None:
            self._h5.close()
            self._h5 = None


def locate_file(
    recording: str | Path,
    out: str | Path,
    *,
    baseline_frames: int = 5,
    calibration=None,
    threshold: float = CONTACT_THRESHOLD,
    chunk_frames: int | None = None,
    workers: int = 1,
    progress: Callable[[int, int], None] | None = None,
) -> dict:
    """Locate every frame of a recording file and write the estimates to ``out``.

    Reads and writes piece by piece (bounded memory). ``out`` is written as it is named:
    write to a temporary name and move it into place if it must appear only complete
    (the command line does). ``progress(done, total)`` is called after each piece.

    Returns
    -------
    dict
        ``frames``, ``contacts`` (frames with a contact), ``saturated`` (frames flagged
        SATURATED), ``force_mean_n`` and ``force_max_n`` over the contacts [N].
    """
    output_format(out)
    contacts = saturated = 0
    force_sum, force_max = 0.0, float("nan")
    with RecordingReader(recording) as reader, EstimatesWriter(out) as writer:
        total = reader.n_frames
        if progress is not None:
            progress(0, total)
        for start, time_s, estimates in iter_locate(
            reader,
            baseline_frames=baseline_frames,
            calibration=calibration,
            threshold=threshold,
            chunk_frames=chunk_frames,
            workers=workers,
        ):
            writer.write(start, time_s, estimates)
            contacts += int(np.count_nonzero(np.isfinite(estimates.row)))
            finite = estimates.force_n[np.isfinite(estimates.force_n)]
            if finite.size:
                force_sum += float(finite.sum())
                force_max = float(np.fmax(force_max, finite.max()))
            saturated += int(np.count_nonzero(estimates.flags & int(Flag.SATURATED)))
            if progress is not None:
                progress(start + len(estimates), total)
        if writer.rows == 0:  # an empty recording still gets its (empty) file
            empty = Estimates(*(np.zeros(0) for _ in _NAMES))
            writer.write(0, np.zeros(0), empty)
            writer.rows = 0
    return {
        "frames": total,
        "contacts": contacts,
        "saturated": saturated,
        "force_mean_n": force_sum / contacts if contacts else float("nan"),
        "force_max_n": force_max,
    }
