"""``run_sweep``: the full grid of values of dotted scene keys over one scene, as one table, streamed.

Nothing here grows with the grid.  The points are decoded from their grid index one at a time
(:meth:`~mbs_models.studies.grid.Grid.point`), handed to a backend in batches as a generator (a bounded
number in flight: :mod:`.backends`), and each finished batch is appended to the table's file at once
(:class:`~mbs_models.studies.sweep_table.SweepFile`).  A file of the same sweep is read chunk by chunk to
find the points it already holds (:class:`~mbs_models.studies.point_set.PointSet`: one bit per grid index up
to the largest held), and at the end the file is put in grid order by an external sort
(:mod:`.table_sort`) -- skipped when its rows already are in order.  Per point, the run keeps at most that
bit; the table itself is in memory only when it is returned (``table=True``, the default) or when there is
no file (``out=None``).

Before the points run, one line says how many there are and roughly how long they will take: a few
points spread over the grid run first (:func:`probe_indices`; their rows are kept), and the mean of their
solves' wall times, times the points to run, over the workers, is the estimate (:func:`announcement`) --
points differ (a light absorber can take five times the steps of a heavy one), so the first point alone
would not do.
"""

from __future__ import annotations

import contextlib
import math
import sys
import warnings
from typing import Any, Callable, Iterator, Sequence

import numpy as np

from ..engine.accuracy import SolverSettings
from ..errors import ClusterError, SceneError
from ..scene import Scene

#: Failed points a summary lists (``table=False``; ``recoil sweep --json``): the first ones in grid order.
SUMMARY_FAILURES = 1000
#: Points spread over the grid that run first, to time a solve before the others start.
PROBE_POINTS = 4


