"""Dotted scene keys: change fields of a scene by name (``recoil run --set``, ``recoil sweep --param``).

A key names one field the way the TOML file would (DESIGN.md "Scene format"):

* ``recoil_spring.stiffness``, ``recoil_brake.orifice_area``, ``firing.pulse.scale_to_momentum``: a field
  of a table (or of a sub-table) the scene has;
* ``absorber.0.contact.gap``, ``absorber.1.mass``: the absorber of that 0-based index;
* ``absorber.mass``, ``absorber.contact.law``, ``contact.gap``: the scene's one absorber (and its contact),
  in a scene with exactly one absorber, whatever the file's version;
* ``conventions.literal_gap_sign``, ``name``.

:func:`apply_overrides` changes every named field at once and then checks the changed tables and the scene
exactly as a file is checked (the element tables' rules, the scene's cross-checks).  Every problem -- an
unknown key (with a "did you mean"), a table the scene lacks, an index out of range, a wrong type or
value -- is one :class:`~mbs_models.errors.SceneError` naming the key as the caller wrote it.

Changing a contact's ``law`` drops the fields of the old law that the new law does not have (a
``hunt-crossley`` contact's ``damping_factor`` when it becomes ``hertz``); fields the new law needs and the
old one lacked must be given beside it (``contact.law = "flores"`` with ``contact.restitution = 0.5``).

:func:`parse_value` reads a value as TOML would (``500``, ``1e-3``, ``true``, ``"flores"``,
``[[0.0, 3e-4], [0.3, 1e-4]]``; a bare word such as ``flores`` is that string); :func:`parse_spec` reads
the values a sweep gives a key: ``100,500,1000`` or ``START:STOP:COUNT`` (both ends included).
"""

from __future__ import annotations

import math
from dataclasses import fields, replace
from typing import Any, Mapping

from ..elements import ELEMENT_TABLES, Table, on_register
from ..elements.contact_laws import CONTACT_LAWS, LAW_FIELDS
from ..elements.table import rekey, suggestion
from ..errors import SceneError
from ..inputs import check_toml_nesting
from .container import Conventions, Scene

_SINGLE_TABLES: list[str] = []
#: Arrays of tables other than the absorbers (``[[tabulated_spring]]``): table name -> the scene's attribute.
_ARRAY_TABLES: dict[str, str] = {}
_TOP_LEVEL: list[str] = []


def _refresh_views() -> None:
    """The keys a dotted override may start with (again after :func:`~mbs_models.register_element`)."""
    _SINGLE_TABLES[:] = [name for name in ELEMENT_TABLES if not ELEMENT_TABLES.many(name)]
    _ARRAY_TABLES.clear()
    _ARRAY_TABLES.update((name, name + "s") for name in ELEMENT_TABLES
                         if ELEMENT_TABLES.many(name) and name != "absorber")
    _TOP_LEVEL[:] = sorted(["name", "conventions", "contact", "absorber", *_SINGLE_TABLES, *_ARRAY_TABLES])


_refresh_views()
on_register(_refresh_views)


