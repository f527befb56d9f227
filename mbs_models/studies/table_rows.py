"""The rows of a sweep's file read back, each checked: a row this library would not have written is dropped.

A sweep resumes from what its file holds, so a row taken as finished must be one: a row cut short by a
fault and ended by a newline (``steps`` 24 where 2463 was written, no ``status``), a second header line, a
cell that is no number where a number belongs, a line of zero bytes (a crash of the file system) must not
pass as a finished point -- it would never run again.  :func:`csv_chunks` reads a CSV file a chunk of lines
at a time and keeps the line number of each row; a line is dropped at once if it cannot be one row of the
table (an odd number of ``"``: a quoted cell cut short; another number of cells; a NUL byte; not UTF-8).
:func:`check_rows` then checks every row's cells against its column:

* ``status``: ``ok`` or an exception's class name (a Python identifier);
* ``error``: empty when ``ok``, else a message -- quoted in a CSV file (:func:`csv_text` always quotes it,
  and :func:`~mbs_models.studies.point.error_text` keeps ``"`` out of it, so that a row cut anywhere in
  its last cell has an odd number of quotes);
* ``wall_time``: a finite number >= 0; every metric empty or a finite number (a count a whole number
  >= 0), and empty in the row of a failed point;
* the parameters: a number (kind ``float``), ``True``/``False`` (``bool``) or any text.

A row that fails any of these is *unreadable*: dropped, its line counted (:class:`Unreadable`), its point
runs again.  A row that passes all but its parameters' kinds is not damaged but another sweep's (the same
key swept over values of another kind): the file is refused, as one holding points of another grid is.
"""

from __future__ import annotations

import csv
import io
import itertools
import re
from pathlib import Path
from typing import Iterator, Mapping, Sequence

import numpy as np
import pandas as pd

from .point import COUNT_COLUMNS, STATUS_COLUMNS, TEXT_COLUMNS

#: Line numbers an :class:`Unreadable` keeps (the first ones; the count is of all).
LISTED_LINES = 5
#: read_csv's arguments for floats that round-trip exactly (pandas 3 does by default and deprecates the option).
EXACT_FLOATS = {"float_precision": "round_trip"} if int(pd.__version__.split(".")[0]) < 3 else {}
#: ``status`` of a failed point: an exception's class name.
_CLASS_NAME = r"[A-Za-z_][A-Za-z0-9_]*"


def is_count(column: str) -> bool:
    """Whether ``column`` holds counts (whole numbers: ``impacts``, ``steps``, ``absorber.N.impacts`` ...)."""
    return column in COUNT_COLUMNS or column.rsplit(".", 1)[-1] in COUNT_COLUMNS


def is_text(column: str) -> bool:
    """Whether ``column`` (not a parameter) holds text."""
    return column in TEXT_COLUMNS


class UnreadableRowsWarning(UserWarning):
    """Rows of a sweep's file were unreadable and dropped (their points run again): the warning ``run_sweep``
    gives when its announcement goes nowhere."""


class Unreadable:
    """The rows dropped while reading a file: ``count``, and the first :data:`LISTED_LINES` line numbers (row
    numbers, 1-based, in a Parquet file: ``unit``)."""

    def __init__(self, path: str | Path, unit: str = "line"):
        self.path, self.unit, self.count, self.numbers = str(path), unit, 0, []

    def add(self, numbers: Sequence[int] | np.ndarray) -> None:
        """Count the rows of line (row) ``numbers``, keeping the first few numbers."""
        numbers = np.asarray(numbers, dtype=np.int64).ravel()
        room = max(0, LISTED_LINES - len(self.numbers))
        self.numbers += [int(n) for n in numbers[:room]]
        self.count += int(numbers.size)

    def text(self) -> str:
        """``t.csv: 3 rows unreadable (line 17, 18, 40): their points run again``."""
        listed = ", ".join(str(n) for n in self.numbers)
        more = ", ..." if self.count > len(self.numbers) else ""
        rows = "1 row" if self.count == 1 else f"{self.count:,} rows"
        their = "its point runs" if self.count == 1 else "their points run"
        return f"{self.path}: {rows} unreadable ({self.unit} {listed}{more}): {their} again"


