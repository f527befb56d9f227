"""The scene format's key reference, read from the elements' own declarations (no second list to keep).

Every key of a scene table is a field of its :class:`~mbs_models.elements.table.Table` dataclass, and the table
declares the rest next to its fields:

* the **description**: the ``Attributes`` section of the table class's docstring, one entry per key
  (``name: text``, continuation lines indented; ``a, b: text`` describes several keys at once), inherited from
  base classes;
* the **unit**: the key's :class:`~mbs_models.elements.table.Rule` ``unit`` (the one its error messages name), or,
  for a key without a unit in its rule (a pure number, a string, a table of pairs), the class attribute
  ``KEY_UNITS`` (``"1"`` for a dimensionless number, ``"text"``, ``"true/false"``, ``"[[m, m^2], ...]"``...);
* the **allowed range**: :meth:`Rule.describe` (without the unit);
* the **choices**: the class attribute ``CHOICES`` (key -> the allowed strings, the tuple its check uses);
* the **default**: the dataclass default, or *required*.

:func:`key_reference` gives all of it for every table of :data:`~mbs_models.elements.TABLES`, nested tables
under their parent (``[[carriage.support]]``), plus the scene-level keys and ``[conventions]``;
:func:`missing_declarations` lists every key that lacks a description or a unit (a test keeps it empty).
The docs build renders it (``docs/_ext/key_reference.py``).  Imports no Exudyn.
"""

from __future__ import annotations

import dataclasses
import inspect
import re
from dataclasses import MISSING, dataclass

from ..elements import ELEMENT_TABLES, TABLES
from ..elements.table import Rule, Table
from .container import Conventions
from .io import FORMAT_VERSIONS

_ENTRY = re.compile(r"^([A-Za-z_][A-Za-z0-9_]*(?:\s*,\s*[A-Za-z_][A-Za-z0-9_]*)*):\s+(.*)$")

#: The keys at the top of a scene file (not in a table): their unit, default and description.
SCENE_KEYS = {
    "version": ("1", "1", f"the scene format version, one of {', '.join(map(str, FORMAT_VERSIONS))}; version 2 "
                          f"has the richer mechanisms (several absorbers, stops, brake, ...); version 1 reads "
                          f"unchanged"),
    "name": ("text", '"unnamed scene"', "the scene's name, shown in outputs and reports"),
}


@dataclass(frozen=True)
class KeyEntry:
    """One key of a scene table: ``key`` (the TOML name), its ``unit``, allowed ``range`` (words), ``default``
    (as TOML would write it, or ``required``), ``choices`` (allowed strings, empty if not a choice) and
    ``description`` (one paragraph).  ``unit`` or ``description`` is ``""`` when undeclared."""

    key: str
    unit: str
    range: str
    default: str
    choices: tuple[str, ...]
    description: str


@dataclass(frozen=True)
class TableReference:
    """The reference of one table: its TOML ``header`` (``[[absorber]]``, ``[absorber.contact]``), the class,
    the first scene-format ``version`` that has it, its one-line ``summary`` and its keys."""

    header: str
    cls: type
    version: int
    summary: str
    keys: tuple[KeyEntry, ...]


def attribute_descriptions(cls: type) -> dict[str, str]:
    """``{key: description}`` from the ``Attributes`` sections of ``cls``'s docstring and its bases' (the
    class's own entries win); each description is its entry's lines joined into one paragraph."""
    out: dict[str, str] = {}
    for klass in reversed(cls.__mro__):
        doc = klass.__dict__.get("__doc__")
        if doc:
            out.update(_parse_attributes(inspect.cleandoc(doc)))
    return out


def _parse_attributes(doc: str) -> dict[str, str]:
    lines = doc.splitlines()
    for i in range(len(lines) - 1):
        if lines[i].strip() == "Attributes" and set(lines[i + 1].strip()) == {"-"}:
            break
    else:
        return {}
    entries: list[tuple[list[str], list[str]]] = []
    for line in lines[i + 2:]:
        if not line.strip():
            if entries:
                break
            continue
        match = _ENTRY.match(line)
        if match and not line[0].isspace():
            entries.append(([name.strip() for name in match.group(1).split(",")], [match.group(2).strip()]))
        elif entries and line[0].isspace():
            entries[-1][1].append(line.strip())
        else:
            break
    return {name: " ".join(text) for names, text in entries for name in names}


