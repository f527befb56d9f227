"""Reading and writing scenes: TOML versions 1 and 2.

``load_scene(path)`` is the one entry point for files; :func:`scene_from_dict` checks keys (unknown keys
with a "did you mean", missing keys, wrong table types, tables a version does not have) before the
element tables check their values.  Every problem is a :class:`~mbs_models.errors.SceneError` naming
the key as it stands in the file (``contact.gap``, ``absorber.1.contact.restitution``).

* **Version 1** (no ``version`` key, or ``version = 1``): the paper's scenes -- ``[barrel]``,
  ``[firing]``, ``[recoil_spring]``, ``[recoil_damper]`` (the last two required), at most one
  ``[absorber]`` with its ``[contact]`` (Hunt-Crossley), ``[conventions]``.  It keeps loading unchanged.
* **Version 2** (``version = 2``): every element table of :mod:`mbs_models.elements` is optional but
  ``[barrel]``; absorbers are ``[[absorber]]`` with ``[absorber.contact]`` (a version-1 ``[absorber]`` +
  ``[contact]`` pair is read as one); every element table of :data:`mbs_models.elements.TABLES`; every
  contact law.

:func:`scene_to_toml` writes version 2.
"""

from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path
from typing import Any

from ..elements import ELEMENT_TABLES
from ..elements.contact_laws import Contact
from ..elements.firing import SCENE_DIRECTORY
from ..elements.table import suggestion
from ..errors import SceneError
from ..inputs import parse_toml, read_text_file
from .container import Conventions, Scene

#: The scene format versions this library reads; it writes the last.
FORMAT_VERSIONS = (1, 2)
FORMAT_VERSION = FORMAT_VERSIONS[-1]
#: Tables a version-1 file must have.
_REQUIRED_V1 = ("barrel", "recoil_spring", "recoil_damper")
_TOP_LEVEL_SCALARS = ("name", "version")


def _version(data: dict) -> int:
    version = data.get("version", 1)
    if isinstance(version, bool) or version not in FORMAT_VERSIONS:
        raise SceneError("version", f"unsupported scene format version {version!r}; this library reads "
                                    f"{' and '.join(str(v) for v in FORMAT_VERSIONS)}")
    return int(version)


def _absorber_entries(data: dict, version: int) -> list[tuple[str, Any]]:
    """``(key, mapping)`` of every absorber in the file: ``[absorber]`` (one) or ``[[absorber]]``."""
    content = data.get("absorber")
    if content is None:
        return []
    if isinstance(content, dict):
        return [("absorber", content)]
    if isinstance(content, list) and version >= 2:
        if len(content) == 1:
            return [("absorber", content[0])]
        return [(f"absorber.{i}", item) for i, item in enumerate(content)]
    if isinstance(content, list):
        raise SceneError("absorber", "several absorbers ([[absorber]]) need a version-2 scene "
                                     "(put version = 2 at the top)")
    raise SceneError("absorber", f"must be a table [absorber], got {type(content).__name__}")


def version_2_tables(data: dict) -> list[tuple[str, str]]:
    """The tables of a parsed scene file that only version 2 has: ``(key, the table as the file spells it)``
    for ``[[absorber]]``, ``[absorber.contact]``, ``[firing.pulse]`` and every table of a later version
    (``[recoil_brake]``, ``[recuperator]``, ``[burst]``, ``[cradle]``, the stops), in the file's order."""
    found = []
    for table, content in data.items():
        cls = ELEMENT_TABLES.get(table)
        if cls is None:
            continue
        if isinstance(content, list):
            found.append((table, f"[[{table}]]"))
        elif cls.SINCE_VERSION > 1:
            found.append((table, f"[{table}]"))
        for entry in content if isinstance(content, list) else [content]:
            if not isinstance(entry, dict):
                continue
            for name, nested in cls.NESTED.items():
                # a version-1 absorber's contact is the top-level [contact]; the nested one is version 2's
                if name in entry and (nested.SINCE_VERSION > 1 or cls.MANY):
                    found.append((f"{table}.{name}", f"[{table}.{name}]"))
            for name in cls.NESTED_MANY:
                if name in entry:
                    found.append((f"{table}.{name}", f"[[{table}.{name}]]"))
    return list(dict.fromkeys(found))


