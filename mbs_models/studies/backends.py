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
  dies; the cluster's own faults (an address that does not answer, a lost scheduler, no worker for
  ``worker_timeout``) stop the run with a :class:`~mbs_models.errors.ClusterError`.  Dask is imported only
  here, and only then (the ``cluster`` extra: ``pip install recoil-mbs[cluster]``).

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
import contextlib
import itertools
import math
import multiprocessing
import os
import queue
import re
import signal
import socket
import sys
import time
from concurrent.futures import FIRST_COMPLETED, CancelledError, Future, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool
from typing import Any, Callable, Iterable, Iterator

from ..errors import ClusterError, SceneError, SimulationError


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

    def _run_alone(self, function: Callable, task: Any) -> Iterator:
        """Run a task that was running when a worker died on its own (``_alone``): its result, or its points'
        lost rows once the task killed its worker again (``_losses``, kept by the backends with workers)."""
        ran, result = self._alone(function, task)
        if ran:
            yield from self._losses.finished(task)
            yield result
        else:
            yield from self._losses.add(task, result)


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
                    yield from self._run_alone(function, task)
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
            future = pool.submit(function, task)
            processes = list((getattr(pool, "_processes", None) or {}).values())  # before a death clears them
            try:
                return True, future.result()
            except BrokenProcessPool:
                return False, death_reason(processes)
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


def death_reason(processes) -> str:
    """Why the worker of a one-process pool died, for the ``error`` of its point: the signal or exit code.
    ``processes``: the pool's worker processes, taken when the task was submitted (once the pool has noticed
    the death its own list may be gone: a loaded machine then lost the signal)."""
    codes = []
    for process in processes:
        try:
            process.join(timeout=5.0)   # the pool reports its death before it has reaped the process
        except (AssertionError, OSError, ValueError):
            pass
        # the pool's own thread may be reaping it at the same time: whichever waitpid loses sees no status until
        # the winner has stored it on the shared Popen (a few microseconds; seconds on a loaded machine)
        deadline = time.monotonic() + 5.0
        while process.exitcode is None and time.monotonic() < deadline:
            time.sleep(0.01)
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


#: Seconds to reach a Dask scheduler (its port answering, then Dask's handshake) before giving up.
CONNECT_TIMEOUT = 10.0
#: Seconds a Dask run goes on with no worker in the cluster before it stops (``worker_timeout``'s default).
WORKER_TIMEOUT = 60.0
#: Seconds between two looks at the cluster (its scheduler, its workers) while no task ends.
CLUSTER_POLL = 1.0
#: ``tcp://HOST:PORT`` or ``tls://HOST:PORT``: HOST a name, an IPv4 address or a bracketed IPv6 address.
_ADDRESS = re.compile(r"(?P<scheme>tcp|tls)://(?P<host>\[[0-9A-Fa-f:.]+\]|[A-Za-z0-9._-]+):(?P<port>[0-9]{1,5})")