# ================================================================================================ keys
def resolve_key(scene: Scene, key: str) -> tuple[str, int | None, tuple[str, ...]]:
    """Where ``key`` points in ``scene``: ``(table, absorber index or None, field path)``.

    ``table`` is ``"absorbers"`` (with the index), ``"conventions"``, ``"name"`` or a single table's name;
    the path names fields from that table down (``("contact", "gap")``).  Raises :class:`SceneError`
    naming ``key`` if it does not name an existing field of the scene.
    """
    if not isinstance(key, str) or not key or any(not part for part in key.split(".")):
        raise SceneError(str(key), "not a dotted scene key (e.g. contact.gap, absorber.mass, "
                                   "recoil_spring.stiffness)")
    head, *rest = key.split(".")
    if head == "name":
        if rest:
            raise SceneError(key, "name is a value, not a table")
        return "name", None, ()
    if head == "conventions":
        names = [f.name for f in fields(Conventions)]
        if len(rest) != 1:
            raise SceneError(key, f"names {'the table' if not rest else 'too much'}: give one flag, "
                                  f"conventions.<flag> ({', '.join(names)})")
        if rest[0] not in names:
            raise SceneError(key, f"unknown key{suggestion(rest[0], names)}")
        return "conventions", None, (rest[0],)
    if head in ("absorber", "contact"):
        absorbers = scene.absorbers
        if head == "absorber" and rest and rest[0].isdigit():
            index = int(rest[0])
            if index >= len(absorbers):
                raise SceneError(key, f"the scene has {len(absorbers)} absorber(s): index {index} does not exist "
                                      f"(indices start at 0)")
            rest = rest[1:]
        else:
            if len(absorbers) != 1:
                field = ".".join(([head] if head == "contact" else []) + rest) or "..."
                raise SceneError(key, "the scene has no absorber" if not absorbers else
                                 f"the scene has {len(absorbers)} absorbers: name one as absorber.N.{field}")
            index = 0
        if head == "contact":
            rest = ["contact", *rest]
        return "absorbers", index, _field_path(absorbers[index], rest, key)
    if head in _ARRAY_TABLES:  # an array of tables: head.N.field, or head.field when the scene has one
        items = getattr(scene, _ARRAY_TABLES[head])
        if rest and rest[0].isdigit():
            index = int(rest[0])
            if index >= len(items):
                raise SceneError(key, f"the scene has {len(items)} [[{head}]] table(s): index {index} does not "
                                      f"exist (indices start at 0)")
            rest = rest[1:]
        elif len(items) != 1:
            raise SceneError(key, f"the scene has no [[{head}]] table to change" if not items else
                             f"the scene has {len(items)} [[{head}]] tables: name one as {head}.N.{'.'.join(rest)}")
        else:
            index = 0
        return _ARRAY_TABLES[head], index, _field_path(items[index], rest, key)
    if head in _SINGLE_TABLES:
        table = getattr(scene, head)
        if table is None:
            raise SceneError(key, f"the scene has no [{head}] table to change")
        return head, None, _field_path(table, rest, key)
    raise SceneError(key, f"unknown key{suggestion(head, _TOP_LEVEL)}")


def _field_path(table: Table, path: list[str], key: str) -> tuple[str, ...]:
    """Check that ``path`` names a field of ``table`` (through its sub-tables)."""
    if not path:
        raise SceneError(key, "names a table, not a field: add the field (e.g. "
                              f"{key}.{table.field_names()[0]})")
    current = table
    path = list(path)
    depth = 0
    while depth < len(path):
        name = path[depth]
        names = type(current).field_names()
        if name not in names:
            raise SceneError(key, f"unknown key{suggestion(name, names)}")
        many = type(current).NESTED_MANY.get(name)
        if many is not None:  # an array of sub-tables: name.N.field
            items = getattr(current, name)
            if depth + 1 >= len(path) or not path[depth + 1].isdigit():
                raise SceneError(key, f"names the array [[{name}]]: add an index and a field (e.g. "
                                      f"{key}.0.{many.field_names()[0]})")
            index = int(path[depth + 1])
            if index >= len(items):
                raise SceneError(key, f"the scene has {len(items)} [[{type(current).TABLE}.{name}]] table(s): index "
                                      f"{index} does not exist (indices start at 0)")
            if depth + 2 >= len(path):
                raise SceneError(key, f"names a table, not a field: add the field (e.g. "
                                      f"{key}.{many.field_names()[0]})")
            current = items[index]
            depth += 2
            continue
        nested = type(current).NESTED.get(name)
        last = depth == len(path) - 1
        if nested is not None and last:
            raise SceneError(key, f"names the table [{name}], not a field: add the field "
                                  f"(e.g. {key}.{nested.field_names()[0]})")
        if not last:
            if nested is None:
                raise SceneError(key, f"{name} is a value, not a table: set it whole")
            current = getattr(current, name)
            if current is None:
                raise SceneError(key, f"the scene has no [{name}] table to change")
        depth += 1
    return tuple(path)


def check_keys(scene: Scene, keys) -> list[str]:
    """The keys, each checked to name a field of ``scene`` (:func:`resolve_key`), none twice."""
    seen: dict[tuple, str] = {}
    out = []
    for key in keys:
        place = resolve_key(scene, key)
        if place in seen:
            raise SceneError(key, f"names the same field as {seen[place]}: give it once")
        seen[place] = key
        out.append(key)
    return out