def scene_from_dict(data: dict[str, Any]) -> Scene:
    """Build a validated :class:`Scene` from a parsed TOML mapping (version 1 or 2)."""
    if not isinstance(data, dict):
        raise SceneError("", "a scene must be a table of tables")
    allowed = list(ELEMENT_TABLES) + ["contact", "conventions"] + list(_TOP_LEVEL_SCALARS)
    for key in data:
        if key not in allowed:
            raise SceneError(key, f"unknown key{suggestion(key, allowed)}")
    version = _version(data)
    newer = version_2_tables(data) if version == 1 else []
    if newer:  # before the version-1 checks: a version-2 file without its version key is no version-1 file
        said = "says version = 1" if "version" in data else "has no version key"
        raise SceneError(newer[0][0], f"the file uses tables of a version-2 scene "
                                      f"({', '.join(spelled for _, spelled in newer)}) but {said}: "
                                      f"add version = 2 at the top")
    if version == 1:
        for table in _REQUIRED_V1:
            if table not in data:
                raise SceneError(table, f"missing required table [{table}]")
    elif "barrel" not in data:
        raise SceneError("barrel", "missing required table [barrel]")

    tables: dict[str, Any] = {}
    for table in ELEMENT_TABLES:
        if table not in data:
            continue
        cls = ELEMENT_TABLES[table]
        if cls.SINCE_VERSION > version:
            raise SceneError(table, f"[{table}] needs a version-{cls.SINCE_VERSION} scene "
                                    f"(put version = {cls.SINCE_VERSION} at the top)")
        if cls.MANY:
            if table != "absorber":  # an array of tables: [[table]] (one table [table] is an array of one)
                entries = data[table] if isinstance(data[table], list) else [data[table]]
                tables[table + "s"] = tuple(cls.from_mapping(entry, table if len(entries) == 1 else f"{table}.{i}",
                                                             version) for i, entry in enumerate(entries))
            continue
        tables[table] = cls.from_mapping(data[table], table, version)
    absorbers = [ELEMENT_TABLES["absorber"].from_mapping(content, key, version)
                 for key, content in _absorber_entries(data, version)]
    if "contact" in data:
        if len(absorbers) != 1:
            raise SceneError("absorber", "missing: a [contact] table needs an [absorber] to touch"
                             if not absorbers else "a top-level [contact] needs exactly one absorber: give each "
                                                   "[[absorber]] its own [absorber.contact]")
        if absorbers[0].contact is not None:
            raise SceneError("contact", "given twice: as [contact] and as [absorber.contact]")
        contact = Contact.from_mapping(data["contact"], "contact", version)
        absorbers[0] = replace(absorbers[0], contact=contact)
    elif version == 1 and absorbers:
        raise SceneError("contact", "missing: an [absorber] needs a [contact] table (wall A drives it)")
    conventions = Conventions()
    if "conventions" in data:
        conventions = _conventions(data["conventions"])
    name = data.get("name", "unnamed scene")
    return Scene(name=name, conventions=conventions, absorbers=tuple(absorbers), **tables)


def _conventions(content) -> Conventions:
    if not isinstance(content, dict):
        raise SceneError("conventions", f"must be a table [conventions], got {type(content).__name__}")
    names = [name for name in Conventions.__dataclass_fields__]
    for key in content:
        if key not in names:
            raise SceneError(f"conventions.{key}", f"unknown key{suggestion(key, names)}")
    return Conventions(**content)


def load_scene(path: str | Path) -> Scene:
    """Read a scene TOML file; raise :class:`SceneError` for unreadable, malformed or invalid files (and for a
    file that is not a regular UTF-8 file of at most 64 MiB, or nests more than 32 deep: :mod:`mbs_models.inputs`)."""
    path = Path(path)
    text = read_text_file(path, "", "scene file")  # a regular UTF-8 file of at most MAX_INPUT_BYTES
    data = parse_toml(text, "", str(path))           # nesting bounded before the parser recurses
    token = SCENE_DIRECTORY.set(path.resolve().parent)  # relative file names in the scene: beside it
    try:
        return scene_from_dict(data)
    finally:
        SCENE_DIRECTORY.reset(token)


def scene_to_dict(scene: Scene) -> dict[str, Any]:
    """The version-2 TOML mapping of a scene (inverse of :func:`scene_from_dict`); omits absent tables."""
    out: dict[str, Any] = {"version": FORMAT_VERSION, "name": scene.name}
    for table in ELEMENT_TABLES:
        if ELEMENT_TABLES.many(table):
            items = getattr(scene, table + "s")
            if items:
                out[table] = [item.to_mapping() for item in items]
            continue
        value = getattr(scene, table)
        if value is not None:
            out[table] = value.to_mapping()
    active = {name: True for name in scene.conventions.active}
    if active:
        out["conventions"] = active
    return out


def _toml_value(value: Any) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        if not math.isfinite(value):
            raise SceneError("", f"cannot write non-finite number {value}")
        return repr(value)
    if isinstance(value, int):
        return str(value)
    if isinstance(value, str):
        return '"' + value.replace("\\", "\\\\").replace('"', '\\"') + '"'
    if isinstance(value, (list, tuple)):  # an array of values (e.g. a table of (stroke, area) pairs)
        return "[" + ", ".join(_toml_value(item) for item in value) + "]"
    raise TypeError(f"cannot write {type(value).__name__} to TOML")


def _table_lines(header: str, values: dict[str, Any], path: str) -> list[str]:
    lines = ["", header]
    nested = []
    for key, value in values.items():
        if isinstance(value, dict) or (isinstance(value, list) and value and all(isinstance(v, dict) for v in value)):
            nested.append((key, value))
        else:
            lines.append(f"{key} = {_toml_value(value)}")
    for key, value in nested:
        if isinstance(value, list):  # an array of sub-tables: [[path.key]]
            for item in value:
                lines += _table_lines(f"[[{path}.{key}]]", item, f"{path}.{key}")
        else:
            lines += _table_lines(f"[{path}.{key}]", value, f"{path}.{key}")
    return lines


def scene_to_toml(scene: Scene) -> str:
    """Serialise a scene to version-2 TOML text (round-trips through :func:`load_scene`)."""
    return mapping_to_toml(scene_to_dict(scene))


def mapping_to_toml(data: dict[str, Any]) -> str:
    """TOML text of a scene mapping (scalars at the top, tables, arrays of tables with their sub-tables)."""
    data = dict(data)
    lines = [f"{key} = {_toml_value(data.pop(key))}" for key in list(data) if not isinstance(data[key], (dict, list))]
    for table, values in data.items():
        if isinstance(values, list):
            for item in values:
                lines += _table_lines(f"[[{table}]]", item, table)
        else:
            lines += _table_lines(f"[{table}]", values, table)
    return "\n".join(lines) + "\n"


__all__ = ["FORMAT_VERSION", "FORMAT_VERSIONS", "load_scene", "version_2_tables", "scene_from_dict", "scene_to_dict", "scene_to_toml",
           "mapping_to_toml"]
