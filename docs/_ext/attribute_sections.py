"""Docstrings of this package list attributes as ``name: text`` lines (the form the key reference parses,
:mod:`mbs_models.scene.keys`); numpy style, which napoleon reads, wants ``name`` on its own line and the text
indented below.  Rewrite the one into the other before napoleon sees it (``Attributes``, ``Class attributes`` and
``Parameters`` sections; an entry already in numpy form, ``name : type``, ends the rewriting of its section); several names sharing one text (``a, b: text``) become one entry each."""

from __future__ import annotations

import re

_ENTRY = re.compile(r"^([A-Za-z_][A-Za-z0-9_]*(?:\s*,\s*[A-Za-z_][A-Za-z0-9_]*)*):\s+(.*)$")
SECTIONS = ("Attributes", "Class attributes", "Parameters")


def rewrite(lines: list[str]) -> list[str]:
    """The docstring ``lines`` with every ``name: text`` entry of an attributes section in numpy form."""
    out: list[str] = []
    i = 0
    while i < len(lines):
        line = lines[i]
        if line.strip() in SECTIONS and i + 1 < len(lines) and set(lines[i + 1].strip()) == {"-"}:
            out += [line, lines[i + 1]]
            i += 2
            entries: list[tuple[list[str], list[str]]] = []
            while i < len(lines):
                current = lines[i]
                match = _ENTRY.match(current)
                if match and not current[0].isspace():
                    entries.append(([n.strip() for n in match.group(1).split(",")], [match.group(2).strip()]))
                elif entries and current.strip() and current[0].isspace():
                    entries[-1][1].append(current.strip())
                else:
                    break
                i += 1
            for names, text in entries:
                for name in names:
                    out.append(name)
                    out += ["    " + part for part in text]
            continue
        out.append(line)
        i += 1
    return out


def _process(app, what, name, obj, options, lines) -> None:
    lines[:] = rewrite(lines)


def setup(app):
    app.setup_extension("sphinx.ext.autodoc")
    app.connect("autodoc-process-docstring", _process, priority=400)  # before napoleon (500)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
