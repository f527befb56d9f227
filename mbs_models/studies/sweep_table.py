"""The table of a sweep: its columns and types, and the file (CSV or Parquet) rows are written to.

One row per point: the parameters (one column per dotted key), the metrics
(:func:`~mbs_models.studies.point.metric_columns`), ``wall_time``, ``status``, ``error``.  Types are
fixed by the column (:func:`frame` for rows, :func:`typed` for a table read back): parameters as
:func:`~mbs_models.studies.grid.column_values` gives them (``kinds``: float, bool or text), metrics
``float64``, counts nullable ``Int64``, text ``object`` (None where empty), so that a table read back from
its file equals the one built in memory.

:class:`SweepFile` never holds the table: rows are appended as they finish (a CSV file: one write per batch
of rows, flushed to the system at once -- a SIGKILL loses nothing written -- and synced to disk at most
every ``sync_interval`` seconds; a Parquet file cannot be appended to, so its rows go to a CSV journal
``FILE.parquet.rows.csv`` beside it), :meth:`SweepFile.chunks` reads the file back ``chunk_rows`` rows at a
time (a CSV line cut short by a kill is dropped), and :meth:`SweepFile.finish` rewrites it in grid order,
atomically, through the external sort of :mod:`.table_sort` (a Parquet file then takes the journal's rows
and the journal goes).  ``FILE.sweep.json`` beside it records what the rows were computed with (the scene,
end time, accuracy...), and a run with other settings is refused (:meth:`SweepFile.check_settings`) rather
than mixed in.
"""

from __future__ import annotations

import json
import os
import time
from pathlib import Path
from typing import Any, Callable, Iterable, Iterator, Mapping, Sequence

import numpy as np
import pandas as pd

from ..outputs import atomic_write_with
from ..errors import SceneError
from .point import COUNT_COLUMNS, STATUS_COLUMNS, TEXT_COLUMNS
from .table_sort import SortStats

FORMATS = {".csv": "csv", ".parquet": "parquet"}
#: Rows read at a time (:meth:`SweepFile.chunks`).
CHUNK_ROWS = 20_000
#: Parameter kinds (:func:`param_kinds`).
KINDS = ("float", "bool", "text")
#: read_csv's arguments for floats that round-trip exactly (pandas 3 does by default and deprecates the option).
_EXACT_FLOATS = {"float_precision": "round_trip"} if int(pd.__version__.split(".")[0]) < 3 else {}


def _is_count(column: str) -> bool:
    return column in COUNT_COLUMNS or column.rsplit(".", 1)[-1] in COUNT_COLUMNS


def _is_text(column: str) -> bool:
    return column in TEXT_COLUMNS


def param_kinds(params: Sequence[str], cells: Sequence[Sequence[Any]]) -> dict[str, str]:
    """Each parameter's kind from its table cells (:attr:`~mbs_models.studies.grid.Grid.cells`): ``float``
    (numbers), ``bool`` or ``text``."""
    kinds = {}
    for param, values in zip(params, cells):
        if all(isinstance(v, float) for v in values):
            kinds[param] = "float"
        elif all(isinstance(v, (bool, np.bool_)) for v in values):
            kinds[param] = "bool"
        else:
            kinds[param] = "text"
    return kinds


def _param_kind(values: Sequence[Any]) -> str:
    if values and all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in values):
        return "float"
    if values and all(isinstance(v, (bool, np.bool_)) for v in values):
        return "bool"
    return "text"