def run_sweep(scene: Scene, params, *, end_time: float = 10.0, accuracy: str | SolverSettings = "standard",
              workers: int | None = None, scheduler=None, out=None, progress=True,
              stop_when_final: Sequence[str] = (), impact_threshold: float = 1000.0,
              batch_size: int | None = None, large: bool = False, table: bool = True, announce=None,
              worker_timeout: float | None = None):
    """Simulate ``scene`` at every point of the grid of ``params`` and return the table (a pandas DataFrame).

    ``params``: dotted scene key -> values (a sequence, or a text spec ``"100,500,1000"`` /
    ``"0:0.12:13"``: START:STOP:COUNT, both ends included), e.g. ``{"absorber.mass": [100, 500, 1000],
    "contact.gap": "0:0.12:13"}``; the full grid runs (the first key varies slowest).  One row per point,
    in grid order: the parameters (a column per key), every scalar metric
    (:func:`~mbs_models.studies.point.metric_columns`), ``wall_time`` (s), ``status`` (``"ok"`` or the
    error's class) and ``error`` (the message).  A point whose combination of values is invalid
    (SceneError), whose solve fails (SimulationError) or that raises anything else (an OverflowError of an
    extreme value...) is a row with its error, and so is a point whose worker process dies each time it runs
    it (status ``WorkerDied``, after a retry: :mod:`.backends`); the sweep goes on.

    ``large``: a grid of more than :data:`~mbs_models.studies.grid.MAX_POINTS` (10^6) points is refused
    (:class:`~mbs_models.studies.grid.GridTooLarge`, a SceneError of key ``large``) unless ``large=True``.
    ``table=False`` (with ``out``) keeps the table in its file only and returns the summary (a dict:
    ``points``, ``resumed``, ``run``, ``failed``, ``out``, ``unreadable`` and ``failures``, the first
    :data:`SUMMARY_FAILURES` failed points): memory then does not depend on the grid's size.

    ``workers``: a local process pool of that many processes (default: every CPU; 1 runs here);
    ``scheduler``: a Dask scheduler address ``"tcp://HOST:PORT"`` or a ``dask.distributed.Client``
    instead (the ``cluster`` extra).  Results are identical whichever runs them.  A fault of the cluster -- an
    address that does not answer (within 10 s), a scheduler lost mid-sweep, no worker for ``worker_timeout``
    seconds (default 60; a line on stderr says it is waiting) -- raises
    :class:`~mbs_models.errors.ClusterError` saying how many rows are kept in ``out`` (a resume runs the rest).

    ``out``: a ``.csv`` (or, with pyarrow, ``.parquet``) file; rows are written as they finish and, at
    the end, the file holds the table in grid order.  If ``out`` already holds rows of the same sweep, only
    the points not yet in it run (a killed sweep resumes; the resumed table equals an uninterrupted one
    but for ``wall_time``); ``FILE.sweep.json`` beside it records the scene and settings, and a file
    computed with others -- or holding rows without that record -- is refused.  Every row read back is
    checked (:mod:`.table_rows`): an unreadable one (cut short, a second header, a cell that is no number)
    is dropped and its point runs again, in one line (``t.csv: 3 rows unreadable (line 17, 18, 40): their
    points run again``: to ``announce``, else an :class:`~.table_rows.UnreadableRowsWarning`).  While it
    runs the sweep holds ``FILE.lock`` (:mod:`.sweep_lock`): another sweep on the same file is refused.  A
    file that cannot be written (a full disk) raises :class:`~.sweep_table.SweepWriteError`, every row
    written kept.  ``progress``: a tqdm bar on a terminal (rate, ETA), False for none, or a
    callable ``progress(done, total)``.  ``announce``: where the line saying how many points and about how
    long goes (:func:`announcement`): a callable taking the line, False for nowhere, None (default) for
    stderr when the tqdm bar is shown.  ``end_time``, ``accuracy``, ``stop_when_final`` and
    ``impact_threshold`` are those of :func:`~mbs_models.simulate`; ``batch_size``: points per task
    (default: about four tasks per worker, at most 16 points each).

    The returned table's ``attrs["sweep"]`` holds ``points``, ``resumed`` (rows taken from ``out``),
    ``run``, ``failed``, ``out`` and ``unreadable`` (rows of ``out`` dropped).  Bad keys, specs, values no point accepts, arguments or files raise
    :class:`SceneError` before anything is written.
    """
    from ..engine.accuracy import solver_settings_for
    from ..engine.final_metrics import check_metric_names
    from ..engine.simulation import _check_arguments
    from ..engine.unit_slips import warn_unit_slips
    from . import backends as _backends
    from .grid import MAX_POINTS, make_grid
    from .point import PointSettings, metric_columns
    from .sweep_lock import SweepLock
    from .sweep_table import SweepFile, param_kinds

    if not isinstance(scene, Scene):
        raise SceneError("scene", f"must be a Scene, got {type(scene).__name__}")
    for name, flag in (("large", large), ("table", table)):
        if not isinstance(flag, bool):
            raise SceneError(name, f"must be True or False, got {flag!r}")
    _check_arguments(scene, end_time, impact_threshold)
    solver_settings_for(accuracy)
    settings = PointSettings(float(end_time), accuracy, check_metric_names(stop_when_final), float(impact_threshold))
    grid = make_grid(scene, params, max_points=None if large else MAX_POINTS)
    warn_unit_slips(scene, grid=dict(zip(grid.keys, grid.values)))  # to the caller of run_sweep
    if batch_size is not None and (isinstance(batch_size, bool) or not isinstance(batch_size, int) or batch_size < 1):
        raise SceneError("batch_size", f"must be a whole number >= 1, got {batch_size!r}")
    _backends.check_backend(workers, scheduler, worker_timeout)
    if not table and out is None:
        raise SceneError("table", "table=False keeps the table in its file only: give out= as well")
    params_columns, metrics = list(grid.keys), metric_columns(scene)
    kinds = param_kinds(params_columns, grid.cells)
    say = _announcer(announce, progress)
    with contextlib.ExitStack() as held:
        if out is not None:
            _check_cells(grid)
            file = SweepFile(out, params_columns, metrics, kinds=kinds)
            held.enter_context(SweepLock(file.path))   # one sweep per file: another one is refused here
            file.clean_temporaries()                    # what a killed run's rewrite left
            recorded = _settings_record(scene, settings)
            file.check_settings(recorded)
            sink: _Sink = _FileSink(file, grid)
            for unreadable in sink.unreadable:
                _note(say, unreadable.text())
        else:
            sink = _MemorySink(grid, metrics, kinds)
        pending = grid.size - sink.done.count
        if not pending:
            backend = _backends.SerialBackend()
        elif scheduler is not None:
            backend = _backends.make_backend(None, scheduler, worker_timeout)
        else:   # a pool of no more workers than tasks (of one, for one task: a crash is then the pool's, not ours)
            requested = _backends.check_workers(workers)
            tasks = math.ceil(pending / (batch_size or _backends.batch_size(pending, requested)))
            backend = (_backends.SerialBackend() if requested == 1 else
                       _backends.ProcessBackend(min(requested, tasks)))
        if out is not None:
            file.write_settings(recorded)
        with backend:
            size = batch_size or _backends.batch_size(pending, backend.workers)
            bar = None
            try:
                probed = probe_indices(sink.done, grid, min(PROBE_POINTS, math.ceil(pending / 10)))
                seconds = _probe(backend, scene, settings, grid, probed, sink)
                if say is not None:
                    say(announcement(grid, sink.resumed, pending, backend.workers, seconds, len(probed),
                                     where=None if out is None else str(out)))
                bar = _progress_bar(progress, grid.size, sink.resumed)
                bar(len(probed))
                missing = (index for index in sink.done.missing(grid.size) if index not in probed)
                for batch in run_points(backend, _tasks(scene, settings, grid, missing, size)):
                    sink.add(batch)
                    bar(len(batch))
            except ClusterError as exc:   # the rows so far are kept: say how many, and where
                sink.abandon()
                raise _stopped(exc, sink.resumed + sink.run, grid.size, out) from None
            except BaseException:
                sink.abandon()
                raise
            finally:
                if bar is not None:
                    bar.close()
        return sink.result(table)


