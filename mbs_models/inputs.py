"""Reading what users give: text files of bounded size, and TOML of bounded nesting.

A scene file and a breech-force CSV file named in a scene are read by :func:`read_text_file`: a regular
file (not a directory, a device such as ``/dev/zero``, a pipe or a socket), at most
:data:`MAX_INPUT_BYTES`, text (no NUL byte) in UTF-8.  The file is opened without blocking (a pipe would
wait for a writer) and checked on the open descriptor, then read with a limit: nothing unbounded is ever
read into memory.  TOML text is parsed by :func:`parse_toml`, which first refuses arrays and inline tables
nested more than :data:`MAX_TOML_NESTING` deep (the standard parser recurses once per level and would
exhaust the interpreter's stack near 1 000) and then tables nested that deep through dotted keys.  Every
problem is one :class:`~mbs_models.errors.SceneError` naming the key the caller gives.
"""

from __future__ import annotations

import io
import os
import re
import stat
from pathlib import Path
from typing import Callable

from .errors import SceneError

#: The largest input file read (bytes): 64 MiB.  A breech-force table of 1 000 000 rows ``time,force`` at
#: full precision (``1.2345678901234567e-05,1.2345678901234567e+06``, 47 bytes with CR LF) is 47 MB.
MAX_INPUT_BYTES = 64 * 2 ** 20
#: The deepest nesting of arrays, inline tables and tables a TOML input may have.  A scene needs 5 (the
#: pairs of a tabulated orifice area inside ``[recoil_brake]``, an absorber's contact in ``[[absorber]]``).
MAX_TOML_NESTING = 32

# a TOML comment or string (skipped: brackets inside do not nest), or one bracket or brace; compiled on first use
# (by re's cache: a run of a scene built in Python reads no TOML)
_TOKEN = r'''\#[^\n]*
                      | """(?:\\.|[^\\"]|"(?!""))*"""{1,3}
                      | "(?:\\.|[^"\\\n])*"
                      | \'\'\'(?:[^']|'(?!''))*\'\'\'{1,3}
                      | '[^'\n]*'
                      | [\[\]{}]'''
_TOKEN_FLAGS = re.VERBOSE | re.DOTALL


def read_text_file(path: str | Path, key: str, what: str, max_bytes: int | None = None) -> str:
    """The UTF-8 text of the regular file ``path`` (at most ``max_bytes``, default :data:`MAX_INPUT_BYTES`).
    SceneError naming ``key`` (``what`` describes the file: ``"scene file"``) for a file that does not exist,
    cannot be opened, is a directory, a device, a pipe or a socket, is larger than ``max_bytes``, holds a NUL
    byte (a binary file) or is not UTF-8."""
    path = Path(path)
    max_bytes = MAX_INPUT_BYTES if max_bytes is None else max_bytes
    flags = os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_BINARY", 0)
    try:
        descriptor = os.open(path, flags)
    except FileNotFoundError:
        raise SceneError(key, f"{what} not found: {path}") from None
    except OSError as exc:
        raise SceneError(key, f"cannot read {what} {path}: {exc.strerror or exc}") from None
    mode = os.fstat(descriptor).st_mode
    if not stat.S_ISREG(mode):
        os.close(descriptor)
        kind = "it is a directory, not a file" if stat.S_ISDIR(mode) else \
            "not a regular file (a device, a pipe or a socket)"
        raise SceneError(key, f"cannot read {what} {path}: {kind}")
    with os.fdopen(descriptor, "rb") as handle:
        try:
            data = handle.read(max_bytes + 1)
        except OSError as exc:
            raise SceneError(key, f"cannot read {what} {path}: {exc.strerror or exc}") from None
    if len(data) > max_bytes:
        raise SceneError(key, f"cannot read {what} {path}: larger than {max_bytes} bytes (the limit of an input file)")
    if b"\0" in data:
        raise SceneError(key, f"cannot read {what} {path}: a binary file (a NUL byte at byte {data.index(0)}), "
                              f"not text")
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise SceneError(key, f"cannot read {what} {path}: not UTF-8 text (byte {exc.start})") from None


def read_two_columns(path: str | Path, key: str, what: str, columns: str, max_rows: int,
                     too_many: Callable[[], SceneError]) -> list[tuple[float, float]]:
    """The number pairs of a CSV file of two columns (``columns``, e.g. ``"time,force"``) after one header line: a
    file within the input limits (:func:`read_text_file`, ``what`` names it), at most ``max_rows`` pairs
    (``too_many()`` is the error past them).  Every error is a SceneError naming ``key``."""
    import csv  # (imported here: a run reads no CSV file)

    text = read_text_file(path, key, what)
    rows = []
    try:
        for row in csv.reader(io.StringIO(text, newline="")):
            if row and any(cell.strip() for cell in row):
                rows.append(row)
                if len(rows) > max_rows + 1:  # the header and the pairs
                    raise too_many()
    except csv.Error as exc:  # a field beyond csv's limit (128 KiB), a NUL byte
        raise SceneError(key, f"{path}: not a CSV table of two columns {columns}: {exc}") from None
    if len(rows) < 3:
        raise SceneError(key, f"{path}: needs a header line and at least two rows {columns}")
    out = []
    for line, row in enumerate(rows[1:], start=2):
        if len(row) != 2:
            raise SceneError(key, f"{path} line {line}: needs two columns {columns}, got {len(row)}")
        try:
            out.append((float(row[0]), float(row[1])))
        except ValueError:
            raise SceneError(key, f"{path} line {line}: not numbers: {','.join(row)[:80]!r}") from None
    return out


def bracket_nesting(text: str) -> int:
    """The deepest nesting of ``[`` and ``{`` in TOML ``text`` outside strings and comments (a table header
    ``[a]`` counts 1, ``[[a]]`` 2)."""
    depth = deepest = 0
    for match in re.finditer(_TOKEN, text, _TOKEN_FLAGS):
        token = match.group()
        if token in "[{":
            depth += 1
            deepest = max(deepest, depth)
        elif token in "]}":
            depth = max(depth - 1, 0)
    return deepest


def data_nesting(data) -> int:
    """The deepest nesting of dicts and lists in parsed ``data`` (a scalar 0, ``{}`` 1), without recursion."""
    deepest = 0
    stack = [(data, 1)]
    while stack:
        item, depth = stack.pop()
        if isinstance(item, dict):
            item = item.values()
        elif not isinstance(item, list):
            continue
        deepest = max(deepest, depth)
        stack += [(child, depth + 1) for child in item]
    return deepest


def check_toml_nesting(text: str, key: str, where: str) -> None:
    """SceneError naming ``key`` if TOML ``text`` nests arrays or inline tables more than
    :data:`MAX_TOML_NESTING` deep (``where`` names the text in the message: a file's path)."""
    if bracket_nesting(text) > MAX_TOML_NESTING:
        raise SceneError(key, f"{where}: arrays or inline tables nested more than {MAX_TOML_NESTING} deep")


def parse_toml(text: str, key: str, where: str) -> dict:
    """``tomllib.loads(text)`` with its nesting bounded by :data:`MAX_TOML_NESTING`; SceneError naming ``key``
    for malformed or too deeply nested TOML (``where`` names the text in the message: a file's path)."""
    import tomllib  # (imported here: a run of a scene built in Python parses no TOML)

    check_toml_nesting(text, key, where)
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise SceneError(key, f"malformed TOML in {where}: {exc}") from None
    if data_nesting(data) > MAX_TOML_NESTING + 1:  # + 1: the document's own table
        raise SceneError(key, f"{where}: tables nested more than {MAX_TOML_NESTING} deep (dotted keys)")
    return data
