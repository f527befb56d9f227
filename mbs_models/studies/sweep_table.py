"""The table of a sweep: its columns and types, and the file (CSV or Parquet) rows are written to.

One row per point: the parameters (one column per dotted key), the metrics
(:func:`~mbs_models.studies.point.metric_columns`), ``wall_time``, ``status``, ``error``.  Types are
fixed by the column (:func:`frame` for rows, :func:`~.table_rows.check_rows` for a table read back): parameters as
:func:`~mbs_models.studies.grid.column_values` gives them (``kinds``: float, bool or text), metrics
``float64``, counts nullable ``Int64``, text ``object`` (None where empty), so that a table read back from
its file equals the one built in memory.

:class:`SweepFile` never holds the table: rows are appended as they finish (a CSV file: one write per batch
of rows, flushed to the system at once -- a SIGKILL loses nothing written -- and synced to disk at most
every ``sync_interval`` seconds; a Parquet file cannot be appended to, so its rows go to a CSV journal
``FILE.parquet.rows.csv`` beside it), :meth:`SweepFile.chunks` reads the file back ``chunk_rows`` rows at a
time, every row checked (:mod:`.table_rows`: a CSV line cut short by a kill, a row cut short and ended by
a newline, a second header line, a cell that is no number where one belongs are dropped and counted in
:attr:`SweepFile.unreadable`, and their points run again), and :meth:`SweepFile.finish` rewrites it in
grid order, atomically, through the external sort of :mod:`.table_sort` (a Parquet file then takes the
journal's rows and the journal goes).  ``FILE.sweep.json`` beside it records what the rows were computed
with (the scene, end time, accuracy...), and a run with other settings -- or over rows without that
record -- is refused (:meth:`SweepFile.check_settings`) rather than mixed in.  A file that cannot be
written (a full disk) raises :class:`SweepWriteError`, every row written before kept; the temporary files
a killed run leaves beside the table go at the next run (:meth:`SweepFile.clean_temporaries`).
"""

from __future__ import annotations

import json
import os
import re
import time
from contextlib import contextmanager
from pathlib import Path
from typing import Any, Callable, Iterable, Iterator, Mapping, Sequence

import numpy as np
import pandas as pd

from ..outputs import atomic_write_with, check_output_dir, prepare_output_dir
from ..errors import RecoilError, SceneError
from .point import STATUS_COLUMNS
from .table_rows import Unreadable, check_rows, csv_chunks, csv_text, is_count, is_text, read_header
from .table_sort import SortStats

FORMATS = {".csv": "csv", ".parquet": "parquet"}
#: Rows read at a time (:meth:`SweepFile.chunks`).
CHUNK_ROWS = 20_000
#: Parameter kinds (:func:`param_kinds`).
KINDS = ("float", "bool", "text")
#: The names of the temporary files written beside a table ``NAME`` (``mkstemp``'s 8 random characters): an
#: atomic rewrite ``.NAME.XXXXXXXX.tmp``, a sort's runs ``.NAME.sort-XXXXXXXX.tmp``, the settings'
#: ``.NAME.sweep.json.XXXXXXXX.tmp``.
_TEMPORARY = r"\.{name}\.(?:sort-|sweep\.json\.)?[a-z0-9_]{{8}}\.tmp"


class SweepWriteError(RecoilError):
    """The table's file (or its journal, or its settings) cannot be written -- the disk is full, the file
    system gone read-only: ``path`` and the system's ``reason``.  Every row written before is kept, and the
    same sweep run again resumes from them."""

    def __init__(self, path: str | os.PathLike, reason: str):
        self.path, self.reason = str(path), reason
        super().__init__(f"cannot write {self.path}: {reason}; every row written before is kept: make room and "
                         "run the same sweep again to resume")


@contextmanager
def writing(path: str | os.PathLike):
    """An OSError while writing ``path`` raised as a :class:`SweepWriteError`."""
    try:
        yield
    except OSError as exc:
        raise SweepWriteError(path, exc.strerror or str(exc) or type(exc).__name__) from None


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
        elif is_text(column):
            data[column] = pd.Series([None if _missing(v) else str(v) for v in values], dtype=object)
        elif is_count(column):
            data[column] = pd.array([pd.NA if _missing(v) else int(v) for v in values], dtype="Int64")
        else:
            data[column] = np.array([np.nan if _missing(v) else float(v) for v in values], dtype="float64")
    return pd.DataFrame(data, columns=columns)


def _missing(value: Any) -> bool:
    if value is None or value is pd.NA:
        return True
    return isinstance(value, float) and value != value


def _inferred_kind(values: pd.Series) -> str:
    """A parameter column's kind as :func:`frame` would infer it from the rows."""
    if len(values) and pd.api.types.is_bool_dtype(values):
        return "bool"
    if len(values) and pd.api.types.is_numeric_dtype(values) and values.notna().all():
        return "float"
    return "text"