def frame(rows: Iterable[dict], params: Sequence[str], metrics: Sequence[str],
          kinds: Mapping[str, str] | None = None) -> pd.DataFrame:
    """The typed table of ``rows`` with the columns ``params + metrics + STATUS_COLUMNS`` (a parameter's type
    from ``kinds``, else from its values)."""
    rows = list(rows)
    columns = [*params, *metrics, *STATUS_COLUMNS]
    data = {}
    for column in columns:
        values = [row.get(column) for row in rows]
        if column in params:
            kind = kinds[column] if kinds else _param_kind(values)
            if kind == "float":
                data[column] = np.array(values, dtype="float64")
            elif kind == "bool":
                data[column] = np.array(values, dtype=bool)
            else:
                data[column] = pd.Series(values, dtype=object)
        elif _is_text(column):
            data[column] = pd.Series([None if _missing(v) else str(v) for v in values], dtype=object)
        elif _is_count(column):
            data[column] = pd.array([pd.NA if _missing(v) else int(v) for v in values], dtype="Int64")
        else:
            data[column] = np.array([np.nan if _missing(v) else float(v) for v in values], dtype="float64")
    return pd.DataFrame(data, columns=columns)


def _missing(value: Any) -> bool:
    if value is None or value is pd.NA:
        return True
    return isinstance(value, float) and value != value


def _text(column: pd.Series) -> pd.Series:
    """A column as ``object`` text: ``str`` values, None where empty."""
    values = column.to_numpy(dtype=object, na_value=None)
    return pd.Series([None if _missing(v) else str(v) for v in values], dtype=object, index=column.index)


def typed(raw: pd.DataFrame, params: Sequence[str], metrics: Sequence[str],
          kinds: Mapping[str, str] | None = None) -> pd.DataFrame:
    """A table read back (from CSV or Parquet) with the types :func:`frame` gives its rows, column by column
    (vectorised: ``typed(read) == frame(rows)``); ValueError if a column cannot have its type (the file holds
    another sweep)."""
    columns = [*params, *metrics, *STATUS_COLUMNS]
    data = {}
    for column in columns:
        values = raw[column].reset_index(drop=True)
        if column in params:
            kind = kinds[column] if kinds else _inferred_kind(values)
            if kind == "float":
                if not (pd.api.types.is_numeric_dtype(values) and not pd.api.types.is_bool_dtype(values)):
                    raise ValueError(f"column {column!r} does not hold numbers")
                data[column] = values.to_numpy(dtype="float64", na_value=np.nan)
            elif kind == "bool":
                if not pd.api.types.is_bool_dtype(values):
                    raise ValueError(f"column {column!r} does not hold true/false")
                data[column] = values.to_numpy(dtype=bool)
            else:
                data[column] = _text(values)
        elif _is_text(column):
            data[column] = _text(values)
        elif _is_count(column):
            data[column] = pd.array(values.to_numpy(dtype="float64", na_value=np.nan), dtype="Int64")
        else:
            data[column] = values.to_numpy(dtype="float64", na_value=np.nan)
    return pd.DataFrame(data, columns=columns)


def _inferred_kind(values: pd.Series) -> str:
    """A parameter column's kind as :func:`frame` would infer it from the rows."""
    if len(values) and pd.api.types.is_bool_dtype(values):
        return "bool"
    if len(values) and pd.api.types.is_numeric_dtype(values) and values.notna().all():
        return "float"
    return "text"


def check_out(path: str | os.PathLike) -> Path:
    """``path`` checked as a sweep's output file: ``.csv`` or ``.parquet`` (with pyarrow installed), in an
    existing directory, not a directory itself."""
    path = Path(path)
    fmt = FORMATS.get(path.suffix.lower())
    if fmt is None:
        raise SceneError("out", f"must be a .csv or .parquet file, got {str(path)!r}")
    if fmt == "parquet":
        try:
            import pyarrow  # noqa: F401
        except ImportError:
            raise SceneError("out", "writing Parquet needs pyarrow, which is not installed: "
                                    "pip install 'recoil-mbs[parquet]', or write a .csv file") from None
    if path.is_dir():
        raise SceneError("out", f"{path} is a directory, not a file")
    parent = path.parent if str(path.parent) else Path(".")
    if not parent.is_dir():
        raise SceneError("out", f"the directory {parent} does not exist")
    if not os.access(parent, os.W_OK) or (path.exists() and not os.access(path, os.W_OK)):
        raise SceneError("out", f"cannot write to {path}")
    return path


