"""Writing estimates: CSV (pyarrow, vectorized, full precision), Parquet, HDF5."""

from __future__ import annotations

from dataclasses import fields
from pathlib import Path

import h5py
import numpy as np
import pyarrow as pa
import pyarrow.csv as pa_csv
import pyarrow.parquet as pq

from tactsense._validation import TactsenseInputError
from tactsense.estimate.deflection import Flag
from tactsense.estimate.locate import Estimates

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


def _flag_names(flags: np.ndarray) -> np.ndarray:
    values, inverse = np.unique(flags, return_inverse=True)
    names = np.array([Flag.describe(int(v)) for v in values], dtype=object)
    return names[inverse]


class EstimatesWriter:
    """Append estimates to a CSV, Parquet or HDF5 file (by extension), piece by piece.

    Every format has the same column names, those of :class:`Estimates` with ``frame``
    and ``time_s`` (units in the name or in :attr:`Estimates.UNITS`: ``axial_mm``,
    ``force_n``...; the names ``live`` writes), and flags as integers (bits of
    :class:`~tactsense.estimate.deflection.Flag`); CSV adds ``flag_names`` (``A|B``,
    empty when none). Parquet and HDF5 keep the units in their metadata. Floats keep
    full precision. HDF5 datasets are compressed (gzip) and checksummed (Fletcher-32),
    with chunks no longer than the data.
    """

    def __init__(self, path: str | Path, *, format: str | None = None):
        self.path = Path(path)
        if format is not None and format not in FORMATS.values():
            raise TactsenseInputError(f"format {format!r}: expected csv, parquet or h5")
        self.format = format or output_format(self.path)
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
            elif name == "iterations":
                value = value.astype(np.int64)
            elif name == "converged":
                value = value.astype(bool)
            columns[name] = value
        if self.format == "csv":  # a text file also says the flags by name, as `live` does
            columns["flag_names"] = _flag_names(columns["flags"])
        return pa.table(columns)

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
            # chunks sized to the data: the first piece (a short file is one small chunk),
            # at least 1024 rows so that a long file written in small pieces is not
            # split into tiny chunks, at most 65,536 rows
            rows = min(65_536, max(1_024, table.num_rows))
            for name in table.column_names:
                column = table.column(name).to_numpy()
                data = self._h5.create_dataset(
                    name,
                    shape=(0,),
                    maxshape=(None,),
                    dtype=column.dtype,
                    chunks=(rows,),
                    compression="gzip",
                    compression_opts=4,
                    shuffle=True,
                    fletcher32=True,
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