def check_out(path: str | os.PathLike) -> Path:
    """``path`` checked as a sweep's output file: ``.csv`` or ``.parquet`` (with pyarrow installed), not a
    directory itself, in a writable directory or one that can be created (:func:`~mbs_models.outputs.check_output_dir`;
    :class:`SweepFile` creates it)."""
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
    check_output_dir(parent, "out")
    if (parent.exists() and not os.access(parent, os.W_OK)) or (path.exists() and not os.access(path, os.W_OK)):
        raise SceneError("out", f"cannot write to {path}")
    return path


class SweepFile:
    """The output file of one sweep (``params`` and ``metrics`` fix its columns, ``kinds`` the parameters'
    types: :func:`param_kinds`; without them they are inferred from the values)."""

    def __init__(self, path: str | os.PathLike, params: Sequence[str], metrics: Sequence[str], *,
                 kinds: Mapping[str, str] | None = None, chunk_rows: int = CHUNK_ROWS, sync_interval: float = 1.0):
        self.path = check_out(path)
        prepare_output_dir(self.path.parent if str(self.path.parent) else Path("."), "out")
        self.format = FORMATS[self.path.suffix.lower()]
        self.params, self.metrics = list(params), list(metrics)
        self.kinds = dict(kinds) if kinds is not None else None
        self.columns = [*self.params, *self.metrics, *STATUS_COLUMNS]
        self.chunk_rows, self.sync_interval = chunk_rows, sync_interval
        self._synced = time.monotonic()
        #: The rows the last reading (:meth:`chunks`) dropped, one :class:`~.table_rows.Unreadable` per file.
        self.unreadable: list[Unreadable] = []

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
        accuracy...) than these, or if it has rows but no settings file (what they were computed with is
        not known: they are not mixed with others), or if that file is not one a sweep writes."""
        if not self.has_rows():
            return
        name = self.settings_path.name
        if not self.settings_path.exists():
            raise SceneError("out", f"{self.path} holds rows but not {name}, the record of what they were "
                                    f"computed with (scene, end time, accuracy): restore {name}, or delete "
                                    f"{self.path.name} to start again")
        try:
            recorded = json.loads(self.settings_path.read_text(encoding="utf-8"))
        except (OSError, ValueError) as exc:
            reason = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
            raise SceneError("out", f"cannot read {self.settings_path} (what {self.path} was computed with): "
                                    f"{reason}; restore it, or delete both to start again") from None
        if not isinstance(recorded, dict):
            raise SceneError("out", f"{self.settings_path} (what {self.path} was computed with) holds a JSON "
                                    f"{type(recorded).__name__}, not the object a sweep writes: restore it, or "
                                    "delete both to start again")
        differing = [key for key in sorted(set(recorded) | set(settings)) if recorded.get(key) != settings.get(key)]
        if differing:
            raise SceneError("out", f"{self.path} holds a sweep computed with another {', '.join(differing)} "
                                    f"(see {name}): choose another file, or delete both to start again")

    def clean_temporaries(self) -> list[Path]:
        """Remove the temporary files a killed run left beside the table (an atomic rewrite, a sort's runs, the
        settings being written: :data:`_TEMPORARY`) and return them.  Only while this sweep holds the
        table's lock (:mod:`.sweep_lock`): no other run can be writing them."""
        pattern = re.compile(_TEMPORARY.format(name=re.escape(self.path.name)) + r"\Z")
        removed = []
        with os.scandir(self.path.parent if str(self.path.parent) else ".") as entries:
            for entry in entries:
                if pattern.match(entry.name):
                    try:
                        os.unlink(entry.path)
                        removed.append(Path(entry.path))
                    except OSError:
                        pass
        return removed

    def write_settings(self, settings: dict[str, Any]) -> None:
        """Record what the rows are computed with (atomically)."""
        text = json.dumps(settings, indent=2, sort_keys=True) + "\n"
        with writing(self.settings_path):
            self._atomic(lambda path: Path(path).write_text(text, encoding="utf-8"), self.settings_path)

    # ------------------------------------------------------------------ reading
    def chunks(self) -> Iterator[pd.DataFrame]:
        """The rows a previous run left (the table, then a Parquet table's journal), checked
        (:func:`~mbs_models.studies.table_rows.check_rows`: the unreadable ones dropped and counted in
        :attr:`unreadable`) and typed as :func:`frame` types rows, ``chunk_rows`` at a time; SceneError if the file holds
        another table (other columns, or parameters of other kinds) or cannot be read."""
        sources = [(self.path, self.format)]
        if self.journal_path is not None:
            sources.append((self.journal_path, "csv"))
        self.unreadable = []
        for path, fmt in sources:
            if not path.exists() or path.stat().st_size == 0:
                continue
            unreadable = Unreadable(path, "line" if fmt == "csv" else "row")
            try:
                pieces = self._csv_pieces(path) if fmt == "csv" else self._parquet_pieces(path)
                for raw, numbers, quoted, dropped in pieces:
                    kinds = self.kinds or {param: _inferred_kind(raw[param]) for param in self.params}
                    clean, broken, foreign = check_rows(raw, self.params, self.metrics, kinds, quoted)
                    if foreign is not None:
                        position, why = foreign
                        raise SceneError("out", f"{path} holds another sweep's rows ({unreadable.unit} "
                                                f"{numbers[position]}: {why}): choose another file, remove those "
                                                "rows, or delete it to start again")
                    unreadable.add(np.sort(np.concatenate([dropped, numbers[broken]])))
                    if len(clean):
                        yield clean
            except (OSError, ValueError, KeyError) as exc:
                if isinstance(exc, SceneError):
                    raise
                raise SceneError("out", f"cannot read the existing {path} to resume it: "
                                        f"{str(exc).splitlines()[0] if str(exc) else type(exc).__name__}") from None
            if unreadable.count:
                self.unreadable.append(unreadable)

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

    def _csv_pieces(self, path: Path) -> Iterator[tuple[pd.DataFrame, np.ndarray, np.ndarray, np.ndarray]]:
        drop_cut_line(path)
        if path.stat().st_size == 0:
            return
        text = [c for c in self.columns if is_text(c) or (self.kinds or {}).get(c) == "text"]
        with open(path, "rb") as handle:
            header = read_header(handle, self.columns)
            self._check_columns(header or [], path)
            yield from csv_chunks(handle, self.columns, text, self.chunk_rows)

    def _parquet_pieces(self, path: Path) -> Iterator[tuple[pd.DataFrame, np.ndarray, None, np.ndarray]]:
        import pyarrow.parquet as pq

        source = pq.ParquetFile(path)
        self._check_columns(source.schema_arrow.names, path)
        first = 1
        for batch in source.iter_batches(batch_size=self.chunk_rows):
            raw = batch.to_pandas()
            yield raw, np.arange(first, first + len(raw), dtype=np.int64), None, np.zeros(0, dtype=np.int64)
            first += len(raw)

    # ------------------------------------------------------------------ writing
    def append(self, rows: Sequence[dict]) -> None:
        """Append ``rows`` to the CSV table (or a Parquet table's journal), flushed to the system at once (a
        killed process loses none of them) and synced to disk at most every ``sync_interval`` seconds; the
        ``error`` cell quoted (:func:`~mbs_models.studies.table_rows.csv_text`).  SweepWriteError if it
        cannot be written (the rows before are kept; a row written in part is dropped when read)."""
        if not rows:
            return
        path = self._appended
        table = frame(rows, self.params, self.metrics, self.kinds)
        with writing(path):
            new = not path.exists() or path.stat().st_size == 0
            text = csv_text(table, header=new)
            with open(path, "a", encoding="utf-8", newline="") as handle:
                self._write(handle, text)
                handle.flush()
                if time.monotonic() - self._synced >= self.sync_interval:
                    os.fsync(handle.fileno())
                    self._synced = time.monotonic()

    @staticmethod
    def _write(handle, text: str) -> None:
        handle.write(text)

    def sync(self) -> None:
        """Sync the appended rows to disk."""
        path = self._appended
        with writing(path):
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

        with writing(self.path):
            self._atomic(write)
            if self.journal_path is not None and self.journal_path.exists():
                self.journal_path.unlink()
        return stats[0]

    def write_all(self, table: pd.DataFrame) -> None:
        """Replace the file by ``table`` (atomically: a temporary file beside it, then renamed)."""
        with writing(self.path):
            if self.format == "csv":
                self._atomic(lambda path: Path(path).write_text(csv_text(table, header=True), encoding="utf-8"))
            else:
                self._atomic(lambda path: table.to_parquet(path, index=False))

    def _atomic(self, write, target: Path | None = None) -> None:
        """Write ``target`` (default: the table's file) through ``write(temporary_path)`` atomically, with the
        mode the umask gives (:func:`mbs_models.outputs.atomic_write_with`)."""
        atomic_write_with(self.path if target is None else target, write)


class _ChunkWriter:
    """Writes a table chunk by chunk: CSV (the bytes of one :func:`~mbs_models.studies.table_rows.csv_text` of
    the whole table) or Parquet (one row
    group per chunk, the types of :func:`parquet_schema`)."""

    def __init__(self, path: Path, fmt: str, params, metrics, kinds):
        self.path, self.format = path, fmt
        self.params, self.metrics, self.kinds = params, metrics, kinds
        self._handle = None
        self._writer = None
        self._schema = None

    def write(self, chunk: pd.DataFrame) -> None:
        if self.format == "csv":
            first = self._handle is None
            if first:
                self._handle = open(self.path, "w", encoding="utf-8", newline="")
            self._handle.write(csv_text(chunk, header=first))
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
        elif is_text(column):
            kind_type = pa.string()
        elif is_count(column):
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


__all__ = ["SweepFile", "SweepWriteError", "writing", "frame", "param_kinds", "check_out", "FORMATS",
           "CHUNK_ROWS", "parquet_schema", "drop_cut_line"]
