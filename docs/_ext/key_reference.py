"""Generate ``reference/keys.md``, the scene format's key reference, from the tables' own declarations
(:func:`mbs_models.scene.keys.key_reference`) at every build: it cannot drift from the code, and the test
``tests/docs/test_key_reference.py`` fails if a key has no description or unit to show."""

from __future__ import annotations

from pathlib import Path

from _write import markdown_cell, write_if_changed

from mbs_models.scene.keys import SCENE_KEYS, key_reference

INTRO = """\
# Scene keys

Every key of every table of a scene file, generated from the tables' own declarations when these pages are built:
the unit and the allowed range are the ones the key is checked against (a value outside gives a one-line
`SceneError` naming the key and the range; nothing is clamped), the default is the one the table takes when the key
is absent (*required*: the file must give it), and the description is the table's docstring. Units are SI; `1` is a
dimensionless number. Version-2 tables need `version = 2` at the top of the file. The same keys, dotted
(`absorber.contact.gap`, `carriage.support.1.stiffness`), are the override keys of `recoil sweep`, `recoil optimise`
and `--set`.
"""


def _row(cells: list[str]) -> str:
    first, *rest = cells
    return "* - " + first + "".join("\n  - " + cell for cell in rest)


def _table(rows: list[list[str]]) -> str:
    header = ["Key", "Unit", "Allowed", "Default", "Description"]
    body = "\n".join(_row(row) for row in [header, *rows])
    return (":::{list-table}\n:header-rows: 1\n:class: key-reference\n:widths: 18 12 16 10 44\n\n"
            f"{body}\n:::\n")


def _allowed(entry) -> str:
    if entry.choices:
        return "one of " + ", ".join(f"`{choice}`" for choice in entry.choices)
    return f"`{entry.range}`" if entry.range else "—"


def render() -> str:
    parts = [INTRO, "## Top-level keys\n",
             _table([[f"`{key}`", unit, "—", f"`{default}`", markdown_cell(text)]
                     for key, (unit, default, text) in SCENE_KEYS.items()])]
    for table in key_reference():
        since = f" *(version {table.version})*" if table.version > 1 else ""
        parts.append(f"## `{table.header}`{since}\n\n{markdown_cell(table.summary)}\n")
        parts.append(_table([[f"`{entry.key}`", f"`{entry.unit}`" if entry.unit else "—", _allowed(entry),
                              entry.default if entry.default == "required" else f"`{entry.default}`",
                              markdown_cell(entry.description)] for entry in table.keys]))
    return "\n".join(parts)


def _generate(app) -> None:
    write_if_changed(Path(app.srcdir) / "reference" / "keys.md", render())


def setup(app):
    app.connect("builder-inited", _generate)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