class DaskBackend(SerialBackend):
    """The workers of a Dask distributed cluster: ``scheduler`` is an address (:func:`check_scheduler`; a
    client is opened here and closed by :meth:`close`, distributed's own log lines silenced meanwhile) or a
    ``dask.distributed.Client`` (used as it is, left open).

    The cluster's faults stop a run with a :class:`~mbs_models.errors.ClusterError`, never a hang or a
    point's error: an address that does not answer within ``connect_timeout`` (s; default
    :data:`CONNECT_TIMEOUT`), a scheduler lost during a run, no worker for ``worker_timeout`` (s; default
    :data:`WORKER_TIMEOUT`, ``math.inf`` to wait for ever; ``say`` is given a line when the wait starts and
    one when it ends: default stderr), a task whose workers kept dying (Dask's ``KilledWorker``).  A worker
    that dies is not a fault: the scheduler runs its tasks elsewhere."""

    name = "dask"

    def __init__(self, scheduler: Any, *, connect_timeout: float = CONNECT_TIMEOUT, worker_timeout: float | None = None,
                 say: Callable[[str], None] | None = None):
        scheduler = check_scheduler(scheduler)
        self.worker_timeout = check_worker_timeout(worker_timeout)
        self.say = _to_stderr if say is None else say
        distributed = import_distributed()
        self._restore_logging: Callable[[], None] | None = None
        if isinstance(scheduler, distributed.Client):
            self.client, self._own = scheduler, False
            self.address = str(getattr(scheduler.scheduler, "address", scheduler))
        else:   # distributed's log lines silenced while this client is open (a CLI's stderr: one line a fault)
            self._restore_logging = silence_distributed()
            try:
                self.client, self._own = connect(scheduler, connect_timeout), True
            except BaseException:
                self._restore_logging()
                raise
            self.address = scheduler
        self._without_workers: float | None = None   # time.monotonic() since when the cluster has had none
        self._losses = _Losses()
        try:
            self.workers = max(1, self._count_workers())
        except BaseException:
            self.close()
            raise

    def run(self, function: Callable, tasks: Iterable, *, in_flight: int | None = None,
            split: Callable[[Any], list] | None = None, lost: Callable[[Any, str], Any] | None = None
            ) -> Iterator[Any]:
        distributed = import_distributed()
        limit = _check_in_flight(in_flight, self.workers)
        tasks = iter(tasks)
        first = list(itertools.islice(tasks, limit))
        if not first:
            return
        finished: queue.SimpleQueue = queue.SimpleQueue()   # futures as they end (done, failed or cancelled)
        running: dict = {}   # future -> (task, deaths)
        self._without_workers = None

        def submit(task, deaths) -> None:
            future = self.client.submit(function, task, pure=False)
            running[future] = (task, deaths)
            future.add_done_callback(finished.put)

        self._losses.start(lost, lambda task: self._alone(function, task)[0])
        suspects: list = []   # parts killed twice: each runs alone at the end
        try:
            for task in first:
                submit(task, 0)
            del first
            while running:
                future = self._next(finished)
                task, deaths = running.pop(future)
                for more in itertools.islice(tasks, 1):
                    submit(more, 0)
                try:
                    result = self._result(future)
                except distributed.KilledWorker as exc:   # it ran on allowed-failures + 1 workers, all died
                    if lost is None:
                        raise self._killed(exc) from None
                    if deaths == 0:
                        for part in (split(task) if split is not None else [task]):
                            submit(part, 1)
                    else:   # run alone once nothing else is in flight (a dying worker strikes all it holds)
                        suspects.append(task)
                    continue
                yield from self._losses.finished(task)
                yield result
            for task in suspects:
                yield from self._run_alone(function, task)
            yield from self._losses.release()
        except ClusterError:
            running.clear()   # nothing to cancel: the scheduler may be gone (a request would wait for it)
            raise
        finally:
            if running and self.client.status == "running":   # a lost scheduler holds nothing to cancel
                with contextlib.suppress(Exception):
                    self.client.cancel(list(running))

    def _next(self, finished: queue.SimpleQueue):
        """The next future to end; while none does, the cluster is looked at every :data:`CLUSTER_POLL` s."""
        while True:
            try:
                future = finished.get(timeout=CLUSTER_POLL)
            except queue.Empty:
                self._check_cluster()
                continue
            self._workers_back()
            return future

    def _result(self, future) -> Any:
        """The future's result; its task's own error (and Dask's ``KilledWorker``: the caller decides) as it is;
        a fault of the cluster as a ClusterError.

        Fetching a result waits for ever if the worker holding it dies meanwhile (Dask computes it again once
        it has a worker), so it is fetched by a thread of its own, looked at every :data:`CLUSTER_POLL` s; a
        fetch left waiting by a ClusterError ends when the client closes (cutting Dask's fetch short instead
        leaves its tasks to log errors)."""
        if future.cancelled():
            raise self._lost()
        fetch = _in_thread(future.result)
        while True:
            try:
                return fetch.result(timeout=CLUSTER_POLL)
            except TimeoutError:
                if fetch.done():   # the task's own
                    raise
                self._check_cluster()
            except OSError:   # the connection to the scheduler broke while fetching (before the client knows)
                if future.status == "error":   # the task's own
                    raise
                raise self._scheduler_lost() from None
            except CancelledError:
                if future.cancelled():
                    raise self._lost() from None
                raise

    def _killed(self, exc) -> ClusterError:
        """The error for a task whose workers kept dying (Dask's ``KilledWorker``) when no ``lost`` is given."""
        return ClusterError(f"Dask workers kept dying while running one task (killed, out of memory?), and the "
                            f"scheduler {self.address} gave it up: {_first_line(exc)}")

    def _lost(self) -> ClusterError:
        """The error for a cancelled task: the client cancels them all when it loses its scheduler."""
        if self.client.status != "running":
            return self._scheduler_lost()
        return ClusterError(f"a task was cancelled on the Dask cluster of {self.address} (by another client?)")

    def _scheduler_lost(self) -> ClusterError:
        return ClusterError(f"the Dask scheduler {self.address} was lost")

    def _count_workers(self) -> int:
        return len(self.client.nthreads())   # one request to the scheduler: worker address -> threads

    def _check_cluster(self) -> None:
        """Raise a ClusterError if the scheduler is lost or no worker has been there for ``worker_timeout``;
        say when the wait for a worker starts and ends."""
        if self.client.status != "running":
            raise self._scheduler_lost()
        try:
            count = self._count_workers()
        except (OSError, CancelledError):
            raise self._scheduler_lost() from None
        now = time.monotonic()
        if count:
            self._workers_back()
            return
        if self._without_workers is None:
            self._without_workers = now
            until = ("" if math.isinf(self.worker_timeout) else
                     f"; giving up after {self.worker_timeout:g} s without one (the worker timeout)")
            self.say(f"dask: waiting for a worker: the scheduler {self.address} has none{until}")
        elif now - self._without_workers >= self.worker_timeout:
            raise ClusterError(f"no Dask worker has been available at {self.address} for {self.worker_timeout:g} s "
                               "(the worker timeout)")

    def _workers_back(self) -> None:
        if self._without_workers is not None:
            self._without_workers = None
            self.say(f"dask: the scheduler {self.address} has workers again; going on")

    def _alone(self, function: Callable, task: Any) -> tuple[bool, Any]:
        """``function(task)`` submitted again and waited for: ``(True, result)``, or ``(False, why)`` if the
        scheduler reports its workers killed again."""
        distributed = import_distributed()
        finished: queue.SimpleQueue = queue.SimpleQueue()
        future = self.client.submit(function, task, pure=False)
        future.add_done_callback(finished.put)
        try:
            return True, self._result(self._next(finished))
        except distributed.KilledWorker as exc:
            return False, f"the Dask workers running it died each time the scheduler tried it ({type(exc).__name__})"

    def close(self) -> None:
        if self._own:
            self._own = False
            close_quietly(self.client)
        if self._restore_logging is not None:
            restore, self._restore_logging = self._restore_logging, None
            restore()