class SweepFile:
    """The output file of one sweep (``params`` and ``metrics`` fix its columns, ``kinds`` the parameters'
    types: :func:`param_kinds`; without them they are inferred from the values)."""

    def __init__(self, path: str | os.PathLike, params: Sequence[str], metrics: Sequence[str], *,
                 kinds: Mapping[str, str] | None = None, chunk_rows: int = CHUNK_ROWS, sync_interval: float = 1.0):
        self.path = check_out(path)
        self.format = FORMATS[self.path.suffix.lower()]
        self.params, self.metrics = list(params), list(metrics)
        self.kinds = dict(kinds) if kinds is not None else None
        self.columns = [*self.params, *self.metrics, *STATUS_COLUMNS]
        self.chunk_rows, self.sync_interval = chunk_rows, sync_interval
        self._synced = time.monotonic()

    # ------------------------------------------------------------------ what the rows were computed with
    @property
    def settings_path(self) -> Path:
        """The file beside the table that records what its rows were computed with (``FILE.sweep.json``)."""
        return self.path.with_name(self.path.name + ".sweep.json")

    @property
    def journal_path(self) -> Path | None:
        """Where the rows of a Parquet table go until :meth:`finish` (``FILE.parquet.rows.csv``); None for CSV."""
        return self.path.with_name(self.path.name + ".rows.csv") if self.format == "parquet" else None

    @property
    def _appended(self) -> Path:
        """The CSV file rows are appended to: the table itself, or a Parquet table's journal."""
        return self.path if self.format == "csv" else self.journal_path

    def has_rows(self) -> bool:
        """Whether the table (or its journal) holds anything."""
        return any(path is not None and path.exists() and path.stat().st_size > 0
                   for path in (self.path, self.journal_path))

    def check_settings(self, settings: dict[str, Any]) -> None:
        """SceneError if the table's rows were computed with other ``settings`` (the scene, end time,
        accuracy...) than these; nothing is known of a table without its settings file (it is taken as is)."""
        if not self.has_rows() or not self.settings_path.exists():
            return
        try:
            recorded = json.loads(self.settings_path.read_text(encoding="utf-8"))
        except (OSError, ValueError) as exc:
            raise SceneError("out", f"cannot read {self.settings_path} (what {self.path} was computed with): "
                                    f"{exc}; delete both to start again") from None
        differing = [key for key in sorted(set(recorded) | set(settings)) if recorded.get(key) != settings.get(key)]
        if differing:
            raise SceneError("out", f"{self.path} holds a sweep computed with another {', '.join(differing)} "
                                    f"(see {self.settings_path.name}): choose another file, or delete both to "
                                    "start again")

    def write_settings(self, settings: dict[str, Any]) -> None:
        """Record what the rows are computed with (atomically)."""
        text = json.dumps(settings, indent=2, sort_keys=True) + "\n"
        self._atomic(lambda path: Path(path).write_text(text, encoding="utf-8"), self.settings_path)

    # ------------------------------------------------------------------ reading
    def chunks(self) -> Iterator[pd.DataFrame]:
        """The rows a previous run left (the table, then a Parquet table's journal), typed (:func:`typed`),
        ``chunk_rows`` at a time; SceneError if the file holds another table (other columns or types) or
        cannot be read."""
        sources = [(self.path, self.format)]
        if self.journal_path is not None:
            sources.append((self.journal_path, "csv"))
        for path, fmt in sources:
            if not path.exists() or path.stat().st_size == 0:
                continue
            try:
                raws = self._csv_chunks(path) if fmt == "csv" else self._parquet_chunks(path)
                for raw in raws:
                    if len(raw):   # a file of its header alone (a run killed before its first row) gives nothing
                        yield typed(raw, self.params, self.metrics, self.kinds)
            except (OSError, ValueError, KeyError) as exc:
                if isinstance(exc, SceneError):
                    raise
                raise SceneError("out", f"cannot read the existing {path} to resume it: "
                                        f"{str(exc).splitlines()[0] if str(exc) else type(exc).__name__}") from None

    def read(self) -> pd.DataFrame:
        """The whole table (an empty one if there is none): :meth:`chunks` joined (in memory)."""
        parts = list(self.chunks())
        if not parts:
            return frame([], self.params, self.metrics, self.kinds)
        return parts[0] if len(parts) == 1 else pd.concat(parts, ignore_index=True)

    def _check_columns(self, columns: Sequence[str], path: Path) -> None:
        if list(columns) != self.columns:
            raise SceneError("out", f"{path} holds another sweep's table (its columns differ from this sweep's): "
                                    "choose another file, or delete it to start again")

    def _csv_chunks(self, path: Path) -> Iterator[pd.DataFrame]:
        drop_cut_line(path)
        if path.stat().st_size == 0:
            return
        header = pd.read_csv(path, nrows=0)
        self._check_columns(header.columns, path)
        text = {c: object for c in self.columns if _is_text(c) or (self.kinds or {}).get(c) == "text"}
        reader = pd.read_csv(path, keep_default_na=False, na_values=[""], dtype=text, chunksize=self.chunk_rows,
                             **_EXACT_FLOATS)
        with reader:
            yield from reader

    def _parquet_chunks(self, path: Path) -> Iterator[pd.DataFrame]:
        import pyarrow.parquet as pq

        source = pq.ParquetFile(path)
        self._check_columns(source.schema_arrow.names, path)
        for batch in source.iter_batches(batch_size=self.chunk_rows):
            yield batch.to_pandas()

    # ------------------------------------------------------------------ writing
    def append(self, rows: Sequence[dict]) -> None:
        """Append ``rows`` to the CSV table (or a Parquet table's journal), flushed to the system at once (a
        killed process loses none of them) and synced to disk at most every ``sync_interval`` seconds."""
        if not rows:
            return
        path = self._appended
        new = not path.exists() or path.stat().st_size == 0
        table = frame(rows, self.params, self.metrics, self.kinds)
        with open(path, "a", encoding="utf-8", newline="") as handle:
            table.to_csv(handle, header=new, index=False)
            handle.flush()
            if time.monotonic() - self._synced >= self.sync_interval:
                os.fsync(handle.fileno())
                self._synced = time.monotonic()

    def sync(self) -> None:
        """Sync the appended rows to disk."""
        path = self._appended
        if path.exists():
            with open(path, "a", encoding="utf-8") as handle:
                os.fsync(handle.fileno())
        self._synced = time.monotonic()

    def finish(self, index_of: Callable[[pd.DataFrame], np.ndarray],
               on_chunk: Callable[[pd.DataFrame], None] | None = None, **sort_options) -> SortStats:
        """Rewrite the table in the order of ``index_of(chunk)`` (the rows' grid indices; one row per index,
        the first in the file kept), atomically, holding a bounded number of rows (:mod:`.table_sort`); a
        Parquet table takes its journal's rows and the journal is removed.  ``on_chunk`` sees the rows in
        their new order."""
        from .table_sort import sort_chunks

        chunks = ((index_of(chunk), chunk) for chunk in self.chunks())
        stats = []

        def write(temporary: Path) -> None:
            with _ChunkWriter(temporary, self.format, self.params, self.metrics, self.kinds) as writer:
                def take(_keys, chunk):
                    if on_chunk is not None:
                        on_chunk(chunk)
                    writer.write(chunk)
                stats.append(sort_chunks(chunks, take, self.path.parent, prefix=f".{self.path.name}.sort-",
                                         **sort_options))

        self._atomic(write)
        if self.journal_path is not None and self.journal_path.exists():
            self.journal_path.unlink()
        return stats[0]

    def write_all(self, table: pd.DataFrame) -> None:
        """Replace the file by ``table`` (atomically: a temporary file beside it, then renamed)."""
        if self.format == "csv":
            self._atomic(lambda path: table.to_csv(path, index=False))
        else:
            self._atomic(lambda path: table.to_parquet(path, index=False))

    def _atomic(self, write, target: Path | None = None) -> None:
        """Write ``target`` (default: the table's file) through ``write(temporary_path)`` atomically, with the
        mode the umask gives (:func:`mbs_models.outputs.atomic_write_with`)."""
        atomic_write_with(self.path if target is None else target, write)