def run_points(backend, tasks):
    """``backend.run`` of :func:`~mbs_models.studies.point.evaluate_batch` over ``tasks``, a point whose worker
    dies a failed row (:func:`~mbs_models.studies.point.split_batch`, :func:`~.point.lost_batch`)."""
    from .point import evaluate_batch, lost_batch, split_batch

    return backend.run(evaluate_batch, tasks, split=split_batch, lost=lost_batch)


def _check_cells(grid) -> None:
    """SceneError if a parameter's table cell holds a line break or a NUL (a file's rows are read back line by
    line, and a line with a NUL is no row)."""
    for key, cells in zip(grid.keys, grid.cells):
        for cell in cells:
            if isinstance(cell, str) and any(c in cell for c in "\n\r\0"):
                raise SceneError(key, f"{cell!r} holds a line break or a NUL, which a cell of the table's file "
                                      "cannot hold")


def _note(say, text: str) -> None:
    """A line about the table (rows dropped): where the announcement goes, else a warning."""
    if say is not None:
        say(text)
    else:
        from .table_rows import UnreadableRowsWarning

        warnings.warn(text, UnreadableRowsWarning, stacklevel=3)


def _stopped(error: ClusterError, rows: int, points: int, out) -> ClusterError:
    if out is None:
        kept = "its rows are lost (no out= file to keep them)"
    else:
        kept = f"the {rows:,} rows are in {out}" if rows else f"no row is in {out}"
        kept += ": run the same sweep again to resume"
    return ClusterError(f"{error} after {rows:,} of {points:,} points; {kept}")


def _settings_record(scene: Scene, settings) -> dict:
    """What every row of a sweep's file is computed with: the scene (its TOML text) and the point settings."""
    from ..scene.io import scene_to_toml

    accuracy = settings.accuracy if isinstance(settings.accuracy, str) else repr(settings.accuracy)
    return {"scene": scene_to_toml(scene), "end_time": settings.end_time, "accuracy": accuracy,
            "stop_when_final": list(settings.stop_when_final), "impact_threshold": settings.impact_threshold}


# ================================================================================================ the points
def _tasks(scene: Scene, settings, grid, missing: Iterator[int], size: int) -> Iterator[tuple]:
    """The backend's tasks ``(scene, settings, [(index, point), ...])``: ``size`` points of ``missing`` each,
    made as the backend asks for them."""
    batch = []
    for index in missing:
        batch.append((index, grid.point(index)))
        if len(batch) == size:
            yield scene, settings, batch
            batch = []
    if batch:
        yield scene, settings, batch