def check_scheduler(scheduler: Any):
    """``scheduler`` checked to be a Dask scheduler address -- ``tcp://HOST:PORT`` or ``tls://HOST:PORT``
    (PORT 1-65535), or ``inproc://...`` (a scheduler in this process) -- or a ``dask.distributed.Client``;
    returns the address (stripped) or the client.  Nothing is contacted."""
    if isinstance(scheduler, str):
        address = scheduler.strip()
        match = _ADDRESS.fullmatch(address)
        if match and 1 <= int(match["port"]) <= 65535 or address.startswith("inproc://") and len(address) > 9:
            return address
    elif scheduler is not None and not isinstance(scheduler, (bool, int, float)):
        if isinstance(scheduler, import_distributed().Client):
            return scheduler
    raise SceneError("scheduler", f"must be a Dask scheduler address tcp://HOST:PORT (or tls://HOST:PORT; PORT "
                                  f"1-65535) or a dask.distributed.Client, got {scheduler!r}")


def check_worker_timeout(seconds: float | None) -> float:
    """``seconds`` (None: :data:`WORKER_TIMEOUT`) checked to be a number of seconds > 0 (``math.inf``: no
    limit)."""
    seconds = WORKER_TIMEOUT if seconds is None else seconds
    if isinstance(seconds, bool) or not isinstance(seconds, (int, float)) or not seconds > 0:
        raise SceneError("worker_timeout", f"must be a number of seconds > 0 (inf: wait for ever), got {seconds!r}")
    return float(seconds)


def connect(address: str, timeout: float = CONNECT_TIMEOUT):
    """A ``dask.distributed.Client`` of the scheduler at ``address``, or a ClusterError: at once if nothing
    listens there (Dask itself retries a refused connection until its timeout), within ``timeout`` (s) if
    nothing answers or what answers is not a Dask scheduler (Dask's own client can wait far longer then)."""
    distributed = import_distributed()
    match = _ADDRESS.fullmatch(address)
    if match:
        host, port = match["host"].strip("[]"), int(match["port"])
        try:
            socket.create_connection((host, port), timeout=timeout).close()
        except OSError as exc:
            reasons = {ConnectionRefusedError: "connection refused (nothing listens on that port)",
                       socket.gaierror: f"unknown host {host!r}", TimeoutError: f"no answer within {timeout:g} s"}
            reason = next((text for kind, text in reasons.items() if isinstance(exc, kind)), exc.strerror or str(exc))
            raise ClusterError(f"cannot connect to the Dask scheduler at {address}: {reason}") from None
        kind = _identity_type(address, timeout)
        if kind != "Scheduler":
            raise ClusterError(f"cannot connect to the Dask scheduler at {address}: {kind}")

    class Client(distributed.Client):
        """Closed at once if it cannot start (else its __del__ prints a traceback and waits 20 s)."""

        def start(self, **kwargs):
            try:
                super().start(**kwargs)
            except BaseException:
                close_quietly(self, timeout)
                raise

    try:
        with _quiet_distributed():
            return Client(address, timeout=timeout, set_as_default=False)
    except Exception as exc:
        raise ClusterError(f"cannot connect to the Dask scheduler at {address} within {timeout:g} s: "
                           f"{_first_line(exc)}") from None