class _ChunkWriter:
    """Writes a table chunk by chunk: CSV (the bytes of one ``to_csv`` of the whole table) or Parquet (one row
    group per chunk, the types of :func:`parquet_schema`)."""

    def __init__(self, path: Path, fmt: str, params, metrics, kinds):
        self.path, self.format = path, fmt
        self.params, self.metrics, self.kinds = params, metrics, kinds
        self._handle = None
        self._writer = None
        self._schema = None

    def write(self, chunk: pd.DataFrame) -> None:
        if self.format == "csv":
            if self._handle is None:
                self._handle = open(self.path, "w", encoding="utf-8", newline="")
                chunk.to_csv(self._handle, index=False)
            else:
                chunk.to_csv(self._handle, header=False, index=False)
            return
        import pyarrow as pa
        import pyarrow.parquet as pq

        schema = self._schema or parquet_schema(self.params, self.metrics, self.kinds, chunk)
        table = pa.Table.from_pandas(chunk, schema=schema, preserve_index=False)
        if self._writer is None:
            self._schema = table.schema
            self._writer = pq.ParquetWriter(self.path, self._schema)
        self._writer.write_table(table.replace_schema_metadata(self._schema.metadata))

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        if exc[0] is None and self._handle is None and self._writer is None:   # no rows: the header / schema
            self.write(frame([], self.params, self.metrics, self.kinds))
        if self._handle is not None:
            self._handle.close()
        if self._writer is not None:
            self._writer.close()


