"""Where the points of a sweep run: in this process, in a local process pool, or on a Dask cluster.

Every backend runs a module-level ``function`` over picklable ``tasks`` and yields the results **as they
finish** (any order: the caller orders them), so that a sweep can write each row as soon as it exists.
``tasks`` may be any iterable -- a generator over a grid of 10^8 points -- and is read lazily: at most
``in_flight`` tasks (default :func:`in_flight`: four per worker) are handed out and not yet returned, the
next one taken as one finishes, so that what a run holds does not depend on how many tasks there are.

* ``serial`` (:class:`SerialBackend`): in this process, in order.
* ``processes`` (:class:`ProcessBackend`): a local pool of worker processes (default: every CPU this
  process may use); each worker builds its own models (Exudyn models cannot be pickled).  The pool is
  kept from one completed ``run`` to the next (its workers keep their models) until :meth:`close`; a run
  that ends early (an error, an interrupt, a caller that stops reading) shuts it down.
* ``dask`` (:class:`DaskBackend`): the workers of a Dask distributed cluster, given as a scheduler address
  ``tcp://HOST:PORT`` or a ``dask.distributed.Client``.  The scheduler re-runs the tasks of a worker that
  dies.  Dask is imported only here, and only then (the ``cluster`` extra: ``pip install recoil-mbs[cluster]``).

A worker process that dies (a crash in compiled code, the out-of-memory killer) reports nothing.  Given
``lost`` (and ``split``), ``run`` does not end there: the tasks the death took (every task of a broken
local pool) run again, cut into parts (``split(task)``: a sweep's batch point by point) handed out first;
a part lost a second time runs alone (a pool of one process: a death is then that part's), and a part
whose worker died alone too yields ``lost(part, reason)`` instead of its result -- so a point that kills
its worker is a failed row and every other point runs.  On Dask the scheduler already re-runs a task
whose worker died (``distributed.scheduler.allowed-failures`` times) before it reports ``KilledWorker``
-- for every task its worker held, not only the one that killed it; the task is then split, its parts
submitted again, a part killed again kept aside and, once nothing else is in flight, submitted alone, and
``lost`` if that one is killed too.  Without ``lost`` a death ends the run.
Whatever kills *every* worker (too little memory for any process) is no point's fault: after
:data:`DEATHS_IN_A_ROW` lost parts in a row, the last task that finished runs again, alone, and if it
dies too (or none has finished) the run ends with a SimulationError, those parts not yielded (``_Losses``).

:func:`make_backend` picks one from ``workers``/``scheduler``; :data:`BACKENDS` maps names to classes.
"""

from __future__ import annotations

import collections
import itertools
import math
import multiprocessing
import os
import signal
import time
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool
from typing import Any, Callable, Iterable, Iterator

from ..errors import SceneError, SimulationError


def default_workers() -> int:
    """Worker processes to use: the CPUs available to this process."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:  # pragma: no cover - not Linux
        return max(1, os.cpu_count() or 1)


def check_workers(workers: int | None) -> int:
    """``workers`` (None: :func:`default_workers`) checked to be a whole number >= 1."""
    workers = default_workers() if workers is None else workers
    if isinstance(workers, bool) or not isinstance(workers, int) or workers < 1:
        raise SceneError("workers", f"must be a whole number >= 1, got {workers!r}")
    return workers


def batch_size(points: int, workers: int, *, per_worker: int = 4, largest: int = 16) -> int:
    """Points per task: about ``per_worker`` tasks per worker (so that the pool stays balanced), at most
    ``largest`` points (so that a lost worker loses little), at least 1."""
    return max(1, min(largest, math.ceil(points / (per_worker * max(1, workers)))))


def in_flight(workers: int, per_worker: int = 4) -> int:
    """Tasks a backend hands out at once: ``per_worker`` per worker (every worker busy, one task queued behind
    each, a few spare for the Dask scheduler to balance)."""
    return per_worker * max(1, workers)


def _check_in_flight(limit: int | None, workers: int) -> int:
    limit = in_flight(workers) if limit is None else limit
    if isinstance(limit, bool) or not isinstance(limit, int) or limit < 1:
        raise SceneError("in_flight", f"must be a whole number >= 1, got {limit!r}")
    return limit


def exit_with_parent(parent: int, period: float = 1.0) -> None:
    """In a pool's worker: a daemon thread that ends this process once ``parent`` is gone (a parent killed
    with SIGKILL leaves its pool's workers waiting for tasks forever otherwise)."""
    import threading

    def watch():
        while os.getppid() == parent:
            time.sleep(period)
        os._exit(1)

    threading.Thread(target=watch, name="exit-with-parent", daemon=True).start()


