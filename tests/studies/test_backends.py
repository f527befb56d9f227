"""Where sweep points run (mbs_models.studies.backends): the backend map, results as tasks finish."""

from __future__ import annotations

import math
import sys
import time

import pytest

from mbs_models import ClusterError, SceneError
from mbs_models.errors import SimulationError
from mbs_models.studies.backends import (BACKENDS, WORKER_TIMEOUT, DaskBackend, ProcessBackend, SerialBackend,
                                         batch_size, check_scheduler, check_worker_timeout, import_distributed,
                                         in_flight, make_backend)


def _pid(task) -> int:
    """The process that ran the task."""
    import os

    return os.getpid()


def test_backend_map():
    assert set(BACKENDS) == {"serial", "processes", "dask"}
    assert isinstance(make_backend(workers=1), SerialBackend) and make_backend(workers=1).name == "serial"
    backend = make_backend(workers=2)
    assert isinstance(backend, ProcessBackend) and backend.workers == 2


@pytest.mark.parametrize("backend", [SerialBackend(), ProcessBackend(2)], ids=["serial", "processes"])
def test_every_task_runs_once(backend):
    with backend:
        assert sorted(backend.run(abs, [-3, -1, -2, 4])) == [1, 2, 3, 4]
        assert list(backend.run(abs, [])) == []


@pytest.mark.parametrize("workers", [0, -1, 1.5, True])
def test_bad_worker_counts(workers):
    with pytest.raises(SceneError, match="workers"):
        make_backend(workers=workers)


def test_workers_and_scheduler_together_are_refused():
    with pytest.raises(SceneError, match="not both"):
        make_backend(workers=2, scheduler="tcp://127.0.0.1:8786")


@pytest.mark.parametrize("scheduler", ["", 3])
def test_bad_scheduler(scheduler):
    with pytest.raises(SceneError) as info:
        make_backend(scheduler=scheduler)
    assert info.value.key == "scheduler"


def test_without_dask_the_error_names_the_cluster_extra(monkeypatch):
    monkeypatch.setitem(sys.modules, "dask.distributed", None)
    with pytest.raises(SceneError) as info:
        import_distributed()
    assert info.value.key == "scheduler" and "recoil-mbs[cluster]" in info.value.message
    with pytest.raises(SceneError, match=r"recoil-mbs\[cluster\]"):
        make_backend(scheduler="tcp://127.0.0.1:8786")


def test_batch_sizes():
    assert batch_size(26, 2) == 4            # about four tasks per worker
    assert batch_size(3, 8) == 1
    assert batch_size(10_000, 2) == 16       # capped: a lost worker loses little


def test_pool_workers_end_when_their_parent_is_killed(tmp_path):
    """A sweep killed with SIGKILL leaves no pool worker behind waiting for tasks."""
    import os
    import signal
    import subprocess
    import time

    script = tmp_path / "parent.py"
    script.write_text(
        "import os, time\n"
        "from mbs_models.studies.backends import ProcessBackend\n"
        "def slow(x):\n"
        "    time.sleep(x)\n"
        "    return os.getpid()\n"
        "backend = ProcessBackend(2)\n"
        "print(sorted(set(backend.run(slow, [0.5, 0.5, 0.5, 0.5]))), flush=True)\n"  # the workers' pids
        "list(backend.run(slow, [60.0, 60.0]))\n")
    parent = subprocess.Popen([sys.executable, str(script)], stdout=subprocess.PIPE, text=True,
                              env={**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)})
    first = parent.stdout.readline()
    assert first.startswith("[")
    time.sleep(1.0)
    children = [int(pid) for pid in subprocess.run(["pgrep", "-P", str(parent.pid)], capture_output=True,
                                                   text=True).stdout.split()]
    parent.send_signal(signal.SIGKILL)
    parent.wait()
    assert children
    deadline = time.monotonic() + 10.0
    while time.monotonic() < deadline and any(_alive(pid) for pid in children):
        time.sleep(0.2)
    alive = [pid for pid in children if _alive(pid)]
    for pid in alive:  # clean up before failing
        os.kill(pid, signal.SIGKILL)
    assert not alive


def _alive(pid: int) -> bool:
    import os

    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    try:  # a zombie (exited, not yet reaped by init) counts as gone
        with open(f"/proc/{pid}/stat") as handle:
            return handle.read().split(")")[-1].split()[0] != "Z"
    except OSError:
        return False


def _counted(tasks, pulled):
    for task in tasks:
        pulled.append(task)
        yield task


