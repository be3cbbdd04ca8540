"""Writing estimates: CSV (pyarrow, vectorized, full precision), Parquet, HDF5."""

from __future__ import annotations

import json
from dataclasses import fields
from pathlib import Path

import h5py
import numpy as np
import pyarrow as pa
import pyarrow.csv as pa_csv
import pyarrow.parquet as pq

from tactsense._validation import TactsenseInputError
from tactsense.estimate.results import ContactTable, Estimates, Flag

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


def estimates_schema(format: str) -> pa.Schema:
    """The columns of a file of :class:`Estimates` and their types, from the definition
    (never from the data of a piece: a piece with no contact must not change a type).

    ``frame`` int64, ``time_s`` float64, the fields of :class:`Estimates` (float64;
    ``iterations`` and ``flags`` int64, ``converged`` bool) and, in CSV, ``flag_names``
    (string).
    """
    types = {"iterations": pa.int64(), "flags": pa.int64(), "converged": pa.bool_()}
    schema = [("frame", pa.int64()), ("time_s", pa.float64())]
    schema += [(name, types.get(name, pa.float64())) for name in _NAMES]
    if format == "csv":
        schema.append(("flag_names", pa.string()))
    return pa.schema(schema)


_CONTACT_TYPES = {
    "frame": pa.int64(),
    "contact": pa.int64(),
    "id": pa.int64(),
    "taxels": pa.int64(),
    "flags": pa.int64(),
    "slip": pa.bool_(),
    "event": pa.string(),
    "flag_names": pa.string(),
    # ---- three-axis slip (r8-triest) ----
    "slip_state": pa.string(),
}
"""Types of the long table's columns that are not float64 (every other column, such as
``x_mm``, ``force_n`` or a finger's ``axial_mm``, is float64)."""


def contacts_schema(names) -> pa.Schema:
    """The long table's columns ``names`` with their types from the definition
    (:data:`_CONTACT_TYPES`, float64 otherwise)."""
    return pa.schema([(name, _CONTACT_TYPES.get(name, pa.float64())) for name in names])


def _conform(columns: dict, schema: pa.Schema) -> pa.Table:
    """``columns`` (name -> array) as a table of exactly ``schema``: the types of the
    file, whatever a piece holds (an empty or all-quiet piece infers no type)."""
    if list(columns) != schema.names:
        raise ValueError(f"a piece has the columns {list(columns)}; the file has {schema.names}")
    arrays = [pa.array(columns[f.name], type=f.type) for f in schema]
    return pa.Table.from_arrays(arrays, schema=schema)


def _h5_dtype(type_: pa.DataType):
    """The HDF5 (numpy) type of an Arrow column type."""
    if pa.types.is_string(type_):
        return h5py.string_dtype()
    return np.dtype(type_.to_pandas_dtype())


def _flag_names(flags: np.ndarray) -> np.ndarray:
    values, inverse = np.unique(flags, return_inverse=True)
    names = np.array([Flag.describe(int(v)) for v in values], dtype=object)
    return names[inverse]