def local_pool(workers: int) -> ProcessPoolExecutor:
    """A pool of ``workers`` local processes: forked where possible (they start in milliseconds with this
    process's imports), else spawned; each worker ends with its parent (:func:`exit_with_parent`)."""
    methods = multiprocessing.get_all_start_methods()
    context = multiprocessing.get_context("fork" if "fork" in methods else "spawn")
    return ProcessPoolExecutor(max_workers=workers, mp_context=context, initializer=exit_with_parent,
                               initargs=(os.getpid(),))


class SerialBackend:
    """Runs every task in this process, in order (one at a time: nothing is held ahead)."""

    name = "serial"
    workers = 1

    def run(self, function: Callable, tasks: Iterable, *, in_flight: int | None = None,
            split: Callable[[Any], list] | None = None, lost: Callable[[Any, str], Any] | None = None
            ) -> Iterator[Any]:
        """``function(task)`` of every task, in order (``split``/``lost``: for a worker's death, which cannot
        happen here: a crash ends this process)."""
        for task in tasks:
            yield function(task)

    def close(self) -> None:
        pass

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


class ProcessBackend(SerialBackend):
    """A local pool of ``workers`` processes (fork where available, else spawn), kept between runs."""

    name = "processes"

    def __init__(self, workers: int | None = None):
        self.workers = check_workers(workers)
        self._pool: ProcessPoolExecutor | None = None
        self._losses = _Losses()

    def run(self, function: Callable, tasks: Iterable, *, in_flight: int | None = None,
            split: Callable[[Any], list] | None = None, lost: Callable[[Any, str], Any] | None = None
            ) -> Iterator[Any]:
        limit = _check_in_flight(in_flight, self.workers)
        tasks = iter(tasks)
        retry: collections.deque = collections.deque()   # (part, 1): parts of tasks a death took, first out

        def take():
            if retry:
                return retry.popleft()
            return next(((task, 0) for task in itertools.islice(tasks, 1)), None)

        running: dict = {}   # future -> (task, deaths: how many pool deaths took it)
        self._losses.start(lost, lambda task: self._alone(function, task)[0])
        finished = False
        try:
            while True:
                broken = False
                while len(running) < limit and (item := take()) is not None:
                    if self._pool is None:
                        self._pool = local_pool(self.workers)
                    try:
                        running[self._pool.submit(function, item[0])] = item
                    except BrokenProcessPool:   # a worker died since the last look
                        retry.appendleft(item)
                        broken = True
                        break
                if not running and not broken:
                    break
                done = wait(running, return_when=FIRST_COMPLETED).done if running else set()
                results, dead = _collect(done, running)
                if dead or broken:   # the pool is broken: every task still running is lost with it
                    if lost is None:
                        raise BrokenProcessPool
                    more_results, more_dead = _collect(wait(list(running)).done, running)
                    results, dead = results + more_results, dead + more_dead
                    self._drop_pool()
                for task, result in results:
                    yield from self._losses.finished(task)
                    yield result
                for task, deaths in dead:
                    if deaths == 0:
                        retry.extend((part, 1) for part in (split(task) if split is not None else [task]))
                        continue
                    ran, result = self._alone(function, task)
                    if ran:
                        yield from self._losses.finished(task)
                        yield result
                    else:
                        yield from self._losses.add(task, result)
            yield from self._losses.release()
            finished = True
        except BrokenProcessPool:   # without ``lost``, a death ends the run
            raise SimulationError("a worker process died (killed, or out of memory); the points it had not "
                                  "finished are not in the table: run the same sweep again to resume") from None
        finally:
            if not finished:   # an error, an interrupt or a caller that stopped reading: no work left behind
                self._drop_pool()

    @staticmethod
    def _alone(function: Callable, task: Any) -> tuple[bool, Any]:
        """``function(task)`` in a pool of its own (one process): ``(True, result)``, or ``(False, why it
        died)`` if that process dies."""
        pool = local_pool(1)
        try:
            try:
                return True, pool.submit(function, task).result()
            except BrokenProcessPool:
                return False, death_reason(pool)
        finally:
            pool.shutdown(wait=True, cancel_futures=True)

    def _drop_pool(self) -> None:
        if self._pool is not None:
            pool, self._pool = self._pool, None
            pool.shutdown(wait=True, cancel_futures=True)

    def close(self) -> None:
        self._drop_pool()