def _summary(cls: type) -> str:
    doc = inspect.getdoc(cls) or ""
    return " ".join(doc.split("\n\n")[0].split())


def _default(field: dataclasses.Field) -> str:
    if field.default is not MISSING:
        value = field.default
    elif field.default_factory is not MISSING:
        value = field.default_factory()
    else:
        return "required"
    if value is None:
        return "none"
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, str):
        return f'"{value}"'
    if isinstance(value, float):
        return f"{value:g}"
    if isinstance(value, tuple) and not value:
        return "none"
    return repr(value)


def _unit(cls: type, name: str) -> str:
    rule = getattr(cls, "RULES", {}).get(name)
    if isinstance(rule, Rule) and rule.unit:
        return rule.unit
    if name in getattr(cls, "NESTED", {}) or name in getattr(cls, "NESTED_MANY", {}):
        return "table"
    return getattr(cls, "KEY_UNITS", {}).get(name, "")


def _range(cls: type, name: str) -> str:
    rule = getattr(cls, "RULES", {}).get(name)
    if not isinstance(rule, Rule):
        return ""
    return dataclasses.replace(rule, unit="").describe()


def table_keys(cls: type) -> tuple[KeyEntry, ...]:
    """Every key of the table class ``cls`` (its dataclass fields, in order), as declared."""
    descriptions = attribute_descriptions(cls)
    choices = getattr(cls, "CHOICES", {})
    return tuple(KeyEntry(key=f.name, unit=_unit(cls, f.name), range=_range(cls, f.name), default=_default(f),
                          choices=tuple(choices.get(f.name, ())), description=descriptions.get(f.name, ""))
                 for f in dataclasses.fields(cls))


def _header(path: str, many: bool) -> str:
    return f"[[{path}]]" if many else f"[{path}]"


def key_reference() -> list[TableReference]:
    """The reference of every scene table in the scene's element order, each followed by its nested tables
    (depth first), then ``[conventions]``.  The scene-level keys are :data:`SCENE_KEYS`."""
    out: list[TableReference] = []

    def visit(path: str, cls: type, many: bool) -> None:
        out.append(TableReference(_header(path, many), cls, cls.SINCE_VERSION, _summary(cls), table_keys(cls)))
        for name, nested in cls.NESTED.items():
            visit(f"{path}.{name}", nested, False)
        for name, nested in cls.NESTED_MANY.items():
            visit(f"{path}.{name}", nested, True)

    for name, cls in ELEMENT_TABLES.items():
        visit(name, cls, cls.MANY)
    out.append(TableReference("[conventions]", Conventions, 1, _summary(Conventions), table_keys(Conventions)))
    return out


def all_table_classes() -> list[type]:
    """Every table class whose keys the reference lists: :data:`TABLES` (nested ones included) and Conventions."""
    return [*dict.fromkeys(TABLES.values()), Conventions]


def missing_declarations() -> list[str]:
    """``"Class.key: what is missing"`` for every key of every table without a description or a unit, and
    every ``Attributes`` entry or ``KEY_UNITS`` / ``CHOICES`` key that names no field (a stale declaration)."""
    problems = []
    for cls in all_table_classes():
        names = {f.name for f in dataclasses.fields(cls)}
        for entry in table_keys(cls):
            if not entry.description:
                problems.append(f"{cls.__name__}.{entry.key}: no description (an entry in its Attributes section)")
            if not entry.unit:
                problems.append(f"{cls.__name__}.{entry.key}: no unit (a Rule unit or a KEY_UNITS entry)")
        for where, declared in (("Attributes", attribute_descriptions(cls)),
                                ("KEY_UNITS", getattr(cls, "KEY_UNITS", {})), ("CHOICES", getattr(cls, "CHOICES", {}))):
            for name in declared:
                if name not in names:
                    problems.append(f"{cls.__name__}.{name}: in {where} but not a field")
        for name, rule in getattr(cls, "RULES", {}).items():
            if name in names and rule.unit and name in getattr(cls, "KEY_UNITS", {}):
                problems.append(f"{cls.__name__}.{name}: unit declared twice (Rule and KEY_UNITS)")
    return problems


__all__ = ["SCENE_KEYS", "KeyEntry", "TableReference", "attribute_descriptions", "table_keys", "key_reference",
           "all_table_classes", "missing_declarations"]
