"""Rows of a table put in order of a key, chunk by chunk: an external merge sort in bounded memory.

A sweep's file gets its rows as they finish -- nearly in grid order, since points are handed out in order
and only a bounded number are in flight -- and must end in grid order, however many rows it has.
:func:`sort_chunks` takes the table as chunks ``(keys, frame)`` (int64 keys, the grid indices; a pandas
DataFrame of the same length) and hands ``write(keys, frame)`` the rows in increasing key order, one row
per key (the first in the input wins):

1. **Runs** (replacement selection, by chunks): the rows read so far but not yet written are kept sorted,
   at most ``carry_rows`` of them; beyond that the smallest are written to the current run (a temporary
   file).  A chunk holding a key below the last written one ends the run and starts the next.  Rows that
   finish at most ``carry_rows`` places out of order therefore make a single run.
2. **Merge**: runs are merged ``fan_in`` at a time (chunk by chunk: everything up to the smallest of the
   runs' current chunk maxima is safe to write) until one pass gives the output.

Memory: ``carry_rows`` plus one input chunk in step 1, one chunk per merged run (``fan_in`` chunks) in
step 2 -- independent of the table's length.  The temporary files (pickled chunks, exact) are made in
``directory`` and removed whatever happens.
"""

from __future__ import annotations

import os
import pickle
import tempfile
from dataclasses import dataclass
from pathlib import Path
from typing import Callable, Iterable, Iterator

import numpy as np
import pandas as pd

#: Rows held back, sorted, before the smallest are written (the disorder one run absorbs).
CARRY_ROWS = 20_000
#: Runs merged at once.
FAN_IN = 8

Write = Callable[[np.ndarray, pd.DataFrame], None]


@dataclass
class SortStats:
    """What a sort did: rows read, rows written (duplicates dropped), runs made, merge passes."""

    rows_in: int = 0
    rows_out: int = 0
    runs: int = 0
    passes: int = 0


class _Run:
    """A temporary file of sorted chunks ``(keys, frame)``, pickled one after the other."""

    def __init__(self, directory: Path, prefix: str):
        handle, name = tempfile.mkstemp(prefix=prefix, suffix=".tmp", dir=directory)
        self.path = Path(name)
        self._file = os.fdopen(handle, "wb")

    def write(self, keys: np.ndarray, frame: pd.DataFrame) -> None:
        pickle.dump((keys, frame), self._file, protocol=pickle.HIGHEST_PROTOCOL)

    def close(self) -> None:
        self._file.close()

    def chunks(self) -> Iterator[tuple[np.ndarray, pd.DataFrame]]:
        with open(self.path, "rb") as handle:
            while True:
                try:
                    yield pickle.load(handle)
                except EOFError:
                    return

    def remove(self) -> None:
        if not self._file.closed:
            self._file.close()
        try:
            self.path.unlink()
        except OSError:
            pass


class _Ordered:
    """Hands sorted pieces to ``write`` without the keys already written (one row per key)."""

    def __init__(self, write: Write):
        self.write, self.last, self.rows = write, -1, 0

    def __call__(self, keys: np.ndarray, frame: pd.DataFrame) -> None:
        """``keys`` sorted (ties in input order), all >= the last key written."""
        keep = keys != self.last
        keep[1:] &= keys[1:] != keys[:-1]
        if not keep.all():
            keys, frame = keys[keep], frame[keep]
        if len(keys):
            self.write(keys, frame.reset_index(drop=True))
            self.last = int(keys[-1])
            self.rows += len(keys)


def _sorted(keys: np.ndarray, frame: pd.DataFrame) -> tuple[np.ndarray, pd.DataFrame]:
    order = np.argsort(keys, kind="stable")
    return keys[order], frame.iloc[order]


def _concat(parts: list[tuple[np.ndarray, pd.DataFrame]]) -> tuple[np.ndarray, pd.DataFrame]:
    if len(parts) == 1:
        return parts[0]
    return np.concatenate([k for k, _ in parts]), pd.concat([f for _, f in parts], ignore_index=True)


def _make_runs(chunks: Iterable[tuple[np.ndarray, pd.DataFrame]], new_run: Callable[[], _Run], carry_rows: int,
               stats: SortStats) -> list[_Run]:
    runs: list[_Run] = []
    out: _Ordered | None = None
    carry: tuple[np.ndarray, pd.DataFrame] | None = None

    def end_run():
        nonlocal out, carry
        if carry is not None and out is not None:
            out(*carry)
        runs[-1].close()
        out, carry = None, None

    for keys, frame in chunks:
        keys = np.asarray(keys, dtype=np.int64)
        if len(keys) == 0:
            continue
        stats.rows_in += len(keys)
        if out is not None and keys.min() < out.last:
            end_run()
        if out is None:
            runs.append(new_run())
            out = _Ordered(runs[-1].write)
        keys, frame = _sorted(*_concat([carry, (keys, frame)] if carry is not None else [(keys, frame)]))
        if len(keys) > carry_rows:
            cut = len(keys) - carry_rows
            out(keys[:cut], frame.iloc[:cut])
            keys, frame = keys[cut:], frame.iloc[cut:]
        carry = (keys, frame)
    if out is not None:
        end_run()
    return runs


def _merge(runs: list[_Run], write: Write) -> int:
    """Merge sorted runs into ``write`` (chunk by chunk); returns the rows written."""
    out = _Ordered(write)
    readers = [run.chunks() for run in runs]
    current = [next(reader, None) for reader in readers]
    while True:
        active = [i for i, chunk in enumerate(current) if chunk is not None]
        if not active:
            return out.rows
        bound = min(int(current[i][0][-1]) for i in active)
        parts = []
        for i in active:
            keys, frame = current[i]
            n = int(np.searchsorted(keys, bound, side="right"))
            parts.append((keys[:n], frame.iloc[:n]))
            current[i] = next(readers[i], None) if n == len(keys) else (keys[n:], frame.iloc[n:])
        out(*_sorted(*_concat(parts)))


def sort_chunks(chunks: Iterable[tuple[np.ndarray, pd.DataFrame]], write: Write, directory: str | os.PathLike, *,
                carry_rows: int = CARRY_ROWS, fan_in: int = FAN_IN, prefix: str = ".sort-") -> SortStats:
    """Hand ``write(keys, frame)`` the rows of ``chunks`` in increasing key order, one per key (the first
    given wins), in memory bounded by ``carry_rows`` and ``fan_in`` chunks (module docstring)."""
    if carry_rows < 1 or fan_in < 2:
        raise ValueError("carry_rows >= 1 and fan_in >= 2")
    directory = Path(directory)
    stats = SortStats()
    made: list[_Run] = []

    def new_run() -> _Run:
        made.append(_Run(directory, prefix))
        return made[-1]

    try:
        runs = _make_runs(chunks, new_run, carry_rows, stats)
        stats.runs = len(runs)
        while len(runs) > fan_in:
            merged = []
            for start in range(0, len(runs), fan_in):
                group = runs[start:start + fan_in]
                run = new_run()
                _merge(group, run.write)
                run.close()
                for old in group:
                    old.remove()
                merged.append(run)
            runs = merged
            stats.passes += 1
        stats.rows_out = _merge(runs, write)
        stats.passes += 1
    finally:
        for run in made:
            run.remove()
    return stats


__all__ = ["sort_chunks", "SortStats", "CARRY_ROWS", "FAN_IN"]