# ================================================================================================ values
def apply_overrides(scene: Scene, overrides: Mapping[str, Any]) -> Scene:
    """A copy of ``scene`` with every dotted key of ``overrides`` set to its value, checked as a file is.

    ``apply_overrides(model_i(500.0, 0.0), {"absorber.mass": 1000.0, "contact.gap": 0.01})``.  The
    values are those a TOML file would hold (numbers, booleans, strings, lists); all keys are applied
    before any check, so that fields which depend on each other (a contact's law and its fields) can change
    together.  Raises :class:`SceneError` naming the key.
    """
    if not isinstance(scene, Scene):
        raise SceneError("scene", f"must be a Scene, got {type(scene).__name__}")
    if not overrides:
        return scene
    # (table, index) -> {"key": the first user key that touched it, "tree": nested {field: value | subtree}}
    groups: dict[tuple[str, int | None], dict[str, Any]] = {}
    name = scene.name
    seen: dict[tuple, str] = {}
    for key, value in overrides.items():
        table, index, path = resolve_key(scene, key)
        place = (table, index, path)
        if place in seen:
            raise SceneError(key, f"names the same field as {seen[place]}: give it once")
        seen[place] = key
        if table == "name":
            if not isinstance(value, str):
                raise SceneError(key, f"must be a string, got {type(value).__name__} {value!r}")
            name = value
            continue
        group = groups.setdefault((table, index), {"tree": {}, "keys": {}})
        node = group["tree"]
        for depth, part in enumerate(path[:-1]):
            node = node.setdefault(part, {})
            group["keys"].setdefault(path[:depth + 1], _prefix(key, len(path) - depth - 1))
        node[path[-1]] = value
        group["keys"].setdefault((), _prefix(key, len(path)) or _canonical(scene, table, index))
    conventions = scene.conventions
    arrays: dict[str, list] = {}   # "absorbers", "tabulated_springs": the changed arrays of tables
    tables: dict[str, Any] = {}
    for (table, index), group in groups.items():
        if table == "conventions":
            try:
                conventions = replace(conventions, **group["tree"])
            except SceneError as exc:
                raise exc from None
        elif index is not None:
            items = arrays.setdefault(table, list(getattr(scene, table)))
            items[index] = _rebuild(items[index], group["tree"], group["keys"], ())
        else:
            tables[table] = _rebuild(getattr(scene, table), group["tree"], group["keys"], ())
    changes: dict[str, Any] = dict(tables)
    changes.update((table, tuple(items)) for table, items in arrays.items())
    if conventions is not scene.conventions:
        changes["conventions"] = conventions
    if name != scene.name:
        changes["name"] = name
    return scene.with_changes(**changes)


def _canonical(scene: Scene, table: str, index: int | None) -> str:
    """The key of a table as the file names it (``absorber``, ``absorber.1``, ``recoil_brake``)."""
    if index is not None:  # an array of tables: "absorbers" -> absorber, absorber.1
        head = table[:-1]
        return head if len(getattr(scene, table)) == 1 else f"{head}.{index}"
    return table


def _prefix(key: str, drop: int) -> str:
    """``key`` without its last ``drop`` parts (the place of a table as the user named it)."""
    return key if drop == 0 else ".".join(key.split(".")[:-drop])


def _rebuild(table: Table, tree: dict[str, Any], keys: dict[tuple, str], at: tuple[str, ...]) -> Table:
    """``table`` with the fields of ``tree`` set (sub-tables rebuilt first); errors name the user's key."""
    changes: dict[str, Any] = {}
    for field, value in tree.items():
        if field in type(table).NESTED and isinstance(value, dict):
            changes[field] = _rebuild(getattr(table, field), value, keys, at + (field,))
        elif field in type(table).NESTED_MANY and isinstance(value, dict):
            items = list(getattr(table, field))
            for index, subtree in value.items():
                items[int(index)] = _rebuild(items[int(index)], subtree, keys, at + (field, index))
            changes[field] = tuple(items)
        else:
            changes[field] = value
    law = changes.get("law")
    if isinstance(law, str) and law in CONTACT_LAWS and law != getattr(table, "law", law):
        allowed = CONTACT_LAWS[law].fields + CONTACT_LAWS[law].optional
        for field in LAW_FIELDS:  # the old law's fields the new one does not have
            if field not in allowed and field not in changes and getattr(table, field, None) is not None:
                changes[field] = None
    try:
        return replace(table, **changes)
    except SceneError as exc:
        raise rekey(exc, table.TABLE, keys[at]) from None
    except TypeError as exc:  # pragma: no cover - resolve_key has checked the names
        raise SceneError(keys[at], str(exc)) from None