def _identity_type(address: str, timeout: float) -> str:
    """What answers at ``address`` says it is (``"Scheduler"``), or why nothing did, within ``timeout`` (s):
    Dask's handshake and an ``identity`` request, on an event loop of their own (in a thread: the caller's
    may be running one)."""
    import asyncio
    import threading

    from distributed.comm import connect as dask_connect
    from distributed.security import Security

    async def identity():
        comm = await dask_connect(address, timeout=timeout, **Security().get_connection_args("client"))
        try:
            await comm.write({"op": "identity", "reply": True})
            return await comm.read()
        finally:
            comm.abort()

    answer: list[str] = [f"no Dask scheduler answered within {timeout:g} s"]

    def ask() -> None:
        try:
            reply = asyncio.run(asyncio.wait_for(identity(), timeout))
        except (asyncio.TimeoutError, TimeoutError):
            return
        except Exception as exc:
            answer[0] = _first_line(exc)
            return
        kind = reply.get("type") if isinstance(reply, dict) else None
        answer[0] = (kind if kind == "Scheduler" else
                     f"what answers is not a Dask scheduler (it is a {kind or 'stranger'})")

    with _quiet_distributed():
        thread = threading.Thread(target=ask, name="dask-identity", daemon=True)
        thread.start()
        thread.join(timeout + 5.0)
    return answer[0]


def _in_thread(function: Callable[[], Any]) -> Future:
    """``function()`` called in a daemon thread of its own; its result (or error) as a Future."""
    import threading

    result: Future = Future()

    def call() -> None:
        try:
            result.set_result(function())
        except BaseException as exc:
            result.set_exception(exc)

    threading.Thread(target=call, name="dask-result", daemon=True).start()
    return result


def _first_line(exc: BaseException) -> str:
    return str(exc).splitlines()[0] if str(exc).strip() else type(exc).__name__


def close_quietly(client, timeout: float = CONNECT_TIMEOUT) -> None:
    """Close ``client`` without distributed's log lines or errors (a lost scheduler's client gives up
    reconnecting, and says so, as it closes), within about ``timeout`` (s)."""
    with _quiet_distributed(), contextlib.suppress(Exception):
        client.close(timeout=timeout)


def silence_distributed() -> Callable[[], None]:
    """distributed's loggers silenced (the faults they would log are said here, once each, in one line);
    returns the function that restores their levels."""
    import logging

    names = ["distributed",
             *(name for name in list(logging.root.manager.loggerDict) if name.startswith("distributed."))]
    loggers = [logging.getLogger(name) for name in names]
    levels = [logger.level for logger in loggers]
    for logger in loggers:
        logger.setLevel(logging.CRITICAL + 1)

    def restore() -> None:
        for logger, level in zip(loggers, levels):
            logger.setLevel(level)

    return restore


@contextlib.contextmanager
def _quiet_distributed():
    restore = silence_distributed()
    try:
        yield
    finally:
        restore()


def _to_stderr(line: str) -> None:
    print(line, file=sys.stderr, flush=True)


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


def check_backend(workers: int | None = None, scheduler: Any = None, worker_timeout: float | None = None) -> None:
    """The arguments of :func:`make_backend` checked (SceneError naming the argument), nothing contacted."""
    if scheduler is None:
        check_workers(workers)
        if worker_timeout is not None:
            raise SceneError("worker_timeout", "is the wait for the workers of a Dask cluster: give a scheduler too")
        return
    if workers is not None:
        raise SceneError("workers", "give either workers (a local pool) or a scheduler (a Dask cluster), not both")
    check_scheduler(scheduler)
    check_worker_timeout(worker_timeout)


def make_backend(workers: int | None = None, scheduler: Any = None, worker_timeout: float | None = None):
    """The backend for these arguments: ``scheduler`` (an address or a Client) -> Dask (``worker_timeout``:
    :class:`DaskBackend`); else ``workers == 1`` -> serial; else a local process pool of ``workers``
    (default: every CPU).  Both given is an error.  Use it as a context manager (``with make_backend(...) as
    backend``): a pool is kept, a client open, until it closes."""
    check_backend(workers, scheduler, worker_timeout)
    if scheduler is not None:
        return DaskBackend(scheduler, worker_timeout=worker_timeout)
    workers = check_workers(workers)
    return SerialBackend() if workers == 1 else ProcessBackend(workers)


__all__ = ["BACKENDS", "SerialBackend", "ProcessBackend", "DaskBackend", "make_backend", "check_backend", "batch_size",
           "in_flight", "default_workers", "check_workers", "check_scheduler", "check_worker_timeout", "connect",
           "close_quietly", "silence_distributed", "import_distributed", "exit_with_parent", "local_pool",
           "death_reason", "CONNECT_TIMEOUT", "WORKER_TIMEOUT", "CLUSTER_POLL", "DEATHS_IN_A_ROW"]