def parquet_schema(params: Sequence[str], metrics: Sequence[str], kinds: Mapping[str, str] | None,
                   sample: pd.DataFrame):
    """The Arrow schema of a sweep's table: parameters double/bool/string (``kinds``, else ``sample``'s
    types), metrics double, counts int64, text string -- the same for every chunk."""
    import pyarrow as pa

    fields = []
    for column in [*params, *metrics, *STATUS_COLUMNS]:
        if column in params:
            kind = kinds[column] if kinds else _inferred_kind(sample[column])
            kind_type = {"float": pa.float64(), "bool": pa.bool_(), "text": pa.string()}[kind]
        elif _is_text(column):
            kind_type = pa.string()
        elif _is_count(column):
            kind_type = pa.int64()
        else:
            kind_type = pa.float64()
        fields.append(pa.field(column, kind_type))
    return pa.schema(fields)


def drop_cut_line(path: Path, block: int = 1 << 16) -> None:
    """Cut a CSV file back to its last complete line (a kill mid-write leaves the last line short), reading
    only its end."""
    with open(path, "rb+") as handle:
        end = handle.seek(0, os.SEEK_END)
        if end == 0:
            return
        handle.seek(end - 1)
        if handle.read(1) == b"\n":
            return
        position = end
        while position > 0:
            start = max(0, position - block)
            handle.seek(start)
            data = handle.read(position - start)
            cut = data.rfind(b"\n")
            if cut >= 0:
                handle.truncate(start + cut + 1)
                return
            position = start
        handle.truncate(0)


__all__ = ["SweepFile", "frame", "typed", "param_kinds", "check_out", "FORMATS", "CHUNK_ROWS", "parquet_schema",
           "drop_cut_line"]