#: Parts in a row whose worker died even alone, before the backend checks that its workers can run at all.
DEATHS_IN_A_ROW = 8


class _Losses:
    """The results ``lost(part, reason)`` of parts whose worker died even alone (:meth:`add`), held back while
    it is not known whether the parts killed their workers or something kills every worker (too little
    memory for any process, a broken installation: no point's fault).  They are yielded once a task
    finishes (:meth:`finished`) or the run ends; :data:`DEATHS_IN_A_ROW` of them in a row make the backend
    ``rerun`` (alone) the last task that finished: if it finishes again the parts were at fault and their
    results are yielded, else -- or with no task finished yet -- the run ends (SimulationError), none of
    them yielded: they run again when the sweep resumes."""

    def __init__(self):
        self.lost = self.rerun = None
        self.held: list = []
        self.canary: Any = None   # the last task that finished: it can run

    def start(self, lost: Callable[[Any, str], Any] | None, rerun: Callable[[Any], bool]) -> None:
        """A run starts (nothing held from a run that ended early)."""
        self.lost, self.rerun, self.held = lost, rerun, []

    def finished(self, task: Any) -> list:
        """A task finished: workers can run; the held results, to yield before its own."""
        self.canary = task
        return self.release()

    def add(self, task: Any, reason: str) -> list:
        """A part's worker died even alone: the results to yield now (none while held)."""
        self.held.append(self.lost(task, reason))
        if len(self.held) < DEATHS_IN_A_ROW:
            return []
        if self.canary is not None and self.rerun(self.canary):
            return self.release()
        count, self.held = len(self.held), []
        test = "a point that ran before died too" if self.canary is not None else "no point has run yet"
        raise SimulationError(f"worker processes died on {count} points in a row, each run alone (the last: "
                              f"{reason}), and {test}: something kills every worker (too little memory?); the "
                              "rows written are kept: run the same sweep again to resume")

    def release(self) -> list:
        held, self.held = self.held, []
        return held


def _collect(done, running: dict) -> tuple[list, list]:
    """``(task, result)`` of the finished futures ``done`` (removed from ``running``), and the ``(task,
    deaths)`` of those a broken pool took; any other exception is raised."""
    results, dead = [], []
    for future in done:
        task, deaths = running.pop(future)
        if isinstance(future.exception(), BrokenProcessPool):
            dead.append((task, deaths))
        else:
            results.append((task, future.result()))
    return results, dead


def death_reason(pool: ProcessPoolExecutor) -> str:
    """Why the worker of a one-process pool died, for the ``error`` of its point: the signal or exit code."""
    codes = []
    for process in list((getattr(pool, "_processes", None) or {}).values()):
        try:
            process.join(timeout=5.0)   # the pool reports its death before it has reaped the process
        except (AssertionError, OSError, ValueError):
            pass
        if process.exitcode:
            codes.append(process.exitcode)
    how = ""
    if codes and codes[0] < 0:
        try:
            name = signal.Signals(-codes[0]).name
        except ValueError:
            name = f"signal {-codes[0]}"
        cause = {"SIGKILL": " (the out-of-memory killer? a user?)", "SIGSEGV": " (a crash in compiled code)",
                 "SIGBUS": " (a crash in compiled code)", "SIGABRT": " (an abort in compiled code)"}.get(name, "")
        how = f" of {name}{cause}"
    elif codes:
        how = f" (exit code {codes[0]})"
    return f"its worker process died{how} each of the 3 times it ran it (in its batch, again, then alone)"