class EstimatesWriter:
    """Append estimates to a CSV, Parquet or HDF5 file (by extension), piece by piece.

    Every format has the same column names, those of :class:`Estimates` with ``frame``
    and ``time_s`` (units in the name or in :attr:`Estimates.UNITS`: ``axial_mm``,
    ``force_n``...; the names ``live`` writes), and flags as integers (bits of
    :class:`~tactsense.estimate.finger.deflection.Flag`); CSV adds ``flag_names`` (``A|B``,
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
        self._schema: pa.Schema | None = None

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
        if self._schema is None:
            self._schema = estimates_schema(self.format)
        return _conform(columns, self._schema)

    def write(self, start: int, time_s, estimates: Estimates) -> None:
        """Append the estimates of frames ``start ...`` with their times [s]."""
        table = self._table(start, time_s, estimates)
        units = {"time_s": "s", **Estimates.UNITS, "flags": "Flag bits"}
        self._append(table, units, "tactsense-estimates")

    def _append(self, table: pa.Table, units: dict, kind: str) -> None:
        """Append a piece already of the file's schema (:func:`_conform`)."""
        if self.format == "csv":
            if self._writer is None:
                self._writer = pa_csv.CSVWriter(str(self.path), table.schema)
            self._writer.write_table(table)
        elif self.format == "parquet":
            if self._writer is None:
                schema = table.schema.with_metadata({"units": json.dumps(units)})
                self._writer = pq.ParquetWriter(str(self.path), schema)
            self._writer.write_table(table.replace_schema_metadata(self._writer.schema.metadata))
        else:
            self._write_h5(table, units, kind)
        self.rows += table.num_rows

    def _write_h5(self, table: pa.Table, units: dict, kind: str) -> None:
        if self._h5 is None:
            self._h5 = h5py.File(self.path, "w")
            self._h5.attrs["format"] = kind
            # chunks sized to the data: the first piece (a short file is one small chunk),
            # at least 1024 rows so that a long file written in small pieces is not
            # split into tiny chunks, at most 65,536 rows
            rows = min(65_536, max(1_024, table.num_rows))
            for field_ in table.schema:
                if pa.types.is_string(field_.type):  # variable length: no filters
                    data = self._h5.create_dataset(
                        field_.name, shape=(0,), maxshape=(None,), chunks=(rows,),
                        dtype=_h5_dtype(field_.type),
                    )  # fmt: skip
                else:
                    data = self._h5.create_dataset(
                        field_.name, shape=(0,), maxshape=(None,), chunks=(rows,),
                        compression="gzip", compression_opts=4, shuffle=True,
                        fletcher32=True, dtype=_h5_dtype(field_.type),
                    )  # fmt: skip
                data.attrs["units"] = units.get(field_.name, "1")
        n = table.num_rows
        for name in table.column_names:
            data = self._h5[name]
            data.resize((self.rows + n,))
            column = table.column(name)
            values = column.to_pylist() if pa.types.is_string(column.type) else column.to_numpy()
            data[self.rows :] = values

    def close(self) -> None:
        if self._writer is not None:
            self._writer.close()
            self._writer = None
        if self._h5 is not None:
            self._h5.close()
            self._h5 = None


