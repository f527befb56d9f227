"""Writing output files safely: check the directory first, write to a temporary name, then rename.

One rule for every output directory of every ``recoil`` command: a missing directory is created (with its
parents), but only once the input has been checked, so that bad input leaves nothing behind.  A command checks
its outputs first, creating nothing (:func:`check_output_dir`, :func:`check_output_file`: an existing path must
be a writable directory, a missing one must have a writable directory as its nearest existing ancestor), and
creates them when it writes (:func:`prepare_output_dir`, :func:`prepare_output_file`).

A report that fails half-way never leaves a half-written file under its final name.  The files get the
permissions any tool gives a new file: ``0666`` minus the process's umask (``0644`` under umask 022),
not the ``0600`` of a temporary file.
"""

from __future__ import annotations

import json
import os
import tempfile
from pathlib import Path
from typing import Any, Callable

from .errors import SceneError


def prepare_output_dir(path: str | Path, key: str = "--out") -> Path:
    """Create ``path`` if needed and check it is a writable directory; SceneError naming ``key`` if not."""
    path = Path(path)
    if path.exists() and not path.is_dir():
        raise SceneError(key, f"{path} exists and is not a directory")
    try:
        path.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise SceneError(key, f"cannot create output directory {path}: {exc.strerror or exc}") from None
    if not os.access(path, os.W_OK | os.X_OK):
        raise SceneError(key, f"output directory {path} is not writable")
    return path


def check_output_dir(path: str | Path, key: str = "--out") -> Path:
    """Check, creating nothing, that :func:`prepare_output_dir` can make ``path`` a writable directory:
    an existing directory must be writable, else its nearest existing ancestor must be a writable
    directory; SceneError naming ``key`` if not."""
    path = Path(path)
    if path.exists():
        if not path.is_dir():
            raise SceneError(key, f"{path} exists and is not a directory")
        if not os.access(path, os.W_OK | os.X_OK):
            raise SceneError(key, f"output directory {path} is not writable")
        return path
    ancestor = path.absolute().parent
    while not ancestor.exists():
        ancestor = ancestor.parent
    if not ancestor.is_dir() or not os.access(ancestor, os.W_OK | os.X_OK):
        raise SceneError(key, f"cannot create output directory {path}: {ancestor} is not a writable directory")
    return path


def current_umask() -> int:
    """The process's umask, read without changing it where Linux reports it (``/proc/self/status``);
    elsewhere set and restored at once."""
    try:
        with open("/proc/self/status", encoding="ascii") as status:
            for line in status:
                if line.startswith("Umask:"):
                    return int(line.split()[1], 8)
    except (OSError, ValueError):
        pass
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


def check_output_file(path: str | Path, key: str) -> Path:
    """Check, creating nothing, that a file can be written at ``path``: ``path`` is not a directory and its
    directory exists and is writable, or can be created (:func:`check_output_dir`).  SceneError naming ``key``
    otherwise.  :func:`prepare_output_file` creates the directory once the input is known to be good."""
    path = Path(path)
    if path.is_dir():
        raise SceneError(key, f"{path} is a directory, not a file")
    check_output_dir(path.parent if str(path.parent) else Path("."), key)
    return path


def prepare_output_file(path: str | Path, key: str) -> Path:
    """:func:`check_output_file`, then create the file's missing directories (:func:`prepare_output_dir`)."""
    path = check_output_file(path, key)
    prepare_output_dir(path.parent if str(path.parent) else Path("."), key)
    return path


def atomic_write_with(path: str | Path, write: Callable[[Path], None]) -> Path:
    """Let ``write(temporary_path)`` write the file, then rename it to ``path`` atomically (a temporary name in the
    same directory: a reader never sees half a file; on any error nothing is left behind).

    The file's mode is ``0666 & ~umask``, as ``open(path, "w")`` would give it (``write`` may be any writer that
    takes a path: ``DataFrame.to_csv``, ``to_parquet``, ``Figure.savefig``).
    """
    path = Path(path)
    directory = path.parent if str(path.parent) else Path(".")
    try:
        handle, temporary = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=directory)
    except OSError as exc:
        raise SceneError(str(path), f"cannot write: {exc.strerror or exc}") from None
    try:
        os.fchmod(handle, 0o666 & ~current_umask())
        os.close(handle)
        write(Path(temporary))
        os.chmod(temporary, 0o666 & ~current_umask())  # a writer that re-created the file
        os.replace(temporary, path)
    except BaseException:
        try:
            os.unlink(temporary)
        except OSError:
            pass
        raise
    return path


def atomic_write_bytes(path: str | Path, data: bytes) -> Path:
    """Write ``data`` to ``path`` atomically (:func:`atomic_write_with`), mode ``0666 & ~umask``."""
    return atomic_write_with(path, lambda temporary: temporary.write_bytes(data))


def atomic_write_text(path: str | Path, text: str) -> Path:
    """Write UTF-8 text atomically."""
    return atomic_write_bytes(path, text.encode("utf-8"))


def atomic_write_json(path: str | Path, data: Any) -> Path:
    """Write JSON (indented, NaN forbidden: non-finite numbers must never pass as results)."""
    return atomic_write_text(path, json.dumps(data, indent=2, allow_nan=False) + "\n")