class DaskBackend(SerialBackend):
    """The workers of a Dask distributed cluster: ``scheduler`` is ``"tcp://HOST:PORT"`` (a client is opened
    and closed here) or a ``dask.distributed.Client`` (used as it is, left open)."""

    name = "dask"

    def __init__(self, scheduler: Any, *, timeout: float = 10.0):
        distributed = import_distributed()
        if isinstance(scheduler, distributed.Client):
            self.client, self._own = scheduler, False
        elif isinstance(scheduler, str) and scheduler.strip():
            try:
                self.client = distributed.Client(scheduler.strip(), timeout=timeout, set_as_default=False)
            except (OSError, TimeoutError, ValueError) as exc:
                reason = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
                raise SceneError("scheduler", f"cannot connect to the Dask scheduler at {scheduler!r}: "
                                              f"{reason}") from None
            self._own = True
        else:
            raise SceneError("scheduler", f"must be an address tcp://HOST:PORT or a dask.distributed.Client, "
                                          f"got {scheduler!r}")
        self.workers = max(1, len(self.client.scheduler_info().get("workers", {})))
        self._losses = _Losses()

    def run(self, function: Callable, tasks: Iterable, *, in_flight: int | None = None,
            split: Callable[[Any], list] | None = None, lost: Callable[[Any, str], Any] | None = None
            ) -> Iterator[Any]:
        distributed = import_distributed()
        limit = _check_in_flight(in_flight, self.workers)
        tasks = iter(tasks)
        first = list(itertools.islice(tasks, limit))
        if not first:
            return
        running = {self.client.submit(function, task, pure=False): (task, 0) for task in first}   # -> (task, deaths)
        del first
        finished = distributed.as_completed(list(running), loop=self.client.loop)

        def submit(task, deaths):
            future = self.client.submit(function, task, pure=False)
            running[future] = (task, deaths)
            finished.add(future)

        self._losses.start(lost, lambda task: self._alone(function, task)[0])
        suspects: list = []   # parts killed twice: each runs alone at the end

        try:
            for future in finished:
                task, deaths = running.pop(future)
                for more in itertools.islice(tasks, 1):
                    submit(more, 0)
                try:
                    result = future.result()
                except distributed.KilledWorker:   # it ran on allowed-failures + 1 workers, all died
                    if lost is None:
                        raise
                    if deaths == 0:
                        for part in (split(task) if split is not None else [task]):
                            submit(part, 1)
                    else:   # run alone once nothing else is in flight (a dying worker strikes all it holds)
                        suspects.append(task)
                    continue
                yield from self._losses.finished(task)
                yield result
            for task in suspects:
                ran, result = self._alone(function, task)
                if ran:
                    yield from self._losses.finished(task)
                    yield result
                else:
                    yield from self._losses.add(task, result)
            yield from self._losses.release()
        finally:
            self.client.cancel([f for f in running if not f.done()])

    def _alone(self, function: Callable, task: Any) -> tuple[bool, Any]:
        """``function(task)`` submitted again and waited for: ``(True, result)``, or ``(False, why)`` if the
        scheduler reports its workers killed again."""
        distributed = import_distributed()
        try:
            return True, self.client.submit(function, task, pure=False).result()
        except distributed.KilledWorker as exc:
            return False, f"the Dask workers running it died each time the scheduler tried it ({type(exc).__name__})"

    def close(self) -> None:
        if self._own:
            self.client.close()


def import_distributed():
    """``dask.distributed``, or a SceneError saying how to install it (the ``cluster`` extra)."""
    try:
        import dask.distributed as distributed
    except ImportError as exc:
        raise SceneError("scheduler", f"a Dask cluster needs dask[distributed], which is not installed ({exc}): "
                                      "pip install 'recoil-mbs[cluster]'") from None
    return distributed


#: Backend classes by name.
BACKENDS = {"serial": SerialBackend, "processes": ProcessBackend, "dask": DaskBackend}


def make_backend(workers: int | None = None, scheduler: Any = None):
    """The backend for these arguments: ``scheduler`` (an address or a Client) -> Dask; else ``workers == 1``
    -> serial; else a local process pool of ``workers`` (default: every CPU).  Both given is an error.
    Use it as a context manager (``with make_backend(...) as backend``): a pool is kept until it closes."""
    if scheduler is not None:
        if workers is not None:
            raise SceneError("workers", "give either workers (a local pool) or a scheduler (a Dask cluster), "
                                        "not both")
        return DaskBackend(scheduler)
    workers = check_workers(workers)
    return SerialBackend() if workers == 1 else ProcessBackend(workers)


__all__ = ["BACKENDS", "SerialBackend", "ProcessBackend", "DaskBackend", "make_backend", "batch_size", "in_flight",
           "default_workers", "check_workers", "import_distributed", "exit_with_parent", "local_pool", "death_reason",
           "DEATHS_IN_A_ROW"]
