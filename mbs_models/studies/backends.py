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

:func:`make_backend` picks one from ``workers``/``scheduler``; :data:`BACKENDS` maps names to classes.
"""

from __future__ import annotations

import itertools
import math
import multiprocessing
import os
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

    def run(self, function: Callable, tasks: Iterable, *, in_flight: int | None = None) -> Iterator[Any]:
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

    def run(self, function: Callable, tasks: Iterable, *, in_flight: int | None = None) -> Iterator[Any]:
        limit = _check_in_flight(in_flight, self.workers)
        tasks = iter(tasks)
        first = list(itertools.islice(tasks, limit))
        if not first:
            return
        if self._pool is None:
            self._pool = local_pool(self.workers)
        pool, finished = self._pool, False
        try:
            running = {pool.submit(function, task) for task in first}
            del first
            while running:
                done, running = wait(running, return_when=FIRST_COMPLETED)
                for future in done:
                    result = future.result()
                    for task in itertools.islice(tasks, 1):
                        running.add(pool.submit(function, task))
                    yield result
            finished = True
        except BrokenProcessPool:
            raise SimulationError("a worker process died (killed, or out of memory); the points it had not "
                                  "finished are not in the table: run the same sweep again to resume") from None
        finally:
            if not finished:   # an error, an interrupt or a caller that stopped reading: no work left behind
                self._pool = None
                pool.shutdown(wait=True, cancel_futures=True)

    def close(self) -> None:
        if self._pool is not None:
            pool, self._pool = self._pool, None
            pool.shutdown(wait=True, cancel_futures=True)


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

    def run(self, function: Callable, tasks: Iterable, *, in_flight: int | None = None) -> Iterator[Any]:
        distributed = import_distributed()
        limit = _check_in_flight(in_flight, self.workers)
        tasks = iter(tasks)
        first = list(itertools.islice(tasks, limit))
        if not first:
            return
        running = {self.client.submit(function, task, pure=False) for task in first}
        del first
        finished = distributed.as_completed(list(running), loop=self.client.loop)
        try:
            for future in finished:
                running.discard(future)
                result = future.result()
                for task in itertools.islice(tasks, 1):
                    new = self.client.submit(function, task, pure=False)
                    running.add(new)
                    finished.add(new)
                yield result
        finally:
            self.client.cancel([f for f in running if not f.done()])

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
           "default_workers", "check_workers", "import_distributed", "exit_with_parent", "local_pool"]