# ================================================================================================ text
def parse_value(text: str, key: str = "") -> Any:
    """A value as TOML reads it (``500`` int, ``1e-3`` float, ``true``, ``"x"``, ``[1, 2]``); text that is no
    TOML value is that text (``flores``).  ``key`` names the value in errors."""
    if not isinstance(text, str):
        return text
    stripped = text.strip()
    if not stripped:
        raise SceneError(key, "no value given")
    check_toml_nesting(stripped, key, "the value")  # before the parser recurses once per level
    import tomllib  # (imported here: only a value given as text is parsed)

    try:
        value = tomllib.loads(f"value = {stripped}")["value"]
    except tomllib.TOMLDecodeError:
        if stripped[0] in "[{\"'":
            raise SceneError(key, f"not a TOML value: {stripped!r}") from None
        return stripped
    if isinstance(value, float) and not math.isfinite(value):
        raise SceneError(key, f"must be a finite number, got {stripped}")
    if isinstance(value, dict):
        raise SceneError(key, "a table is not a value: set its fields one by one")
    return value


def parse_assignment(text: str, what: str = "--set", example: str = "KEY=VALUE (e.g. contact.gap=0.01)"
                     ) -> tuple[str, str]:
    """``"KEY=VALUE"`` -> ``(KEY, VALUE)`` (both stripped), or a SceneError naming ``what``."""
    key, sep, value = text.partition("=")
    key, value = key.strip(), value.strip()
    if not sep or not key:
        raise SceneError(what, f"expected {example}, got {text!r}")
    if not value:
        raise SceneError(key, "no value given after '='")
    return key, value


def _shortest(value: float) -> float:
    """The shortest decimal within 4 ulp of ``value``: a range's point without the round-off of its
    computation (``1e-4:3e-4:5`` has 0.0002, not 0.00019999999999999998; 1/3 stays 1/3)."""
    for digits in range(1, 18):
        candidate = float(f"{value:.{digits}g}")
        if abs(candidate - value) <= 4 * math.ulp(value):
            return candidate
    return value


def _spec_text(spec: str, key: str) -> str:
    if not isinstance(spec, str):
        raise SceneError(key, f"must be a text spec (100,500,1000 or START:STOP:COUNT), got {spec!r}")
    text = spec.strip()
    if not text:
        raise SceneError(key, "no values given (use 100,500,1000 or START:STOP:COUNT)")
    return text


def _range(text: str, key: str) -> tuple[float, float, int]:
    """``START:STOP:COUNT`` read and checked: (start, stop, count)."""
    parts = [p.strip() for p in text.split(":")]
    if len(parts) != 3:
        raise SceneError(key, f"a range is START:STOP:COUNT (e.g. 0:0.12:13), got {text!r}")
    try:
        start, stop = float(parts[0]), float(parts[1])
    except ValueError:
        raise SceneError(key, f"START and STOP of {text!r} must be numbers") from None
    if not (math.isfinite(start) and math.isfinite(stop)):
        raise SceneError(key, f"START and STOP of {text!r} must be finite numbers")
    try:
        count = int(parts[2])
    except ValueError:
        raise SceneError(key, f"COUNT of {text!r} must be a whole number >= 2, got {parts[2]!r}") from None
    if count < 2:
        raise SceneError(key, f"COUNT of {text!r} must be a whole number >= 2 (both ends are included), "
                              f"got {count}")
    return start, stop, count


def spec_size(spec: str, key: str = "") -> int:
    """How many values :func:`parse_spec` gives ``spec``, without making them (a range's COUNT is read, not
    generated: a grid's size is known before a ``0:1:10000000000`` fills the memory)."""
    text = _spec_text(spec, key)
    if not text.startswith("[") and ":" in text:
        return _range(text, key)[2]
    return len(parse_spec(text, key))


def parse_spec(spec: str, key: str = "") -> list[Any]:
    """The values of a sweep parameter: ``"100,500,1000"`` (a list of TOML values), ``"0:0.12:13"``
    (``START:STOP:COUNT``: COUNT evenly spaced numbers, both ends included exactly, each point the shortest
    decimal within 4 ulp of ``START + i (STOP - START) / (COUNT - 1)``: no round-off noise) or ``"[...]"`` (a
    TOML array, whose items may themselves be lists).  ``key`` names the parameter in errors."""
    text = _spec_text(spec, key)
    if text.startswith("["):
        values = parse_value(text, key)
        if not isinstance(values, list) or not values:
            raise SceneError(key, f"must be a non-empty TOML array, got {text!r}")
        return values
    if ":" in text:
        start, stop, count = _range(text, key)
        step = (stop - start) / (count - 1)
        return [start] + [_shortest(start + i * step) for i in range(1, count - 1)] + [stop]
    items = [item.strip() for item in text.split(",")]
    if any(not item for item in items):
        raise SceneError(key, f"an empty item in the list {text!r}")
    return [parse_value(item, key) for item in items]


__all__ = ["apply_overrides", "check_keys", "resolve_key", "parse_value", "parse_spec", "spec_size",
           "parse_assignment"]