# ================================================================================================ writing
def csv_text(table: pd.DataFrame, header: bool) -> str:
    """``table`` as CSV text (pandas' ``to_csv``: the shortest exact floats, empty for a missing value), the
    ``error`` cell always quoted (module docstring); with the header line if ``header``.  ValueError if a cell
    holds a line break (rows are read back line by line: :func:`~mbs_models.studies.point.error_text` makes
    messages one line, and a sweep refuses parameter values with one)."""
    error = table["error"]
    body = table.drop(columns="error").to_csv(index=False, header=header, lineterminator="\n")
    lines = body.split("\n")[:-1]
    if len(lines) != len(table) + header or any(isinstance(e, str) and ("\n" in e or "\r" in e) for e in error):
        raise ValueError("a cell of a sweep's table holds a line break: its rows are read line by line")
    cells = (["error"] if header else []) + [
        "" if value is None or value != value else '"' + str(value).replace('"', '""') + '"'
        for value in error.to_numpy(dtype=object)]
    return "".join(f"{line},{cell}\n" for line, cell in zip(lines, cells))


# ================================================================================================ reading CSV
def read_header(handle, columns: Sequence[str]) -> list[str] | None:
    """The cells of the first line of ``handle`` (binary, at its start), None for an empty file."""
    first = handle.readline()
    if not first.strip():
        return None
    try:
        return next(csv.reader([first.decode("utf-8").rstrip("\r\n")]))
    except (UnicodeDecodeError, csv.Error, StopIteration):
        return ["(unreadable header)"]


def _one_row(line: bytes, cells: int) -> bool:
    """Whether ``line`` can be one row of ``cells`` cells (quotes paired, no NUL byte, UTF-8)."""
    quotes = line.count(b'"')
    if quotes % 2 or b"\0" in line:
        return False
    if quotes == 0:
        if not line.isascii():
            try:
                line.decode("utf-8")
            except UnicodeDecodeError:
                return False
        return line.count(b",") + 1 == cells
    try:
        return len(next(csv.reader([line.decode("utf-8").rstrip("\r\n")]))) == cells
    except (UnicodeDecodeError, csv.Error, StopIteration):
        return False


