"""A Dask cluster of separate processes, for the tests that kill parts of it: one ``dask scheduler`` and
``workers`` ``dask worker --no-nanny`` processes (one Dask worker each, so that a killed worker stays dead),
each started and waited for on a condition (never a fixed sleep), killed with SIGKILL."""

from __future__ import annotations

import contextlib
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

#: Seconds to wait for a process of the cluster to start (generous: the tests run on loaded 2-core machines).
START_TIMEOUT = 180.0


def environment() -> dict:
    """This process's environment with its import path, for the subprocesses (they import mbs_models)."""
    return {**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)}


def wait_until(condition, timeout: float, what: str, every: float = 0.02) -> None:
    """Return once ``condition()`` is true; fail the test saying ``what`` was awaited after ``timeout`` s."""
    deadline = time.monotonic() + timeout
    while not condition():
        if time.monotonic() > deadline:
            raise AssertionError(f"waited {timeout:g} s for {what}")
        time.sleep(every)


def free_port() -> int:
    """A local TCP port nobody listens on (bound, then released)."""
    import socket

    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return probe.getsockname()[1]


class DaskProcesses:
    """The scheduler's ``address``; :meth:`kill_scheduler`, :meth:`kill_workers`; :meth:`close` kills what is
    left.  The processes' output goes to ``scheduler.log`` and ``worker-N.log`` in ``directory``."""

    def __init__(self, directory: Path, workers: int = 2):
        self.directory = Path(directory)
        self.scheduler: subprocess.Popen | None = None
        self.workers: list[subprocess.Popen] = []
        self._logs: list = []
        try:
            self._start(workers)
        except BaseException:
            self.close()
            raise

    def _spawn(self, module: str, arguments: list[str], log: str) -> subprocess.Popen:
        handle = open(self.directory / log, "w")
        self._logs.append(handle)
        return subprocess.Popen([sys.executable, "-m", module, *arguments], stdout=handle, stderr=subprocess.STDOUT,
                                env=environment(), start_new_session=True)

    def _start(self, workers: int) -> None:
        from dask.distributed import Client

        file = self.directory / "scheduler.json"
        self.scheduler = self._spawn("distributed.cli.dask_scheduler",
                                     ["--host", "127.0.0.1", "--port", "0", "--no-dashboard", "--scheduler-file",
                                      str(file)], "scheduler.log")

        def written() -> bool:
            assert self.scheduler.poll() is None, (self.directory / "scheduler.log").read_text()
            try:
                return bool(json.loads(file.read_text()).get("address"))
            except (OSError, ValueError):
                return False

        wait_until(written, START_TIMEOUT, "the Dask scheduler to start")
        self.address = json.loads(file.read_text())["address"]
        self.workers = [self._spawn("distributed.cli.dask_worker",
                                    [self.address, "--no-nanny", "--nthreads", "1", "--no-dashboard", "--host",
                                     "127.0.0.1"], f"worker-{n}.log") for n in range(workers)]
        with Client(self.address, timeout=START_TIMEOUT, set_as_default=False) as client:
            client.wait_for_workers(workers, timeout=START_TIMEOUT)

    def kill_scheduler(self) -> None:
        _kill(self.scheduler)

    def kill_workers(self) -> None:
        for worker in self.workers:
            _kill(worker)

    def close(self) -> None:
        for process in [*self.workers, self.scheduler]:
            _kill(process)
        for handle in self._logs:
            handle.close()


def _kill(process: subprocess.Popen | None) -> None:
    if process is not None and process.poll() is None:
        with contextlib.suppress(ProcessLookupError):
            os.kill(process.pid, signal.SIGKILL)
    if process is not None:
        process.wait()


@contextlib.contextmanager
def dask_processes(directory: Path, workers: int = 2):
    """A :class:`DaskProcesses` of ``workers`` workers, killed on the way out."""
    cluster = DaskProcesses(directory, workers)
    try:
        yield cluster
    finally:
        cluster.close()