@pytest.mark.parametrize("backend", [SerialBackend(), ProcessBackend(2)], ids=["serial", "processes"])
def test_tasks_are_taken_as_results_are_read(backend):
    """At most ``in_flight`` tasks are taken ahead of the results read: a generator of a million tasks is read
    as far as the run goes, never made whole."""
    pulled = []
    with backend:
        results = backend.run(abs, _counted(range(-1, -1_000_000, -1), pulled), in_flight=3)
        first = [next(results) for _ in range(5)]
        assert len(pulled) <= 5 + 3
        results.close()
    assert all(r >= 1 for r in first) and len(pulled) <= 8


def test_the_pool_is_kept_between_runs_and_not_after_an_early_end():
    import os

    with ProcessBackend(2) as backend:
        pids = set(backend.run(_pid, range(8)))
        assert pids and os.getpid() not in pids
        assert backend._pool is not None
        workers = set(backend._pool._processes)   # on a loaded machine one worker may have run all eight
        assert pids <= workers
        again = set(backend.run(_pid, range(8)))
        assert again <= workers               # the same worker processes
        results = backend.run(_pid, range(8))
        next(results)
        results.close()                       # a caller that stops reading: the pool goes
        assert backend._pool is None
        assert set(backend.run(_pid, range(4))).isdisjoint(workers)   # a new pool
    assert backend._pool is None


def test_in_flight_per_worker():
    assert in_flight(2) == 8 and in_flight(1) == 4
    with pytest.raises(SceneError) as info:
        list(ProcessBackend(2).run(abs, [1], in_flight=0))
    assert info.value.key == "in_flight"


def test_dask_takes_tasks_as_results_are_read(dask_cluster):
    from mbs_models.studies.backends import DaskBackend

    pulled = []
    with DaskBackend(dask_cluster.scheduler_address) as backend:
        assert backend.workers >= 1
        results = backend.run(abs, _counted(range(-1, -100_000, -1), pulled), in_flight=4)
        first = [next(results) for _ in range(6)]
        assert all(r >= 1 for r in first) and len(pulled) <= 6 + 4
        results.close()
        assert sorted(backend.run(abs, [-3, -1, -2])) == [1, 2, 3]


# ================================================================================================ Dask's faults
@pytest.mark.parametrize("address", ["tcp://127.0.0.1:8786", " tcp://node-7.cluster.example:8786 ", "tls://10.0.0.2:1",
                                     "tcp://[::1]:65535", "inproc://192.0.2.2/1234/1"])
def test_scheduler_addresses(address):
    assert check_scheduler(address) == address.strip()


@pytest.mark.parametrize("address", ["garbage", "", "127.0.0.1:8786", "tcp://127.0.0.1", "tcp://:8786",
                                     "tcp://127.0.0.1:0", "tcp://127.0.0.1:65536", "udp://127.0.0.1:8786",
                                     "tcp://127.0.0.1:8786/path", "tcp://a b:8786", "inproc://", 8786, True, None])
def test_malformed_scheduler_addresses_are_bad_input(address):
    with pytest.raises(SceneError) as info:
        check_scheduler(address)
    assert info.value.key == "scheduler"
    assert "tcp://HOST:PORT" in info.value.message and repr(address) in info.value.message


@pytest.mark.parametrize("seconds", [0, -1.0, math.nan, -math.inf, True, "60"])
def test_bad_worker_timeouts(seconds):
    with pytest.raises(SceneError) as info:
        check_worker_timeout(seconds)
    assert info.value.key == "worker_timeout"


def test_worker_timeout_default_and_no_limit():
    assert check_worker_timeout(None) == WORKER_TIMEOUT == 60.0
    assert check_worker_timeout(math.inf) == math.inf and check_worker_timeout(2) == 2.0


def test_a_worker_timeout_without_a_scheduler_is_refused():
    with pytest.raises(SceneError) as info:
        make_backend(workers=2, worker_timeout=10.0)
    assert info.value.key == "worker_timeout"


def _no_leftover_client(capfd) -> None:
    """No Client half-made and left to its __del__ (which prints a traceback after a 20 s wait)."""
    import gc

    gc.collect()
    assert "Exception ignored" not in capfd.readouterr().err


def test_a_refused_connection_is_a_cluster_error_at_once(capfd):
    """Refused: said at once, not after the connect timeout (Dask itself retries a refused connection until then)."""
    from dask_processes import free_port

    pytest.importorskip("dask.distributed")
    port, start = free_port(), time.monotonic()
    with pytest.raises(ClusterError) as info:
        DaskBackend(f"tcp://127.0.0.1:{port}", connect_timeout=120.0)
    assert time.monotonic() - start < 60.0
    assert str(info.value) == (f"cannot connect to the Dask scheduler at tcp://127.0.0.1:{port}: connection refused "
                               "(nothing listens on that port)")
    _no_leftover_client(capfd)


def test_an_unknown_host_is_a_cluster_error():
    pytest.importorskip("dask.distributed")
    with pytest.raises(ClusterError, match="unknown host 'no-such-host.invalid'"):
        DaskBackend("tcp://no-such-host.invalid:8786")