def line_checks(data: bytes, lengths: np.ndarray, cells: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """For each line of ``data`` (lines of ``lengths`` bytes, each ending in a newline): whether it can be one
    row of ``cells`` cells (the number of commas outside quotes; quotes paired, no NUL byte, UTF-8), whether it
    is empty (no row at all), whether it ends with a quote.  Vectorised over the bytes; only a line holding a
    quote, a NUL or a byte beyond ASCII is looked at alone (:func:`_one_row`)."""
    ends = np.cumsum(lengths) - 1                   # the index of each line's newline
    starts = ends - lengths + 1
    array = np.frombuffer(data, dtype=np.uint8)
    before = np.maximum(ends - 1, 0)
    crlf = (lengths >= 2) & (array[before] == 13)
    empty = (lengths == 1) | ((lengths == 2) & crlf)
    last = np.maximum(np.where(crlf, ends - 2, ends - 1), 0)
    quoted_end = (lengths >= 2 + crlf) & (array[last] == 34)
    commas = np.flatnonzero(array == 44)            # (8 bytes a comma: reduceat would cast every byte to int64)
    fits = np.searchsorted(commas, ends) - np.searchsorted(commas, starts) + 1 == cells
    del commas
    special = [np.flatnonzero(array == byte) for byte, found in ((34, b'"' in data), (0, b"\0" in data)) if found]
    if not data.isascii():
        special.append(np.flatnonzero(array >= 128))
    if special:
        for i in np.unique(np.searchsorted(ends, np.concatenate(special))):
            fits[i] = _one_row(data[starts[i]:ends[i] + 1], cells)
    return fits & ~empty, empty, quoted_end


def csv_chunks(handle, columns: Sequence[str], text_columns: Sequence[str], chunk_rows: int, first_line: int = 2
               ) -> Iterator[tuple[pd.DataFrame, np.ndarray, np.ndarray, np.ndarray]]:
    """``(raw, line_numbers, quoted_end, dropped)`` for each ``chunk_rows`` lines of ``handle`` (binary, after
    the header): the rows parsed (texts as ``object``, the rest as pandas infers), each one's line number,
    whether its line ends with a quote, and the numbers of the lines that cannot be one row (dropped:
    :func:`line_checks`).  Empty lines are no rows."""
    number = first_line
    text = {column: object for column in text_columns}
    while True:
        lines = list(itertools.islice(handle, chunk_rows))
        if not lines:
            return
        if not lines[-1].endswith(b"\n"):
            lines[-1] += b"\n"
        lengths = np.fromiter(map(len, lines), dtype=np.int64, count=len(lines))
        data = b"".join(lines)
        del lines                                   # the chunk is held once: its bytes
        fits, empty, quoted = line_checks(data, lengths, len(columns))
        numbers = np.arange(number, number + len(lengths), dtype=np.int64)
        number += len(lengths)
        dropped = numbers[~fits & ~empty]
        if not fits.all():
            ends = np.cumsum(lengths)
            data = b"".join(data[end - length:end] for end, length in zip(ends[fits], lengths[fits]))
        numbers, quoted = numbers[fits], quoted[fits]
        raw = _parse(data, columns, text) if len(numbers) else None
        if raw is None or len(raw) != len(numbers):   # pandas saw the lines otherwise: one at a time
            raw, keep = _parse_each(data.splitlines(keepends=True), columns, text)
            dropped = np.sort(np.concatenate([dropped, numbers[~keep]]))
            numbers, quoted = numbers[keep], quoted[keep]
        yield raw, numbers, quoted, dropped


def _parse(data: bytes, columns: Sequence[str], text: Mapping[str, type]) -> pd.DataFrame | None:
    try:
        return pd.read_csv(io.BytesIO(data), names=list(columns), header=None, index_col=False,
                           keep_default_na=False, na_values=[""], dtype=dict(text), skip_blank_lines=False,
                           **EXACT_FLOATS)
    except (ValueError, UnicodeDecodeError, pd.errors.ParserError):
        return None


def _parse_each(lines: list[bytes], columns: Sequence[str], text) -> tuple[pd.DataFrame, np.ndarray]:
    """The lines parsed one by one (the slow way, for a chunk pandas could not read whole): the rows of those
    that give one row each, and which did."""
    parts, keep = [], np.zeros(len(lines), dtype=bool)
    for i, line in enumerate(lines):
        raw = _parse(line, columns, text)
        if raw is not None and len(raw) == 1:
            parts.append(raw.astype(object))
            keep[i] = True
    if not parts:
        return pd.DataFrame({column: pd.Series([], dtype=object) for column in columns}), keep
    return pd.concat(parts, ignore_index=True), keep


# ================================================================================================ checking
def _numbers(values: pd.Series) -> tuple[np.ndarray, np.ndarray]:
    """A column as float64 (NaN where empty) and where a cell is not a number (or not finite)."""
    present = values.notna().to_numpy()
    if pd.api.types.is_bool_dtype(values):
        return np.full(len(values), np.nan), present
    if pd.api.types.is_numeric_dtype(values):
        numbers = values.to_numpy(dtype="float64", na_value=np.nan)
        bad = np.zeros(len(values), dtype=bool)
    else:   # text among the numbers: each cell parsed alone (exactly: pandas' parser rounds correctly)
        numbers = pd.to_numeric(values.astype(object), errors="coerce").to_numpy(dtype="float64", na_value=np.nan)
        bad = present & np.isnan(numbers)
    with np.errstate(invalid="ignore"):
        bad |= present & ~np.isfinite(numbers)
    return numbers, bad


def texts(values: pd.Series) -> np.ndarray:
    """A column as an object array of ``str``, None where empty."""
    out = values.to_numpy(dtype=object, na_value=None)
    if pd.api.types.infer_dtype(out, skipna=True) in ("string", "empty"):
        return out
    return np.array([None if v is None or v != v else str(v) for v in out], dtype=object)


def _bools(values: pd.Series) -> tuple[np.ndarray, np.ndarray]:
    if pd.api.types.is_bool_dtype(values):
        return values.to_numpy(dtype=bool), np.zeros(len(values), dtype=bool)
    mapped = values.astype(object).map({"True": True, "False": False, True: True, False: False})
    bad = mapped.isna().to_numpy()
    return mapped.fillna(False).to_numpy(dtype=bool), bad


def check_rows(raw: pd.DataFrame, params: Sequence[str], metrics: Sequence[str], kinds: Mapping[str, str],
               quoted_end: np.ndarray | None = None) -> tuple[pd.DataFrame, np.ndarray, tuple[int, str] | None]:
    """Every row of ``raw`` checked (module docstring): ``(table, broken, foreign)`` -- the sound rows in the
    types :func:`~mbs_models.studies.sweep_table.frame` gives rows (parameters float64, bool or text, metrics
    float64, counts ``Int64``, text ``object`` with None where empty), which rows are unreadable, and
    ``(position, why)`` of the first row that is sound but whose parameters are not of their kinds (None if
    every one is).  ``quoted_end``: whether each row's line ends with a quote (a CSV file; None for Parquet)."""
    count = len(raw)
    broken = np.zeros(count, dtype=bool)
    clean: dict[str, np.ndarray] = {}
    status = texts(raw["status"])
    present_status = pd.notna(status)
    ok = status == "ok"
    failed = present_status & ~ok
    names = np.zeros(count, dtype=bool)   # whether a failed row's status is a class name (each value matched once)
    if failed.any():
        named = {value: re.fullmatch(_CLASS_NAME, value) is not None for value in pd.unique(status[failed])}
        names[failed] = [named[value] for value in status[failed]]
    broken |= ~present_status | (failed & ~names)
    error = texts(raw["error"])
    has_error = pd.notna(error)
    broken |= (ok & has_error) | (failed & ~has_error)
    if quoted_end is not None:
        broken |= failed & ~np.asarray(quoted_end, dtype=bool)
    for column in (*metrics, "wall_time"):
        if is_text(column):
            clean[column] = texts(raw[column])
            broken |= failed & pd.notna(clean[column])
            continue
        numbers, bad = _numbers(raw[column])
        present = ~np.isnan(numbers)
        broken |= bad
        if column == "wall_time":
            broken |= ~present | (present & (numbers < 0))
        else:
            broken |= failed & (present | bad)
            if is_count(column):
                with np.errstate(invalid="ignore"):
                    broken |= present & ((numbers != np.floor(numbers)) | (numbers < 0))
        clean[column] = numbers
    clean["status"], clean["error"] = status, error
    foreign: tuple[int, str] | None = None
    for column in params:
        kind = kinds[column]
        if kind == "float":
            numbers, bad = _numbers(raw[column])
            bad |= np.isnan(numbers)
            clean[column], why = numbers, f"column {column!r} does not hold numbers"
        elif kind == "bool":
            clean[column], bad = _bools(raw[column])
            why = f"column {column!r} does not hold true/false"
        else:
            clean[column], bad, why = texts(raw[column]), np.zeros(count, dtype=bool), ""
        sound_but_other = bad & ~broken
        if foreign is None and sound_but_other.any():
            foreign = (int(np.flatnonzero(sound_but_other)[0]), why)
    keep = ~broken
    columns = [*params, *metrics, *STATUS_COLUMNS]
    data = {}
    for column in columns:
        values = clean[column][keep] if not keep.all() else clean[column]
        if column not in params and is_count(column):
            values = pd.array(values, dtype="Int64")
        elif values.dtype == object:
            values = pd.Series(values, dtype=object)
        data[column] = values
    return pd.DataFrame(data, columns=columns), broken, foreign


__all__ = ["Unreadable", "UnreadableRowsWarning", "csv_text", "csv_chunks", "line_checks", "read_header",
           "check_rows", "texts", "is_count", "is_text", "LISTED_LINES", "EXACT_FLOATS"]
