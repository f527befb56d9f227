"""One sweep per table (mbs_models.studies.sweep_lock): a second one refused at once, naming the first; a lock
that outlives its process never blocks."""

from __future__ import annotations

import os
import signal
import subprocess
import sys

import pytest

from mbs_models import SceneError
from mbs_models.studies.sweep_lock import SweepLock

#: A process that takes the lock of the table argv[1], says so, and waits.
HOLDER = """
import sys, time
from mbs_models.studies.sweep_lock import SweepLock
lock = SweepLock(sys.argv[1])
lock.acquire()
print("locked", flush=True)
time.sleep(120)
"""


def _holder(table):
    proc = subprocess.Popen([sys.executable, "-c", HOLDER, str(table)], stdout=subprocess.PIPE, text=True,
                            env={**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)})
    assert proc.stdout.readline().strip() == "locked"
    return proc


def test_a_second_sweep_is_refused_naming_the_first_and_a_killed_one_blocks_nothing(tmp_path):
    table = tmp_path / "t.csv"
    proc = _holder(table)
    try:
        with pytest.raises(SceneError) as info:
            SweepLock(table).acquire()
        assert info.value.key == "out"
        assert info.value.message.startswith(f"{table} is being written by another sweep (process {proc.pid} on ")
        assert info.value.message.endswith("): wait for it to end, or give another file")
    finally:
        os.kill(proc.pid, signal.SIGKILL)     # as the out-of-memory killer would: no clean-up
        proc.wait()
    assert (tmp_path / "t.csv.lock").exists()  # the file stays ...
    with SweepLock(table) as lock:             # ... and blocks nothing: the system dropped the lock
        assert lock.holder().startswith(f"process {os.getpid()} on ")
        other = subprocess.run([sys.executable, "-c", "import sys\nfrom mbs_models.studies.sweep_lock import "
                                "SweepLock\ntry:\n    SweepLock(sys.argv[1]).acquire()\nexcept Exception as e:\n"
                                "    print(e)", str(table)], capture_output=True, text=True,
                               env={**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)})
        assert f"(process {os.getpid()} on " in other.stdout   # still held after reading who holds it
    assert not (tmp_path / "t.csv.lock").exists()   # removed when released


def test_the_same_process_cannot_take_it_twice(tmp_path):
    """A POSIX lock does not exclude its own process: the lock keeps its own list."""
    table = tmp_path / "t.csv"
    with SweepLock(table):
        with pytest.raises(SceneError, match="another sweep of this process"):
            SweepLock(table).acquire()
    with SweepLock(table):   # released: taken again
        pass


def test_a_lock_file_removed_by_its_holder_is_not_locked_in_vain(tmp_path, monkeypatch):
    """The holder removes the file as it releases it: a taker that opened the old file retries on the new one."""
    from mbs_models.studies import sweep_lock

    table = tmp_path / "t.csv"
    first = SweepLock(table)
    calls = []
    real = sweep_lock._same_file

    def released_meanwhile(fd, path):
        calls.append(path)
        if len(calls) == 1:                       # the holder releases between our open and our lock
            os.unlink(path)
        return real(fd, path)

    monkeypatch.setattr(sweep_lock, "_same_file", released_meanwhile)
    first.acquire()
    assert len(calls) == 2 and first.path.exists()
    first.release()