def probe_indices(done, grid, count: int) -> list[int]:
    """``count`` points of ``grid`` not in ``done``, spread over every key at once: the j-th takes the value at
    ``(j + 1/2) / count`` of each key's range (a diagonal of the grid: evenly spaced indices would hit the
    same value of the last key every time), or the first missing point after it."""
    picks: list[int] = []
    for j in range(count):
        start = sum(((2 * j + 1) * n // (2 * count)) * stride for n, stride in zip(grid.shape, grid.strides))
        index = next(done.missing(grid.size, start=start), None)
        if index is None:
            index = next(done.missing(grid.size), None)
        if index is not None and index not in picks:
            picks.append(index)
    return picks


def _probe(backend, scene: Scene, settings, grid, indices: Sequence[int], sink) -> float | None:
    """Run the points ``indices`` (one per task, together) into ``sink``; the mean wall time (s) of their
    solves, None if none solved."""
    times = []
    tasks = [(scene, settings, [(index, grid.point(index))]) for index in indices]
    for batch in run_points(backend, tasks):
        sink.add(batch)
        times += [row["wall_time"] for _, row in batch if row["status"] == "ok"]
    return sum(times) / len(times) if times else None


# ================================================================================================ the line
def duration_text(seconds: float) -> str:
    """``0.4 s``, ``12 s``, ``7 min``, ``3.1 h``, ``2.3 days``, ``4.0 years``."""
    if seconds < 10:
        return f"{seconds:.1f} s"
    if seconds < 90:
        return f"{seconds:.0f} s"
    if seconds < 90 * 60:
        return f"{seconds / 60:.0f} min"
    if seconds < 48 * 3600:
        return f"{seconds / 3600:.1f} h"
    if seconds < 365 * 86400:
        return f"{seconds / 86400:.1f} days"
    return f"{seconds / (365.25 * 86400):.1f} years"


def _per_point_text(seconds: float) -> str:
    """A point's time to two significant digits: ``4.2 ms``, ``12 ms``, ``1.5 s``."""
    value, unit = (seconds * 1e3, "ms") if seconds < 1 else (seconds, "s")
    digits = max(0, 1 - math.floor(math.log10(value))) if value > 0 else 1
    return f"{value:.{digits}f} {unit}"


def announcement(grid, resumed: int, pending: int, workers: int, seconds: float | None, probed: int,
                 where: str | None = None) -> str:
    """The line a sweep starts with: how many points (the grid's shape), how many the file already holds,
    and about how long the others take -- ``seconds`` (the mean solve of the ``probed`` points, measured) x
    ``pending`` / ``workers``, labelled an estimate; or why there is none."""
    from .grid import shape_text

    count = f"{grid.size:,} point{'s' if grid.size != 1 else ''} ({shape_text(grid.shape)})"
    held = f", {resumed:,} already in {where}" if resumed else ""
    if pending == 0:
        return f"sweep: {count}{held}: nothing to run"
    workers_text = f"{workers} worker{'s' if workers != 1 else ''}"
    others = f" for the {pending:,} to run" if resumed else ""
    sample = "one point's solve" if probed == 1 else f"the mean solve of {probed} points"
    if seconds is None:
        return (f"sweep: {count}{held}; {pending:,} to run on {workers_text}; no time estimate: "
                f"{'the point' if probed == 1 else f'all {probed} points'} tried failed")
    total = seconds * pending / workers
    return (f"sweep: {count}{held}, ~{_per_point_text(seconds)} per point on {workers_text}: about "
            f"{duration_text(total)}{others} (an estimate from {sample})")


def _announcer(announce, progress) -> Callable[[str], None] | None:
    if callable(announce):
        return announce
    if announce is False or announce is not None and not announce:
        return None
    if announce is None and (progress is not True or not sys.stderr.isatty()):
        return None
    return lambda line: print(line, file=sys.stderr, flush=True)


# ================================================================================================ where rows go
class _Tally:
    """Failed rows counted, and the first :data:`SUMMARY_FAILURES` kept (parameters, status, error)."""

    def __init__(self, params: Sequence[str]):
        self.params, self.failed, self.failures = list(params), 0, []

    def add(self, chunk) -> None:
        failed = chunk[chunk["status"] != "ok"]
        self.failed += len(failed)
        room = SUMMARY_FAILURES - len(self.failures)
        if room > 0 and len(failed):
            self.failures += failed[[*self.params, "status", "error"]].head(room).to_dict("records")


class _Sink:
    """Where the rows of a sweep go: ``done`` (the points already there), ``resumed`` (how many), ``add``,
    ``abandon`` (the run stops early) and ``result``."""

    def __init__(self, grid):
        from .point_set import PointSet

        self.grid, self.done, self.resumed, self.run = grid, PointSet(), 0, 0
        self.unreadable: list = []   # per file read, its rows dropped (table_rows.Unreadable)

    def labelled(self, batch) -> list[dict]:
        rows = []
        for index, row in batch:
            row.update(zip(self.grid.keys, self.grid.label(index)))  # the values as table cells (lists as TOML)
            rows.append(row)
        self.run += len(rows)
        return rows

    def abandon(self) -> None:
        pass

    def summary(self, failed: int, out) -> dict[str, Any]:
        return {"points": self.grid.size, "resumed": self.resumed, "run": self.run, "failed": failed, "out": out,
                "unreadable": sum(u.count for u in self.unreadable)}


class _MemorySink(_Sink):
    """No file: the rows kept by grid index, the table made at the end."""

    def __init__(self, grid, metrics, kinds):
        super().__init__(grid)
        self.metrics, self.kinds, self.rows = metrics, kinds, {}

    def add(self, batch) -> None:
        for (index, _), row in zip(batch, self.labelled(batch)):
            self.rows[index] = row

    def result(self, table: bool):
        from .sweep_table import frame

        frame_ = frame([self.rows[i] for i in sorted(self.rows)], list(self.grid.keys), self.metrics, self.kinds)
        frame_.attrs["sweep"] = self.summary(int((frame_["status"] != "ok").sum()), None)
        return frame_


class _FileSink(_Sink):
    """The table's file: read once at the start (which points it holds, whether in grid order), appended to as
    batches finish, put in grid order at the end."""

    def __init__(self, file, grid):
        super().__init__(grid)
        self.file = file
        self.tally = _Tally(grid.keys)
        self.last, self.in_order = -1, True
        self._scan()

    def index_of(self, chunk) -> np.ndarray:
        return self.grid.indices([chunk[key] for key in self.grid.keys])

    def _scan(self) -> None:
        for chunk in self.file.chunks():
            indices = self.index_of(chunk)
            outside = np.flatnonzero(indices < 0)
            if outside.size:
                label = {key: chunk[key].iloc[outside[0]] for key in self.grid.keys}
                raise SceneError("out", f"{self.file.path} holds points that are not in this sweep (e.g. "
                                        f"{label}): choose another file, or delete it")
            new = self.done.add(indices)
            self._follow(indices)
            self.tally.add(chunk[new])
        self.resumed = self.done.count
        self.unreadable = list(self.file.unreadable)
        if self.unreadable:   # the rewrite at the end leaves them out
            self.in_order = False

    def _follow(self, indices: np.ndarray) -> None:
        """Whether the file's rows, in file order, are still strictly increasing in grid index."""
        if self.in_order and len(indices):
            self.in_order = bool(indices[0] > self.last and np.all(np.diff(indices) > 0))
            self.last = int(indices[-1])

    def add(self, batch) -> None:
        rows = self.labelled(batch)
        self.file.append(rows)
        self._follow(np.array([index for index, _ in batch], dtype=np.int64))
        if self.in_order:
            self.tally.add(_status_frame(rows, self.grid.keys))

    def _finish(self) -> None:
        """The file in grid order: rewritten (a Parquet table always: its journal goes in) unless it is."""
        if self.in_order and self.file.format == "csv":
            self.file.sync()
            return
        self.tally = _Tally(self.grid.keys)
        self.file.finish(self.index_of, on_chunk=self.tally.add)
        self.in_order = True

    def abandon(self) -> None:
        """A Parquet table takes its journal's rows (readable with the others); a CSV table keeps its rows as
        they are (the next run puts them in order).  Nothing raised: the run is ending on another error (a full
        disk leaves the journal, which the next run reads)."""
        from ..errors import RecoilError

        try:
            if self.file.format == "parquet":
                self.file.finish(self.index_of)
            else:
                self.file.sync()
        except (RecoilError, OSError):
            pass

    def result(self, table: bool):
        self._finish()
        if table:
            frame_ = self.file.read()
            frame_.attrs["sweep"] = self.summary(int((frame_["status"] != "ok").sum()), str(self.file.path))
            return frame_
        return {**self.summary(self.tally.failed, str(self.file.path)), "failures": self.tally.failures}


def _status_frame(rows: list[dict], params: Sequence[str]):
    import pandas as pd

    return pd.DataFrame({column: [row[column] for row in rows] for column in [*params, "status", "error"]})


# ================================================================================================ progress
class _Bar:
    """Progress of a sweep: a tqdm bar, a callable ``progress(done, total)``, or nothing."""

    def __init__(self, bar=None, callback=None, total: int = 0, initial: int = 0):
        self.bar, self.callback, self.total, self.done = bar, callback, total, initial

    def __call__(self, count: int) -> None:
        if count <= 0:
            return
        self.done += count
        if self.bar is not None:
            self.bar.update(count)
        if self.callback is not None:
            self.callback(self.done, self.total)

    def close(self) -> None:
        if self.bar is not None:
            self.bar.close()


def _progress_bar(progress, total: int, initial: int) -> _Bar:
    if callable(progress):
        return _Bar(callback=progress, total=total, initial=initial)
    if not progress or not sys.stderr.isatty():
        return _Bar(total=total, initial=initial)
    from tqdm import tqdm

    return _Bar(tqdm(total=total, initial=initial, unit="point", desc="sweep", dynamic_ncols=True, smoothing=0.1),
                total=total, initial=initial)


__all__ = ["run_sweep", "announcement", "probe_indices", "duration_text", "SUMMARY_FAILURES", "PROBE_POINTS"]
