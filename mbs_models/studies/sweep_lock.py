"""One sweep per table at a time: a lock held on ``FILE.lock`` beside the table while a sweep runs.

Two sweeps into one file would each compute every point and interleave their rows.  :class:`SweepLock`
takes an exclusive POSIX record lock (``fcntl.lockf``) on ``FILE.lock`` without waiting: a second sweep
on the same file is refused at once (a :class:`~mbs_models.errors.SceneError` of key ``out``), naming the
process that holds it (the lock file holds ``process PID on HOST since TIME``).  The system drops the
lock when its process ends, however it ends (a SIGKILL, the out-of-memory killer): a stale lock file never
blocks a later run, which simply takes it.  (A POSIX lock is the process's own -- a forked worker does
not hold it -- and works on NFS v4; it does not exclude the process itself, so the lock files this process
holds are also kept in :data:`_HELD`; and closing any descriptor of the file drops the process's lock, so
its holder reads it only through its own.)  The holder removes the file when it is done; a taker that finds
the file it locked replaced or removed meanwhile tries again.  On a file system without locks (``ENOLCK``)
the sweep runs unlocked, with a warning.
"""

from __future__ import annotations

import errno
import fcntl
import os
import socket
import time
import warnings
from pathlib import Path

from ..errors import SceneError

#: The lock files this process holds (a POSIX lock does not exclude its own process).
_HELD: set[str] = set()


class SweepLock:
    """The lock of the sweep table ``table`` (a context manager): ``FILE.lock`` beside it."""

    def __init__(self, table: str | os.PathLike):
        self.table = Path(table)
        self.path = self.table.with_name(self.table.name + ".lock")
        self._fd: int | None = None
        self._key = os.path.realpath(self.path)

    def __enter__(self) -> "SweepLock":
        self.acquire()
        return self

    def __exit__(self, *exc) -> None:
        self.release()

    def acquire(self) -> None:
        """Take the lock, or SceneError (key ``out``) if another sweep holds it."""
        if self._key in _HELD:
            raise SceneError("out", f"{self.table} is being written by another sweep of this process: wait for it "
                                    "to end, or give another file")
        for _ in range(100):   # the file may be removed by its holder between our open and our lock
            try:
                fd = os.open(self.path, os.O_RDWR | os.O_CREAT | os.O_CLOEXEC, 0o666)
            except OSError as exc:
                raise SceneError("out", f"cannot create the lock file {self.path}: "
                                        f"{exc.strerror or exc}") from None
            try:
                fcntl.lockf(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except OSError as exc:
                os.close(fd)
                if exc.errno in (errno.EACCES, errno.EAGAIN):
                    raise SceneError("out", f"{self.table} is being written by another sweep ({self.holder()}): "
                                            "wait for it to end, or give another file") from None
                warnings.warn(f"{self.path}: the file system cannot lock files ({exc.strerror or exc}): this sweep "
                              "runs unlocked -- make sure no other sweep writes the same file", RuntimeWarning,
                              stacklevel=3)
                return
            if _same_file(fd, self.path):
                break
            os.close(fd)
        else:   # pragma: no cover - a file replaced a hundred times in a row
            raise SceneError("out", f"cannot lock {self.path}: it keeps being replaced")
        self._fd = fd
        _HELD.add(self._key)
        stamp = f"process {os.getpid()} on {socket.gethostname()} since {time.strftime('%Y-%m-%d %H:%M:%S')}\n"
        try:
            os.ftruncate(fd, 0)
            os.write(fd, stamp.encode("utf-8"))
        except OSError:   # a full disk: the lock holds all the same, unnamed
            pass

    def holder(self) -> str:
        """Who holds the lock, as its file says (``process PID on HOST since TIME``), or ``another process``."""
        try:
            if self._fd is not None:   # ours: read through our descriptor (closing another one would drop the lock)
                text = os.pread(self._fd, 4096, 0).decode("utf-8", "replace").strip()
            else:
                text = self.path.read_text(encoding="utf-8", errors="replace").strip()
        except OSError:
            text = ""
        return text.splitlines()[0] if text else "another process"

    def release(self) -> None:
        """Remove the lock file and drop the lock (nothing if not held)."""
        if self._fd is None:
            return
        try:
            os.unlink(self.path)
        except OSError:
            pass
        os.close(self._fd)
        self._fd = None
        _HELD.discard(self._key)


def _same_file(fd: int, path: Path) -> bool:
    """Whether ``fd`` is still the file at ``path`` (its holder may have removed it before we locked it)."""
    try:
        named = os.stat(path)
    except OSError:
        return False
    opened = os.fstat(fd)
    return (named.st_dev, named.st_ino) == (opened.st_dev, opened.st_ino)


__all__ = ["SweepLock"]
