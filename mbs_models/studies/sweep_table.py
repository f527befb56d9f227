"""The table of a sweep: its columns and types, and the file (CSV or Parquet) rows are written to.

One row per point: the parameters (one column per dotted key), the metrics
(:func:`~mbs_models.studies.point.metric_columns`), ``wall_time``, ``status``, ``error``.  Types are
fixed by the column (:func:`frame`): parameters as :func:`~mbs_models.studies.grid.column_values` gives
them, metrics ``float64``, counts nullable ``Int64``, text ``object`` (None where empty), so that a table
read back from its file equals the one built in memory.

:class:`SweepFile` appends rows as they finish (CSV: one flushed write per batch of rows; Parquet: the
whole file rewritten atomically, at most every ``parquet_interval`` seconds, since Parquet cannot be
appended to) and, at the end, rewrites the file in grid order.  :meth:`SweepFile.read` reads what a
previous run of the same sweep left (a CSV line cut short by a kill is dropped), so that a sweep resumes
with the points not yet in the file; ``FILE.sweep.json`` beside it records what the rows were computed
with (the scene, end time, accuracy...), and a run with other settings is refused
(:meth:`SweepFile.check_settings`) rather than mixed in.
"""

from __future__ import annotations

import io
import json
import os
import time
from pathlib import Path
from typing import Any, Iterable, Sequence

import numpy as np
import pandas as pd

from ..outputs import atomic_write_with
from ..errors import SceneError
from .point import COUNT_COLUMNS, STATUS_COLUMNS, TEXT_COLUMNS

FORMATS = {".csv": "csv", ".parquet": "parquet"}
#: read_csv's arguments for floats that round-trip exactly (pandas 3 does by default and deprecates the option).
_EXACT_FLOATS = {"float_precision": "round_trip"} if int(pd.__version__.split(".")[0]) < 3 else {}


def _is_count(column: str) -> bool:
    return column in COUNT_COLUMNS or column.rsplit(".", 1)[-1] in COUNT_COLUMNS


def _is_text(column: str) -> bool:
    return column in TEXT_COLUMNS


def frame(rows: Iterable[dict], params: Sequence[str], metrics: Sequence[str]) -> pd.DataFrame:
    """The typed table of ``rows`` with the columns ``params + metrics + STATUS_COLUMNS``."""
    rows = list(rows)
    columns = [*params, *metrics, *STATUS_COLUMNS]
    data = {}
    for column in columns:
        values = [row.get(column) for row in rows]
        if column in params:
            if values and all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in values):
                data[column] = np.array(values, dtype="float64")
            elif values and all(isinstance(v, (bool, np.bool_)) for v in values):
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
    """The output file of one sweep (``params`` and ``metrics`` fix its columns)."""

    def __init__(self, path: str | os.PathLike, params: Sequence[str], metrics: Sequence[str], *,
                 parquet_interval: float = 2.0):
        self.path = check_out(path)
        self.format = FORMATS[self.path.suffix.lower()]
        self.params, self.metrics = list(params), list(metrics)
        self.columns = [*self.params, *self.metrics, *STATUS_COLUMNS]
        self.parquet_interval = parquet_interval
        self._rows: list[dict] = []     # Parquet: every row so far (the file is rewritten whole)
        self._last_write = 0.0

    # ------------------------------------------------------------------ what the rows were computed with
    @property
    def settings_path(self) -> Path:
        """The file beside the table that records what its rows were computed with (``FILE.sweep.json``)."""
        return self.path.with_name(self.path.name + ".sweep.json")

    def check_settings(self, settings: dict[str, Any]) -> None:
        """SceneError if the table's rows were computed with other ``settings`` (the scene, end time,
        accuracy...) than these; nothing is known of a table without its settings file (it is taken as is)."""
        if not self.path.exists() or not self.settings_path.exists():
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
    def read(self) -> pd.DataFrame:
        """The rows a previous run left in the file (an empty table if there is none); SceneError if the
        file holds another table (other columns) or cannot be read."""
        if not self.path.exists() or self.path.stat().st_size == 0:
            return frame([], self.params, self.metrics)
        try:
            if self.format == "csv":
                raw = self._read_csv()
            else:
                raw = pd.read_parquet(self.path)
        except (OSError, ValueError) as exc:
            raise SceneError("out", f"cannot read the existing {self.path} to resume it: "
                                    f"{str(exc).splitlines()[0] if str(exc) else type(exc).__name__}") from None
        if list(raw.columns) != self.columns:
            raise SceneError("out", f"{self.path} holds another sweep's table (its columns differ from this sweep's): "
                                    "choose another file, or delete it to start again")
        records = raw.astype(object).where(raw.notna(), None).to_dict("records")
        self._rows = list(records) if self.format == "parquet" else []
        return frame(records, self.params, self.metrics)

    def _read_csv(self) -> pd.DataFrame:
        text = self.path.read_text(encoding="utf-8")
        if not text.endswith("\n"):  # the last line was cut short (a kill mid-write): drop it
            text = text[:text.rfind("\n") + 1]
            with open(self.path, "w", encoding="utf-8") as handle:
                handle.write(text)
        if not text.strip():
            return pd.DataFrame(columns=self.columns)
        return pd.read_csv(io.StringIO(text), keep_default_na=False, na_values=[""],
                           dtype={c: object for c in TEXT_COLUMNS}, **_EXACT_FLOATS)

    # ------------------------------------------------------------------ writing
    def append(self, rows: Sequence[dict]) -> None:
        """Write ``rows`` (CSV: appended and flushed to disk; Parquet: rewritten, throttled)."""
        if not rows:
            return
        if self.format == "csv":
            new = not self.path.exists() or self.path.stat().st_size == 0
            table = frame(rows, self.params, self.metrics)
            with open(self.path, "a", encoding="utf-8", newline="") as handle:
                table.to_csv(handle, header=new, index=False)
                handle.flush()
                os.fsync(handle.fileno())
        else:
            self._rows += list(rows)
            if time.monotonic() - self._last_write >= self.parquet_interval:
                self._write_parquet(frame(self._rows, self.params, self.metrics))

    def flush(self) -> None:
        """Parquet: write the rows held back by the throttle."""
        if self.format == "parquet" and self._rows:
            self._write_parquet(frame(self._rows, self.params, self.metrics))

    def write_all(self, table: pd.DataFrame) -> None:
        """Replace the file by ``table`` (atomically: a temporary file beside it, then renamed)."""
        if self.format == "csv":
            self._atomic(lambda path: table.to_csv(path, index=False))
        else:
            self._write_parquet(table)

    def _write_parquet(self, table: pd.DataFrame) -> None:
        self._atomic(lambda path: table.to_parquet(path, index=False))
        self._last_write = time.monotonic()

    def _atomic(self, write, target: Path | None = None) -> None:
        """Write ``target`` (default: the table's file) through ``write(temporary_path)`` atomically, with the
        mode the umask gives (:func:`mbs_models.outputs.atomic_write_with`)."""
        atomic_write_with(self.path if target is None else target, write)


__all__ = ["SweepFile", "frame", "check_out", "FORMATS"]