@pytest.mark.parametrize("scheme, reason", [("tcp", "no Dask scheduler answered within 1 s"), ("tls", "TLS")])
def test_a_listener_that_is_no_dask_scheduler_is_a_cluster_error_within_the_timeout(scheme, reason, capfd):
    """A port that accepts connections and never answers (Dask's own client waits far longer than its timeout
    there), or TLS without its configuration."""
    import socket

    pytest.importorskip("dask.distributed")
    with socket.socket() as listener:
        listener.bind(("127.0.0.1", 0))
        listener.listen(8)   # connections complete in the backlog; nothing is ever read or written
        address = f"{scheme}://127.0.0.1:{listener.getsockname()[1]}"
        with pytest.raises(ClusterError) as info:
            DaskBackend(address, connect_timeout=1.0)
    assert str(info.value).startswith(f"cannot connect to the Dask scheduler at {address}: ")
    assert reason in str(info.value)
    _no_leftover_client(capfd)


def test_a_workers_address_is_not_a_scheduler(dask_cluster):
    worker = next(iter(dask_cluster.scheduler_info["workers"]))
    with pytest.raises(ClusterError) as info:
        DaskBackend(worker)
    assert str(info.value) == (f"cannot connect to the Dask scheduler at {worker}: what answers is not a Dask "
                               "scheduler (it is a Worker)")


def test_no_worker_for_the_worker_timeout_is_a_cluster_error_said_while_waiting(workerless_dask_cluster):
    address, said = workerless_dask_cluster.scheduler_address, []
    with DaskBackend(address, worker_timeout=1.0, say=said.append) as backend:
        assert backend.workers == 1   # none: as if one, for the batch sizes
        with pytest.raises(ClusterError) as info:
            list(backend.run(abs, [-1, -2]))
    assert str(info.value) == f"no Dask worker has been available at {address} for 1 s (the worker timeout)"
    assert said == [f"dask: waiting for a worker: the scheduler {address} has none; giving up after 1 s without one "
                    "(the worker timeout)"]


def test_workers_that_come_while_waiting_take_the_tasks(workerless_dask_cluster):
    cluster, said = workerless_dask_cluster, []

    def say(line):
        said.append(line)
        if line.startswith("dask: waiting"):
            cluster.scale(1)

    with DaskBackend(cluster.scheduler_address, worker_timeout=math.inf, say=say) as backend:
        assert sorted(backend.run(abs, [-1, -2, -3])) == [1, 2, 3]
    assert said == [f"dask: waiting for a worker: the scheduler {cluster.scheduler_address} has none",
                    f"dask: the scheduler {cluster.scheduler_address} has workers again; going on"]


def test_a_task_that_kills_its_workers_is_a_cluster_error():
    """Dask gives a task up once its workers died running it (KilledWorker; here after the first death): an
    error of the run, not of the task."""
    import os

    import dask

    distributed = pytest.importorskip("dask.distributed")
    with dask.config.set({"distributed.scheduler.allowed-failures": 0}), \
            distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=True, host="127.0.0.1",
                                     dashboard_address=None) as cluster, \
            DaskBackend(cluster.scheduler_address) as backend:
        with pytest.raises(ClusterError) as info:
            list(backend.run(os._exit, [1]))
        cluster.wait_for_workers(1, timeout=60)   # its nanny restarts the worker: close once it has (see below)
    assert str(info.value).startswith("Dask workers kept dying while running one task (killed, out of memory?), "
                                      f"and the scheduler {cluster.scheduler_address} gave it up: ")


# ================================================================================================ worker deaths
def _poisoned(task):
    """A task ``(poison, signal, flag, batch)``: each number of ``batch`` doubled; its worker process kills itself
    with ``signal`` if the batch holds a number of ``poison``, or once the file ``flag`` exists."""
    import os

    poison, sig, flag, batch = task
    if any(x in poison for x in batch) or (flag is not None and os.path.exists(flag)):
        import faulthandler

        faulthandler.disable()   # pytest's, inherited by the worker: no traceback dump on the test's stderr
        os.kill(os.getpid(), sig)
    return [2 * x for x in batch]


def _tasks(batches, poison, sig=None, flag=None):
    import signal

    return [(frozenset(poison), sig or signal.SIGKILL, flag, batch) for batch in batches]


def _by_number(task):
    poison, sig, flag, batch = task
    return [(poison, sig, flag, [x]) for x in batch]


def _lost(task, reason):
    return [("lost", x, reason) for x in task[3]]


def _flat(results):
    out = [item for result in results for item in result]
    return sorted(x for x in out if not isinstance(x, tuple)), [x for x in out if isinstance(x, tuple)]


