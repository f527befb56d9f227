"""Where sweep points run (mbs_models.studies.backends): the backend map, results as tasks finish."""

from __future__ import annotations

import sys

import pytest

from mbs_models import SceneError
from mbs_models.studies.backends import (BACKENDS, ProcessBackend, SerialBackend, batch_size, import_distributed,
                                         make_backend)


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