class ContactsWriter(EstimatesWriter):
    """Append a :class:`~tactsense.estimate.contacts.ContactTable` to a CSV, Parquet or
    HDF5 file (by extension), piece by piece: the long table, one row per contact per
    frame.

    Columns: ``frame``, ``time_s``, ``id`` (the tracked identity; -1 when not tracked),
    the table's columns (``x_mm``, ``y_mm``, ``z_mm``, ``row``, ``col``, ``force_n``,
    ``peak``, ``major_mm``, ``minor_mm``, ``orientation_deg``, ``taxels``, ``area_mm2``, ``flags``,
    ``contact``, the velocities and ``slip`` when tracked, and any extra columns such as
    a finger's ``axial_mm`` and ``angle_deg``), and ``event``: ``birth`` on the row where
    an id is born, ``split:P`` where it splits off id P, empty otherwise. Deaths and
    merges happen where an id has no row: they are kept in the file's metadata (Parquet
    key ``events``, HDF5 dataset group ``events``, CSV: a sidecar ``NAME.events.csv``)
    as (frame, kind, id, other) rows. CSV adds ``flag_names``.
    """

    def __init__(
        self, path: str | Path, *, format: str | None = None, events_path: str | Path | None = None
    ):
        super().__init__(path, format=format)
        self.events: list = []
        self.events_path = Path(events_path) if events_path else events_sidecar(self.path)

    def _contact_table(self, time_s, table) -> pa.Table:
        n = len(table)
        columns = {
            "frame": np.asarray(table.frame, dtype=np.int64),
            "time_s": np.asarray(time_s, dtype=float),
            "id": (
                np.full(n, -1, np.int64) if table.id is None else np.asarray(table.id, np.int64)
            ),
        }
        for name, value in table.columns().items():
            if name in columns:
                continue
            if name in ("taxels", "flags", "contact"):
                value = value.astype(np.int64)
            columns[name] = value
        columns["event"] = np.full(n, "", dtype=object)
        if self.format == "csv":
            columns["flag_names"] = _flag_names(columns["flags"])
        if self._schema is None:  # the first piece names the columns, the definition types them
            self._schema = contacts_schema(columns)
        return _conform(columns, self._schema)

    def write_contacts(self, time_s, table, events=()) -> None:
        """Append a table of contacts, ``time_s`` per row [s], and its track events."""
        arrow = self._contact_table(time_s, table)
        events = list(events)
        if events and table.id is not None and len(table):
            marks = arrow.column("event").to_pylist()
            where = {
                (int(f), int(i)): k
                for k, (f, i) in enumerate(zip(table.frame, table.id, strict=True))
            }
            for e in events:
                k = where.get((int(e.frame), int(e.id)))
                if k is not None and e.kind in ("birth", "split"):
                    marks[k] = e.kind if e.kind == "birth" else f"split:{e.others[0]}"
            arrow = arrow.set_column(
                arrow.column_names.index("event"), "event", pa.array(marks, pa.string())
            )
        self.events.extend(events)
        units = {"time_s": "s", **_contact_units(arrow.column_names), "flags": "Flag bits"}
        self._append(arrow, units, "tactsense-contacts")

    def close(self) -> None:
        events = _events_table(self.events)
        if self.format == "parquet" and self._writer is not None:
            # pyarrow writes key-value metadata with the footer: the events go there
            self._writer.add_key_value_metadata({"events": _events_json(self.events)})
        if self.format == "h5" and self._h5 is not None:
            group = self._h5.create_group("events")
            for name in events.column_names:
                column = events.column(name)
                values = (
                    column.to_pylist() if pa.types.is_string(column.type) else column.to_numpy()
                )
                group.create_dataset(
                    name, data=values,
                    dtype=h5py.string_dtype() if pa.types.is_string(column.type) else None,
                )  # fmt: skip
        if self.format == "csv" and self._writer is not None:
            pa_csv.write_csv(events, str(self.events_path))
        super().close()


def events_sidecar(path: str | Path) -> Path:
    """The CSV file beside a CSV long table that holds its track events."""
    path = Path(path)
    return path.with_name(path.stem + ".events.csv")


SUFFIX_UNITS = (("_mm_s", "mm/s"), ("_mm2", "mm2"), ("_mm", "mm"), ("_n", "N"),
                ("_deg", "deg"), ("_s", "s"))  # fmt: skip
"""An extra column's unit from its name's ending (``x_sd_mm``: mm, ``force_sd_n``: N)."""


def _contact_units(names=()) -> dict:
    """Units of the long table's columns: :attr:`ContactTable.UNITS`, and for the
    extras of ``names`` their name's ending (:data:`SUFFIX_UNITS`), else "1"."""
    units = dict(ContactTable.UNITS)
    for name in names:
        if name not in units:
            units[name] = next((u for end, u in SUFFIX_UNITS if name.endswith(end)), "1")
    return units


def _events_table(events) -> pa.Table:
    return pa.table(
        {
            "frame": pa.array([int(e.frame) for e in events], pa.int64()),
            "kind": pa.array([e.kind for e in events], pa.string()),
            "id": pa.array([int(e.id) for e in events], pa.int64()),
            "other": pa.array([int(e.others[0]) if e.others else -1 for e in events], pa.int64()),
        }
    )


def _events_json(events) -> str:
    import json

    return json.dumps(
        [[int(e.frame), e.kind, int(e.id), int(e.others[0]) if e.others else -1] for e in events]
    )