@pytest.mark.parametrize("sig, named", [("SIGKILL", "died of SIGKILL (the out-of-memory killer? a user?)"),
                                        ("SIGSEGV", "died of SIGSEGV (a crash in compiled code)")])
def test_a_task_that_kills_its_worker_is_lost_and_the_others_run(sig, named):
    """Batches of three numbers; the one holding 13 kills its worker (and the pool with it) every time: 13 is
    lost with the signal named, its batch mates 12 and 14 and every other batch (in flight then, or not yet
    taken) come back; the run ends normally and the pool works afterwards."""
    import signal

    batches = [[i, i + 1, i + 2] for i in range(0, 30, 3)]
    with ProcessBackend(2) as backend:
        done, lost = _flat(backend.run(_poisoned, _tasks(batches, {13}, getattr(signal, sig)), split=_by_number,
                                       lost=_lost))
        assert done == [2 * x for x in range(30) if x != 13]
        assert lost == [("lost", 13, f"its worker process {named} each of the 3 times it ran it (in its batch, "
                                     "again, then alone)")]
        assert _flat(backend.run(_poisoned, _tasks([[1], [2]], set()))) == ([2, 4], [])


def test_a_run_of_poisoned_tasks_is_lost_point_by_point():
    """Twenty tasks in a row that kill their worker (more than twice DEATHS_IN_A_ROW): a task that ran before
    runs again, alone, finishes, so the deaths are the tasks' own -- all twenty lost, the others run."""
    from mbs_models.studies.backends import DEATHS_IN_A_ROW

    poison = set(range(10, 30))
    assert len(poison) > 2 * DEATHS_IN_A_ROW
    with ProcessBackend(2) as backend:
        done, lost = _flat(backend.run(_poisoned, _tasks([[i] for i in range(40)], poison), split=_by_number,
                                       lost=_lost))
    assert sorted(x[1] for x in lost) == sorted(poison)
    assert done == [2 * x for x in range(40) if x not in poison]


def test_workers_that_die_whatever_they_run_end_the_run(tmp_path):
    """Every worker dies (no task ever finishes, or -- after some did -- the last one that finished dies too when
    run again): no point's fault, so nothing is lost; SimulationError after DEATHS_IN_A_ROW tasks."""
    from mbs_models.studies.backends import DEATHS_IN_A_ROW

    with ProcessBackend(2) as backend:
        with pytest.raises(SimulationError, match="no point has run yet: something kills every worker"):
            list(backend.run(_poisoned, _tasks([[i] for i in range(100)], range(100)), split=_by_number, lost=_lost))
    flag = tmp_path / "die"
    seen = []
    with ProcessBackend(2) as backend:
        with pytest.raises(SimulationError, match="a point that ran before died too"):
            for result in backend.run(_poisoned, _tasks([[i] for i in range(100)], set(), flag=str(flag)),
                                      split=_by_number, lost=_lost):
                seen += result
                if len(seen) == 5:
                    flag.touch()     # from now on every process dies
    assert not any(isinstance(x, tuple) for x in seen)   # no lost point was handed out
    assert 5 <= len(seen) < 100 - DEATHS_IN_A_ROW


def test_without_lost_a_death_ends_the_run():
    with ProcessBackend(2) as backend:
        with pytest.raises(SimulationError, match="a worker process died"):
            list(backend.run(_poisoned, _tasks([[i] for i in range(10)], {3})))


def test_a_task_that_kills_its_dask_workers_is_lost():
    """On Dask the scheduler retries a task whose worker dies (allowed-failures times, 0 here), then reports
    KilledWorker: the batch is split, the poisoned number lost, its batch mates and the rest come back."""
    import os
    import signal

    dask = pytest.importorskip("dask")
    distributed = pytest.importorskip("dask.distributed")
    from mbs_models.studies.backends import DaskBackend

    def poisoned(task):   # a local function: pickled by value for the Dask workers (this module is not theirs)
        batch = task[3]
        if 13 in batch:
            os.kill(os.getpid(), signal.SIGKILL)
        return [2 * x for x in batch]

    with dask.config.set({"distributed.scheduler.allowed-failures": 0}):
        with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1",
                                      dashboard_address=None) as cluster:
            with DaskBackend(cluster.scheduler_address) as backend:
                done, lost = _flat(backend.run(poisoned, _tasks([[i, i + 1] for i in range(0, 20, 2)], {13}),
                                               split=_by_number, lost=_lost))
            # the nannies restart the killed workers: closing the cluster while one is half started fails inside
            # distributed ("can only join a started process"), so wait for them first
            cluster.wait_for_workers(2, timeout=60)
    assert done == [2 * x for x in range(20) if x != 13]
    assert lost == [("lost", 13, "the Dask workers running it died each time the scheduler tried it (KilledWorker)")]
